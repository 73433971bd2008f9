"""Closed interpolating curves: interpolation, scipy's periodic spline, and the loop checks."""

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from kinematics.errors import DesignError
from kinematics.spline import ClosedCurve, self_intersections, winding_number
from tests.pricking_cases import KERNEL_A, KERNEL_B


@pytest.mark.parametrize("degree", [3, 5])
@pytest.mark.parametrize("points", [KERNEL_A, KERNEL_B], ids=["kernel-a", "kernel-b"])
def test_passes_through_every_point(points, degree):
    curve = ClosedCurve(points, degree)
    np.testing.assert_allclose(curve(curve.knots[:-1]), points, atol=1e-9)
    chords = np.linalg.norm(np.roll(points, -1, axis=0) - points, axis=1)
    np.testing.assert_allclose(np.diff(curve.knots), chords, rtol=1e-14)  # closing chord included


def test_cubic_matches_an_independent_periodic_cubic_spline():
    curve = ClosedCurve(KERNEL_A, 3)
    other = CubicSpline(curve.knots, np.vstack([KERNEL_A, KERNEL_A[:1]]), bc_type="periodic")
    u = np.linspace(0, curve.period, 2001)
    np.testing.assert_allclose(curve(u), other(u), atol=1e-10)
    np.testing.assert_allclose(curve(u, 2), other(u, 2), atol=1e-9)


def test_quintic_is_four_times_continuous_at_the_seam():
    curve = ClosedCurve(KERNEL_B, 5)
    for order in range(5):
        np.testing.assert_allclose(curve(curve.period - 1e-9, order), curve(1e-9, order),
                                   atol=1e-5 * 10**order)


def test_radial_extremes_come_from_the_curve_not_the_points():
    curve = ClosedCurve(KERNEL_A, 3)
    (_, r_min), (_, r_max) = curve.radius_extrema((0.0, 0.0))
    radii = np.linalg.norm(KERNEL_A, axis=1)
    dense = np.linalg.norm(curve(np.linspace(0, curve.period, 400001)), axis=1)
    # the dense scan (step 1.8e-3 mm) is itself off by up to R'' h^2 / 8, about 1e-7 mm
    assert dense.max() <= r_max <= dense.max() + 1e-7 and r_max > radii.max()
    assert dense.min() - 1e-7 <= r_min <= dense.min() and r_min < radii.min()


def test_duplicated_point():
    points = np.insert(KERNEL_A, 5, KERNEL_A[4], axis=0)
    with pytest.raises(DesignError) as caught:
        ClosedCurve(points, 3)
    assert caught.value.problems[0].code == "coincident_points"
    assert "Q5 and Q6" in caught.value.problems[0].message


def test_nearly_coincident_point():
    points = np.insert(KERNEL_A, 5, KERNEL_A[4] + [0.01, 0.0], axis=0)
    with pytest.raises(DesignError) as caught:
        ClosedCurve(points, 3)
    assert caught.value.problems[0].code == "coincident_points"


def test_point_two_mm_beside_q5_makes_a_tiny_loop():
    # passes a naive chord check (2 mm is not coincident) but the curve crosses itself
    points = np.insert(KERNEL_A, 5, KERNEL_A[4] + [2.0, 0.5], axis=0)
    with pytest.raises(DesignError) as caught:
        ClosedCurve(points, 3)
    assert caught.value.problems[0].code == "self_intersecting_curve"


def test_polygon_helpers():
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    assert winding_number(square, (0.5, 0.5)) == 1
    assert winding_number(square[::-1], (0.5, 0.5)) == -1
    assert winding_number(square, (2.0, 0.5)) == 0
    bow_tie = np.array([[0, 0], [1, 1], [1, 0], [0, 1]], dtype=float)
    assert len(self_intersections(bow_tie)) == 1
    assert len(self_intersections(square)) == 0


def test_sun_centre_inside_the_loop():
    curve = ClosedCurve(KERNEL_A, 3)
    problems = curve.centre_problems((0.0, -180.0))
    assert [p.code for p in problems] == ["origin_inside_loop"]
    assert curve.centre_problems((0.0, 0.0)) == []
