"""Metrics of a closed tip path over one carrier revolution (mechanism-agnostic).

A :class:`TipPath` is any periodic planar point motion with closed-form
derivatives and bounds on its speed and acceleration; the planting mechanism
supplies one, and the tests supply synthetic paths whose answers are known by
hand. Extremes are certified minima (see :mod:`kinematics.sweep`); soil
crossings are roots of the continuous model found by Brent's method, with every
interval that could hide a dip below the soil between two samples refined.

Defined choices (documented in the README):

* the revolution is taken centred on the lowest point; *entry* is the last
  downward crossing of the soil line before it, *exit* the first upward one
  after it, so a tip path that wiggles across the soil line still has one
  defined hole;
* every further downward crossing in the revolution is an extra soil
  penetration and is counted (``PlantEvents.penetrations`` > 1 fails a check);
* a planting depth that the path cannot reach above (tip never out of the soil)
  has no crossing and raises :class:`NoSoilCrossingError`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from .scalar import brentq

from . import tolerances as tol
from .errors import DesignError, Problem
from .sweep import CertifiedMinimum, certified_minimum

__all__ = [
    "TipPath",
    "PlantEvents",
    "HoleMetrics",
    "NoSoilCrossingError",
    "vertical_extremes",
    "soil_crossings",
    "plant_events",
    "hole_metrics",
]

TWO_PI = 2.0 * np.pi


class NoSoilCrossingError(DesignError):
    """The tip path never crosses the soil line (planting depth too large)."""


@dataclass(frozen=True)
class TipPath:
    """A periodic tip motion over the carrier angle.

    Attributes
    ----------
    motion : callable
        ``phi (n,) -> PointMotion`` with position, velocity (mm/rad) and
        acceleration (mm/rad^2), each (n, 2).
    attitude : callable
        ``phi (n,) -> (n,)`` planter attitude (rad).
    speed_bound, acceleration_bound : float
        Upper bounds on ``|velocity|`` and ``|acceleration|`` over all phi.
    """

    motion: Callable
    attitude: Callable
    speed_bound: float
    acceleration_bound: float

    def position(self, phi):
        return self.motion(np.atleast_1d(phi)).position

    def height(self, phi):
        return self.position(phi)[:, 1]


@dataclass(frozen=True)
class PlantEvents:
    """Where one plant goes into the soil (carrier angles in rad, heights in mm)."""

    lowest: float
    lowest_height: float
    highest: float
    highest_height: float
    soil_level: float
    entry: float
    exit: float
    penetrations: int
    lowest_search: CertifiedMinimum
    highest_search: CertifiedMinimum

    @property
    def trajectory_height(self) -> float:
        return self.highest_height - self.lowest_height


@dataclass(frozen=True)
class HoleMetrics:
    """Hole made at one plant spacing (mm)."""

    spacing: float
    x_entry: float
    x_exit: float
    x_lowest: float
    width: float
    verticality: float
    span: float


def vertical_extremes(path: TipPath, *, steps: int = tol.STEPS_PER_REVOLUTION,
                      start: float = 0.0):
    """Certified lowest and highest points of the path over one revolution.

    Returns
    -------
    lowest, highest : CertifiedMinimum
        ``highest.value`` is the negated height of the highest point.
    """
    common = dict(steps=steps, lipschitz=path.speed_bound, curvature=path.acceleration_bound)
    lowest = certified_minimum(path.height, start, start + TWO_PI, **common)
    highest = certified_minimum(lambda p: -path.height(p), start, start + TWO_PI, **common)
    return lowest, highest


def soil_crossings(path: TipPath, soil_level: float, start: float, *,
                   steps: int = tol.STEPS_PER_REVOLUTION, xtol: float = tol.ROOT_XTOL,
                   max_splits: int = 40):
    """Every crossing of ``y = soil_level`` by the tip in ``[start, start + 2 pi)``.

    Intervals of the screening grid are split until each one either keeps its
    slope sign (``|y'| > K h`` at an end, so at most one crossing, found by
    Brent's method) or stays clear of the line (``min |gap| > K h^2 / 8``), with
    ``K`` the acceleration bound: no pair of crossings hides between samples.
    A tangency that survives ``max_splits`` halvings counts only if the sign changes.

    Returns
    -------
    angles : (k,) float
        Sorted crossing angles (rad).
    downward : (k,) bool
        True where the tip goes into the soil.
    """
    curvature = path.acceleration_bound

    def gap_and_slope(phi):
        motion = path.motion(phi)
        return motion.position[:, 1] - soil_level, motion.velocity[:, 1]

    def gap_at(s):
        return float(path.height(np.array([s]))[0] - soil_level)

    left = np.linspace(start, start + TWO_PI, steps + 1)
    gap, slope = gap_and_slope(left)
    right, g_right, s_right = left[1:], gap[1:], slope[1:]
    left, g_left, s_left = left[:-1], gap[:-1], slope[:-1]
    roots = []
    for _ in range(max_splits + 1):
        width = right - left
        # the slope keeps its sign over the interval: at most one crossing
        monotone = np.maximum(np.abs(s_left), np.abs(s_right)) > curvature * width
        # both ends on one side and too far from the line to reach it
        clear = (g_left * g_right > 0.0) & (
            np.minimum(np.abs(g_left), np.abs(g_right)) > curvature * width**2 / 8.0)
        # an exact zero counts once, at the right end of its interval
        change = (g_left != 0.0) & ((g_right == 0.0) | (np.sign(g_left) != np.sign(g_right)))
        settled = monotone | clear
        for k in np.flatnonzero(settled & change):
            roots.append(right[k] if g_right[k] == 0.0
                         else brentq(gap_at, left[k], right[k], xtol=xtol))
        keep = ~settled
        if not keep.any():
            break
        left, right = left[keep], right[keep]
        g_left, g_right, s_left, s_right = g_left[keep], g_right[keep], s_left[keep], s_right[keep]
        middle = 0.5 * (left + right)
        g_mid, s_mid = gap_and_slope(middle)
        left, right = np.concatenate([left, middle]), np.concatenate([middle, right])
        g_left, g_right = np.concatenate([g_left, g_mid]), np.concatenate([g_mid, g_right])
        s_left, s_right = np.concatenate([s_left, s_mid]), np.concatenate([s_mid, s_right])
    else:
        # unresolved only at a tangency (slope and gap both ~0): count a sign change once
        for k in np.flatnonzero((g_left != 0.0) & (np.sign(g_left) != np.sign(g_right))):
            roots.append(brentq(gap_at, left[k], right[k], xtol=xtol))
    angles = np.array(sorted(roots))
    if angles.size == 0:
        return angles, np.zeros(0, dtype=bool)
    slope = path.motion(angles).velocity[:, 1]
    # at a crossing where the slope vanishes use the sign just after it
    probe = path.height(angles + 1e-7) - soil_level
    downward = np.where(slope != 0.0, slope < 0.0, probe < 0.0)
    return angles, downward


def _stationary(path: TipPath, guess: float, reach: float) -> float:
    """Where ``dy/dphi = 0`` next to ``guess``: the minimum's location to round-off.

    The value of a flat minimum is found to ``atol`` but its location only to
    about ``sqrt(atol / y'')``; the analytic slope pins the location down, which
    the hole verticality (x at the lowest point) needs.
    """
    def slope(s):
        return float(path.motion(np.array([s])).velocity[0, 1])

    for width in (reach, 4 * reach):
        a, b = guess - width, guess + width
        if slope(a) < 0.0 < slope(b):
            return brentq(slope, a, b, xtol=tol.ROOT_XTOL)
    return guess  # a kink, not a smooth minimum: keep the certified argument


def plant_events(path: TipPath, depth: float, *, steps: int = tol.STEPS_PER_REVOLUTION,
                 depth_field: str = "field.depth") -> PlantEvents:
    """Lowest point, soil line and the entry and exit crossings of one plant.

    The soil line is ``y_g = min(y) + depth`` (spec). Raises
    :class:`NoSoilCrossingError` naming ``depth_field`` when the tip never
    leaves the soil, and ``ValueError`` for a non-positive depth.
    """
    if not depth > 0.0:
        raise ValueError(f"depth must be positive, not {depth!r}")
    lowest, highest = vertical_extremes(path, steps=steps)
    height = -highest.value - lowest.value
    soil = lowest.value + depth
    if depth >= height:
        raise NoSoilCrossingError([Problem(
            depth_field, "no_soil_crossing",
            f"planting depth {depth:g} mm is not less than the tip path's height "
            f"{height:.3f} mm: the tip never leaves the soil, so there is no entry or exit")])
    centre = _stationary(path, lowest.argument, TWO_PI / steps)
    angles, downward = soil_crossings(path, soil, centre - np.pi, steps=steps)
    before = angles[(angles < centre) & downward]
    after = angles[(angles > centre) & ~downward]
    if before.size == 0 or after.size == 0:
        raise NoSoilCrossingError([Problem(
            depth_field, "no_soil_crossing",
            f"no soil crossing found around the lowest point at phi = "
            f"{np.degrees(centre):.3f} deg with depth {depth:g} mm")])
    return PlantEvents(
        lowest=float(np.mod(centre, TWO_PI)), lowest_height=lowest.value,
        highest=float(np.mod(highest.argument, TWO_PI)), highest_height=-highest.value,
        soil_level=soil, entry=float(before.max()), exit=float(after.min()),
        penetrations=int(downward.sum()), lowest_search=lowest, highest_search=highest)


def hole_metrics(path: TipPath, events: PlantEvents, spacing: float, *,
                 steps: int = tol.STEPS_PER_REVOLUTION) -> HoleMetrics:
    """Hole width, verticality and span at plant spacing ``spacing`` (mm).

    Absolute motion ``X = x + (S / pi) phi`` (the machine advances ``2 S`` per
    carrier revolution). ``span`` is the x-extent of the tip while it is below
    the soil line: it exceeds ``width`` when the absolute path loops in the soil.
    """
    drift = spacing / np.pi

    def absolute_x(phi):
        phi = np.atleast_1d(phi)
        return path.position(phi)[:, 0] + drift * phi

    x_entry, x_exit = absolute_x(np.array([events.entry, events.exit]))
    # evaluate the lowest point in the same revolution as entry and exit
    lowest = events.lowest
    if lowest < events.entry:
        lowest += TWO_PI
    elif lowest > events.exit:
        lowest -= TWO_PI
    x_lowest = absolute_x(np.array([lowest]))[0]
    soil_steps = max(8, int(np.ceil(steps * (events.exit - events.entry) / TWO_PI)))
    common = dict(steps=soil_steps, lipschitz=path.speed_bound + drift,
                  curvature=path.acceleration_bound)
    low = certified_minimum(absolute_x, events.entry, events.exit, **common)
    high = certified_minimum(lambda p: -absolute_x(p), events.entry, events.exit, **common)
    return HoleMetrics(spacing=spacing, x_entry=float(x_entry), x_exit=float(x_exit),
                       x_lowest=float(x_lowest), width=float(abs(x_exit - x_entry)),
                       verticality=float(abs(0.5 * (x_entry + x_exit) - x_lowest)),
                       span=float(-high.value - low.value))
