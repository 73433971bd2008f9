"""The certified search over poses: least distance of a sweep scene through an interval, interference.

Engine-agnostic: the scene is any :class:`cadgen.sweep.scene.SweepScene` (the
FCL one is :class:`cadgen.sweep.fcl.FclScene`); this module never imports an
engine. :func:`certified_distance` feeds the scene's distance to
:func:`kinematics.sweep.certified_minimum` and scans the same samples for
interference; :func:`plain_scan` is the sampling-only peer.

The search relies on the distance being continuous in the carrier angle
``phi`` with ``|d distance / d phi|`` at most the caller's Lipschitz bound
``L`` (and, for the second-order screen, the relative acceleration at most
``A``); how to form both from the mechanism's speeds and
:func:`cadgen.sweep.scene.part_reach` is in :mod:`cadgen.sweep.scene`.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from cadgen.solids.errors import SolidInputError
from cadgen.sweep.scene import SweepScene

__all__ = [
    "INTERFERENCE_XTOL",
    "INTERFERENCE_RESOLUTION",
    "MAX_EVALUATIONS",
    "SweepResult",
    "certified_distance",
    "plain_scan",
]

#: Carrier-angle tolerance (rad) of the ends of an interference range (bisection).
INTERFERENCE_XTOL = 1e-9
#: Narrowest interval (rad) the interference scan splits where the Lipschitz bound
#: cannot rule out an overlap; an overlap shorter than this can hide in one.
INTERFERENCE_RESOLUTION = 1e-6
#: Default budget of poses of :func:`certified_distance` (each pass).
MAX_EVALUATIONS = 20_000


@dataclass(frozen=True)
class SweepResult:
    """Outcome of :func:`certified_distance`.

    Attributes
    ----------
    minimum : float
        Least distance found (mm); 0 when the groups interfere.
    argument : float
        Carrier angle where it occurs (rad).
    bound : float
        Certified lower bound: no carrier angle of the interval gives less (mm).
    certified : bool
        The bound is within ``atol`` of the minimum.
    evaluations : int
        Poses evaluated in all (screen, refinement and interference scan).
    point_a, point_b : (3,) float
        Nearest points at ``argument``, world frame (mm); equal when overlapping.
    pair : tuple of str
        The instances they belong to.
    interference_ranges : list of (float, float)
        Carrier-angle ranges (rad) where the groups overlap, ends within
        ``INTERFERENCE_XTOL``; an overlap that runs through ``upper`` and on from
        ``lower`` is two ranges.
    unresolved : int
        Intervals no wider than ``resolution`` (or left when the budget ran out)
        where the Lipschitz bound could not rule out a brief overlap and none was
        sampled (see :func:`certified_distance`).
    samples_phi, samples_distance : (steps + 1,) float
        The screening grid and its distances, to plot distance against carrier angle.
    lipschitz, acceleration, atol : float
        As given (``acceleration`` None when not given).
    seconds : float
        Wall time of the sweep.
    certificate : (n, 3) float or None
        The search's final partition of ``[lower, upper]``: each interval's ends
        (rad) and the lower bound of the distance proved on it (mm); the least
        is ``bound``. None for a scene searched whole-pose or an overlap.
    """

    minimum: float
    argument: float
    bound: float
    certified: bool
    evaluations: int
    point_a: np.ndarray
    point_b: np.ndarray
    pair: tuple
    interference_ranges: list
    unresolved: int
    samples_phi: np.ndarray = field(repr=False)
    samples_distance: np.ndarray = field(repr=False)
    lipschitz: float = 0.0
    acceleration: float | None = None
    atol: float = 0.0
    seconds: float = 0.0
    certificate: np.ndarray | None = field(default=None, repr=False)

    @property
    def interferes(self) -> bool:
        return bool(self.interference_ranges) or self.minimum <= 0.0


def _curvature(acceleration, lipschitz):
    """``d'' <= A + L^2 / d`` on an interval whose first-order lower bound is ``d > 0``."""

    def bound(first_order_bounds):
        with np.errstate(divide="ignore"):
            return np.where(first_order_bounds > 0.0,
                            acceleration + lipschitz**2 / first_order_bounds, np.inf)

    return bound


class _Memo:
    """The scene's distance with a cache, so the screening grid is posed once for both passes."""

    def __init__(self, scene):
        self.scene = scene
        self.values = {}

    def __call__(self, phis):
        phis = np.atleast_1d(np.asarray(phis, dtype=float))
        out = np.empty(phis.shape)
        for index, phi in np.ndenumerate(phis):
            key = float(phi)
            if key not in self.values:
                self.values[key] = self.scene.distance(key)
            out[index] = self.values[key].distance
        return out

    def proximity(self, phi):
        self(np.array([phi]))
        return self.values[float(phi)]


