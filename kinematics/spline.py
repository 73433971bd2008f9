"""Closed interpolating curves through type-value points (the pricking mechanism's tip loop).

The paper calls its curve a cubic "Lagrange" curve, but its knot vector, de Boor
recursion and coincident end control points make it a periodic B-spline
interpolant with knots at the accumulated chord lengths (the closing chord
included): scipy's ``make_interp_spline(..., bc_type="periodic")``. The
parameter ``u`` is therefore in mm of chord length, period = perimeter of the
control polygon. Degree 3 is the paper's; 5 gives smoother gears.

Checks that a drawn loop can be a tip path: no coincident points (singular
collocation), no self-intersection (a point a little beside its neighbours
makes a tiny loop that passes a chord check), and where the sun centre lies.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import make_interp_spline
from .scalar import minimize_scalar

from .errors import DesignError, Problem
from .planar import cross as _cross

__all__ = ["ClosedCurve", "winding_number", "self_intersections"]

#: Smallest chord, as a fraction of the mean chord, before two points count as coincident.
COINCIDENT_CHORD_RATIO = 1e-3
#: Samples of the whole loop for its dense checks, shared among the spans (8 to 64 each).
DENSE_SAMPLES = 8192


def self_intersections(polygon: np.ndarray) -> np.ndarray:
    """Index pairs ``(i, j)``, ``i < j``, of non-adjacent edges of a closed polygon that cross.

    Near-linear in the number of edges: two edges can cross only if their
    midpoints are within the sum of their half-lengths, so a KD-tree on the
    midpoints proposes the candidate pairs (a digitised loop has thousands of
    edges; all pairs would take gigabytes).

    Parameters
    ----------
    polygon : (n, 2) float
        Vertices, not repeating the first at the end.
    """
    from scipy.spatial import cKDTree

    start = np.asarray(polygon, dtype=float)
    end = np.roll(start, -1, axis=0)
    n = len(start)
    middle = 0.5 * (start + end)
    reach = float(np.linalg.norm(end - start, axis=1).max())
    pairs = cKDTree(middle).query_pairs(reach * (1 + 1e-9), output_type="ndarray")
    if pairs.size == 0:
        return np.zeros((0, 2), dtype=int)
    i, j = pairs.min(axis=1), pairs.max(axis=1)
    keep = (j - i >= 2) & ~((i == 0) & (j == n - 1))  # neighbours share a vertex
    i, j = i[keep], j[keep]
    p0, p1, q0, q1 = start[i], end[i], start[j], end[j]
    d1 = _cross(p1 - p0, q0 - p0)
    d2 = _cross(p1 - p0, q1 - p0)
    d3 = _cross(q1 - q0, p0 - q0)
    d4 = _cross(q1 - q0, p1 - q0)
    hit = (d1 * d2 < 0) & (d3 * d4 < 0)
    order = np.lexsort((j[hit], i[hit]))
    return np.stack([i[hit][order], j[hit][order]], axis=-1)


def winding_number(polygon: np.ndarray, point) -> int:
    """How many times a closed polygon turns around ``point`` (0 when outside)."""
    offset = np.asarray(polygon, dtype=float) - np.asarray(point, dtype=float)
    angles = np.arctan2(offset[:, 1], offset[:, 0])
    steps = np.diff(np.append(angles, angles[0]))
    steps = (steps + np.pi) % (2 * np.pi) - np.pi
    return int(round(steps.sum() / (2 * np.pi)))


@dataclass(frozen=True)
class ClosedCurve:
    """Periodic interpolating B-spline through ``points`` with chord-length knots.

    Parameters
    ----------
    points : (m, 2) float
        Type-value points Q1..Qm in the loop's order (mm); the first is not repeated.
    degree : int
        3 (the paper) or 5.
    path : str
        Field path of the points, for error messages.

    Raises
    ------
    DesignError
        ``coincident_points`` (with the 1-based point numbers) or
        ``self_intersecting_curve`` (with where).
    """

    points: np.ndarray
    degree: int = 3
    path: str = "trajectory.points"
    samples_per_span: int | None = None
    _spline: object = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        points = np.asarray(self.points, dtype=float)
        if points.ndim != 2 or points.shape[1] != 2 or not np.all(np.isfinite(points)):
            raise ValueError("points must be a finite (m, 2) array")
        if self.degree not in (3, 5):
            raise ValueError(f"degree must be 3 or 5, not {self.degree}")
        if len(points) < self.degree + 2:
            raise DesignError.single(self.path, "too_few_points",
                                     f"{len(points)} points are too few for a closed curve of "
                                     f"degree {self.degree} (at least {self.degree + 2})")
        object.__setattr__(self, "points", points)
        if self.samples_per_span is None:
            # 64 a span for a drawn loop of a dozen points; a digitised loop of thousands has
            # short spans, and about 8192 samples in all still resolve every one of them
            object.__setattr__(self, "samples_per_span",
                               int(np.clip(DENSE_SAMPLES // len(points), 8, 64)))
        chords = np.linalg.norm(np.roll(points, -1, axis=0) - points, axis=1)
        tiny = np.flatnonzero(chords < COINCIDENT_CHORD_RATIO * chords.mean())
        if tiny.size:
            m = len(points)
            pairs = ", ".join(f"Q{k + 1} and Q{(k + 1) % m + 1} ({chords[k]:.3g} mm apart)"
                              for k in tiny)
            raise DesignError.single(
                self.path, "coincident_points",
                f"{pairs}: coincident or nearly coincident points make the interpolation "
                "singular; remove one or move it")
        knots = np.concatenate([[0.0], np.cumsum(chords)])
        closed = np.vstack([points, points[:1]])
        spline = make_interp_spline(knots, closed, k=self.degree, bc_type="periodic")
        object.__setattr__(self, "_spline", spline)
        crossings = self_intersections(self.polyline())
        if crossings.size:
            u = self.polyline_parameters()
            where = ", ".join(sorted({self.describe(u[i]) for i, _ in crossings[:4]}))
            raise DesignError.single(
                self.path, "self_intersecting_curve",
                f"the interpolated loop crosses itself ({len(crossings)} crossings) near {where}: "
                "a point lies beside the path of its neighbours; move it onto the loop")

    # -------------------------------------------------------------- geometry
    @property
    def knots(self) -> np.ndarray:
        """Parameters of Q1..Qm and of the return to Q1 (mm of chord length)."""
        return self._spline.t[self.degree:-self.degree]

    @property
    def period(self) -> float:
        return float(self.knots[-1])

    def __call__(self, u, derivative: int = 0):
        """Point (or its ``derivative``-th derivative) at parameters ``u``: shape ``u.shape + (2,)``."""
        u = np.mod(np.asarray(u, dtype=float), self.period)
        return self._spline(u, nu=derivative)

    def polyline_parameters(self) -> np.ndarray:
        spans = len(self.knots) - 1
        local = np.arange(self.samples_per_span) / self.samples_per_span
        knots = self.knots
        return (knots[:-1, None] + np.diff(knots)[:, None] * local).ravel()[: spans * self.samples_per_span]

    def polyline(self) -> np.ndarray:
        """Dense samples of the loop, ``samples_per_span`` per span, not closed."""
        return self(self.polyline_parameters())

    def describe(self, u: float) -> str:
        """Where ``u`` lies, in the designer's terms: between which type-value points."""
        k = int(np.searchsorted(self.knots, np.mod(u, self.period), side="right") - 1)
        m = len(self.points)
        return f"Q{k % m + 1}-Q{(k + 1) % m + 1}"

    def radius_extrema(self, centre):
        """Refined extremes of ``R(u) = |p(u) - centre|`` on the curve, not the points.

        Returns
        -------
        (u_min, R_min), (u_max, R_max)
        """
        centre = np.asarray(centre, dtype=float)
        u = self.polyline_parameters()
        radius = np.linalg.norm(self(u) - centre, axis=1)
        step = u[1] - u[0]
        results = []
        for sign in (1.0, -1.0):
            values = sign * radius
            local = np.flatnonzero((values <= np.roll(values, 1)) & (values <= np.roll(values, -1)))
            local = local[values[local] <= values.min() + 1e-3 * np.ptp(values) + 1e-12]
            best_u, best_v = float(u[values.argmin()]), float(values.min())
            for k in local:
                width = 2 * max(step, np.diff(self.knots).max() / self.samples_per_span)
                res = minimize_scalar(
                    lambda s: sign * float(np.linalg.norm(self(s) - centre)),
                    bounds=(u[k] - width, u[k] + width), method="bounded",
                    options={"xatol": 1e-12 * self.period})
                if res.fun < best_v:
                    best_u, best_v = float(res.x), float(res.fun)
            best_u = self._stationary(best_u, centre, width=2 * step)
            best_v = sign * float(np.linalg.norm(self(best_u) - centre))
            results.append((float(np.mod(best_u, self.period)), sign * best_v))
        return results[0], results[1]

    def _stationary(self, guess: float, centre, width: float) -> float:
        """Polish an extremum of R as the root of ``dR/du ~ (p - O).p'``.

        A minimiser pins a flat extremum's location only to about sqrt(eps);
        the slope has a simple root there, which bisection finds to round-off
        (the dead centres must be exact: the branch of the arccos flips there).
        """
        from .scalar import brentq

        def slope(u):
            return float(np.dot(self(u) - centre, self(u, 1)))

        low, high = guess - width, guess + width
        if slope(low) * slope(high) < 0:
            return brentq(slope, low, high, xtol=1e-15 * self.period, rtol=1e-15)
        return guess

    def centre_problems(self, centre, path: str = "trajectory.sun_centre") -> list:
        """The sun centre must lie outside the loop (else no tip annulus contains the loop)."""
        centre = np.asarray(centre, dtype=float)
        turns = winding_number(self.polyline(), centre)
        if turns != 0:
            return [Problem(path, "origin_inside_loop",
                            f"the sun centre ({float(centre[0]):g}, {float(centre[1]):g}) lies inside the tip "
                            "loop: the tip cannot stay within reach l +- 2a of it; move the "
                            "loop or the centre so the centre is outside")]
        return []
