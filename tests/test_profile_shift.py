"""Profile shift (cadgen.gears.teeth, kinematics.profile_shift) against the textbook and simulated cuts.

Independent sources only: the shifted spur gear's closed forms, written out here (tooth
thickness on the reference circle ``m (pi/2 + 2 x tan alpha)``, tip ``r + (ha* + x) m``, root
``r - (hf* - x) m``, the involute's thickness at any radius, the start of the generated
involute, the undercut-free tooth count ``2 (ha* - x) / sin^2 alpha``), measured on the cut
outlines with shapely; and a simulated rack cut whose rack is built here, not by the code.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import shapely
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from kinematics.arclength import ArcLengthCurve
from cadgen.gears.cache import stage_key
from cadgen.gears.meshing import meshing_check
from cadgen.gears.pairs import circle_pair, generate_pair
from cadgen.gears.spur import CircleCurve, circular_gear
from cadgen.gears.teeth import CutterChoice, ToothSystem, gear_outline

ALPHA = math.radians(20.0)
HA, HF, RHO_F = 1.0, 1.25, 0.38      # the standard basic rack (ToothSystem's defaults)


def inv(angle):
    return np.tan(angle) - angle


def reference_thickness(module, shift, backlash=0.0):
    """Textbook: the shifted tooth on the reference (pitch) circle, mm."""
    return module * (math.pi / 2 + 2 * shift * math.tan(ALPHA)) - backlash


def involute_thickness(radius, pitch_radius, module, shift):
    """Textbook: the tooth's thickness (arc) at ``radius`` on its involute flanks, mm."""
    base = pitch_radius * math.cos(ALPHA)
    return 2 * radius * (reference_thickness(module, shift) / (2 * pitch_radius) + inv(ALPHA)
                         - inv(np.arccos(base / radius)))


def form_radius(pitch_radius, module, shift):
    """Textbook: where the rack's straight flank stops generating the involute (its end is
    ``hf* - rho_f (1 - sin alpha)`` = 1.0 modules below the rack's reference line), or None
    when that point lies beyond the interference point (undercut)."""
    flank_end = (HF - RHO_F * (1 - math.sin(ALPHA)) - shift) * module
    along = pitch_radius * math.sin(ALPHA) - flank_end / math.sin(ALPHA)
    if along < 0:
        return None
    return math.hypot(pitch_radius * math.cos(ALPHA), along)


def width(outline, radius, teeth, samples=20001):
    """Tooth 0's width (mm) along the circle of ``radius``, measured with shapely: the
    outline's polygon cut by an arc over one angular pitch centred on tooth 0 (+x axis)."""
    angle = np.linspace(-math.pi / teeth, math.pi / teeth, samples)
    arc = shapely.LineString(radius * np.column_stack([np.cos(angle), np.sin(angle)]))
    return shapely.Polygon(outline).intersection(arc).length


def cut_spur(teeth, module, shift, flank_points=200):
    system = ToothSystem(module, profile_shift=shift)
    return circular_gear("g", CircleCurve(teeth * module / 2), teeth, system, 0.0,
                         flank_points=flank_points)


def assert_textbook_tooth(teeth, module, shift, outline):
    radius = teeth * module / 2
    radii = np.hypot(outline[:, 0], outline[:, 1])
    tolerance = 3e-4 * module      # the flanks are polylines of 200 points
    assert width(outline, radius, teeth) == pytest.approx(reference_thickness(module, shift),
                                                          abs=tolerance)
    assert radii.max() == pytest.approx(radius + (HA + shift) * module, abs=1e-7)
    assert radii.min() == pytest.approx(radius - (HF - shift) * module, abs=1e-7)
    start = form_radius(radius, module, shift)
    tip = radius + (HA + shift) * module
    for r in np.linspace(start + 0.02 * module, tip - 0.02 * module, 7):
        assert width(outline, r, teeth) == pytest.approx(
            involute_thickness(r, radius, module, shift), abs=tolerance), r


CASES = {"12 teeth +0.3": (12, 2.0, 0.3), "17 teeth +0.5": (17, 3.0, 0.5),
         "24 teeth -0.4": (24, 2.5, -0.4), "40 teeth +0.8": (40, 1.0, 0.8),
         "30 teeth 0": (30, 1.5, 0.0)}


