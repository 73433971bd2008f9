"""Brent's root and bounded minimum (kinematics.scalar) against scipy's, the methods they port."""

import math

import numpy as np
import pytest
from scipy import optimize

from kinematics.errors import ConvergenceError
from kinematics.scalar import brentq, minimize_scalar

ROOT_CASES = [
    (lambda x: x**3 - 2 * x - 5, 2.0, 3.0),
    (lambda x: math.cos(x) - x, 0.0, 1.0),
    (lambda x: math.exp(x) - 1e-8, -30.0, 5.0),
    (lambda x: (x - 1.2345678901) ** 5, 0.0, 3.0),            # a flat, multiple root
    (lambda x: math.atan(50 * (x - 0.3)), -1.0, 2.0),           # steep
    (lambda x: x, -1.0, 1.0),
]


@pytest.mark.parametrize("f, a, b", ROOT_CASES)
@pytest.mark.parametrize("xtol", [2e-12, 1e-6])
def test_brentq_matches_scipy(f, a, b, xtol):
    """The same algorithm, step for step: the same root, or both out of iterations."""
    try:
        theirs = optimize.brentq(f, a, b, xtol=xtol)
    except RuntimeError:   # the flat quintic root at 2e-12: scipy runs out of iterations too
        with pytest.raises(ConvergenceError):
            brentq(f, a, b, xtol=xtol)
        return
    assert brentq(f, a, b, xtol=xtol) == theirs


def test_brentq_refuses_an_unbracketed_interval_and_reports_no_convergence():
    with pytest.raises(ValueError):
        brentq(lambda x: x * x + 1, -1.0, 1.0)
    with pytest.raises(ConvergenceError):
        brentq(lambda x: x**3 - 2 * x - 5, 2.0, 3.0, xtol=1e-300, rtol=0.0, maxiter=3)


MINIMUM_CASES = [
    (lambda x: (x - 0.7) ** 2, (0.0, 2.0)),
    (lambda x: math.sin(x), (3.0, 6.0)),                        # minimum at 3 pi / 2
    (lambda x: abs(x - 0.25) + 0.1 * x**2, (-1.0, 1.0)),       # a kink
    (lambda x: x, (0.0, 1.0)),                                  # at the bound
    (lambda x: math.cosh(x - 10.0), (9.0, 11.0)),
]


@pytest.mark.parametrize("f, bounds", MINIMUM_CASES)
@pytest.mark.parametrize("xatol", [1e-5, 1e-11])
def test_bounded_minimum_matches_scipy(f, bounds, xatol):
    ours = minimize_scalar(f, bounds=bounds, method="bounded", options={"xatol": xatol})
    theirs = optimize.minimize_scalar(f, bounds=bounds, method="bounded", options={"xatol": xatol})
    assert (ours.x, ours.fun, ours.nfev) == (theirs.x, theirs.fun, theirs.nfev)
    assert ours.success


def test_bounded_minimum_finds_the_analytic_minimum():
    result = minimize_scalar(math.sin, bounds=(3.0, 6.0), options={"xatol": 1e-12})
    assert result.x == pytest.approx(1.5 * np.pi, abs=1e-7)
    assert result.fun == pytest.approx(-1.0, abs=1e-14)
