"""Inverse design of the pricking mechanism: identities, second methods, and every hard case of the spec."""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from kinematics.errors import ConvergenceError, DesignError
from kinematics.pricking import design_pricking, link_lengths
from kinematics.pricking_motion import _mode_functions
from kinematics.spline import ClosedCurve
from tests.pricking_cases import KERNEL_A, KERNEL_B

TWO_PI = 2 * np.pi


@pytest.fixture(scope="module")
def kernel_a3():
    return design_pricking(KERNEL_A, rocker=45.0, degree=3)


@pytest.fixture(scope="module")
def kernel_b5():
    return design_pricking(KERNEL_B, rocker=45.0, degree=5)


@pytest.fixture(scope="module")
def kernel_b3():
    return design_pricking(KERNEL_B, rocker=45.0, degree=3)


def unit(angle):
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


def code_of(points, **options):
    with pytest.raises(DesignError) as caught:
        design_pricking(points, **{"rocker": 45.0, **options})
    return caught.value.problems[0]


# ------------------------------------------------------------------ linkage and kinematics
def test_link_lengths_from_the_curves_radial_extremes():
    curve = ClosedCurve(KERNEL_A, 3)
    linkage = link_lengths(curve, (0.0, 0.0), 45.0)
    radius = np.linalg.norm(curve(np.linspace(0, curve.period, 400001)), axis=1)
    assert linkage.l == pytest.approx((radius.max() + radius.min()) / 2, abs=1e-7)
    assert linkage.a == pytest.approx((radius.max() - radius.min()) / 4, abs=1e-7)
    assert linkage.needle == pytest.approx(np.sqrt(linkage.l**2 - 45.0**2))


@pytest.mark.parametrize("name", ["kernel_a3", "kernel_b5"])
def test_inverse_then_forward_returns_the_points(name, request):
    design = request.getfixturevalue(name)
    motion, link = design.motion, design.linkage
    v = motion.v(design.curve.knots[:-1])
    tip = 2 * link.a * unit(motion.phi1(v)) + link.l * unit(motion.phi2(v))
    np.testing.assert_allclose(tip, design.curve.points, atol=1e-9)


def test_dead_centres_put_o_b_d_in_line(kernel_b5):
    motion = kernel_b5.motion
    for v in (motion.v_max, motion.v_min):
        phi1, phi2 = motion.phi1(np.array([v]))[0], motion.phi2(np.array([v]))[0]
        assert abs(np.sin(phi2 - phi1)) < 1e-9


@pytest.mark.parametrize("name", ["kernel_a3", "kernel_b3", "kernel_b5"])
def test_one_carrier_turn_and_no_net_needle_turn(name, request):
    motion = request.getfixturevalue(name).motion
    end = motion.period
    assert motion.phi1(end) - motion.phi1(0.0) == pytest.approx(motion.sense * TWO_PI, abs=1e-9)
    assert motion.phi2(end) - motion.phi2(0.0) == pytest.approx(0.0, abs=1e-9)
    v = np.linspace(0, end, 20001)
    assert np.all(motion.sense * motion.phi1_rate(v) > 0)


def test_ratio_against_finite_differences_of_the_raw_geometry(kernel_b5):
    motion = kernel_b5.motion
    angles, _ = _mode_functions(motion.curve, motion.linkage, motion.sense)
    v = np.linspace(5.0, motion.period - 5.0, 37)
    v = v[(np.abs(v - motion.v_min) > 1.0) & (np.abs(v - motion.v_max) > 1.0)]
    h = 1e-4
    d1 = (angles(v + h)[0] - angles(v - h)[0]) / (2 * h)
    d2 = (angles(v + h)[1] - angles(v - h)[1]) / (2 * h)
    np.testing.assert_allclose(motion.ratio(v), 1 - d2 / d1, atol=1e-6)


# ---------------------------------------------------------------------------- gear stages
@pytest.mark.parametrize("name", ["kernel_a3", "kernel_b5"])
def test_each_stage_closes_by_an_independent_quadrature(name, request):
    # stage 1 turns the intermediate once per carrier turn: integral i1 dphi1 = 2 pi;
    # stage 2 turns the planet once per intermediate turn: integral i2 i1 dphi1 = 2 pi
    design = request.getfixturevalue(name)
    motion = design.motion
    first, second = design.stages

    def stage_ratio(stage, v):
        return stage.constant * motion.ratio(np.array([v]))[0] ** stage.exponent

    def turn(v):
        return abs(motion.phi1_rate(np.array([v]))[0])

    integrands = [lambda v: stage_ratio(first, v) * turn(v),
                  lambda v: stage_ratio(second, v) * stage_ratio(first, v) * turn(v)]
    for stage, integrand in zip(design.stages, integrands):
        total = sum(quad(integrand, lo, hi, epsabs=1e-13, epsrel=1e-13, limit=200)[0]
                    for lo, hi in zip(motion.breaks[:-1], motion.breaks[1:]))
        assert total == pytest.approx(TWO_PI, abs=1e-9)
        assert stage.closure_error < 1e-9


