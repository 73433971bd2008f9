"""Planar outlines: validation before extrusion, and the few shapes housings are made of.

An outline is an ``(n, 2)`` float array of points in mm, counter-clockwise, the
first point not repeated at the end (the convention of
:class:`cadgen.gears.teeth.GearProfile`).

Why validate at all: manifold3d turns an outline into a cross section with a
boolean union under a fill rule, and a self-intersecting outline (a bowtie) comes
out as *one of its lobes*, silently, with a plausible volume. So every outline is
checked here first, and every problem is reported with a field path and a code
(:class:`kinematics.errors.DesignError`), all at once where that makes sense.

The shape helpers return polygons that *contain* the curved shape they stand for
(circumscribed), except :func:`circle`, which is the inscribed regular polygon
(its vertices on the circle), so that its area has a closed form.

shapely is imported inside the functions that use it, to keep this import light.
"""

from __future__ import annotations

import math

import numpy as np

from cadgen.solids.errors import SolidInputError
from cadgen.solids.tolerances import CHORD_TOLERANCE, CONTAINMENT_MARGIN, DEGENERATE_AREA_RTOL
from kinematics.errors import DesignError, Problem

__all__ = [
    "signed_area",
    "validate_outline",
    "validate_holes",
    "outline_problems",
    "holes_problems",
    "circle",
    "hull_of_circles",
    "offset_outline",
    "segments_for",
]

#: At most this many self-intersections are listed in a message (all are counted).
_MAX_LISTED_LOCATIONS = 5


# --------------------------------------------------------------------------- math


def signed_area(points) -> float:
    """Shoelace area of a closed polygon, positive when counter-clockwise.

    Parameters
    ----------
    points : (n, 2) float
        Vertices, the first not repeated at the end.

    Returns
    -------
    float
        mm^2 (for points in mm).
    """
    points = np.asarray(points, dtype=float)
    x, y = points[:, 0], points[:, 1]
    # Centring first keeps the cross products small for an outline far from the
    # origin (a gear placed at 200 mm), where they would otherwise cancel.
    x = x - x.mean()
    y = y - y.mean()
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def _format_point(point) -> str:
    return f"({point[0]:.6g}, {point[1]:.6g}) mm"


def _check_segments(segments) -> int:
    if isinstance(segments, bool) or int(segments) != segments or segments < 3:
        raise SolidInputError("segments", f"segments must be an integer >= 3, not {segments!r}")
    return int(segments)


def _check_positive(name: str, value) -> float:
    value = float(value)
    if not (math.isfinite(value) and value > 0.0):
        raise SolidInputError(name, f"{name} must be finite and > 0, not {value!r}")
    return value


# --------------------------------------------------------------------- validation


def _self_intersections(points: np.ndarray) -> np.ndarray:
    """Points (k, 2) where a ring touches or crosses itself (empty if none found).

    The ring is noded (split at every intersection); a node where more than two
    pieces end is a place the ring meets itself.
    """
    import shapely

    pieces = shapely.get_parts(shapely.node(shapely.LinearRing(points)))
    ends = np.concatenate([shapely.get_coordinates(shapely.get_point(pieces, 0)),
                           shapely.get_coordinates(shapely.get_point(pieces, -1))])
    nodes, counts = np.unique(ends, axis=0, return_counts=True)
    return nodes[counts > 2]