@pytest.mark.parametrize("teeth, module, shift", CASES.values(), ids=CASES.keys())
def test_a_shifted_circular_gear_is_the_textbook_shifted_spur_gear(teeth, module, shift):
    profile, check, _ = cut_spur(teeth, module, shift)
    assert_textbook_tooth(teeth, module, shift, profile.outline)
    assert check.profile_shift == shift


@settings(max_examples=12, deadline=None)
@given(teeth=st.integers(12, 60), module=st.floats(0.5, 6.0), shift=st.floats(-0.5, 0.8))
def test_any_shifted_circular_gear_has_the_textbook_tooth(teeth, module, shift):
    radius = teeth * module / 2
    # the textbook tooth needs no undercut (the involute reaches its form circle) and a tip
    assume(form_radius(radius, module, shift) is not None)
    assume(involute_thickness(radius + (HA + shift) * module, radius, module, shift)
           > 0.1 * module)
    profile, _, _ = cut_spur(teeth, module, shift)
    assert_textbook_tooth(teeth, module, shift, profile.outline)


def involute_deficit(outline, teeth, module, shift, radius):
    """How much thinner (mm) the cut tooth is at ``radius`` than its involute."""
    return involute_thickness(radius, teeth * module / 2, module, shift) \
        - width(outline, radius, teeth, samples=100001)


def test_twelve_teeth_are_undercut_without_a_shift_and_not_at_0_3():
    teeth, module = 12, 2.0
    # textbook: a rack undercuts fewer than 2 (ha* - x) / sin^2(alpha) teeth
    assert 2 * (HA - 0.0) / math.sin(ALPHA) ** 2 > teeth > 2 * (HA - 0.3) / math.sin(ALPHA) ** 2
    base = teeth * module / 2 * math.cos(ALPHA)
    plain, plain_check, _ = cut_spur(teeth, module, 0.0, flank_points=400)
    shifted, shifted_check, _ = cut_spur(teeth, module, 0.3, flank_points=400)
    # undercut: the rack's tip cuts into the involute just above the base circle
    assert involute_deficit(plain.outline, teeth, module, 0.0, base + 1e-3 * module) > 2e-3
    # shifted: the involute is whole from the base circle to the tip
    tip = teeth * module / 2 + 1.3 * module
    for r in np.linspace(base * (1 + 1e-6), tip - 0.02 * module, 12):
        assert abs(involute_deficit(shifted.outline, teeth, module, 0.3, r)) < 1e-4, r
    # the checks say the same, and the shift thickens the root section
    assert plain_check.undercut_teeth == list(range(teeth))
    assert shifted_check.undercut_teeth == []
    assert shifted_check.root_thickness_min > plain_check.root_thickness_min


def test_a_pinion_cutter_cuts_the_same_shifted_tooth_as_the_rack():
    # V-zero between cutter and gear: a cutter shifted by -x cuts the gear shifted by x
    teeth, module, shift, cutter_teeth = 30, 2.0, 0.4, 24
    radius = teeth * module / 2
    system = ToothSystem(module, profile_shift=shift)
    cutters = [CutterChoice("shaper", cutter_teeth * module / 2)] * teeth
    outline, _ = gear_outline(ArcLengthCurve.circle(radius), teeth, system, cutters=cutters,
                              flank_points=200, fillet_points=100)
    # the whole involute lies inside the cutter's interference point: no tip trimmed
    assert math.hypot(radius * math.cos(ALPHA),
                      (radius + cutter_teeth * module / 2) * math.sin(ALPHA)) \
        > radius + (HA + shift) * module
    tolerance = 5e-4 * module
    assert width(outline, radius, teeth) == pytest.approx(reference_thickness(module, shift),
                                                          abs=tolerance)
    tip = radius + (HA + shift) * module
    for r in np.linspace(form_radius(radius, module, shift) + 0.05 * module,
                         tip - 0.02 * module, 5):
        assert width(outline, r, teeth) == pytest.approx(
            involute_thickness(r, radius, module, shift), abs=tolerance)
    assert np.hypot(outline[:, 0], outline[:, 1]).max() == pytest.approx(tip, abs=1e-7)