def _interference(distance, grid, values, lipschitz, xtol, resolution, budget):
    """Overlap ranges from the screening samples, refined where the bound allows an overlap.

    Level by level, as :func:`certified_minimum` does: an interval with both ends
    overlapping counts as overlapping; both ends clear and
    ``(d_left + d_right - L h) / 2 > 0``: clear, certified; one end of each:
    split until narrower than ``xtol`` (bisection of the boundary); otherwise
    split until narrower than ``resolution``. Returns ``(ranges, unresolved,
    evaluations)``; intervals left when ``budget`` evaluations are spent count
    as unresolved.
    """
    left, right = grid[:-1], grid[1:]
    f_left, f_right = values[:-1], values[1:]
    ranges, unresolved, evaluations = [], 0, 0
    while left.size:
        o_left, o_right = f_left <= 0.0, f_right <= 0.0
        width = right - left
        both = o_left & o_right
        ranges += list(zip(left[both], right[both]))
        mixed = o_left ^ o_right
        settled = mixed & (width <= xtol)
        middle = 0.5 * (left + right)
        ranges += [(a, m) if oa else (m, b) for a, b, m, oa in
                   zip(left[settled], right[settled], middle[settled], o_left[settled])]
        clear = ~(o_left | o_right)
        possible = clear & (0.5 * (f_left + f_right - lipschitz * width) <= 0.0)
        small = possible & (width <= resolution)
        unresolved += int(small.sum())
        split = (mixed & ~settled) | (possible & ~small)
        if evaluations + int(split.sum()) > budget:
            unresolved += int(split.sum())
            break
        left, right, middle = left[split], right[split], middle[split]
        f_left, f_right = f_left[split], f_right[split]
        if not left.size:
            break
        f_middle = distance(middle)
        evaluations += middle.size
        left, right = np.concatenate([left, middle]), np.concatenate([middle, right])
        f_left, f_right = np.concatenate([f_left, f_middle]), np.concatenate([f_middle, f_right])
    merged = []
    for start, end in sorted((float(a), float(b)) for a, b in ranges):
        if merged and start <= merged[-1][1]:
            merged[-1] = (merged[-1][0], max(merged[-1][1], end))
        else:
            merged.append((start, end))
    return merged, unresolved, evaluations


def _pair_speeds(scene, lipschitz, acceleration, instance_bounds):
    """Per pair ``(L, A)`` arrays: each pair's two instances' bounds summed, capped by the
    scene-wide ones when given (both are true bounds: the smaller is too)."""
    count = len(scene.pairs)
    speed = np.full(count, np.inf if lipschitz is None else float(lipschitz))
    accel = None if acceleration is None and instance_bounds is None else \
        np.full(count, np.inf if acceleration is None else float(acceleration))
    if instance_bounds is not None:
        missing = sorted({n for pair in scene.pairs for n in pair} - set(instance_bounds))
        if missing:
            raise SolidInputError("instance_bounds", f"no speed bound for instances {missing}")
        for name, bounds in instance_bounds.items():
            if len(bounds) != 2 or not all(math.isfinite(b) and b >= 0.0 for b in bounds):
                raise SolidInputError("instance_bounds",
                                      f"{name}: need (speed, acceleration) finite >= 0, "
                                      f"not {bounds!r}")
        own = np.array([[instance_bounds[a][k] + instance_bounds[b][k] for k in (0, 1)]
                        for a, b in scene.pairs], dtype=float).reshape(count, 2)
        speed = np.minimum(speed, own[:, 0])
        accel = np.minimum(accel, own[:, 1])
    if accel is not None and not np.all(np.isfinite(accel)):
        accel = None
    return speed, accel


