"""Circular gears by symmetry (cadgen.gears.spur) against independent sources.

Second methods: the general path (every tooth space cut from the whole blank, every tooth
measured: ``generate_pair(..., symmetric=False)``) on the same exact circle, and on the
spline circle the general path used before (``kinematics.arclength.ArcLengthCurve``); closed
forms: the involute flank, the tip and root circles, the tooth thickness on the pitch circle
(p/2 minus the backlash), the z-fold symmetry.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from kinematics.arclength import ArcLengthCurve
from cadgen.gears.pairs import circle_pair, generate_pair
from cadgen.gears.spur import BLANK_POINTS, CircleCurve, circular_gear
from cadgen.gears.teeth import ToothSystem
from tests.test_teeth import involute_deviation


def _sag(radius: float, chords_per_turn: int) -> float:
    """Largest distance between a circle and its inscribed polygon of that many chords."""
    return radius * (1.0 - math.cos(math.pi / chords_per_turn))


def _distance(a, b) -> float:
    """Two-way largest distance of the vertices of each ring from the other ring."""
    ring_a, ring_b = shapely.LinearRing(a), shapely.LinearRing(b)
    return max(shapely.distance(ring_b, shapely.points(a)).max(),
               shapely.distance(ring_a, shapely.points(b)).max())


# ----------------------------------------------------------------------------- the circle
def test_circle_curve_is_the_spline_circle_exactly():
    radius = 37.5
    exact = CircleCurve(radius, start=np.pi, rate=-0.8)
    spline = ArcLengthCurve.circle(radius)
    s = np.linspace(0.0, exact.length, 1001)
    point, tangent, outward = exact.frame(s)
    assert exact.length == pytest.approx(spline.length, rel=1e-12)
    np.testing.assert_allclose(np.linalg.norm(point, axis=1), radius, rtol=1e-15)
    np.testing.assert_allclose(np.einsum("ij,ij->i", tangent, outward), 0.0, atol=1e-15)
    np.testing.assert_allclose(point / radius, outward, atol=1e-15)
    np.testing.assert_allclose(exact.curvature(s), 1 / radius, rtol=1e-15)
    # the spline circle starts at +x: the same frames, the exact one turned by its start
    turned = CircleCurve(radius)
    np.testing.assert_allclose(turned.frame(s)[0], spline.frame(s)[0], atol=1e-9)
    np.testing.assert_allclose(spline.curvature(s), 1 / radius, rtol=1e-8)
    # the contact of tau runs clockwise at rate 0.8: its arc length from tau = 0, counter-clockwise
    np.testing.assert_allclose(exact.arc_of_source(np.array([0.0, 1.0])),
                               [0.0, exact.length - radius * 0.8], rtol=1e-15)


def test_a_circle_pair_gives_exact_circles_with_the_spline_circles_arcs():
    pair = circle_pair(("a", "b"), 24.0, 30.0)
    spline = dataclasses.replace(pair, radii=())   # the same contact functions, splined
    tau = np.linspace(0.0, 2 * np.pi, 37)
    for which in (0, 1):
        exact, reference = pair.curve(which), spline.curve(which)
        assert isinstance(exact, CircleCurve) and exact.reversed == reference.reversed
        np.testing.assert_allclose(np.mod(exact.arc_of_source(tau) - reference.arc_of_source(tau)
                                          + 1.0, exact.length) - 1.0, 0.0, atol=1e-9)
        s = np.linspace(0.0, exact.length, 101)
        np.testing.assert_allclose(exact.frame(s)[0], reference.frame(s)[0], atol=1e-9)


# ----------------------------------------------------------------------------- against the general path
CASES = {   # (teeth drive, driven, module, backlash, shaper everywhere)
    "undercut 12 : 20": (12, 20, 2.0, 0.0, False),
    "paper 1:1 pair": (30, 30, 1.8, 0.05, False),
    "paper sun to idler": (40, 48, 1.8, 0.05, False),
    "coarse 17 : 53": (17, 53, 4.0, 0.1, False),
    "shaper 24 : 30": (24, 30, 2.0, 0.05, True),
}


@pytest.fixture(scope="module", params=list(CASES), ids=list(CASES))
def both_paths(request):
    z1, z2, module, backlash, shaper = CASES[request.param]
    system = ToothSystem(module, backlash=backlash)
    pair = circle_pair(("drive", "driven"), z1 * module / 2, z2 * module / 2)
    options = dict(system=system, force_shaper=shaper, flank_points=48)
    symmetric = generate_pair(pair, (z1, z2), **options)
    general = generate_pair(pair, (z1, z2), symmetric=False, **options)
    spline = generate_pair(dataclasses.replace(pair, radii=()), (z1, z2), **options)
    return system, symmetric, general, spline


def test_outline_is_the_general_paths_within_the_blanks_chords(both_paths):
    system, symmetric, general, spline = both_paths
    for k in (0, 1):
        teeth = symmetric.teeth[k]
        tip = teeth * system.module / 2 + system.addendum_height
        # both cut the same envelopes; their tip arcs are chords of the addendum circle, at
        # most BLANK_POINTS a turn (general) and a whole number a pitch (symmetric)
        bound = (_sag(tip, BLANK_POINTS) + _sag(tip, teeth * math.ceil(BLANK_POINTS / teeth))
                 + 1e-9)
        assert _distance(symmetric.profiles[k].outline, general.profiles[k].outline) <= bound
        # and the spline circle's general path is the exact circle's to rounding
        assert _distance(general.profiles[k].outline, spline.profiles[k].outline) < 1e-9
        ring = shapely.LinearRing(symmetric.profiles[k].outline)
        assert ring.is_simple and ring.is_ccw
        area_general = shapely.Polygon(general.profiles[k].outline).area
        assert shapely.Polygon(ring).area == pytest.approx(area_general,
                                                           abs=2 * bound * ring.length)


def test_checks_are_the_general_paths(both_paths):
    system, symmetric, general, _ = both_paths
    for fast, slow in zip(symmetric.checks, general.checks):
        assert (fast.undercut_teeth, fast.pointed_teeth, fast.concave_teeth) == \
            (slow.undercut_teeth, slow.pointed_teeth, slow.concave_teeth)
        assert (fast.cutter, fast.shaper_teeth, fast.convex) == \
            (slow.cutter, slow.shaper_teeth, slow.convex)
        assert [code for code, _ in fast.problems] == [code for code, _ in slow.problems]
        # both measure along 8192-gons of the offset circles; the tip region's chords differ
        for name in ("root_thickness_min", "tip_thickness_min"):
            assert getattr(fast, name) == pytest.approx(getattr(slow, name),
                                                        abs=1e-5 * system.module), name
        assert fast.curvature_min == pytest.approx(slow.curvature_min, rel=1e-12)
        # the radius is the circle's normal: the general path finds it up to arccos's
        # rounding at 1 (one ulp below 1 is 1.2e-6 deg), this path gives the exact 0
        assert fast.pressure_angle_deviation_max_deg == 0.0
        floor = np.degrees(np.arccos(1.0 - np.finfo(float).eps))
        assert slow.pressure_angle_deviation_max_deg <= floor


def test_spaces_are_every_space_turned(both_paths):
    _, symmetric, general, _ = both_paths
    for fast, slow in zip(symmetric.spaces, general.spaces):
        assert len(fast) == len(slow)
        for a, b in zip(fast, slow):
            np.testing.assert_allclose(a, b, atol=1e-9)


@pytest.mark.parametrize("teeth", [18, 24, 60])
def test_rack_cut_circle_is_the_involute(teeth):
    module = 2.5
    curve = CircleCurve(teeth * module / 2)
    profile, _, _ = circular_gear("g", curve, teeth, ToothSystem(module), 0.0)
    deviation, count = involute_deviation(profile.outline, teeth, module)
    assert count > 20 * teeth and deviation < 1e-6
    radii = np.linalg.norm(profile.outline, axis=1)
    assert radii.max() == pytest.approx(teeth * module / 2 + module, abs=1e-9)
    assert radii.min() == pytest.approx(teeth * module / 2 - 1.25 * module, abs=1e-9)


def _chords_across(outline, radius: float) -> np.ndarray:
    """The outline's edges crossing the circle of ``radius``: (k, 2, 2) start and end."""
    end = np.roll(outline, -1, axis=0)
    r0, r1 = np.linalg.norm(outline, axis=1), np.linalg.norm(end, axis=1)
    across = (np.minimum(r0, r1) <= radius) & (np.maximum(r0, r1) >= radius)
    return np.stack([outline[across], end[across]], axis=1)


