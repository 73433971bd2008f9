"""Closed pitch curves parametrized by arc length, the form a gear cutter needs.

A cutter's pitch line (rack) or pitch circle (shaper) rolls without slipping on
the gear's pitch curve, so the tooth generator needs the point ``P(s)``, unit
tangent ``t(s)``, outward normal ``n(s)`` and curvature at any arc length ``s``.
Built from an exact parametric curve and its derivative: arc length is the
piecewise Chebyshev integral of the speed (spectrally accurate), the exact
points at uniform arc length are interpolated by a periodic quintic spline.
Curves are stored counter-clockwise; ``n`` points out of the enclosed region and
the curvature is positive where the curve is convex.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import make_interp_spline

from .chebyshev import PiecewiseChebyshev
from .planar import unit as _unit, perp as _perp

__all__ = ["ArcLengthCurve"]

TWO_PI = 2.0 * np.pi


@dataclass(frozen=True)
class ArcLengthCurve:
    """A closed, counter-clockwise planar curve with arc length as parameter.

    Attributes
    ----------
    length : float
        Perimeter (mm).
    reversed : bool
        True when the source parametrization ran clockwise and was reversed;
        ``source_to_arc`` then maps a source parameter to ``length - s``.
    """

    length: float
    reversed: bool
    _spline: object = field(repr=False)
    _arc_of_source: PiecewiseChebyshev = field(repr=False)
    _source_period: float = 0.0

    # ----------------------------------------------------------- construction
    @classmethod
    def from_parametric(cls, position, velocity, period: float, *, breaks=None,
                        samples: int = 4096) -> "ArcLengthCurve":
        """From ``position(tau) -> (n, 2)`` and ``velocity(tau) -> (n, 2)`` on ``[0, period)``.

        ``breaks`` are parameters where the curve is only piecewise smooth.
        """
        breaks = np.unique(np.concatenate([[0.0, period], np.asarray(
            breaks if breaks is not None else np.linspace(0, period, 17), dtype=float)]))
        breaks = breaks[(breaks >= 0) & (breaks <= period)]
        speed = PiecewiseChebyshev.interpolate(
            lambda tau: np.linalg.norm(velocity(tau), axis=-1), breaks)
        arc = speed.antiderivative()
        length = float(arc(period))
        # orientation from the shoelace area of a dense sample
        probe = position(np.linspace(0.0, period, 2048, endpoint=False))
        area = 0.5 * np.sum(probe[:, 0] * np.roll(probe[:, 1], -1)
                            - np.roll(probe[:, 0], -1) * probe[:, 1])
        flipped = area < 0
        s = np.arange(samples) * (length / samples)
        source_arc = (length - s) % length if flipped else s
        tau = _invert_monotone(arc, source_arc, 0.0, period)
        points = position(tau)
        closed_s = np.append(s, length)
        spline = make_interp_spline(closed_s, np.vstack([points, points[:1]]), k=5,
                                    bc_type="periodic")
        return cls(length, bool(flipped), spline, arc, float(period))

    @classmethod
    def from_polar(cls, radius, radius_rate, *, breaks=None, samples: int = 4096):
        """From a polar curve ``rho = radius(theta)`` with ``radius_rate = d rho / d theta``."""
        def position(theta):
            return radius(theta)[..., None] * _unit(theta)

        def velocity(theta):
            u = _unit(theta)
            return radius_rate(theta)[..., None] * u + radius(theta)[..., None] * _perp(u)

        return cls.from_parametric(position, velocity, TWO_PI, breaks=breaks, samples=samples)

    @classmethod
    def circle(cls, radius: float, samples: int = 4096) -> "ArcLengthCurve":
        return cls.from_polar(lambda t: np.full(np.shape(t), float(radius)),
                              lambda t: np.zeros(np.shape(t)), samples=samples)

    # ------------------------------------------------------------- evaluation
    def arc_of_source(self, tau):
        """Arc length of the source parameter ``tau`` (in this curve's counter-clockwise sense)."""
        s = self._arc_of_source(np.mod(np.asarray(tau, dtype=float), self._source_period))
        return np.mod(self.length - s, self.length) if self.reversed else s

    def point(self, s):
        """``P(s)``, shape ``s.shape + (2,)``."""
        return self._spline(np.mod(np.asarray(s, dtype=float), self.length))

    def frame(self, s):
        """``(P, t, n)`` at ``s``: point, unit tangent, outward unit normal."""
        s = np.mod(np.asarray(s, dtype=float), self.length)
        tangent = self._spline(s, 1)
        tangent = tangent / np.linalg.norm(tangent, axis=-1, keepdims=True)
        return self._spline(s), tangent, np.stack([tangent[..., 1], -tangent[..., 0]], axis=-1)

    def curvature(self, s):
        """Signed curvature (1/mm), positive where convex."""
        s = np.mod(np.asarray(s, dtype=float), self.length)
        d1, d2 = self._spline(s, 1), self._spline(s, 2)
        return (d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0]) / np.linalg.norm(d1, axis=-1) ** 3

    def polyline(self, count: int = 2048):
        return self.point(np.arange(count) * (self.length / count))


def _invert_monotone(function, targets, low, high, iterations: int = 60):
    """Solve ``function(x) = targets`` for an increasing function on ``[low, high]``."""
    lo = np.full_like(targets, low, dtype=float)
    hi = np.full_like(targets, high, dtype=float)
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        above = function(mid) > targets
        hi = np.where(above, mid, hi)
        lo = np.where(above, lo, mid)
    return 0.5 * (lo + hi)
