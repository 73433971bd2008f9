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


def _flat_bottom(x):
    # zero over [0.8, 1.2] with kinks at both ends: a distance of bodies that cross
    return np.maximum(np.abs(x - 1.0) - 0.2, 0.0)


def test_a_value_on_the_floor_is_the_certified_minimum_at_once():
    result = certified_minimum(_flat_bottom, 0.0, 3.0, steps=300, lipschitz=1.0, floor=0.0)
    assert result.certified and result.value == result.bound == 0.0
    assert result.evaluations == 301 and not result.budget_spent


def test_a_search_that_cannot_close_stops_at_its_budget_and_says_so():
    # without the floor, the zero plateau must be split down to 2 atol / L: never
    result = certified_minimum(_flat_bottom, 0.0, 3.0, steps=300, lipschitz=1.0,
                               max_evaluations=5_000)
    assert result.budget_spent and not result.certified
    assert result.evaluations <= 5_000
    assert result.bound <= 0.0 == result.value and result.gap == -result.bound > result.atol


def test_an_interval_bound_of_the_caller_is_used_and_kept_valid():
    f = lambda x: (x - 1.234) ** 2
    plain = certified_minimum(f, 0.0, 3.0, steps=30, lipschitz=6.0, atol=1e-6)
    # f'' = 2: f >= min(f_l, f_r) - 2 h^2 / 8, given as the caller's own bound
    own = certified_minimum(f, 0.0, 3.0, steps=30, lipschitz=6.0, atol=1e-6,
                            interval_bound=lambda a, b, h: np.minimum(a, b) - h**2 / 4)
    assert plain.certified and own.certified
    assert own.value == pytest.approx(0.0, abs=1e-12) and own.bound <= 0.0
    assert own.evaluations < plain.evaluations


@pytest.mark.parametrize("bound, value, target, verdict", [
    (0.0, 5.0, 10.0, "fail"),        # the value is below the target: the minimum is too
    (12.0, 15.0, 10.0, "pass"),      # the bound is above it
    (8.0, 12.0, 10.0, "undecided"),  # the gap straddles it
    (10.0, 10.0, 10.0, "fail"),      # "> target" is not met on the target
], ids=["fail", "pass", "undecided", "on-target"])
def test_verdict_of_an_uncertified_minimum(bound, value, target, verdict):
    from kinematics.sweep import CertifiedMinimum

    search = CertifiedMinimum(value, 0.0, bound, 0, 0, atol=1e-9, budget_spent=True)
    assert search.verdict_above(target) == verdict