def _arc_inside(outline, radius: float) -> float:
    """Length of the circle of ``radius`` inside the polygon: the exact arcs between the
    circle's crossings with the polygon's edges, each kept if its middle is inside."""
    start, end = outline, np.roll(outline, -1, axis=0)
    d = end - start
    a, b = np.einsum("ij,ij->i", d, d), 2 * np.einsum("ij,ij->i", start, d)
    c = np.einsum("ij,ij->i", start, start) - radius**2
    root = np.sqrt(np.maximum(b * b - 4 * a * c, 0.0))
    angles = []
    for t in ((-b - root) / (2 * a), (-b + root) / (2 * a)):
        hit = (b * b - 4 * a * c >= 0) & (t >= 0) & (t < 1)
        point = start[hit] + t[hit, None] * d[hit]
        angles.append(np.arctan2(point[:, 1], point[:, 0]))
    angles = np.sort(np.concatenate(angles))
    spans = np.diff(np.append(angles, angles[0] + 2 * np.pi))
    middle = angles + spans / 2
    inside = shapely.contains_xy(shapely.Polygon(outline), radius * np.cos(middle),
                                 radius * np.sin(middle))
    return float(radius * spans[inside].sum())


@settings(max_examples=25, deadline=None, derandomize=True, database=None)
@given(teeth=st.integers(17, 90), module=st.floats(0.5, 5.0),
       backlash=st.floats(0.0, 0.04), phase=st.floats(0.0, 1.0))