def simulated_cut(curve, teeth, module, shift, positions_per_pitch=200):
    """A gear cut by rolling this test's own trapezoid rack (no tip fillet) on ``curve``: the
    basic rack, moved ``x m`` out, its reference line ``x m`` outside the rolling line."""
    pitch = math.pi * module
    tan = math.tan(ALPHA)
    top = (HA + 2.0) * module
    tip_half = pitch / 4 - HF * module * tan          # the rack tooth is the gear's space
    top_half = pitch / 4 + top * tan
    tooth = np.array([[-top_half, top], [-tip_half, -HF * module], [tip_half, -HF * module],
                      [top_half, top]]) + [0.0, shift * module]
    s = np.arange(4096) * (curve.length / 4096)
    point, _, outward = curve.frame(s)
    blank = shapely.Polygon(point + (HA + shift) * module * outward)
    centres = (np.arange(teeth) + 0.5) * pitch
    racks = []
    for position in np.arange(teeth * positions_per_pitch) * (pitch / positions_per_pitch):
        p, t, n = (v[0] for v in curve.frame(np.array([position])))
        offsets = np.mod(centres - position + curve.length / 2, curve.length) - curve.length / 2
        for offset in offsets[np.abs(offsets) < 1.6 * pitch]:
            racks.append(shapely.Polygon(p + (tooth[:, :1] + offset) * t + tooth[:, 1:] * n))
    gear = blank.difference(shapely.union_all(racks))
    return np.asarray(max(getattr(gear, "geoms", [gear]), key=lambda g: g.area).exterior.coords)


def heights(points, curve):
    """Signed distance (mm) of each point from the pitch curve, positive outside."""
    pitch = shapely.Polygon(curve.polyline(8192))
    ring = pitch.exterior
    distance = shapely.distance(ring, shapely.points(points))
    return np.where(shapely.contains_xy(pitch, points[:, 0], points[:, 1]), -distance, distance)


def test_a_shifted_rack_envelope_on_a_non_circular_curve_is_the_simulated_cut():
    curve = ArcLengthCurve.from_polar(lambda t: 30 + 8 * np.cos(t), lambda t: -8 * np.sin(t))
    teeth, shift = 24, 0.4
    module = curve.length / (teeth * math.pi)
    ours, _ = gear_outline(curve, teeth, ToothSystem(module, profile_shift=shift))
    cut = simulated_cut(curve, teeth, module, shift)
    height_ours, height_cut = heights(ours, curve), heights(cut, curve)
    # tip and root curves x m further out (the root from the rack's flat tip)
    assert height_ours.max() == pytest.approx((HA + shift) * module, abs=1e-4)
    assert height_ours.min() == pytest.approx(-(HF - shift) * module, abs=1e-4)
    assert height_cut.min() == pytest.approx(-(HF - shift) * module, abs=1e-3)
    # the flanks (above the fillet, which this rack does not have)
    band = lambda h: (h > -(HA - shift) * module + 0.25 * module) & (h < (HA + shift - 0.05) * module)
    ring_ours, ring_cut = shapely.LinearRing(ours), shapely.LinearRing(cut)
    assert shapely.distance(ring_cut, shapely.points(ours[band(height_ours)])).max() < 2e-3
    # the simulated cut's scallops stand off the exact envelope by (step)^2 x curvature
    assert shapely.distance(ring_ours, shapely.points(cut[band(height_cut)])).max() < 1e-2


def test_a_v_zero_pair_meshes_with_the_backlash_it_is_given():
    module, backlash = 2.0, 0.05
    pair = circle_pair(("pinion", "wheel"), 20.0, 30.0)          # 20 and 30 teeth
    span = pair.period / 20
    for shifts in ((0.0, 0.0), (0.4, -0.4)):
        generated = generate_pair(pair, (20, 30), system=ToothSystem(module, backlash=backlash),
                                  shifts=shifts, flank_points=96)
        report = meshing_check(*generated.profiles, pair, poses=48, span=span)
        assert report.interference_poses == 0
        # V-zero: the two teeth's thickness changes cancel, the circumferential backlash on the
        # pitch circle stays the two gears' thinning, 2 x 0.05 mm
        assert report.backlash_arc_max == pytest.approx(2 * backlash, abs=2e-3)
        assert [c.profile_shift for c in generated.checks] == list(shifts)
    # a non-circular pair's shifts must sum to zero: its pitch curves cannot move
    contact_only = dataclasses.replace(pair, radii=None)
    with pytest.raises(ValueError, match="V-zero"):
        generate_pair(contact_only, (20, 30), system=ToothSystem(module), shifts=(0.3, 0.1))