def certified_distance(scene: SweepScene, *, lipschitz: float | None = None,
                       acceleration: float | None = None,
                       steps: int = 360, atol: float = 1e-6,
                       lower: float = 0.0, upper: float = 2.0 * math.pi,
                       xtol: float = INTERFERENCE_XTOL,
                       resolution: float = INTERFERENCE_RESOLUTION,
                       max_evaluations: int = MAX_EVALUATIONS,
                       instance_bounds: dict | None = None) -> SweepResult:
    """Certified least distance of the scene's groups over ``[lower, upper]``, and interference.

    Parameters
    ----------
    scene : SweepScene
    lipschitz : float
        Upper bound ``L`` (mm/rad) on ``|d distance / d phi|``: the largest
        relative speed of any point of group A against any point of group B (see
        :mod:`cadgen.sweep.scene`). The caller's responsibility: too small a
        bound voids the certificate. May be left out when ``instance_bounds``
        is given (then the largest pair's).
    acceleration : float, optional
        Upper bound ``A`` (mm/rad^2) on the relative acceleration of any point of
        A against any point of B. The distance is then screened to second order,
        ``d'' <= A + L^2 / d`` (it is the least of point-to-point distances, each
        obeying that), which a smooth minimum needs: with ``L`` alone the search
        splits down to intervals of ``2 atol / L`` round it, thousands of poses.
        A kink (the nearest features switching) needs only ``L``.
    steps : int
        Intervals of the screening grid; its poses are evaluated exactly (the
        distance curve of the report).
    atol : float
        The true minimum lies in ``[bound, minimum]`` and ``minimum - bound <= atol``
        when ``certified``.
    lower, upper : float
        Carrier-angle interval (rad); for two arms half a turn apart the
        distance repeats every ``pi``.
    xtol : float
        Tolerance (rad) of the ends of interference ranges.
    resolution : float
        Narrowest interval (rad) split in search of an overlap.
    max_evaluations : int
        Budget of poses, for the minimum search and again for the interference
        scan; when spent, ``certified`` is False (or ``unresolved`` counts the
        intervals left).
    instance_bounds : dict, optional
        ``{instance name: (speed mm/rad, acceleration mm/rad^2)}`` bounds of any
        point of each instance, for a scene that answers per pair (``pairs``,
        ``lower_bounds``, ``refine``, ``exact``: :class:`cadgen.sweep.fcl.FclScene`):
        a pair's bounds are its two instances' summed, so a slow pair is
        certified with its own (smaller) bound.

    Notes
    -----
    Interference is scanned on the screening samples first. An overlap shorter
    than a step can fall between two samples; the Lipschitz bound rules that
    out wherever ``d_left + d_right > L h`` (the distance cannot reach 0 in
    between), so only the remaining intervals are split further (a collide and
    distance query per midpoint), down to ``resolution``; the ends of each
    overlap are bisected to ``xtol``. What is left (``unresolved``) are
    intervals narrower than ``resolution`` in which the distance comes within
    ``L * resolution / 2`` of 0, next to a range found or at a near touch: an
    overlap missed there lasts less than ``resolution``. A brief separation
    inside an overlap (both ends of an interval overlapping) is not looked for:
    the parts interfere either way. When ``bound > 0`` no overlap exists at all.

    The scan runs first: when it finds an overlap the minimum is 0, certified
    (the distance is never negative), at the first overlapping pose sampled.
    Otherwise a scene that answers per pair is searched pair by pair
    (:func:`cadgen.sweep.pairwise.pairwise_minimum`), any other with
    :func:`kinematics.sweep.certified_minimum` on its whole-pose distance.
    """
    from kinematics import tolerances as tol
    from kinematics.sweep import certified_minimum

    pairwise = all(hasattr(scene, name) for name in ("pairs", "lower_bounds", "refine", "exact"))
    if instance_bounds is not None and not pairwise:
        raise SolidInputError("instance_bounds", "the scene does not answer pair by pair")
    if lipschitz is None and instance_bounds is None:
        raise SolidInputError("lipschitz", "a speed bound is needed: lipschitz or instance_bounds")
    if lipschitz is not None and not (math.isfinite(lipschitz) and lipschitz >= 0.0):
        raise SolidInputError("lipschitz", f"must be a finite bound >= 0, not {lipschitz!r}")
    if acceleration is not None and not (math.isfinite(acceleration) and acceleration >= 0.0):
        raise SolidInputError("acceleration", f"must be a finite bound >= 0, not {acceleration!r}")
    if not (isinstance(steps, (int, np.integer)) and steps >= 2):
        raise SolidInputError("steps", f"must be an integer >= 2, not {steps!r}")
    if not (math.isfinite(lower) and math.isfinite(upper) and upper > lower):
        raise SolidInputError("interval", f"need finite lower < upper, got [{lower!r}, {upper!r}]")
    if not (xtol > 0.0 and resolution >= xtol):
        raise SolidInputError("xtol",
                              f"need 0 < xtol <= resolution, got {xtol!r} and {resolution!r}")
    if not atol > 0.0:
        raise SolidInputError("atol", f"must be positive, not {atol!r}")
    start = time.perf_counter()
    grid = np.linspace(lower, upper, int(steps) + 1)   # certified_minimum's screening grid
    certificate = None
    if pairwise:
        from cadgen.sweep.pairwise import PairSamples, pairwise_minimum

        speeds, accelerations = _pair_speeds(scene, lipschitz, acceleration, instance_bounds)
        lipschitz = float(speeds.max())
        if acceleration is None and accelerations is not None:
            acceleration = float(accelerations.max())
        samples = PairSamples(scene, lipschitz=speeds)
        distance, evaluated = samples.distances, samples.poses
    else:
        memo = _Memo(scene)
        distance, evaluated = memo, memo.values
    lipschitz = float(lipschitz)
    values = distance(grid)
    ranges, unresolved, _ = _interference(distance, grid, values, lipschitz, xtol, resolution,
                                          max_evaluations)
    if ranges:
        # the distance is never negative: an overlap is the certified minimum, and
        # searching on would only split the overlap down to 2 atol / L
        minimum = bound = 0.0
        if pairwise:
            argument = min(phi for phi, pose in evaluated.items()
                           if pose.complete and pose.nearest.overlap)
            near = evaluated[argument].nearest
        else:
            argument = min(phi for phi, near in evaluated.items() if near.overlap)
            near = memo.proximity(argument)
    elif pairwise:
        found = pairwise_minimum(samples, grid, lipschitz=speeds, acceleration=accelerations,
                                 atol=atol, max_evaluations=max_evaluations,
                                 xatol=tol.REFINE_XATOL)
        minimum, argument, bound, near = found.value, found.argument, found.bound, found.nearest
        certificate = found.certificate
    else:
        curvature = None if acceleration is None else _curvature(float(acceleration), lipschitz)
        found = certified_minimum(memo, lower, upper, steps=int(steps), lipschitz=lipschitz,
                                  curvature=curvature, atol=atol, max_evaluations=max_evaluations)
        minimum, argument, bound = found.value, found.argument, max(found.bound, 0.0)
        near = memo.proximity(argument)
    return SweepResult(
        minimum=float(minimum), argument=float(argument), bound=float(bound),
        certified=bool(minimum - bound <= atol * (1.0 + 1e-9)), evaluations=len(evaluated),
        point_a=near.point_a, point_b=near.point_b, pair=near.pair,
        interference_ranges=ranges, unresolved=unresolved, samples_phi=grid,
        samples_distance=values, lipschitz=lipschitz, acceleration=acceleration, atol=float(atol),
        seconds=time.perf_counter() - start, certificate=certificate)


def plain_scan(scene: SweepScene, poses: int = 3600, *, lower: float = 0.0,
               upper: float = 2.0 * math.pi) -> tuple:
    """The sampling-only peer: least distance over ``poses`` evenly spaced carrier angles.

    Returns ``(minimum, argument)`` (mm, rad). No bound: the true minimum may be
    lower by up to ``L * step / 2``.
    """
    if not (isinstance(poses, (int, np.integer)) and poses >= 1):
        raise SolidInputError("poses", f"must be a positive integer, not {poses!r}")
    phis = np.linspace(lower, upper, int(poses), endpoint=False)
    values = scene.distances(phis)
    best = int(np.argmin(values))
    return float(values[best]), float(phis[best])
