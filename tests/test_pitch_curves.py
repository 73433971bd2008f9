"""Pitch curves and closure: the spec's figures, closed forms, and an independent quadrature."""

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from kinematics.errors import ConvergenceError, DesignError
from kinematics.pitch_curves import (CirclePitchCurve, FocalEllipsePitchCurve, LimaconPitchCurve,
                                     polar_curvature, polar_perimeter, solve_closure)
from tests.conftest import PAPER_LIMACON


def independent_centre_distance(curve, r_max):
    """Closure by adaptive Gauss-Kronrod (QUADPACK) and Brent: a second method."""
    def residual(a):
        value, _ = quad(lambda t: curve.radius(t) / (a - curve.radius(t)), 0.0, 2 * np.pi,
                        epsabs=1e-12, epsrel=1e-12, limit=500)
        return value - 2 * np.pi
    # bracket away from the pole at max r1, where QUADPACK meets round-off
    return brentq(residual, r_max + 1.0, 2 * r_max, xtol=1e-14, rtol=1e-15)


def test_paper_centre_distance_matches_spec_and_quadpack(paper_curve):
    closure = solve_closure(paper_curve)
    assert closure.centre_distance == pytest.approx(59.944, abs=1e-3)  # spec figure
    reference = independent_centre_distance(paper_curve, closure.radius_max[1])
    assert closure.centre_distance == pytest.approx(reference, rel=1e-9)
    assert closure.error_estimate < 1e-10
    assert abs(closure.residual) < 1e-13


def test_one_degree_rectangle_rule_gives_the_papers_coarse_value(paper_curve):
    # the spec: counting both ends of a 1-degree grid gives 59.997 mm, our rule does not
    t = np.radians(np.arange(0, 361))
    r = paper_curve.radius(t)
    coarse = brentq(lambda a: np.sum(r / (a - r)) * np.radians(1) - 2 * np.pi, r.max() + 1e-9, 100)
    assert coarse == pytest.approx(59.997, abs=1e-3)


def test_paper_perimeter(paper_curve):
    assert polar_perimeter(paper_curve) == pytest.approx(192.886, abs=1e-3)


def test_paper_curvature_figures_from_the_spec(paper_curve):
    # geometry spec: the central gear has a concave stretch down to about -0.034 1/mm
    t = np.linspace(0, 2 * np.pi, 20001)
    assert polar_curvature(paper_curve, t).min() == pytest.approx(-0.034, abs=5e-4)


def test_closed_form_derivatives_against_finite_differences(paper_curve):
    t = np.linspace(0.1, 6.2, 37)
    h = 1e-3
    # 8th-order central differences
    c = np.array([1 / 280, -4 / 105, 1 / 5, -4 / 5, 0, 4 / 5, -1 / 5, 4 / 105, -1 / 280])
    c2 = np.array([-1 / 560, 8 / 315, -1 / 5, 8 / 5, -205 / 72, 8 / 5, -1 / 5, 8 / 315, -1 / 560])
    samples = np.array([paper_curve.radius(t + k * h) for k in range(-4, 5)])
    r, dr, ddr = paper_curve.radius_derivatives(t)
    np.testing.assert_allclose(c @ samples / h, dr, atol=1e-9)
    np.testing.assert_allclose(c2 @ samples / h**2, ddr, atol=2e-6)


def test_circle_closes_at_twice_its_radius_with_identity_law():
    closure = solve_closure(CirclePitchCurve(25.0))
    assert closure.centre_distance == pytest.approx(50.0, rel=1e-15)
    phi = np.linspace(-20, 20, 41)
    np.testing.assert_allclose(closure.law.integral(phi), phi, atol=1e-12)


@pytest.mark.parametrize("eccentricity", [0.3, 0.6, 0.9, 0.95], ids=lambda e: f"e={e}")
def test_focal_ellipse_pair_closed_form(eccentricity):
    # hard case: the closure root close to max r1, ratio swing ((1+e)/(1-e))^2 up to 1:1521
    closure = solve_closure(FocalEllipsePitchCurve(30.0, eccentricity))
    assert closure.centre_distance == pytest.approx(60.0, rel=1e-12)
    assert closure.ratio_swing == pytest.approx(((1 + eccentricity) / (1 - eccentricity)) ** 2,
                                                rel=1e-9)
    phi = np.linspace(-np.pi + 0.01, np.pi - 0.01, 50) + 2 * np.pi * 7
    exact = 2 * np.arctan((1 - eccentricity) / (1 + eccentricity) * np.tan(phi / 2)) + 2 * np.pi * 7
    np.testing.assert_allclose(closure.law.integral(phi), exact, atol=1e-11)


def test_unresolvable_law_is_rejected_not_nan():
    # hard case: a law too peaked for the node budget raises, never returns NaN
    with pytest.raises(ConvergenceError, match="did not converge"):
        solve_closure(FocalEllipsePitchCurve(30.0, 0.999), max_nodes=4096)


def test_pitch_curve_through_its_centre_is_rejected():
    # hard case: r1 touches zero -> pointed pitch curve, named
    base = LimaconPitchCurve(**PAPER_LIMACON)
    _, x, y = base._xy(1.0)
    through = LimaconPitchCurve(**{**PAPER_LIMACON, "g1": PAPER_LIMACON["g1"] - float(x),
                                   "g2": PAPER_LIMACON["g2"] - float(y)})
    with pytest.raises(DesignError) as caught:
        solve_closure(through)
    assert caught.value.problems[0].code == "pointed_pitch_curve"


@pytest.mark.parametrize("e2", [0.3, 0.75, 0.0], ids=str)
def test_open_limacon_is_rejected(e2):
    with pytest.raises(DesignError) as caught:
        LimaconPitchCurve(**{**PAPER_LIMACON, "e2": e2})
    assert caught.value.problems[0].path == "pitch_curve.e2"


@pytest.mark.parametrize("e2", [0.5, 1.5, 2.0], ids=str)
def test_half_integer_e2_closes(e2):
    curve = LimaconPitchCurve(**{**PAPER_LIMACON, "e2": e2})
    t = np.linspace(0, 1, 5)
    np.testing.assert_allclose(curve.radius(t + 2 * np.pi), curve.radius(t), atol=1e-12)


def test_radius_rate_bound_holds(paper_curve):
    t = np.linspace(0, 2 * np.pi, 100001)
    assert np.abs(paper_curve.radius_derivatives(t)[1]).max() <= paper_curve.radius_rate_bound()
