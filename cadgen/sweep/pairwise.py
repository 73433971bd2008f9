"""Pose by pose and pair by pair: the least distance of a pair scene, certified per pair of parts.

Engine-agnostic (the FCL scene is :class:`cadgen.sweep.fcl.FclScene`). The
distance of two groups is the least of their pairs' distances, and each pair
has its own speed bound (a cam on a slow housing against a planter shell is
slower than the fastest blade), so the search keeps, for every sampled pose and
every pair, a *lower bound* of the pair's distance at three costs:

0. ``scene.lower_bounds(phi, pairs)``: bounding spheres, microseconds; before
   that, what the neighbouring poses carry over (``v - L |dphi|``), nothing;
1. ``scene.refine(phi, p, below)``: one pair's hull separation, which is often
   the exact distance already (:mod:`cadgen.sweep.proxies`), tens of microseconds;
2. ``scene.exact(phi, p, lower)``: the exact engine, a millisecond or more;

and climbs a pair only where the certificate needs it (the
:class:`cadgen.sweep.scene.PairScene` interface). An interval's bound is
the least of its pairs' bounds, each from the pair's end values and speed and
acceleration bounds (:func:`kinematics.sweep.lipschitz_bound`,
:func:`kinematics.sweep.chord_bound`), never below what its parent interval
proved for that pair; lower bounds at the ends keep every bound true (both
formulas grow with the end values). The reported minimum is always an attained
distance: found at a pose whose every pair below it was evaluated exactly.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass

import numpy as np

from cadgen.sweep.scene import Proximity

__all__ = ["PoseSample", "PairSamples", "PairwiseMinimum", "pairwise_minimum"]

#: Levels of a pair's value at a pose: what established it.
CHEAP, REFINED, EXACT = 0, 1, 2


@dataclass
class PoseSample:
    """What is known at one pose.

    Attributes
    ----------
    lower : (P,) float
        A lower bound of each pair's distance (mm).
    level : (P,) int
        :data:`CHEAP`, :data:`REFINED` or :data:`EXACT`.
    bounded : (P,) bool
        The pair's cheap bound (bounding spheres) was taken; before that, ``lower``
        is only what neighbouring poses or the caller carried over.
    nearest : Proximity or None
        The least distance attained among the pairs evaluated.
    cap : float
        Pairs were evaluated only as far as needed to tell whether the pose's
        distance is below ``cap``: when ``complete`` it is (``nearest`` is the
        pose's distance), otherwise the distance is at least ``cap``.
    complete : bool
    """

    lower: np.ndarray
    level: np.ndarray
    bounded: np.ndarray
    nearest: Proximity | None
    cap: float
    complete: bool

    @property
    def distance(self) -> float:
        """The pose's distance when ``complete``, else ``cap`` (a lower bound of it)."""
        return self.nearest.distance if self.complete else self.cap


class PairSamples:
    """The poses of a pair scene evaluated so far, each as far as a caller needed.

    Parameters
    ----------
    scene : pair scene
        ``pairs``, ``lower_bounds(phi, pairs)``, ``refine(phi, p, below)`` and
        ``exact(phi, p, lower)`` (see :class:`cadgen.sweep.fcl.FclScene`).
    lipschitz : (P,) float, optional
        Per pair, a bound of ``|d distance / d phi|``: a new pose then starts from
        its neighbours' bounds, less ``L |dphi|``, and a pair that stays far is
        not even placed.
    """

    def __init__(self, scene, lipschitz=None):
        self.scene = scene
        self.count = len(scene.pairs)
        self.poses: dict = {}
        self.lipschitz = None if lipschitz is None else np.asarray(lipschitz, dtype=float)
        self._sorted: list = []   # the poses' angles, increasing (their neighbours)
        self.hint = None   # the pair nearest at the last complete pose: evaluated first

    # -------------------------------------------------------------- one pose
    def pose(self, phi: float, cap: float = math.inf, skip=None, floor=None) -> PoseSample:
        """The pose at ``phi``, evaluated until its distance is known if below ``cap``.

        ``skip`` (P,) bool marks pairs the caller knows to stay at or above
        ``cap`` on its interval: they are evaluated only if the pose's distance
        turns out below ``cap`` (then it must be the pose's true distance).
        ``floor`` (P,) are lower bounds the caller proved already (its interval's).
        """
        phi = float(phi)
        known = self.poses.get(phi)
        if known is not None and (known.complete or known.cap >= cap):
            return known
        if known is not None:   # keep what an earlier, lower-capped visit proved
            sample = PoseSample(known.lower.copy(), known.level.copy(), known.bounded.copy(),
                                known.nearest, cap, False)
        else:
            sample = PoseSample(self._neighbours(phi), np.zeros(self.count, dtype=np.int8),
                                np.zeros(self.count, dtype=bool), None, cap, False)
        if floor is not None:
            np.maximum(sample.lower, floor, out=sample.lower)
        chosen = np.ones(self.count, dtype=bool) if skip is None else ~np.asarray(skip, bool)
        self._settle(phi, sample, chosen, cap)
        best = sample.nearest.distance if sample.nearest is not None else math.inf
        if best < cap and skip is not None and (~chosen).any():
            # a new low: the skipped pairs must not hide a lower one at this very pose
            self._settle(phi, sample, ~chosen, best)
            best = sample.nearest.distance
        sample.complete = best < cap
        if not sample.complete and skip is not None and (~chosen).any():
            # skipped pairs were only known to stay above the caller's own threshold
            sample.cap = min(cap, float(sample.lower[~chosen].min()))
        if sample.complete:
            self.hint = self.scene.pairs.index(sample.nearest.pair)
        if known is None:
            bisect.insort(self._sorted, phi)
        self.poses[phi] = sample
        return sample

    def _neighbours(self, phi):
        """Lower bounds (P,) carried from the nearest poses on each side: ``v - L |dphi|``."""
        out = np.full(self.count, -np.inf)
        if self.lipschitz is None or not self._sorted:
            return out
        at = bisect.bisect_left(self._sorted, phi)
        for k in (at - 1, at):
            if 0 <= k < len(self._sorted) and self._sorted[k] != phi:
                near = self._sorted[k]
                out = np.maximum(out, self.poses[near].lower - self.lipschitz * abs(phi - near))
        return out

    def _settle(self, phi, sample, chosen, cap):
        """Evaluate the ``chosen`` pairs that could be below ``min(cap, best)``: cheap first.

        The hint (the pair nearest at the last pose) goes first, for a threshold:
        the least distance attained so far (an exact pair, or two points of the
        solids). Then the bounding spheres of the pairs still below it, and
        pass 1 refines pairs in order of their bounds until one reaches the
        threshold: a pair whose bound reaches a distance attained elsewhere
        cannot be the nearest. Pass 2 sends the refined pairs still below the
        least *exact* distance to the exact engine, lowest bound first (the pair
        that attained the threshold among them), so that a far pair rarely costs
        an exact query and the pose's distance is always an exact one.
        """
        lower, level, scene = sample.lower, sample.level, self.scene
        state = {"upper": sample.nearest.distance if sample.nearest is not None else math.inf}
        pending = []

        def threshold():
            return min(cap, state["upper"])

        def consider(p):
            """Refine pair ``p``; True when it settled the pose (an overlap)."""
            if level[p] == CHEAP:
                bound, attained, near = scene.refine(phi, int(p), threshold())
                lower[p] = max(lower[p], bound)
                level[p] = REFINED
                state["upper"] = min(state["upper"], attained)
                if near is not None:
                    level[p] = EXACT
                    if sample.nearest is None or near.distance < sample.nearest.distance:
                        sample.nearest = near
                    return near.distance <= 0.0
            # the pair that attained ``upper`` is not exact yet: it must stay a candidate
            # until an exact distance falls below its bound (only ``best`` rules it out)
            best = sample.nearest.distance if sample.nearest is not None else math.inf
            if level[p] == REFINED and lower[p] < min(cap, best):
                pending.append(int(p))
            return False

        hint = self.hint if self.hint is not None and chosen[self.hint] else None
        if hint is not None and level[hint] != EXACT and lower[hint] < threshold():
            if consider(hint):
                return
        need = chosen & ~sample.bounded & (lower < threshold())
        if need.any():
            np.maximum(lower, scene.lower_bounds(phi, need), out=lower)
            sample.bounded |= need
        for p in np.argsort(lower, kind="stable"):
            if not chosen[p] or level[p] == EXACT or p == hint:
                continue
            if lower[p] >= threshold():
                break   # sorted: no later pair can be lower
            if consider(p):
                return
        for p in sorted(set(pending), key=lambda q: lower[q]):
            best = sample.nearest.distance if sample.nearest is not None else math.inf
            if lower[p] >= min(cap, best):
                break
            near = scene.exact(phi, p, float(lower[p]))
            lower[p] = near.distance
            level[p] = EXACT
            if sample.nearest is None or near.distance < sample.nearest.distance:
                sample.nearest = near
            if near.distance <= 0.0:
                return

    def upgrade(self, phi: float, pairs, below: float = math.inf) -> None:
        """Raise the given pairs at an evaluated pose one level (refine, then exact);
        an exact hull certificate is looked for only below ``below``."""
        sample = self.poses[float(phi)]
        for p in pairs:
            p = int(p)
            if sample.level[p] == CHEAP:
                bound, _, near = self.scene.refine(float(phi), p, below)
                sample.lower[p] = max(sample.lower[p], bound)
                sample.level[p] = EXACT if near is not None else REFINED
            elif sample.level[p] == REFINED:
                near = self.scene.exact(float(phi), p, float(sample.lower[p]))
                sample.lower[p] = near.distance
                sample.level[p] = EXACT

    def distances(self, phis) -> np.ndarray:
        """Exact distances ``(n,)`` of the poses (evaluated completely)."""
        phis = np.atleast_1d(np.asarray(phis, dtype=float))
        return np.array([self.pose(phi).distance for phi in phis.ravel()]).reshape(phis.shape)


@dataclass(frozen=True)
class PairwiseMinimum:
    """Outcome of :func:`pairwise_minimum`: the least attained distance and its certificate."""

    value: float
    argument: float
    nearest: Proximity
    bound: float
    budget_spent: bool
    #: ``(n, 3)``: every interval of the final partition of the search range (left, right,
    #: its proved lower bound of the distance), in the order they were settled
    certificate: np.ndarray


def _pair_bounds(f_left, f_right, width, lipschitz, acceleration):
    """Per interval and pair ``(K, P)``: the lower bound from the end values and the speeds."""
    from kinematics.sweep import chord_bound, lipschitz_bound

    width = width[:, None]
    bounds = lipschitz_bound(f_left, f_right, width, lipschitz)
    if acceleration is not None:
        # d'' <= A + L^2 / d where d >= the first-order bound (point pairs' distances)
        with np.errstate(divide="ignore", invalid="ignore"):
            curvature = np.where(bounds > 0.0, acceleration + lipschitz**2 / bounds, np.inf)
            second = chord_bound(f_left, f_right, width, curvature)
        bounds = np.where(np.isfinite(second), np.maximum(bounds, second), bounds)
    return np.maximum(bounds, 0.0)


def pairwise_minimum(samples: PairSamples, grid, *, lipschitz, acceleration=None,
                     atol: float, max_evaluations: int, xatol: float) -> PairwiseMinimum:
    """Certified least distance over ``[grid[0], grid[-1]]``, the grid's poses evaluated completely.

    Parameters
    ----------
    samples : PairSamples
    grid : (n,) float
        Increasing carrier angles (rad), every one already in ``samples`` and complete.
    lipschitz, acceleration : (P,) float
        Per pair: bounds of ``|d distance / d phi|`` and of the relative
        acceleration of any point of one part against any point of the other.
    atol : float
        The search ends when no interval's bound is more than ``atol`` below the value.
    max_evaluations : int
        Budget of poses (those of the grid included).
    xatol : float
        Tolerance (rad) of the bounded 1-D minimisation that polishes the best sample;
        with acceleration bounds, no finer than a step that changes the distance
        by a tenth of ``atol`` at the curvature bound (finer only wanders on the
        flat bottom: twenty poses on the ground clearance's).
    """
    from kinematics.scalar import minimize_scalar

    lipschitz = np.asarray(lipschitz, dtype=float)
    acceleration = None if acceleration is None else np.asarray(acceleration, dtype=float)
    grid = np.asarray(grid, dtype=float)
    lower_end, upper_end = float(grid[0]), float(grid[-1])
    values = np.array([samples.poses[float(phi)].distance for phi in grid])
    best = int(np.argmin(values))
    state = {"value": float(values[best]), "argument": float(grid[best])}
    if acceleration is not None and values[best] > 0.0:
        # a step x off the bottom costs at most K x^2 / 2 there (K the curvature bound)
        curvature = float(np.max(acceleration + lipschitz**2 / values[best]))
        xatol = max(xatol, math.sqrt(0.2 * atol / curvature))

    def record(phi, sample):
        if sample.complete and sample.distance < state["value"]:
            state.update(value=sample.distance, argument=float(phi))
            return True
        return False

    def polish(a, b):
        def f(phi):
            sample = samples.pose(phi)
            record(phi, sample)
            return sample.distance

        minimize_scalar(f, bounds=(a, b), method="bounded", options={"xatol": xatol})

    if state["value"] > 0.0:
        # Brent round the best sample first: the better value lets the bounds retire
        # most intervals at once (as kinematics.sweep.certified_minimum does)
        polish(grid[max(best - 1, 0)], grid[min(best + 1, len(grid) - 1)])
    left, right = grid[:-1].copy(), grid[1:].copy()
    inherited = np.zeros((left.size, samples.count))
    retired, improved, spent, reach = math.inf, False, False, 0.0
    settled = []
    while left.size:
        target = state["value"] - atol
        ends_left = [samples.poses[float(phi)] for phi in left]
        ends_right = [samples.poses[float(phi)] for phi in right]
        f_left = np.array([s.lower for s in ends_left])
        f_right = np.array([s.lower for s in ends_right])
        bounds = np.maximum(_pair_bounds(f_left, f_right, right - left, lipschitz, acceleration),
                            inherited)
        interval = bounds.min(axis=1)
        active = interval < target
        if (~active).any():
            retired = min(retired, float(interval[~active].min()))
            settled.append(np.column_stack([left[~active], right[~active], interval[~active]]))
        left, right, bounds = left[active], right[active], bounds[active]
        ends_left = [s for s, a in zip(ends_left, active) if a]
        ends_right = [s for s, a in zip(ends_right, active) if a]
        if not left.size:
            break
        # before splitting, raise the ends of the pairs that keep an interval open
        raised = False
        for ends, phis in ((ends_left, left), (ends_right, right)):
            for sample, phi, row in zip(ends, phis, bounds):
                open_pairs = row < target
                cheap = open_pairs & (sample.level == CHEAP)
                loose = open_pairs & (sample.level == REFINED) & (sample.lower < state["value"])
                if cheap.any() or loose.any():
                    samples.upgrade(phi, np.flatnonzero(cheap | loose), below=state["value"])
                    raised = True
        if raised:
            inherited = bounds
            continue
        if len(samples.poses) + left.size > max_evaluations:
            spent = True
            break
        middle = 0.5 * (left + right)
        for phi, row, a, b in zip(middle, bounds, left, right):
            sample = samples.pose(phi, cap=state["value"], skip=row >= target, floor=row)
            if record(phi, sample):
                improved, reach = True, float(b - a)
        left, right = np.concatenate([left, middle]), np.concatenate([middle, right])
        inherited = np.concatenate([bounds, bounds])
    if improved and state["value"] > 0.0:   # a new basin was found by splitting: polish it
        polish(max(lower_end, state["argument"] - reach), min(upper_end, state["argument"] + reach))
    open_bound = float(interval[active].min()) if left.size and active.any() else math.inf
    if left.size and active.any():   # the budget ran out: what is left stays open
        settled.append(np.column_stack([left, right, interval[active]]))
    bound = min(max(min(retired, open_bound), 0.0), state["value"])
    nearest = samples.poses[state["argument"]].nearest
    return PairwiseMinimum(state["value"], state["argument"], nearest, bound, spent,
                           np.concatenate(settled) if settled else np.empty((0, 3)))
