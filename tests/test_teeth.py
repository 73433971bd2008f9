"""Cutter enveloping: the involute of a circle, and simulated cuts as the second method."""

import numpy as np
import pytest
import shapely

from kinematics.arclength import ArcLengthCurve
from kinematics.pitch_curves import LimaconPitchCurve
from cadgen.gears.teeth import (CutterChoice, ToothSystem, gear_outline, simulated_rack_cut,
                          simulated_shaper_cut)
from tests.conftest import PAPER_LIMACON

ALPHA = np.radians(20.0)


def involute_deviation(outline, teeth, module):
    """Largest distance (mm) of outline points in the involute band from the nearest analytic flank.

    Tooth k is centred at angle 2 pi k / z; its flanks at radius R lie at
    +-(p/4r + inv(alpha) - inv(alpha_R)). The band runs from 0.3 m above the
    base circle and 0.8 m below the pitch circle (clear of the fillet) to the tip.
    """
    radius = teeth * module / 2
    base = radius * np.cos(ALPHA)
    r = np.linalg.norm(outline, axis=1)
    theta = np.arctan2(outline[:, 1], outline[:, 0])
    band = (r > max(base + 0.3 * module, radius - 0.8 * module)) & (r < radius + 0.99 * module)
    inv = lambda a: np.tan(a) - a
    offset = (np.pi * module / 4) / radius + inv(ALPHA) - inv(np.arccos(base / r[band]))
    centres = 2 * np.pi * np.arange(teeth) / teeth
    best = np.full(band.sum(), np.inf)
    for sign in (1.0, -1.0):
        angle = theta[band][:, None] - (centres[None, :] + sign * offset[:, None])
        best = np.minimum(best, np.abs((angle + np.pi) % (2 * np.pi) - np.pi).min(axis=1))
    return float((best * r[band]).max()), int(band.sum())


@pytest.mark.parametrize("teeth", [18, 24, 60])  # above the 17-tooth undercut limit
def test_rack_on_a_circle_cuts_the_involute(teeth):
    module = 2.5
    ring, _ = gear_outline(ArcLengthCurve.circle(teeth * module / 2), teeth, ToothSystem(module))
    deviation, count = involute_deviation(ring, teeth, module)
    assert count > 20 * teeth and deviation < 1e-6


@pytest.mark.parametrize("cutter_teeth", [10, 18, 30])
def test_shaper_on_a_circle_cuts_the_same_involute(cutter_teeth):
    module, teeth = 2.5, 24
    radius, cutter = teeth * module / 2, cutter_teeth * module / 2
    cutters = [CutterChoice("shaper", cutter)] * teeth
    ring, _ = gear_outline(ArcLengthCurve.circle(radius), teeth, ToothSystem(module),
                           cutters=cutters)
    # a gear point is conjugate to the cutter's involute only inside the cutter's interference
    # point N_c (tangent to its base circle): |O N_c|^2 = (r cos a)^2 + ((r + r_c) sin a)^2.
    # Beyond it a small cutter's root trims the gear's tips (10 teeth: 31.72 mm < tip 32.5 mm)
    limit = np.hypot(radius * np.cos(ALPHA), (radius + cutter) * np.sin(ALPHA))
    inside = np.linalg.norm(ring, axis=1) < min(limit, radius + 0.9 * module)
    deviation, count = involute_deviation(ring[inside], teeth, module)
    assert count > 20 * teeth and deviation < 1e-6
    trimmed = (np.linalg.norm(ring, axis=1) > limit) & (np.linalg.norm(ring, axis=1) < radius + 0.99 * module)
    if limit < radius + module:
        assert involute_deviation(ring[trimmed], teeth, module)[0] > 1e-3


def test_spur_gear_outline_radii():
    module, teeth = 2.5, 24
    ring, _ = gear_outline(ArcLengthCurve.circle(teeth * module / 2), teeth, ToothSystem(module))
    radii = np.linalg.norm(ring, axis=1)
    assert radii.max() == pytest.approx(teeth * module / 2 + module, abs=1e-9)
    assert radii.min() == pytest.approx(teeth * module / 2 - 1.25 * module, abs=1e-9)


def two_way_distance(a, b):
    ring_a, ring_b = shapely.LinearRing(a), shapely.LinearRing(b)
    return (max(ring_b.distance(shapely.Point(p)) for p in a[::2]),
            max(ring_a.distance(shapely.Point(p)) for p in b[::2]))


def test_rack_envelope_agrees_with_a_simulated_cut_on_a_non_circular_curve():
    # r = 30 + 8 cos t: convex, rack everywhere; reference = 200 rack positions per pitch
    curve = ArcLengthCurve.from_polar(lambda t: 30 + 8 * np.cos(t), lambda t: -8 * np.sin(t))
    system = ToothSystem(curve.length / (24 * np.pi))
    ring, _ = gear_outline(curve, 24, system)
    reference = simulated_rack_cut(curve, 24, system, positions_per_pitch=200)
    ours_to_cut, cut_to_ours = two_way_distance(ring, reference)
    # the cut leaves scallops between positions (about (p/200)^2 times the curvature scale):
    # our exact envelope lies on the cut; the cut's scallop peaks stand off it by < 1e-2 mm
    assert ours_to_cut < 1e-3
    assert cut_to_ours < 1e-2


def test_shaper_envelope_agrees_with_a_simulated_cut_on_a_concave_curve():
    # the paper's central gear: concave down to -0.034 1/mm, cut by a 19-tooth pinion cutter
    curve = LimaconPitchCurve(**PAPER_LIMACON)
    arc = ArcLengthCurve.from_polar(curve.radius, lambda t: curve.radius_derivatives(t)[1])
    system = ToothSystem(arc.length / (22 * np.pi))
    phase = float(arc.arc_of_source(np.array([0.0]))[0])
    cutters = [CutterChoice("shaper", 19 * system.module / 2)] * 22
    ring, _ = gear_outline(arc, 22, system, phase=phase, cutters=cutters)
    reference = simulated_shaper_cut(arc, 22, system, 19, phase=phase, positions_per_pitch=80)
    ours_to_cut, cut_to_ours = two_way_distance(ring, reference)
    assert ours_to_cut < 2e-2 and cut_to_ours < 2e-2


def test_a_rack_cannot_cut_a_concave_stretch():
    # the reason for the shaper: a rack rolled on the concave stretch gouges the teeth
    curve = LimaconPitchCurve(**PAPER_LIMACON)
    arc = ArcLengthCurve.from_polar(curve.radius, lambda t: curve.radius_derivatives(t)[1])
    system = ToothSystem(arc.length / (22 * np.pi))
    phase = float(arc.arc_of_source(np.array([0.0]))[0])
    envelope, _ = gear_outline(arc, 22, system, phase=phase)
    reference = simulated_rack_cut(arc, 22, system, phase=phase, positions_per_pitch=40)
    assert shapely.Polygon(envelope).area - shapely.Polygon(reference).area > 10.0  # mm^2


def test_tooth_system_rejects_bad_values():
    with pytest.raises(ValueError, match="module"):
        ToothSystem(0.0)
    with pytest.raises(ValueError, match="tip_radius"):
        ToothSystem(2.0, tip_radius=-0.1)
