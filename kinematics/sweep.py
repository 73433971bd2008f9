"""Certified minimum of a function of the carrier angle (engine-agnostic).

Sampling alone can miss the true minimum between samples. Given a bound ``L``
on ``|df/dphi|`` (the largest relative speed of any point of one body against
the other, for a distance), the value on ``[phi_i, phi_i+1]`` is at least
``(f_i + f_i+1 - L h) / 2``. Intervals whose bound could undercut the best
value are first refined by bounded 1-D minimisation (Brent, fast but only
local), then split in halves (branch and bound, all active intervals evaluated
in one vectorized call per level) until every interval's bound is within
``atol`` of the best value. The result carries the minimum, where it occurs,
and the certified lower bound: the true minimum lies in ``[bound, value]``.

Where a bound ``K`` on ``f''`` is known the screen is second order,
``f >= min(f_i, f_i+1) - K h^2 / 8``, which also holds for a pointwise minimum of
such functions (a distance between polylines). Near a smooth minimum this
leaves a handful of intervals to refine instead of dozens. A caller may add a
bound of its own (``interval_bound``), and a known ``floor`` (a distance is never
negative): a value found on the floor is the minimum, certified at once.

The work is bounded (``max_evaluations``): a search that spends its budget
returns what it reached, ``certified = False`` and the gap ``[bound, value]``.
Why a budget, not a finer tolerance: where two bodies touch or cross, a
distance has a kink (its curvature is unbounded), so only the first-order bound
holds there and closing it to ``atol`` would need intervals ``2 atol / L`` wide.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from .scalar import minimize_scalar

from . import tolerances as tol

__all__ = ["CertifiedMinimum", "certified_minimum", "Verdict", "lipschitz_bound", "chord_bound"]


class Verdict:
    """Outcomes of comparing a searched minimum with a target (closed choice)."""

    PASS = "pass"
    FAIL = "fail"
    UNDECIDED = "undecided"


@dataclass(frozen=True)
class CertifiedMinimum:
    """Outcome of :func:`certified_minimum`.

    Attributes
    ----------
    value : float
        Smallest value found (sampled or refined).
    argument : float
        Where it occurs (rad).
    bound : float
        Certified lower bound: no argument in the interval gives less.
    refined_intervals : int
        Intervals refined by Brent or split by branch and bound.
    evaluations : int
        Function evaluations in all (samples plus refinement).
    atol : float
        The tolerance the search was asked for.
    budget_spent : bool
        True when the search stopped at ``max_evaluations`` (see ``gap``).
    """

    value: float
    argument: float
    bound: float
    refined_intervals: int
    evaluations: int
    atol: float = 0.0
    budget_spent: bool = False

    @property
    def certified(self) -> bool:
        """True when the bound is within ``atol`` of the value (the search finished)."""
        return self.value - self.bound <= self.atol * (1.0 + 1e-9)

    @property
    def gap(self) -> float:
        """``value - bound``: the true minimum lies in ``[bound, value]``."""
        return self.value - self.bound

    def verdict_above(self, target: float) -> str:
        """Whether the true minimum is above ``target`` (:class:`Verdict`).

        ``fail`` when the value found is not above it (the true minimum is no
        larger); ``pass`` when the certified bound is above it, or when the search
        certified (value within ``atol``) and the value is above it; otherwise
        ``undecided``: the gap ``[bound, value]`` straddles the target.
        """
        if not self.value > target:
            return Verdict.FAIL
        if self.bound > target or self.certified:
            return Verdict.PASS
        return Verdict.UNDECIDED


def lipschitz_bound(f_left, f_right, width, lipschitz):
    """Least value on ``[a, a + width]`` of any ``L``-Lipschitz ``f`` with ``f(a) >= f_left``
    and ``f(a + width) >= f_right`` (arrays broadcast together).

    ``(f_left + f_right - L h) / 2`` where the two cones ``f_left - L x`` and
    ``f_right - L (h - x)`` cross inside the interval; otherwise the higher end
    alone bounds it, ``max(f_left, f_right) - L h`` (an end known only by a
    loose lower bound then costs nothing).
    """
    f_left, f_right = np.asarray(f_left, dtype=float), np.asarray(f_right, dtype=float)
    reach = np.asarray(lipschitz, dtype=float) * width
    with np.errstate(invalid="ignore"):
        return np.where(np.abs(f_left - f_right) <= reach, 0.5 * (f_left + f_right - reach),
                        np.maximum(f_left, f_right) - reach)


def chord_bound(f_left, f_right, width, curvature):
    """Least value on ``[a, a + width]`` of any ``f`` with ``f'' <= K`` and end values at least
    ``f_left``, ``f_right``: the minimum of ``chord(x) - K (x - a)(b - x) / 2`` (arrays broadcast).

    Tighter than ``min(f_left, f_right) - K h^2 / 8`` wherever the ends differ;
    like it, it holds for a pointwise minimum of such functions (a distance),
    and for lower bounds of the end values (it grows with both).
    """
    f_left, f_right = np.asarray(f_left, dtype=float), np.asarray(f_right, dtype=float)
    sag = 0.5 * np.asarray(curvature, dtype=float) * np.asarray(width, dtype=float) ** 2
    rise = f_right - f_left
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.clip(np.where(sag > 0.0, 0.5 - rise / (2.0 * sag), 0.0), 0.0, 1.0)
    t = np.where(sag > 0.0, t, np.where(rise >= 0.0, 0.0, 1.0))
    return f_left + rise * t - sag * t * (1.0 - t)


def _interval_bounds(f_left, f_right, width, lipschitz, curvature, interval_bound=None,
                     floor=-np.inf):
    bounds = 0.5 * (f_left + f_right - lipschitz * width)
    if interval_bound is not None:
        with np.errstate(invalid="ignore"):
            own = np.asarray(interval_bound(f_left, f_right, width), dtype=float)
        bounds = np.where(np.isfinite(own), np.maximum(bounds, own), bounds)
    if curvature is not None:
        bend = curvature(bounds) if callable(curvature) else curvature
        bend = np.broadcast_to(np.asarray(bend, dtype=float), bounds.shape)
        with np.errstate(invalid="ignore"):
            second = np.minimum(f_left, f_right) - bend * width**2 / 8.0
        bounds = np.where(np.isfinite(second), np.maximum(bounds, second), bounds)
    return np.maximum(bounds, floor)


def _finite(values, arguments):
    values = np.asarray(values, dtype=float)
    if not np.all(np.isfinite(values)):
        bad = np.asarray(arguments)[~np.isfinite(values)][0]
        raise ArithmeticError(f"function is not finite at phi = {bad!r}")
    return values


def certified_minimum(function, lower: float, upper: float, *, steps: int,
                      lipschitz: float, curvature=None, atol: float = 1e-9,
                      xatol: float = tol.REFINE_XATOL, floor: float | None = None,
                      interval_bound=None,
                      max_evaluations: int = tol.MINIMUM_SEARCH_EVALUATIONS) -> CertifiedMinimum:
    """Certified minimum of a continuous ``function`` on ``[lower, upper]``.

    Parameters
    ----------
    function : callable
        Vectorized: ``(n,) float -> (n,) float``.
    lower, upper : float
        The interval (rad).
    steps : int
        Intervals of the screening grid (>= 2).
    lipschitz : float
        Upper bound on ``|df/dphi|`` over the interval.
    curvature : float or callable, optional
        Upper bound on ``d2f/dphi2``; a callable receives the first-order lower
        bounds of intervals and returns a bound per interval (a distance's
        curvature grows as the distance shrinks).
    atol : float
        The search stops when no interval's bound is more than ``atol`` below
        the best value: the true minimum is then within ``atol`` of ``value``.
    xatol : float
        Absolute tolerance of the Brent refinement (rad).
    floor : float, optional
        A value the function never goes below (0 for a distance). Bounds are
        never lower; a value on the floor is the certified minimum.
    interval_bound : callable, optional
        ``(f_left, f_right, width) -> (n,) float``: a further valid lower bound
        of the function on each interval (combined with the others by ``max``).
    max_evaluations : int
        Budget; when spent the result says ``certified = False`` (and
        ``budget_spent``) and carries the bound actually reached.
    """
    if not upper > lower:
        raise ValueError(f"upper must exceed lower, got [{lower}, {upper}]")
    if steps < 2:
        raise ValueError(f"steps must be at least 2, not {steps}")
    if not (np.isfinite(lipschitz) and lipschitz >= 0):
        raise ValueError(f"lipschitz must be a finite non-negative bound, not {lipschitz}")
    if not atol > 0:
        raise ValueError(f"atol must be positive, not {atol}")
    floor = -np.inf if floor is None else float(floor)

    def interval_bounds(f_left, f_right, width):
        return _interval_bounds(f_left, f_right, width, lipschitz, curvature, interval_bound,
                                floor)

    grid = np.linspace(lower, upper, steps + 1)
    with np.errstate(all="ignore"):
        values = _finite(function(grid), grid)
    left, right = grid[:-1], grid[1:]
    f_left, f_right = values[:-1], values[1:]
    bounds = interval_bounds(f_left, f_right, right - left)
    best = int(values.argmin())
    value, argument = float(values[best]), float(grid[best])
    evaluations = grid.size
    refined = 0

    def polish(a, b):
        nonlocal value, argument, evaluations
        result = minimize_scalar(lambda s: float(function(np.array([s]))[0]), bounds=(a, b),
                                 method="bounded", options={"xatol": xatol})
        evaluations += result.nfev
        if np.isfinite(result.fun) and result.fun < value:
            value, argument = float(result.fun), float(result.x)

    if value > floor:
        # Brent first round the best sample: it reaches a smooth minimum fast, and the
        # better value lets the bounds discard most intervals at once
        polish(grid[max(best - 1, 0)], grid[min(best + 1, steps)])
        refined += 1
    # branch and bound on whatever could still undercut, one vectorized call per level
    retired = np.inf
    improved = False
    spent = False
    while True:
        active = bounds < value - atol
        if (~active).any():
            retired = min(retired, float(bounds[~active].min()))
        left, right, f_left, f_right = left[active], right[active], f_left[active], f_right[active]
        if left.size == 0:
            break
        if evaluations + left.size > max_evaluations:
            spent = True
            break
        middle = 0.5 * (left + right)
        with np.errstate(all="ignore"):
            f_middle = _finite(function(middle), middle)
        evaluations += middle.size
        refined += middle.size
        k = int(f_middle.argmin())
        if f_middle[k] < value:
            value, argument, improved = float(f_middle[k]), float(middle[k]), True
            reach = right[k] - left[k]
        left, right = np.concatenate([left, middle]), np.concatenate([middle, right])
        f_left, f_right = np.concatenate([f_left, f_middle]), np.concatenate([f_middle, f_right])
        bounds = interval_bounds(f_left, f_right, right - left)
    if improved and value > floor:  # a new basin was found by splitting: polish its bottom
        polish(max(lower, argument - reach), min(upper, argument + reach))
    open_bound = float(bounds.min()) if left.size else np.inf
    bound = min(max(min(retired, open_bound), floor), value)
    return CertifiedMinimum(value, argument, bound, refined, evaluations, atol, spent)