def outline_problems(points, path: str, *,
                     area_rtol: float = DEGENERATE_AREA_RTOL) -> tuple[np.ndarray | None, list[Problem]]:
    """Check one outline and return it counter-clockwise, with every problem found.

    The non-raising form of :func:`validate_outline`, for validators that collect
    problems of several parts before raising once.

    Parameters
    ----------
    points : (n, 2) array_like
        Outline in mm, closed or not (an exactly repeated last point is dropped).
    path : str
        Field path the problems are reported at.
    area_rtol : float
        See :data:`cadgen.solids.tolerances.DEGENERATE_AREA_RTOL`.

    Returns
    -------
    outline : (n, 2) float or None
        The outline, counter-clockwise, or None if there were problems.
    problems : list of Problem
    """
    try:
        points = np.array(points, dtype=float)
    except (TypeError, ValueError) as error:
        return None, [Problem(path, "not_an_outline", f"cannot read the outline as (n, 2) numbers: {error}")]
    if points.ndim != 2 or points.shape[1] != 2:
        return None, [Problem(path, "not_an_outline",
                              f"an outline is an (n, 2) array of points in mm, not shape {points.shape}")]

    problems = []
    finite = np.isfinite(points).all(axis=1)
    if not finite.all():
        bad = np.flatnonzero(~finite)
        problems.append(Problem(path, "not_finite",
                                f"{bad.size} of {len(points)} points are NaN or infinite, "
                                f"the first at index {bad[0]}: {points[bad[0]].tolist()}"))
    if len(points) > 1 and np.array_equal(points[0], points[-1]):
        points = points[:-1]  # a closed ring: the repeat carries no information
    if len(points) < 3:
        problems.append(Problem(path, "too_few_points",
                                f"an outline needs at least 3 distinct points, not {len(points)}"))
    # Consecutive duplicates make a zero-length edge with no direction: shapely
    # and manifold3d each drop it their own way, so the caller must fix the source.
    # (NaN never equals NaN, so non-finite points are not reported twice.)
    repeated = np.flatnonzero(np.all(points == np.roll(points, -1, axis=0), axis=1)) if len(points) > 1 else []
    if len(repeated):
        listed = ", ".join(f"{i} and {(i + 1) % len(points)} at {_format_point(points[i])}"
                           for i in repeated[:_MAX_LISTED_LOCATIONS])
        more = f" (and {len(repeated) - _MAX_LISTED_LOCATIONS} more)" if len(repeated) > _MAX_LISTED_LOCATIONS else ""
        problems.append(Problem(path, "duplicate_points",
                                f"{len(repeated)} pair(s) of consecutive points coincide: points {listed}{more}"))
    if problems:
        return None, problems

    import shapely
    from shapely.validation import explain_validity

    extent = float(np.ptp(points, axis=0).max())

    def degenerate(area):
        return Problem(path, "degenerate_outline",
                       f"the outline encloses no area ({area:.3g} mm^2 for a {extent:.6g} mm wide "
                       f"outline): its points lie on a line, or nearly")

    # Points on one line first: such an outline also folds back on itself, but
    # "no area" is the useful diagnosis. (The signed area alone cannot tell: a
    # bowtie's two lobes cancel to zero too.)
    hull_area = shapely.MultiPoint(points).convex_hull.area
    if hull_area <= area_rtol * extent ** 2:
        return None, [degenerate(hull_area)]
    if not shapely.LinearRing(points).is_simple:
        nodes = _self_intersections(points)
        if len(nodes):
            where = ", ".join(_format_point(p) for p in nodes[:_MAX_LISTED_LOCATIONS])
            more = f" and {len(nodes) - _MAX_LISTED_LOCATIONS} more places" if len(nodes) > _MAX_LISTED_LOCATIONS else ""
            where = f"at {where}{more}"
        else:  # overlaps along an edge leave no node of degree > 2; shapely still says where
            where = f"({explain_validity(shapely.Polygon(points))})"
        return None, [Problem(path, "self_intersecting_outline",
                              f"the outline crosses or touches itself {where}; manifold3d would "
                              f"silently keep one lobe of it, so it is refused")]
    area = signed_area(points)
    if abs(area) <= area_rtol * extent ** 2:
        return None, [degenerate(area)]
    return (points if area > 0 else points[::-1]).copy(), []


def validate_outline(points, path: str, *, area_rtol: float = DEGENERATE_AREA_RTOL) -> np.ndarray:
    """A checked outline, counter-clockwise.

    Parameters
    ----------
    points : (n, 2) array_like
        Outline in mm, closed or not (an exactly repeated last point is dropped).
    path : str
        Field path the problems are reported at, e.g. ``"gears.central.outline"``.
    area_rtol : float
        See :data:`cadgen.solids.tolerances.DEGENERATE_AREA_RTOL`.

    Returns
    -------
    (n, 2) float
        The outline, counter-clockwise, without a repeated last point.

    Raises
    ------
    DesignError
        With every problem found, codes ``not_an_outline``, ``not_finite``,
        ``too_few_points``, ``duplicate_points``, ``degenerate_outline`` (no area),
        ``self_intersecting_outline`` (the message says where, in mm).
    """
    outline, problems = outline_problems(points, path, area_rtol=area_rtol)
    if problems:
        raise DesignError(problems)
    return outline