@pytest.mark.parametrize("name", ["kernel_a3", "kernel_b5"])
def test_rolling_gears_have_equal_perimeters_and_whole_teeth(name, request):
    design = request.getfixturevalue(name)
    for stage, teeth, module in zip(design.stages, design.teeth, design.modules):
        assert stage.drive.perimeter == pytest.approx(stage.driven.perimeter, rel=1e-10)
        assert stage.perimeter == pytest.approx(teeth * np.pi * module, rel=1e-12)
    # the equal-perimeter split: both stages carry the target module
    assert design.modules[0] == pytest.approx(2.0, rel=1e-9)
    assert design.stages[0].perimeter == pytest.approx(design.stages[1].perimeter, rel=1e-8)
    assert 0.95 < design.scale < 1.05


def test_forward_check_from_the_tabulated_pitch_curves(kernel_a3, kernel_b5):
    assert kernel_b5.forward_deviation < 1e-6      # quintic: smooth ratio, spline-exact
    assert kernel_a3.forward_deviation < 1e-3      # cubic: the ratio's 2nd derivative jumps
    finer = design_pricking(KERNEL_A, rocker=45.0, degree=3, grid=2880)
    assert finer.forward_deviation < kernel_a3.forward_deviation / 8


def turning_concave(gear):
    """Second method: the tabulated pitch polygon turns against its orientation somewhere."""
    r, psi = gear.table["radius"], gear.table["body_angle"]
    xy = np.c_[r * np.cos(psi), r * np.sin(psi)]
    edges = np.diff(np.vstack([xy, xy[:1]]), axis=0)
    turns = edges[:, 0] * np.roll(edges[:, 1], -1) - edges[:, 1] * np.roll(edges[:, 0], -1)
    area = np.sum(xy[:, 0] * np.roll(xy[:, 1], -1) - np.roll(xy[:, 0], -1) * xy[:, 1])
    return bool(np.any(turns * np.sign(area) < 0))


def test_kernel_a_cubic_gears_are_concave_and_the_tool_says_where(kernel_a3):
    assert [g.convex for g in kernel_a3.gears] == [False] * 4
    concave = [f for f in kernel_a3.findings if f.code == "concave_pitch_curve"]
    assert len(concave) == 4
    assert all("near Q" in f.message and "degree-5" in f.message for f in concave)


def test_kernel_b_quintic_all_convex_cubic_not(kernel_b5, kernel_b3):
    assert all(g.convex for g in kernel_b5.gears)
    assert sum(not g.convex for g in kernel_b3.gears) >= 2


@pytest.mark.parametrize("name", ["kernel_a3", "kernel_b3", "kernel_b5"])
def test_convexity_agrees_with_the_polygon_turning_test(name, request):
    design = request.getfixturevalue(name)
    for gear in design.gears:
        assert turning_concave(gear) == (not gear.convex), gear.name


# ----------------------------------------------------------------------------- hard cases
def test_one_fixed_arccos_branch_would_oscillate(kernel_b5):
    # the pitfall: phi1 = alpha + arccos(c) everywhere swings back and forth, no full turn
    curve = ClosedCurve(KERNEL_B, 5)
    link = link_lengths(curve, (0.0, 0.0), 45.0)
    u = np.linspace(0, curve.period, 4001)
    rel = curve(u)
    radius = np.linalg.norm(rel, axis=1)
    cosine = np.clip((radius**2 + 4 * link.a**2 - link.l**2) / (4 * link.a * radius), -1, 1)
    fixed = np.unwrap(np.arctan2(rel[:, 1], rel[:, 0])) + np.arccos(cosine)
    steps = np.diff(fixed)
    assert (steps > 0).any() and (steps < 0).any()          # not monotone
    assert abs(fixed[-1] - fixed[0]) < 1e-6                  # no net turn: it oscillates
    assert abs(kernel_b5.motion.phi1(kernel_b5.motion.period) - kernel_b5.motion.phi1(0.0)) \
        == pytest.approx(TWO_PI, abs=1e-9)


@pytest.mark.parametrize("da, dl, code", [
    (0.5, 0.0, "dead_centre_mismatch"), (1.0, 0.0, "dead_centre_mismatch"),
    (-0.5, 0.0, "unreachable_points"), (0.0, 1.0, "unreachable_points"),
    (0.0, -1.0, "unreachable_points"), (0.0, 0.5, "unreachable_points")])
def test_a_or_l_set_by_hand(da, dl, code):
    link = link_lengths(ClosedCurve(KERNEL_A, 3), (0.0, 0.0), 45.0)
    problem = code_of(KERNEL_A, a=link.a + da, l=link.l + dl)
    assert problem.code == code


