"""Piecewise Chebyshev interpolants against closed forms."""

import numpy as np
import pytest

from kinematics.chebyshev import PiecewiseChebyshev
from kinematics.errors import ConvergenceError


def test_values_derivatives_and_integrals_of_a_smooth_function():
    f = PiecewiseChebyshev.interpolate(lambda u: np.exp(np.sin(3 * u)), [0.0, 1.0, 2.0, 2 * np.pi])
    u = np.linspace(0, 2 * np.pi, 1001)
    np.testing.assert_allclose(f(u), np.exp(np.sin(3 * u)), atol=1e-13)
    np.testing.assert_allclose(f.derivative()(u), 3 * np.cos(3 * u) * np.exp(np.sin(3 * u)),
                               atol=1e-10)
    # integral of exp(sin 3u) over a period is 2 pi I0(1)
    from scipy.special import i0

    assert f.integral() == pytest.approx(2 * np.pi * i0(1.0), abs=1e-12)
    assert f.antiderivative()(2 * np.pi) == pytest.approx(2 * np.pi * i0(1.0), abs=1e-12)


def test_kink_on_a_break_converges_kink_inside_a_piece_is_split():
    on_break = PiecewiseChebyshev.interpolate(lambda u: np.abs(u - 1.3), [0.0, 1.3, 3.0])
    assert len(on_break.coefficients) == 2
    inside = PiecewiseChebyshev.interpolate(lambda u: np.abs(u - 1.3) ** 3, [0.0, 3.0])
    u = np.linspace(0, 3, 301)
    np.testing.assert_allclose(inside(u), np.abs(u - 1.3) ** 3, atol=1e-10)


def test_non_finite_function_is_an_error():
    def log_shifted(u):
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.log(u - 0.5)

    with pytest.raises(ConvergenceError, match="not finite"):
        PiecewiseChebyshev.interpolate(log_shifted, [0.0, 1.0])