def holes_problems(outer: np.ndarray, holes, path: str, *,
                   area_rtol: float = DEGENERATE_AREA_RTOL) -> tuple[list[np.ndarray], list[Problem]]:
    """Check holes against a validated outer outline (non-raising form of :func:`validate_holes`).

    Parameters
    ----------
    outer : (n, 2) float
        A valid outline (as returned by :func:`validate_outline`).
    holes : sequence of (m_i, 2) array_like
    path : str
        Hole ``i`` is reported at ``f"{path}[{i}]"``.
    area_rtol : float

    Returns
    -------
    holes : list of (m_i, 2) float
        Counter-clockwise, or an empty list if there were problems.
    problems : list of Problem
    """
    import shapely

    checked, problems = [], []
    for index, hole in enumerate(holes):
        outline, found = outline_problems(hole, f"{path}[{index}]", area_rtol=area_rtol)
        checked.append(outline)
        problems.extend(found)
    valid = [i for i, hole in enumerate(checked) if hole is not None]
    if not valid:
        return [], problems

    outer_polygon = shapely.Polygon(outer)
    polygons = np.array([shapely.Polygon(checked[i]) for i in valid], dtype=object)
    # "Strictly inside": a hole touching the outline would leave a wall of zero
    # thickness, which no machine cuts and which manifold3d may merge away.
    inside = shapely.contains_properly(outer_polygon, polygons)
    for i, polygon, ok in zip(valid, polygons, inside):
        if ok:
            continue
        outside = shapely.difference(polygon, outer_polygon).area
        how = (f"{outside:.6g} mm^2 of it lies outside the outline" if outside > 0
               else "it touches the outline, leaving a wall of zero thickness")
        problems.append(Problem(f"{path}[{i}]", "hole_outside_outline",
                                f"hole {i} is not strictly inside the outline: {how}"))

    tree = shapely.STRtree(polygons)
    pairs = tree.query(polygons, predicate="intersects")
    for a, b in pairs.T[pairs[0] < pairs[1]]:
        overlap = shapely.intersection(polygons[a], polygons[b]).area
        problems.append(Problem(f"{path}[{valid[b]}]", "holes_overlap",
                                f"holes {valid[a]} and {valid[b]} overlap or touch "
                                f"(common area {overlap:.6g} mm^2); holes must be disjoint"))
    return ([] if problems else [checked[i] for i in valid]), problems


def validate_holes(outer, holes, path: str, *, outer_path: str | None = None,
                   area_rtol: float = DEGENERATE_AREA_RTOL) -> list[np.ndarray]:
    """Checked holes of an outline: each valid, strictly inside, pairwise disjoint.

    Parameters
    ----------
    outer : (n, 2) array_like
        The outer outline; validated too, its problems reported at ``outer_path``.
    holes : sequence of (m_i, 2) array_like
    path : str
        Hole ``i`` is reported at ``f"{path}[{i}]"``.
    outer_path : str, optional
        Defaults to ``path``.
    area_rtol : float

    Returns
    -------
    list of (m_i, 2) float
        The holes, each counter-clockwise (the extruder reverses them as it needs).

    Raises
    ------
    DesignError
        Codes of :func:`validate_outline` per hole, plus ``hole_outside_outline``
        and ``holes_overlap`` (touching counts as overlapping).
    """
    outer, problems = outline_problems(outer, outer_path or path, area_rtol=area_rtol)
    if problems:
        raise DesignError(problems)
    checked, problems = holes_problems(outer, holes, path, area_rtol=area_rtol)
    if problems:
        raise DesignError(problems)
    return checked


# ---------------------------------------------------------------------- shapes


def circle(radius: float, segments: int, centre=(0.0, 0.0)) -> np.ndarray:
    """The regular polygon inscribed in a circle (vertices on the circle).

    Parameters
    ----------
    radius : float
        mm, > 0.
    segments : int
        Number of vertices, >= 3; the first at angle 0.
    centre : (2,) float

    Returns
    -------
    (segments, 2) float
        Counter-clockwise. Its area is ``segments / 2 * radius**2 * sin(2 pi / segments)``,
        less than the disc's: use :func:`hull_of_circles` for a polygon that contains the disc.
    """
    radius = _check_positive("radius", radius)
    segments = _check_segments(segments)
    angles = 2.0 * np.pi * np.arange(segments) / segments
    return np.asarray(centre, dtype=float) + radius * np.column_stack([np.cos(angles), np.sin(angles)])