def test_any_circular_gear_is_z_fold_and_has_the_closed_form_tooth(teeth, module, backlash,
                                                                    phase):
    system = ToothSystem(module, backlash=backlash * module)
    radius = teeth * module / 2
    curve = CircleCurve(radius, start=0.3)
    profile, check, _ = circular_gear("g", curve, teeth, system, phase * system.pitch)
    outline = profile.outline
    assert shapely.LinearRing(outline).is_simple
    radii = np.linalg.norm(outline, axis=1)
    assert radii.max() <= radius + system.addendum_height + 1e-9
    assert radii.min() >= radius - system.dedendum_depth - 1e-9
    # z-fold: the outline turned by one pitch is itself, a tooth's vertices further on
    assert len(outline) % teeth == 0
    turn = 2 * np.pi / teeth
    c, s = math.cos(turn), math.sin(turn)
    np.testing.assert_allclose(outline @ np.array([[c, s], [-s, c]]),
                               np.roll(outline, -len(outline) // teeth, axis=0),
                               atol=1e-9 * radius)
    # on the pitch circle a rack-cut tooth (from 17 teeth on, no undercut reaching it) is as
    # thick as the rack's space: p/2 - backlash, less what the flank's chords cut off the
    # involute (a chord of length L on a curve of radius rho stands L^2 / (8 rho) inside it;
    # the involute's radius at radius r is sqrt(r^2 - r_base^2))
    expected = teeth * (system.pitch / 2 - system.backlash)
    chords = _chords_across(outline, radius)
    base = radius * math.cos(system.pressure_angle)
    low = np.minimum(*np.linalg.norm(chords, axis=2).T)
    sag = (np.linalg.norm(chords[:, 1] - chords[:, 0], axis=1) ** 2
           / (8 * np.sqrt(np.maximum(low**2 - base**2, 0.0)))).sum()
    measured = _arc_inside(outline, radius)
    assert expected - sag - 1e-9 <= measured <= expected + 1e-9
    # the tip thickness measured on one tooth is every tooth's (z of them, equal)
    tip_arc = _arc_inside(outline, radius + system.addendum_height - 1e-4 * module)
    assert check.tip_thickness_min == pytest.approx(tip_arc / teeth, rel=1e-4)
    # the rack undercuts a radius of curvature below m ha* / sin^2(alpha): under 17.1 teeth
    assert check.undercut_teeth == (list(range(teeth)) if teeth < 2 / math.sin(
        system.pressure_angle) ** 2 else [])


def test_a_circular_gear_needs_a_circle_and_whole_teeth():
    with pytest.raises(TypeError, match="CircleCurve"):
        circular_gear("g", ArcLengthCurve.circle(30.0), 24, ToothSystem(2.5), 0.0)
    with pytest.raises(ValueError, match="does not hold 25 teeth"):
        circular_gear("g", CircleCurve(30.0), 25, ToothSystem(2.5), 0.0)
    with pytest.raises(ValueError, match="radius"):
        CircleCurve(-1.0)
