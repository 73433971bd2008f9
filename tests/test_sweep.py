"""Certified minimum search against brute-force dense scans."""

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from kinematics.sweep import certified_minimum


@pytest.mark.parametrize("steps", [8, 36, 360])
def test_narrow_well_between_samples(steps):
    # a Gaussian well narrower than the grid step, placed off the grid
    centre, width, depth = 1.2345, 0.01, 3.0
    f = lambda x: np.cos(x) - depth * np.exp(-((x - centre) / width) ** 2)
    lipschitz = 1 + depth * np.sqrt(2 / np.e) / width  # max |f'|
    result = certified_minimum(f, 0.0, 2 * np.pi, steps=steps, lipschitz=lipschitz, atol=1e-7)
    # second method: Brent on a bracket known by construction to hold only the well's bottom
    truth = minimize_scalar(f, bounds=(centre - width, centre + width), method="bounded",
                            options={"xatol": 1e-13}).fun
    assert result.value == pytest.approx(truth, abs=1e-10)
    assert result.certified and result.bound <= result.value
    assert truth >= result.bound


def test_second_order_screen_refines_fewer_intervals():
    f = lambda x: np.sin(3 * x) + 0.3 * np.cos(7 * x)
    first = certified_minimum(f, 0, 2 * np.pi, steps=3600, lipschitz=5.1)
    second = certified_minimum(f, 0, 2 * np.pi, steps=3600, lipschitz=5.1, curvature=9 + 0.3 * 49)
    assert second.value == pytest.approx(first.value, abs=1e-9)
    assert first.certified and second.certified
    assert second.evaluations < first.evaluations


@pytest.mark.parametrize("kwargs, match", [
    (dict(steps=1, lipschitz=1.0), "steps"),
    (dict(steps=10, lipschitz=np.nan), "lipschitz"),
    (dict(steps=10, lipschitz=-1.0), "lipschitz"),
])
def test_bad_arguments(kwargs, match):
    with pytest.raises(ValueError, match=match):
        certified_minimum(np.sin, 0.0, 1.0, **kwargs)


def test_non_finite_function_is_an_error():
    with pytest.raises(ArithmeticError, match="not finite"):
        certified_minimum(lambda x: np.log(x - 0.5), 0.0, 1.0, steps=10, lipschitz=10.0)