def test_a_v_pair_meshes_at_its_working_centre_distance_with_the_backlash_it_is_given():
    """Circular gears may take any two shifts: cut on their reference circles, they mesh at the
    working centre distance of ISO 21771 (the inverse of the involute function, solved by
    Newton's method), tips shortened to the standard clearance. Each gear thinned by b on its
    reference circle turns the wheel's free play to 2 b / r2; on its working circle, arc
    2 b a_w / a."""
    from cadgen.gears.circular import tip_shortening, working_shift_sum
    from cadgen.gears.trains import working_centre_distance

    module, backlash, alpha = 2.0, 0.05, math.radians(20.0)
    for shifts in ((0.3, 0.1), (-0.2, -0.25), (0.5, -0.1)):
        reference = circle_pair(("pinion", "wheel"), 20.0, 30.0)
        a = 50.0
        a_w = working_centre_distance(20, 30, module, sum(shifts), alpha)
        # the forward rule gives back the shift sum at that distance
        assert working_shift_sum(20, 30, module, a_w, alpha) == pytest.approx(sum(shifts),
                                                                               abs=1e-12)
        short = tip_shortening((20, 30), module, shifts, (a_w,), alpha)
        generated = generate_pair(reference, (20, 30), system=ToothSystem(module, backlash=backlash),
                                  shifts=shifts, shortening=short, flank_points=96)
        working = circle_pair(reference.names, a_w * 20 / 50, a_w * 30 / 50)
        report = meshing_check(*generated.profiles, working, poses=48, span=working.period / 20)
        assert report.interference_poses == 0, shifts
        assert report.backlash_arc_max == pytest.approx(2 * backlash * a_w / a, abs=2e-3), shifts


def test_the_cache_key_holds_the_shift():
    pair = circle_pair(("a", "b"), 20.0, 30.0)
    options = dict(flank_points=48, bore_radius=0.0, force_shaper=False, poses=32, span=None,
                   circular=True)
    keys = {stage_key("s", pair, (20, 30), ToothSystem(2.0), shifts=shifts, **options)
            for shifts in ((0.0, 0.0), (0.2, -0.2), (-0.2, 0.2))}
    assert len(keys) == 3


def test_the_tooth_system_refuses_a_shift_that_leaves_no_tip_or_no_root():
    for shift in (-1.0, 1.25, float("nan")):
        with pytest.raises(ValueError, match="profile_shift"):
            ToothSystem(2.0, profile_shift=shift)


def test_the_closed_forms_the_checks_use_are_the_measured_ones():
    """kinematics.profile_shift's undercut radius, least shift and tip thickness: measured on
    cut gears (the undercut check against a 12-tooth and a 24-tooth gear either side of
    their limits; the tip width of a cut gear)."""
    from kinematics.profile_shift import tip_thickness, undercut_free_shift, undercut_radius

    # 12 teeth of module 2: radius 12 mm, undercut-free from x = 1 - 12 sin^2 / 2 = 0.2982
    assert undercut_free_shift(12.0, 2.0, ALPHA) == pytest.approx(1 - 6 * math.sin(ALPHA) ** 2)
    assert undercut_radius(2.0, ALPHA, 1.0, 0.3) < 12.0 < undercut_radius(2.0, ALPHA, 1.0, 0.29)
    for teeth, module, shift in ((17, 3.0, 0.5), (12, 2.0, 0.3), (30, 1.5, -0.3)):
        profile, check, _ = cut_spur(teeth, module, shift, flank_points=400)
        radius = teeth * module / 2
        tip = radius + (HA + shift) * module
        measured = width(profile.outline, tip - 1e-4 * module, teeth)
        closed = involute_thickness(tip - 1e-4 * module, radius, module, shift)
        assert measured == pytest.approx(closed, abs=1e-3)
        assert tip_thickness(radius, module, ALPHA, 1.0, shift) == pytest.approx(
            involute_thickness(tip, radius, module, shift), rel=1e-12)
        assert check.tip_thickness_min == pytest.approx(measured, abs=2e-3)
