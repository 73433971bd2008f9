"""Closed contours for cutting: validity, and thinning to a chord tolerance that keeps them cuttable.

Geometry, not a file format: the DXF writer draws the thinned contour and the solids
are extruded from the same one, so STL and DXF describe one part. numpy and shapely
only (shapely imported inside the functions).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["closed_points", "ring_problems", "thin_ring", "thin_outline", "ring_measures",
           "open_ring", "thinned_outline", "thinned_contour", "MAX_TOLERANCE_HALVINGS"]

MAX_TOLERANCE_HALVINGS = 30


def closed_points(points) -> np.ndarray:
    """``points`` as an (n, 2) float array, a repeated closing point dropped."""
    points = np.asarray(points, dtype=float)
    if points.ndim == 2 and points.shape[1] == 2 and len(points) > 1 and np.array_equal(points[0], points[-1]):
        points = points[:-1]
    return points


def ring_problems(label: str, points: np.ndarray) -> list[str]:
    """Problems of a closed curve: shape, finiteness, at least 3 points, simple, non-zero area."""
    import shapely

    if points.ndim != 2 or points.shape[1] != 2:
        return [f"{label} must be an (n, 2) array of points, got shape {points.shape}"]
    bad = ~np.isfinite(points).all(axis=1)
    if bad.any():
        first = int(np.flatnonzero(bad)[0])
        return [f"{label} has {int(bad.sum())} non-finite point(s), the first at index {first}: "
                f"{points[first].tolist()}"]
    distinct = len(np.unique(points, axis=0))
    if distinct < 3:
        return [f"{label} needs at least 3 distinct points, got {distinct}"]
    ring = shapely.LinearRing(points)
    if not ring.is_simple:
        reason = shapely.is_valid_reason(shapely.Polygon(ring))
        return [f"{label} is self-intersecting ({reason})"]
    if shapely.Polygon(ring).area <= 0.0:
        return [f"{label} encloses no area"]
    return []


def _douglas_peucker(ring, tolerance: float):
    """Douglas-Peucker thinning of a shapely ring (a seam, so tests can swap the algorithm)."""
    return ring.simplify(tolerance, preserve_topology=True)


def thin_ring(points: np.ndarray, tolerance: float, *, keep_clear=None) -> tuple[np.ndarray, float]:
    """Thin a simple closed curve to within ``tolerance``, keeping it simple.

    Parameters
    ----------
    points : (n, 2) float
        Simple closed curve, the first point not repeated.
    tolerance : float
        mm, > 0.
    keep_clear : (centre (2,), radius) or None
        A disc the thinned ring must still enclose with clearance (the bore).

    Returns
    -------
    points : (k, 2) float
        Thinned curve, counter-clockwise, the first point not repeated.
    tolerance_used : float
        The tolerance that gave a simple ring (``0.0``: the input returned unthinned).
    """
    import shapely

    ring = shapely.LinearRing(points)

    def acceptable(candidate) -> bool:
        if candidate.is_empty or candidate.geom_type != "LinearRing" or len(candidate.coords) < 4:
            return False
        if not candidate.is_simple:
            return False
        polygon = shapely.Polygon(candidate)
        if polygon.area <= 0.0:
            return False
        if keep_clear is not None:
            centre, radius = keep_clear
            point = shapely.Point(centre)
            if not polygon.contains(point) or candidate.distance(point) <= radius:
                return False
        return True

    tolerance_used = 0.0
    result = points
    trial = tolerance
    for _ in range(MAX_TOLERANCE_HALVINGS + 1):
        candidate = _douglas_peucker(ring, trial)
        if acceptable(candidate):
            result = np.asarray(candidate.coords, dtype=float)[:-1]
            tolerance_used = trial
            break
        trial /= 2.0
    if not shapely.LinearRing(result).is_ccw:
        result = result[::-1]
    return np.ascontiguousarray(result), tolerance_used


def ring_measures(points: np.ndarray) -> tuple[float, float]:
    """Area and perimeter of a closed polygon, (n, 2) points not repeated."""
    x, y = points[:, 0], points[:, 1]
    area = 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))
    perimeter = float(np.linalg.norm(np.roll(points, -1, axis=0) - points, axis=1).sum())
    return area, perimeter


def open_ring(points: np.ndarray, gap: float) -> np.ndarray:
    """A closed ring (n, 2), first point not repeated, as an open polyline whose ends are at
    least ``gap`` apart: the trailing points within ``gap`` of the first are left out (a ring
    smaller than ``gap`` is returned whole, its closing segment left out)."""
    points = np.asarray(points, dtype=float)
    far = np.flatnonzero(np.linalg.norm(points - points[0], axis=1) >= gap)
    return points if far.size == 0 else points[: far[-1] + 1]


def thin_outline(points: np.ndarray, tolerance: float, centre, bore_radius: float):
    """A cutting outline thinned to ``tolerance``, still clear of its bore: (ring, tolerance used)."""
    keep_clear = ((np.asarray(centre, dtype=float), float(bore_radius)) if bore_radius > 0
                  else None)
    return thin_ring(points, tolerance, keep_clear=keep_clear)



def thinned_outline(profile, chord_tolerance: float = 0.005) -> np.ndarray:
    """The outline a gear's DXF file holds: thinned to ``chord_tolerance``, simple, bore kept clear.

    The solids are extruded from it, so the STL and the DXF describe the same cut part.
    """
    return thinned_contour(profile.outline, chord_tolerance, centre=profile.centre,
                           bore_radius=profile.bore_radius)


def thinned_contour(points, chord_tolerance: float = 0.005, *, centre=(0.0, 0.0),
                    bore_radius: float = 0.0) -> np.ndarray:
    """A dense closed contour thinned as the DXF writers thin it (a cam's, a gear's)."""
    tolerance = float(chord_tolerance)
    if not (math.isfinite(tolerance) and tolerance > 0):
        raise ValueError(f"chord_tolerance must be a finite number > 0 mm, got {chord_tolerance!r}")
    return thin_outline(closed_points(points), tolerance, centre, bore_radius)[0]