def test_extremes_from_the_points_give_nan_naively_and_a_specific_error_here():
    radii = np.linalg.norm(KERNEL_A, axis=1)
    a, l = (radii.max() - radii.min()) / 4, (radii.max() + radii.min()) / 2
    curve = ClosedCurve(KERNEL_A, 3)
    radius = np.linalg.norm(curve(np.linspace(0, curve.period, 20001)), axis=1)
    with np.errstate(invalid="ignore"):
        naive = np.arccos((radius**2 + 4 * a * a - l * l) / (4 * a * radius))
    assert np.isnan(naive).any()
    assert code_of(KERNEL_A, a=a, l=l).code == "unreachable_points"


def test_dead_centre_by_the_nearest_sample_puts_samples_on_the_wrong_branch(kernel_a3):
    curve = ClosedCurve(KERNEL_A, 3)
    link = link_lengths(curve, (0.0, 0.0), 45.0)
    count = 36
    u = np.linspace(0, curve.period, count, endpoint=False) + 0.37 * curve.period / count
    rel = curve(u)
    radius = np.linalg.norm(rel, axis=1)
    theta = np.arccos(np.clip((radius**2 + 4 * link.a**2 - link.l**2) / (4 * link.a * radius),
                              -1, 1))
    alpha = np.unwrap(np.arctan2(rel[:, 1], rel[:, 0]))
    offset = lambda target: np.abs(np.mod(u - target + curve.period / 2, curve.period)
                                   - curve.period / 2)
    k_max, k_min = int(np.argmin(offset(link.u_max))), int(np.argmin(offset(link.u_min)))
    position = (np.arange(count) - k_max) % count
    naive_sign = np.where(position < (k_min - k_max) % count, -1, 1)
    exact_sign = np.where(np.mod(u - link.u_max, curve.period)
                          < np.mod(link.u_min - link.u_max, curve.period), -1, 1)
    wrong = naive_sign != exact_sign
    assert wrong.any()                                           # a sample sits on the wrong side
    assert np.degrees(2 * theta[wrong]).max() > 1.0              # and is degrees off
    order = np.argsort(position)
    naive = np.unwrap((alpha + naive_sign * theta)[order])
    assert (np.diff(naive) > 0).any()                            # phi1 steps backwards
    motion = kernel_a3.motion
    v = np.linspace(0, motion.period, 36, endpoint=False) + 0.37 * motion.period / 36
    assert np.all(np.diff(motion.phi1(v)) * motion.sense > 0)    # ours does not


def test_duplicated_point_and_a_point_beside_q5():
    assert code_of(np.insert(KERNEL_A, 5, KERNEL_A[4], axis=0)).code == "coincident_points"
    beside = np.insert(KERNEL_A, 5, KERNEL_A[4] + [2.0, 0.5], axis=0)
    assert code_of(beside).code == "self_intersecting_curve"


def test_q4_and_q6_squeezed_towards_q5():
    squeezed = KERNEL_A.copy()
    for k in (3, 5):
        squeezed[k, 0] = KERNEL_A[4, 0] + 0.2 * (KERNEL_A[k, 0] - KERNEL_A[4, 0])
    problem = code_of(squeezed)
    assert problem.code == "ratio_not_positive"
    assert "Q3-Q4" in problem.message or "Q4-Q5" in problem.message


@pytest.mark.parametrize("height", [-90.0, -110.0, -130.0])
def test_dent_at_the_top(height):
    dented = KERNEL_A.copy()
    dented[10] = [10.0, height]
    assert code_of(dented).code == "no_assembly_mode"


def test_sun_centre_inside_the_loop():
    assert code_of(KERNEL_A, centre=(0.0, -180.0)).code == "origin_inside_loop"


def test_rocker_longer_than_the_reach():
    assert code_of(KERNEL_A, rocker=500.0).code == "rocker_too_long"


@settings(max_examples=20, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(offsets=st.lists(st.tuples(st.floats(-6, 6), st.floats(-6, 6)), min_size=12, max_size=12),
       degree=st.sampled_from([3, 5]))
def test_perturbed_loops_give_a_verified_design_or_a_specific_error(offsets, degree):
    points = KERNEL_B + np.array(offsets)
    try:
        design = design_pricking(points, rocker=45.0, degree=degree)
    except DesignError as error:
        assert error.problems and all(p.code for p in error.problems)
        return
    except ConvergenceError as error:  # a specific, worded failure, never a NaN
        assert "converge" in str(error) or "pieces" in str(error)
        return
    assert design.forward_deviation < 0.05
    for gear in design.gears:
        assert np.all(np.isfinite(gear.table["radius"])) and gear.table["radius"].min() > 0
    assert np.isfinite(design.ratio_min) and design.ratio_min > 0
