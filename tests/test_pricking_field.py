"""Field motion of the pricking mechanism: identities and the paper's trends over inclination."""

import numpy as np
import pytest

from kinematics.errors import DesignError
from kinematics.pricking import design_pricking
from kinematics.pricking_field import _FieldModel, field_motion, needle_geometry
from tests.pricking_cases import KERNEL_A, KERNEL_B

THETAS = [0.0, 6.5, 20.0, 33.5]
SPEED, RPM, DEPTH = 560.0, 75.0, 70.0


@pytest.fixture(scope="module", params=["kernel-a", "kernel-b"])
def case(request):
    points, degree = (KERNEL_A, 3) if request.param == "kernel-a" else (KERNEL_B, 5)
    design = design_pricking(points, rocker=45.0, degree=degree)
    results = field_motion(design, carrier_speed_rpm=RPM, forward_speed=SPEED, depth=DEPTH,
                           inclinations_deg=THETAS)
    return design, results


def test_the_papers_trends(case):
    _, results = case
    width = [r.width for r in results]
    height = [r.projected_height for r in results]
    entry = [r.entry_angle_deg for r in results]
    leave = [r.exit_angle_deg for r in results]
    mouth = [r.hole_mouth for r in results]
    assert np.ptp(width) == 0.0                                   # keeps its width
    np.testing.assert_allclose(height, height[0] * np.cos(np.radians(THETAS)), rtol=1e-12)
    assert np.all(np.diff(entry) < 0) and np.all(np.diff(leave) < 0)   # angles fall
    assert np.all(np.diff(mouth) > 0)                              # the mouth widens


def test_crossings_are_on_the_surface_line_and_bracket_the_bottom(case):
    design, results = case
    model = _FieldModel(design, RPM, SPEED)
    for r in results:
        tips = model.tip(np.array([r.entry_parameter, r.exit_parameter]))
        np.testing.assert_allclose(tips[:, 1], r.surface_level, atol=1e-8)
        # vertical depth in the hole's plane is kept: (surface - lowest) cos(theta) = depth
        v = np.linspace(0, design.motion.period, 200001)
        lowest = model.tip(v)[:, 1].min()
        assert (r.surface_level - lowest) * np.cos(np.radians(r.inclination_deg)) == \
            pytest.approx(DEPTH, abs=1e-6)
        assert r.time_in_soil_deg == pytest.approx(r.exit_progress_deg - r.entry_progress_deg)


def test_entry_angle_from_the_needle_positions_at_the_crossing(case):
    design, results = case
    model = _FieldModel(design, RPM, SPEED)
    for r in results:
        at = np.array([r.entry_parameter])
        theta = np.radians(r.inclination_deg)
        # second method: the needle as the segment from its root to its tip (positions, not the
        # axis angle), projected into the hole's plane: vertical component scaled once
        needle = model.tip(at)[0] - model.root(at)[0]
        direction = np.array([needle[0], needle[1] * np.cos(theta)])
        expected = np.degrees(np.arctan2(abs(direction[1]), abs(direction[0])))
        assert r.entry_angle_deg == pytest.approx(expected, abs=1e-9)


def test_slow_window_edges_are_at_ten_percent_of_the_speed(case):
    design, results = case
    model = _FieldModel(design, RPM, SPEED)
    windows = results[0].slow_windows_deg
    assert windows
    v = np.linspace(0, design.motion.period, 100001)
    progress = np.degrees(model.progress(v))
    speed = np.abs(model.horizontal_speed(v))
    for start, stop in windows:
        inside = (np.mod(progress - start, 360.0) > 0.5) & \
                 (np.mod(progress - start, 360.0) < (stop - start) - 0.5)
        assert np.all(speed[inside] < 0.1 * SPEED)


def test_needle_is_perpendicular_to_the_rocker_and_points_down_at_the_bottom(case):
    design, _ = case
    needle = needle_geometry(design)
    motion, link = design.motion, design.linkage
    v = np.linspace(0, motion.period, 50)
    tip = motion.tip(v)
    b = 2 * link.a * np.stack([np.cos(motion.phi1(v)), np.sin(motion.phi1(v))], -1)
    axis = needle.axis_angle(motion.phi2(v))
    root = tip - link.needle * np.stack([np.cos(axis), np.sin(axis)], -1)
    np.testing.assert_allclose(np.linalg.norm(root - b, axis=1), link.rocker, rtol=1e-9)
    np.testing.assert_allclose(np.einsum("ij,ij->i", root - b, tip - root), 0.0, atol=1e-8)
    low = v[np.argmin(tip[:, 1])]
    assert np.sin(needle.axis_angle(motion.phi2(np.array([low]))))[0] < -0.5


def test_depth_beyond_the_loop_is_an_error():
    design = design_pricking(KERNEL_B, rocker=45.0, degree=5)
    with pytest.raises(DesignError) as caught:
        field_motion(design, carrier_speed_rpm=RPM, forward_speed=SPEED, depth=400.0,
                     inclinations_deg=[20.0])
    assert (caught.value.problems[0].path, caught.value.problems[0].code) == \
        ("field.depth", "no_soil_crossing")