def hull_of_circles(circles, segments: int, *, margin: float = CONTAINMENT_MARGIN) -> np.ndarray:
    """A convex polygon containing every disc, converging to the discs' convex hull.

    Each disc is replaced by the regular ``segments``-gon *circumscribed* about it
    (edges tangent to the circle, vertices at ``r / cos(pi / segments)``), all on
    the same angular grid, and the convex hull of those polygons is returned. So
    the result contains every disc exactly, at any segment count (not only in the
    limit), and lies within ``max r * (1 / cos(pi / segments) - 1)`` of the exact hull.

    Because all discs share one grid, the result is ``hull(centres_i + r_i G)``
    with ``G`` the unit circumscribed polygon; growing every radius by ``w`` gives
    that polygon offset by ``w G``, so two calls that differ by ``w`` in every
    radius are everywhere at least ``w`` apart (used for housing walls).

    Parameters
    ----------
    circles : (k, 3) array_like
        Rows ``(cx, cy, r)`` in mm, ``r > 0``.
    segments : int
        Sides of each circumscribed polygon (per full circle), >= 3.
    margin : float
        Relative outward push of the vertices, so containment survives rounding
        (:data:`cadgen.solids.tolerances.CONTAINMENT_MARGIN`).

    Returns
    -------
    (m, 2) float
        Counter-clockwise convex polygon.
    """
    from scipy.spatial import ConvexHull

    circles = np.asarray(circles, dtype=float)
    if circles.ndim == 1:
        circles = circles[None, :]
    if circles.ndim != 2 or circles.shape[1] != 3 or len(circles) == 0:
        raise SolidInputError("circles", f"circles must be (k, 3) rows (cx, cy, r) with k >= 1, not shape {circles.shape}")
    if not np.isfinite(circles).all() or (circles[:, 2] <= 0).any():
        raise SolidInputError("circles", f"circles must be finite with radii > 0, got {circles.tolist()}")
    segments = _check_segments(segments)

    angles = 2.0 * np.pi * (np.arange(segments) + 0.5) / segments  # edges tangent at k * 2 pi / n
    vertex_radii = circles[:, 2] / np.cos(np.pi / segments) * (1.0 + margin)
    directions = np.column_stack([np.cos(angles), np.sin(angles)])
    points = (circles[:, None, :2] + vertex_radii[:, None, None] * directions[None]).reshape(-1, 2)
    hull = ConvexHull(points)
    return points[hull.vertices]  # scipy lists 2-D hull vertices counter-clockwise


def offset_outline(points, distance: float, segments: int, *, path: str = "outline",
                   margin: float = CONTAINMENT_MARGIN) -> np.ndarray:
    """Outward offset of an outline with round joins, containing the exact offset.

    shapely's buffer puts the vertices of its round joins *on* the arc, so its
    chords cut inside the exact offset. Here the buffer distance is enlarged to
    ``distance / cos(pi / segments)`` so that every chord of a join is at least
    ``distance`` from the corner: the result contains the exact offset region, and
    straight edges lie at most ``distance * (1 / cos(pi / segments) - 1)`` too far out.

    Parameters
    ----------
    points : (n, 2) array_like
        A valid outline (checked with :func:`validate_outline` at ``path``).
    distance : float
        mm, >= 0 (0 returns the checked outline).
    segments : int
        Join segments per full circle, >= 4, rounded up to a multiple of 4 (shapely
        counts them per quarter circle).
    path : str
        Field path for problems with ``points``.
    margin : float
        Relative outward push so containment survives rounding.

    Returns
    -------
    (m, 2) float
        Counter-clockwise outline.

    Raises
    ------
    DesignError
        If ``points`` is not a valid outline.
    SolidInputError
        For a negative distance, or if the offset closes a void (a C shape whose
        mouth is narrower than ``2 * distance``): the result would need a hole.
    """
    import shapely

    outline = validate_outline(points, path)
    distance = float(distance)
    if not (math.isfinite(distance) and distance >= 0.0):
        raise SolidInputError("distance", f"an outward offset needs a finite distance >= 0, not {distance!r}")
    if distance == 0.0:
        return outline
    quarter_segments = max(1, math.ceil(_check_segments(segments) / 4))
    enlarged = distance / math.cos(np.pi / (4 * quarter_segments)) * (1.0 + margin)
    grown = shapely.Polygon(outline).buffer(enlarged, quad_segs=quarter_segments, join_style="round")
    if grown.geom_type != "Polygon" or len(grown.interiors):
        raise SolidInputError("distance", f"offsetting {path} by {distance} mm closes a void "
                                          "(the result would have a hole); offset a simpler outline")
    ring = np.asarray(grown.exterior.coords)[:-1]
    return ring if signed_area(ring) > 0 else ring[::-1].copy()


def segments_for(radius: float, chord_tolerance: float = CHORD_TOLERANCE, *, minimum: int = 8) -> int:
    """Segments per full circle so that a polygon stays within a tolerance of its circle.

    The bound used is the circumscribed polygon's, ``r (1 / cos(pi / n) - 1) <= tol``,
    which is larger than the inscribed one's ``r (1 - cos(pi / n))``, so it holds for both.

    Parameters
    ----------
    radius : float
        mm, > 0.
    chord_tolerance : float
        mm, > 0.
    minimum : int
        Fewest segments returned (>= 3).

    Returns
    -------
    int
    """
    radius = _check_positive("radius", radius)
    chord_tolerance = _check_positive("chord_tolerance", chord_tolerance)
    count = math.ceil(np.pi / math.acos(radius / (radius + chord_tolerance)))
    return max(_check_segments(minimum), count)
