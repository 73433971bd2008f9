"""How far each planting metric passes its target: the one definition of a margin.

The studio's margins list, the population screen and the optimiser's constraints all
use these functions, so "margin" means the same number everywhere. From the targets
(:class:`kinematics.evaluation.Targets`), not from a target's text:

* ``> m``  (a lower bound only) gives ``value - m``;
* ``< M``  (an upper bound only) gives ``M - value``;
* ``lo-hi`` (both) gives the nearer side, ``min(value - lo, hi - value)``;
* ``= k``  (``lo == hi``) gives minus the distance, ``-|value - k|``.

A margin is in the metric's unit, negative when the metric fails by that much. It is
normalised by the size of its bound (``|hi|`` when there is an upper bound, else
``|lo|``); a bound of 0 has no scale and no normalised margin (NaN here, None in the
studio's JSON).
"""

from __future__ import annotations

import numpy as np

from .evaluation import Targets

__all__ = ["metric_bounds", "bounds_of", "margins", "normalised_margins", "is_equality",
           "min_margin"]


def metric_bounds(targets: Targets = Targets()) -> dict:
    """``{metric key: (low, high)}`` of every planting metric, None where a side is open."""
    t = targets
    return {"trajectory_height": (t.trajectory_height_min, None),
            "hole_width": (0.0, t.hole_width_max),
            "hole_verticality": (None, t.hole_verticality_max),
            "angle_difference": (0.0, t.angle_difference_max_deg),
            "arm_distance": (t.arm_distance_min, None),
            "ground_clearance": (t.ground_clearance_min, None),
            "module": (t.module_min, None),
            "soil_penetrations": (1.0, 1.0)}


def bounds_of(key: str, targets: Targets = Targets()) -> tuple:
    """``(low, high)`` of the metric ``key``; a per-spacing key (``hole_width@185``) is its metric's."""
    return metric_bounds(targets).get(key.split("@", 1)[0], (None, None))


def margins(values, low, high):
    """Margins of ``values`` against ``[low, high]`` and the scale that normalises them.

    Parameters
    ----------
    values : (...) float
        Metric values; NaN stays NaN.
    low, high : float, (...) float or None
        The bounds (None: that side open; an array: a bound per design, as when the
        targets themselves are searched). Both None: every margin NaN.

    Returns
    -------
    margin, scale : (...) float
        ``scale`` is ``|high|`` when there is an upper bound, else ``|low|``; NaN where it
        is 0 or there is no bound (a float when the bounds are).
    """
    values = np.asarray(values, dtype=float)
    if low is None and high is None:
        return np.full(values.shape, np.nan), float("nan")
    if high is None:
        margin = values - low
    elif low is None:
        margin = high - values
    else:
        # lo == hi is an equality target: minus the distance, which is what the nearer
        # side gives there too, min(v - k, k - v) = -|v - k|
        margin = np.minimum(values - low, high - values)
    scale = np.abs(high if high is not None else low)
    scale = np.where(scale > 0.0, scale, np.nan)
    return margin, (float(scale) if scale.ndim == 0 else scale)


def normalised_margins(values, low, high):
    """``margin / scale`` (see :func:`margins`); NaN where the scale is 0 or a margin is not finite."""
    margin, scale = margins(values, low, high)
    with np.errstate(invalid="ignore"):
        out = margin / scale
    return np.where(np.isfinite(out), out, np.nan)


def is_equality(key: str, targets: Targets = Targets()) -> bool:
    """True for a target ``= k`` (``soil_penetrations``), whose margin is at best 0."""
    low, high = bounds_of(key, targets)
    return low is not None and high is not None and np.all(np.equal(low, high))


def min_margin(normalised, equality=None) -> np.ndarray:
    """The smallest normalised margin of each design: ``normalised`` (N, m) -> (N,).

    NaN columns (a bound of 0, no scale) are left out. An equality target (``equality``,
    an (m,) bool mask: see :func:`is_equality`) counts only when it fails: met, its margin
    is 0 whatever the design, and would hide how much room every other target has. A
    design whose every column is left out gets NaN.
    """
    normalised = np.array(normalised, dtype=float)
    if equality is not None:
        met = np.asarray(equality, dtype=bool) & (normalised >= 0.0)
        normalised[met] = np.nan
    finite = np.where(np.isnan(normalised), np.inf, normalised)
    out = finite.min(axis=-1)
    return np.where(np.all(np.isnan(normalised), axis=-1), np.nan, out)
