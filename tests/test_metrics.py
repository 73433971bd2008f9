"""Each metric's definition on synthetic tip paths whose answers are known by hand."""

import numpy as np
import pytest
from scipy.optimize import brentq

from kinematics.metrics import (NoSoilCrossingError, TipPath, hole_metrics, plant_events,
                                soil_crossings, vertical_extremes)
from kinematics.planting import PointMotion


def trig_path(terms_x, terms_y):
    """x, y as sums of a cos(k phi) + b sin(k phi): exact derivatives and bounds."""
    def series(terms, phi, order):
        total = np.zeros_like(phi)
        for k, a, b in terms:
            c, s = np.cos(k * phi), np.sin(k * phi)
            if order == 0:
                total += a * c + b * s
            elif order == 1:
                total += k * (-a * s + b * c)
            else:
                total += -k * k * (a * c + b * s)
        return total

    def motion(phi):
        phi = np.atleast_1d(np.asarray(phi, dtype=float))
        parts = [np.stack([series(terms_x, phi, o), series(terms_y, phi, o)], -1) for o in range(3)]
        return PointMotion(*parts)

    def bound(order):
        return float(np.hypot(sum(k**order * np.hypot(a, b) for k, a, b in terms_x),
                              sum(k**order * np.hypot(a, b) for k, a, b in terms_y)))

    return TipPath(motion=motion, attitude=lambda phi: 0.1 * np.sin(np.atleast_1d(phi)),
                   speed_bound=bound(1), acceleration_bound=bound(2))


# x = A sin(phi) + C cos(phi), y = B cos(phi): top at 0, bottom at pi
A, B, C = 60.0, 300.0, 25.0
ELLIPSE = trig_path([(1, C, A)], [(1, B, 0.0)])


def test_height_of_an_ellipse():
    low, high = vertical_extremes(ELLIPSE, steps=36)
    assert -high.value - low.value == pytest.approx(2 * B, abs=1e-9)
    assert low.argument == pytest.approx(np.pi, abs=1e-6)


@pytest.mark.parametrize("depth", [5.0, 35.0, 120.0])
@pytest.mark.parametrize("spacing", [0.0, 150.0, 200.0])
def test_hole_metrics_closed_form(depth, spacing):
    events = plant_events(ELLIPSE, depth, steps=360)
    theta = np.arccos(1 - depth / B)  # B cos(phi) = -B + depth at phi = pi -+ theta
    assert events.entry == pytest.approx(np.pi - theta, abs=1e-12)
    assert events.exit == pytest.approx(np.pi + theta, abs=1e-12)
    assert events.penetrations == 1
    hole = hole_metrics(ELLIPSE, events, spacing, steps=360)
    x_entry = A * np.sin(theta) - C * np.cos(theta) + spacing * (np.pi - theta) / np.pi
    x_exit = -A * np.sin(theta) - C * np.cos(theta) + spacing * (np.pi + theta) / np.pi
    assert hole.x_entry == pytest.approx(x_entry, abs=1e-9)
    assert hole.width == pytest.approx(abs(x_exit - x_entry), abs=1e-9)
    assert hole.verticality == pytest.approx(C * depth / B, abs=1e-9)
    # span: extent of X = A sin + C cos + S phi / pi over the soil window, by dense scan
    phi = np.linspace(np.pi - theta, np.pi + theta, 400001)
    x = A * np.sin(phi) + C * np.cos(phi) + spacing * phi / np.pi
    assert hole.span == pytest.approx(np.ptp(x), abs=1e-7)
    assert hole.span >= hole.width - 1e-12


def test_depth_beyond_the_path_has_no_crossing():
    with pytest.raises(NoSoilCrossingError) as caught:
        plant_events(ELLIPSE, 2 * B + 1.0, steps=360)
    assert caught.value.problems[0].path == "field.depth"
    assert caught.value.problems[0].code == "no_soil_crossing"


@pytest.mark.parametrize("depth", [0.0, -3.0])
def test_non_positive_depth_is_an_error(depth):
    with pytest.raises(ValueError, match="depth"):
        plant_events(ELLIPSE, depth)


def dense_crossings(path, level, start, count=2_000_001):
    """Second method: dense sampling then Brent on every sign change."""
    phi = np.linspace(start, start + 2 * np.pi, count)
    gap = path.height(phi) - level
    idx = np.flatnonzero(np.sign(gap[:-1]) != np.sign(gap[1:]))
    f = lambda s: path.height(np.array([s]))[0] - level
    return np.array([brentq(f, phi[i], phi[i + 1], xtol=1e-14) for i in idx])


def test_several_crossings_defined_choice():
    # hard case: a double dip at the bottom; the hump between the dips rises above the soil
    path = trig_path([(1, 0.0, 60.0)], [(1, 300.0, 0.0), (4, 100.0, 0.0), (1, 0.0, 8.0)])
    events = plant_events(path, 60.0, steps=720)
    reference = dense_crossings(path, events.soil_level, events.lowest - np.pi)
    assert events.penetrations == 2 == reference.size // 2
    before = reference[reference < events.lowest]
    after = reference[reference > events.lowest]
    assert events.entry == pytest.approx(before.max(), abs=1e-10)  # last crossing before
    assert events.exit == pytest.approx(after.min(), abs=1e-10)    # first crossing after


def test_dip_between_samples_is_found():
    # a harmonic whose dips are narrower than the 10-degree screening step
    path = trig_path([(1, 0.0, 60.0)], [(1, 300.0, 0.0), (25, 6.0, 0.0)])
    lowest, _ = vertical_extremes(path, steps=36)
    level = lowest.value + 40.0
    coarse, _ = soil_crossings(path, level, lowest.argument - np.pi, steps=36)
    reference = dense_crossings(path, level, lowest.argument - np.pi)
    assert coarse.size == reference.size
    np.testing.assert_allclose(coarse, reference, atol=1e-10)
