"""The duckbill cam: motion laws, linkage, timing at the events, contour read back, checks.

Independent sources: the laws' closed-form end conditions and peaks, numerical
integration of their derivatives; the linkage's own loop-closure equations
(link lengths preserved); the tip height at the event that closes the duckbill;
and a simulated follower on the generated contour (the roller circle brought into
contact with the contour polygon, written out here from the drawing's geometry).
"""

import math

import numpy as np
import pytest
import shapely
from scipy.integrate import quad
from scipy.optimize import brentq

from cadgen.cam.design import design_cam
from cadgen.design import build_mechanism, evaluate
from cadgen.pipeline.build import build
from cadgen.params import ParameterError, stage_problems, validate_text
from kinematics.duckbill import DuckbillLinkage
from kinematics.errors import DesignError
from kinematics.motion_laws import MOTION_LAWS, FollowerProgram

from helpers import edited, reference_text


# ------------------------------------------------------------------ motion laws
@pytest.mark.parametrize("name", sorted(MOTION_LAWS))
def test_law_end_conditions_and_derivatives(name):
    law = MOTION_LAWS[name]
    s, ds, dds = law(np.array([0.0, 1.0]))
    np.testing.assert_allclose(s, [0.0, 1.0], atol=1e-15)
    np.testing.assert_allclose(ds, [0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(dds, [0.0, 0.0], atol=1e-12)
    # the derivatives integrate back to the law (a second method: quadrature)
    for x in (0.1, 0.37, 0.5, 0.81):
        np.testing.assert_allclose(quad(lambda u: law(u)[1], 0, x, epsabs=1e-14)[0], law(x)[0],
                                   atol=1e-12)
        np.testing.assert_allclose(quad(lambda u: law(u)[2], 0, x, epsabs=1e-14)[0], law(x)[1],
                                   atol=1e-11)


def test_law_peak_accelerations_match_the_closed_forms():
    # cycloidal: 2 pi at x = 1/4; 3-4-5: 10/sqrt(3) at x = (3 - sqrt 3)/6
    assert MOTION_LAWS["cycloidal"](0.25)[2] == pytest.approx(2 * np.pi, rel=1e-14)
    x = (3 - np.sqrt(3)) / 6
    assert MOTION_LAWS["polynomial-345"](x)[2] == pytest.approx(10 / np.sqrt(3), rel=1e-13)
    grid = np.linspace(0, 1, 100001)
    assert MOTION_LAWS["polynomial-345"](grid)[2].max() == pytest.approx(10 / np.sqrt(3), rel=1e-8)


def test_program_is_continuous_and_periodic():
    program = FollowerProgram(0.2, rise=(3.0, 3.5), fall=(4.0, 5.0), rise_law="polynomial-345")
    for edge in (3.0, 3.5, 4.0, 5.0):
        below, above = program(np.array([edge - 1e-9, edge + 1e-9]))[0]
        assert abs(below - above) < 1e-9
    theta = np.linspace(0, 2 * np.pi, 97)
    np.testing.assert_allclose(program(theta)[0], program(theta + 6 * np.pi)[0], atol=1e-13)
    assert program(np.array([0.0, 3.75, 5.5]))[0].tolist() == [0.0, 0.2, 0.0]
    with pytest.raises(DesignError) as caught:
        FollowerProgram(0.2, rise=(3.0, 4.5), fall=(4.0, 5.0))
    assert caught.value.problems[0].code == "phase_order"


# ------------------------------------------------------------------ linkage
@pytest.fixture(scope="module")
def linkage():
    return DuckbillLinkage.design(L1=130.0, L2=190.0, pot_diameter=30.0, mouth_clearance=5.0,
                                  blade_length=85.0, closed_half_angle=math.radians(18.0),
                                  blade_crank=20.0, blade_link=35.0, base_radius=40.0,
                                  roller_arm=45.0)


def test_closed_blades_meet_at_the_tip_and_the_mouth_clears_the_pot(linkage):
    d0, lb = linkage.closed_half_angle, linkage.blade_length
    tip = linkage.hinge + lb * np.array([-np.sin(d0), -np.cos(d0)])
    np.testing.assert_allclose(tip, [-130.0, -190.0], atol=1e-12)
    # opened by the design angle, the right tip is 20 mm (half the 40-mm mouth) off the axis
    beta = linkage.opening_angle
    open_tip = linkage.hinge + lb * np.array([-np.sin(d0 - beta), -np.cos(d0 - beta)])
    assert open_tip[0] + 130.0 == pytest.approx(20.0, abs=1e-12)


def test_blade_loop_keeps_its_link_lengths_and_inverts(linkage):
    beta = np.linspace(0.0, linkage.opening_angle, 25)
    pin = linkage.crank_pin(beta)
    rod = np.stack([np.full_like(beta, -130.0), linkage.push_rod_end(beta)], axis=-1)
    np.testing.assert_allclose(np.linalg.norm(pin - linkage.hinge, axis=1), 20.0, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(rod - pin, axis=1), 35.0, atol=1e-12)
    drop = linkage.push_rod_end(0.0)[0] - linkage.push_rod_end(beta)
    np.testing.assert_allclose(linkage.blade_opening(drop), beta, atol=1e-12)
    assert np.all(np.diff(drop) > 0)   # pushing the rod down opens the blades


def test_lever_drives_the_push_rod_by_its_stroke(linkage):
    pin = linkage.rod_pin(np.array([0.0, linkage.lever_lift]))
    assert pin[0, 0] == pytest.approx(-130.0, abs=1e-12)       # G on the duckbill axis at rest
    assert pin[0, 1] - pin[1, 1] == pytest.approx(linkage.stroke, rel=1e-12)
    assert linkage.opening_of_lever(linkage.lever_lift) == pytest.approx(linkage.opening_angle,
                                                                         abs=1e-12)
    centre = linkage.roller_centre(np.array([0.0]))[0][0]
    assert np.hypot(*centre) == pytest.approx(40.0, abs=1e-12)  # at rest on the base circle


@pytest.mark.parametrize("change, path, code", [
    (dict(pot_diameter=200.0), "cam.pot_diameter", "mouth_narrower_than_pot"),
    (dict(opening_angle=math.radians(5.0)), "cam.opening_angle_deg", "mouth_narrower_than_pot"),
    (dict(blade_crank=40.0), "cam.duckbill.blade_crank", "crank_crosses_axis"),
    (dict(blade_length=200.0), "cam.duckbill.blade_length", "blade_too_long"),
    (dict(blade_link=5.0), "cam.duckbill.blade_link", "link_too_short"),
])
def test_impossible_linkages_are_rejected_at_their_field(change, path, code):
    options = dict(L1=130.0, L2=190.0, pot_diameter=30.0, mouth_clearance=5.0, blade_length=85.0,
                   closed_half_angle=math.radians(18.0), blade_crank=20.0, blade_link=35.0,
                   base_radius=40.0, roller_arm=45.0)
    with pytest.raises(DesignError) as caught:
        DuckbillLinkage.design(**{**options, **change})
    assert (path, code) in {(p.path, p.code) for p in caught.value.problems}


# ------------------------------------------------------------------ the paper's cam
@pytest.fixture(scope="module")
def paper():
    params = validate_text(reference_text())
    mechanism = build_mechanism(params)
    evaluation = evaluate(params, mechanism, steps=720)
    return params, mechanism, evaluation, design_cam(params, mechanism, evaluation.events)


def test_timing_sits_at_the_events(paper):
    params, mechanism, evaluation, cam = paper
    events, timing = evaluation.events, cam.timing
    assert timing.opening[0] == pytest.approx(events.lowest - math.radians(5.0), abs=1e-12)
    # the duckbill starts closing where the tip is the seedling's height above the soil
    cleared = timing.events["seedling_cleared"]
    height = mechanism.positions(np.array([cleared]), points=("N",))["N"][0, 1]
    assert height == pytest.approx(events.soil_level + params.cam.seedling_height, abs=1e-9)
    assert events.exit < cleared < timing.closing[0] + 1e-15
    # closed through catching and transport, open from just after the lowest point until cleared
    phi = np.linspace(0.0, 2 * np.pi, 3601)
    lam, _, beta = cam.profile.follower_at_carrier(phi, cam.cam_angle)
    closed = (phi <= timing.opening[0]) | (phi >= timing.closing[1])
    held_open = (phi >= timing.opening[1]) & (phi <= timing.closing[0])
    assert np.all(lam[closed] == 0.0) and np.all(np.abs(beta[closed]) < 1e-12)
    np.testing.assert_allclose(beta[held_open], cam.linkage.opening_angle, atol=1e-12)
    assert timing.closing[1] <= 2 * np.pi - math.radians(20.0)
    assert np.all(np.diff(lam[(phi > timing.opening[0]) & (phi < timing.opening[1])]) > 0)


def test_pitch_curve_derivatives_against_finite_differences(paper):
    profile = paper[3].profile
    theta = np.linspace(0.0, 2 * np.pi, 50, endpoint=False) + 0.013
    h = 1e-5
    p, d1, d2 = profile.pitch_point(theta)
    plus, minus = profile.pitch_point(theta + h)[0], profile.pitch_point(theta - h)[0]
    np.testing.assert_allclose(d1, (plus - minus) / (2 * h), atol=1e-6)
    np.testing.assert_allclose(d2, (plus - 2 * p + minus) / h**2, atol=2e-3)


def test_dwells_are_circles_about_E(paper):
    cam = paper[3]
    program = cam.profile.program
    low = np.linspace(program.fall[1], program.rise[0] + 2 * np.pi, 50) % (2 * np.pi)
    high = np.linspace(program.rise[1], program.fall[0], 50)
    np.testing.assert_allclose(np.linalg.norm(cam.profile.pitch_point(low)[0], axis=1), 40.0,
                               atol=1e-12)
    outer = np.linalg.norm(cam.linkage.roller_centre(cam.linkage.lever_lift)[0][0])
    np.testing.assert_allclose(np.linalg.norm(cam.profile.pitch_point(high)[0], axis=1), outer,
                               atol=1e-12)
    assert np.allclose(cam.profile.pressure_angle(low), 0.0, atol=1e-12)


def _roller_centre_on_cam(theta, lam, r_base=40.0, arm=45.0):
    """The roller centre in the cam frame, written out from the linkage drawing."""
    pivot = np.array([-r_base, -arm])
    centre = pivot + arm * np.array([-np.sin(lam), np.cos(lam)])
    c, s = np.cos(-theta), np.sin(-theta)
    return np.array([c * centre[0] - s * centre[1], s * centre[0] + c * centre[1]])


def test_follower_read_back_from_the_contour_matches_the_law(paper):
    """Simulated follower: the roller circle touching the contour polygon at each cam angle."""
    cam = paper[3]
    points = 20000
    contour = shapely.Polygon(cam.profile.working_profile(points))
    assert contour.is_valid
    ring = contour.exterior
    roller = cam.profile.roller_radius

    def gap(lam, theta):
        centre = shapely.Point(_roller_centre_on_cam(theta, lam))
        sign = -1.0 if contour.contains(centre) else 1.0
        return sign * ring.distance(centre) - roller

    program = cam.profile.program
    theta = np.concatenate([np.linspace(*program.rise, 40), np.linspace(*program.fall, 40),
                            [0.5, 2.0, (program.rise[1] + program.fall[0]) / 2]])
    read = np.array([brentq(gap, -0.05, program.lift + 0.05, args=(t,), xtol=1e-14)
                     for t in theta])
    # Stated tolerance: the polygon's chords sag at most s^2/(8 rho) (s = chord, rho the
    # working profile's smallest radius); through the 45-mm roller arm that is < 1e-7 rad here.
    chord = contour.length / points
    sag = chord**2 / (8 * cam.check.profile_radius_min)
    np.testing.assert_allclose(read, program(theta)[0], atol=4 * sag / 45.0 + 1e-10)
    assert 4 * sag / 45.0 < 1e-6


def test_pressure_angle_against_a_second_construction(paper):
    """Normal from the sampled pitch curve, lever velocity from the drawing's geometry."""
    cam = paper[3]
    program = cam.profile.program
    theta = np.linspace(program.rise[0], program.fall[1], 60)
    h = 1e-6
    angles = []
    for t in theta:
        lam = program(np.array([t]))[0][0]
        tangent = (cam.profile.pitch_point(t + h)[0][0] - cam.profile.pitch_point(t - h)[0][0])
        lever = _roller_centre_on_cam(t, lam + h) - _roller_centre_on_cam(t, lam - h)
        cosine = abs(tangent @ lever) / (np.linalg.norm(tangent) * np.linalg.norm(lever))
        angles.append(math.asin(min(1.0, cosine)))   # normal-to-velocity = 90 deg - tangent-to-velocity
    np.testing.assert_allclose(cam.profile.pressure_angle(theta), angles, atol=1e-6)
    assert cam.check.pressure_angle_max == pytest.approx(
        cam.profile.pressure_angle(np.linspace(0, 2 * np.pi, 200001)).max(), abs=1e-7)


def test_curvature_against_three_point_circles(paper):
    profile = paper[3].profile
    # inside the rise: across a phase boundary the jerk jumps and the three-point circle is O(h)
    theta = np.linspace(profile.program.rise[0], profile.program.rise[1], 32)[1:-1]
    h = 1e-4
    for t in theta:
        a, b, c = (profile.pitch_point(t + d)[0][0] for d in (-h, 0.0, h))
        # Menger curvature of the three points (sign: the pitch curve runs clockwise)
        area2 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        menger = 2 * area2 / (np.linalg.norm(b - a) * np.linalg.norm(c - b) * np.linalg.norm(c - a))
        assert -menger == pytest.approx(profile.pitch_curvature(t)[0], rel=1e-5, abs=1e-9)


def test_paper_cam_passes_its_checks(paper):
    check = paper[3].check
    assert check.problems == []
    assert check.pressure_angle_max < math.radians(30.0)
    assert check.pitch_radius_convex_min > paper[3].profile.roller_radius


def test_roller_larger_than_the_smallest_convex_radius_is_reported(paper):
    params, mechanism, evaluation, cam = paper
    smallest = cam.check.pitch_radius_convex_min
    big = validate_text(edited(roller_radius=f"{smallest + 1.0:.3f}"))
    design = design_cam(big, mechanism, evaluation.events)
    codes = {(p.path, p.code) for p in design.check.problems}
    assert ("cam.roller_radius", "roller_undercut") in codes
    assert not design.cuttable
    # and the geometry agrees: that roller's offset contour crosses itself (a cusp)
    assert not shapely.Polygon(design.profile.working_profile(20000)).is_valid


@pytest.mark.parametrize("changes, path, code", [
    (dict(seedling_height="700.0"), "cam.seedling_height", "seedling_not_cleared"),
    (dict(closing_duration_deg="150.0"), "cam.timing.closing_duration_deg", "closes_too_late"),
    (dict(opening_duration_deg="120.0"), "cam.timing.opening_duration_deg", "phase_order"),
    (dict(pot_diameter="190.0"), "cam.pot_diameter", "mouth_narrower_than_pot"),
    (dict(L2="150.0"), "cam.lever.roller_arm", "push_rod_inverted"),
], ids=["seedling", "closing", "opening", "pot", "push-rod"])
def test_impossible_cam_files_name_the_field_in_the_cam_stage(changes, path, code):
    # the file loads (a metrics-only evaluation may go on), the problem kept with its stage;
    # a build that runs the cam refuses it before any stage runs
    params = validate_text(edited(**changes))
    found = {(p.path, p.code, p.stage) for p in stage_problems(params)}
    assert (path, code, "cam") in found, found
    with pytest.raises(ParameterError) as caught:
        build(params, None, effects=["cam"])
    assert (path, code) in {(p.path, p.code) for p in caught.value.problems}


def test_unknown_cam_law_is_refused_at_load():
    with pytest.raises(ParameterError) as caught:
        validate_text(edited(rise_law='"cycloid"'))
    assert any(p.path == "cam.rise_law" and p.stage is None for p in caught.value.problems)


def test_cam_dxf_is_one_closed_cutting_path_within_the_chord_tolerance(paper, tmp_path):
    import ezdxf

    from cadgen.export.cam_dxf import write_cam_dxf

    profile = paper[3].profile
    contour, pitch = profile.working_profile(3600), profile.pitch_curve(3600)
    summary = write_cam_dxf(tmp_path / "cam.dxf", contour, pitch, bore_radius=6.0,
                            chord_tolerance=0.005)
    doc = ezdxf.readfile(tmp_path / "cam.dxf")
    assert not doc.audit().has_errors and doc.units == 4   # millimetres
    outlines = doc.modelspace().query('LWPOLYLINE[layer=="OUTLINE"]')
    assert len(outlines) == 1 and outlines[0].closed
    written = shapely.LinearRing([p[:2] for p in outlines[0].get_points()])
    assert written.is_simple
    # every point of the dense contour lies within the chord tolerance of the written path
    assert max(written.distance(shapely.Point(p)) for p in contour[::7]) <= 0.005 + 1e-12
    assert len(doc.modelspace().query('CIRCLE[layer=="BORE"]')) == 1
    assert summary.outline_points_written < len(contour)
