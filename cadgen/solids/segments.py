"""Split housings cut into segments that bolt together, so each printed piece fits the printer.

A gearbox of the paper design is about 122 x 582 mm; no common printer takes a half
of it. :func:`segment_cuts` chooses cut lines across the housing and
:func:`segment_housing` cuts base and cover along them into pieces joined by bolted
*splice lugs*. Documented choices (ours, not a standard's):

* **Cuts across the long axis.** The long axis is the principal axis (largest second
  moment of area) of the flange outline; every cut is a vertical plane perpendicular
  to it. Base and cover are cut on the same planes, so a piece of the base and the
  piece of the cover above it print, and are assembled, as a pair.
* **As few cuts as will do.** Each piece must fit the build volume in the pose the
  machine prints it in: a half lies on its end wall, so the piece's height is its
  half's z extent, and its footprint is the box of the flange outline (and lugs)
  between its cuts, along and across the long axis; a footprint may be turned 90
  degrees on the bed (as :func:`cadgen.solids.outcome.fits_build_volume`), and
  ``margin`` mm are kept free along each axis.
* **Never through a bearing seat.** A cut keeps ``seat radius + SEAT_RIM_MIN + lug
  thickness`` from every seat's centre, so the bore stays whole (a bearing seat split
  in two printed pieces would not be round) and the lugs, as thick as the flange
  half, do not reach the seat's rim. Between two seats the midpoint is preferred (the
  most material either side); cuts in the end gaps (past the last seat) are taken only
  when needed. A cut whose lugs would cover a flange bolt (closer than the lug
  thickness plus half the flange width) is moved off it when the gap allows, since a
  lug standing on the flange leaves no seat for that bolt's nut; the flange holes are
  drilled again through the lugs in any case, so no bolt hole is ever plugged.
* **Lugs outside the side walls.** The cavity is full of gears turning close to the
  walls (the clearance is a few mm), so nothing may be added inside it; the splice
  sits where the cut crosses the outer wall, on both long sides, as a block ``3 d_h``
  wide outwards from the wall (the flange's width, :data:`LUG_WIDTH_HOLES`, so the
  piece's footprint grows by nothing) and ``max(wall, 1.5 d)`` thick on each side of
  the plane (the flange half's rule: a nut or head bears on 1.5 bolt diameters of
  material), reaching one wall thickness into the wall so it is fused to it, over the
  half's whole height. Whatever of a lug would reach into the cavity is cut away.
* **At least two bolts per cut per half.** One bolt each side of the housing: a single
  bolt would leave the joint free to hinge about it, two far apart carry the bending
  of the long housing in its plane, and the lugs' height carries it about the
  other axis. Each bolt (the flange's ISO bolt, ``housing.bolt_size``, through
  ``housing.bolt_hole_diameter`` holes) is horizontal, along the cut's normal,
  through both lugs (grip ``2 x`` lug thickness), in the middle of the half's height
  left beside the flange (so the splice bolt's hole never meets the flange's vertical
  holes, and the nut does not sit on the flange).

Every piece is one watertight solid: the half cut by the slab between its cuts, the
lugs on its side of each cut joined to it, then the bolt holes drilled.

manifold3d and shapely are imported inside the functions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from cadgen.solids.errors import SolidInputError
from cadgen.solids.split_housing import SEAT_RIM_MIN, flange_thickness
from cadgen.solids.tolerances import FLANGE_WIDTH_HOLES
from kinematics.errors import DesignError, Problem

__all__ = ["SegmentPiece", "SpliceJoint", "SegmentedHousing", "segment_cuts", "segment_housing",
           "segment_extents", "segment_problems", "long_axis", "lug_thickness",
           "SEGMENT_MARGIN", "LUG_WIDTH_HOLES", "CUT_STEP", "FLANGE_BOLT_PENALTY"]

#: Free space (mm) kept along each axis of the build volume round a piece.
SEGMENT_MARGIN = 1.0
#: A lug's width outwards from the outer wall, in bolt clearance-hole diameters (the flange's).
LUG_WIDTH_HOLES = FLANGE_WIDTH_HOLES
#: Spacing (mm) of the cut positions tried between the seats.
CUT_STEP = 1.0
#: Cost of a cut whose lugs cover a flange bolt, against 0 at a gap's midpoint and 1 at its
#: edge: such a cut is taken only when no other cut in reach fits.
FLANGE_BOLT_PENALTY = 2.0
#: A cut line must cross the outer outline (mm beyond its ends).
_BEYOND = 1.0
#: Path of the problems (the build volume is what a split answers to).
_PATH = "manufacturing.build_volume"


class SegmentPiece(NamedTuple):
    """One segment of a housing: the part-name suffix (``"1"``, ...) and its two halves."""

    suffix: str
    base: object      # manifold3d.Manifold
    cover: object


class SpliceJoint(NamedTuple):
    """The bolted splice at one cut.

    ``bolts`` are the bolts' centres on the cut plane, ``(k, 3)`` mm (two per half);
    ``axis`` the unit bolt axis (the cut's normal, along the long axis); ``grip`` the
    clamped length (both lugs, mm).
    """

    point: np.ndarray
    direction: np.ndarray
    bolts: np.ndarray
    axis: np.ndarray
    bolt_size: str
    bolt_hole_diameter: float
    grip: float


@dataclass(frozen=True)
class SegmentedHousing:
    """A split housing's pieces (in order along the long axis) and the joints between them."""

    pieces: list
    joints: list


# ------------------------------------------------------------------ geometry (numpy, shapely)


def long_axis(outline) -> tuple:
    """``(centroid (2,), unit axis (2,))`` of a polygon: its principal axis of largest spread.

    From the polygon's second moments of area (Green's theorem on the edges), so the
    spacing of the vertices does not matter. The axis points to +y, or to +x when it is
    square with y (a fixed sign makes the cut order repeatable).
    """
    points = np.asarray(outline, dtype=float)
    if points.ndim != 2 or points.shape[1] != 2 or len(points) < 3:
        raise SolidInputError("outline", f"a long axis needs an (n >= 3, 2) polygon, not shape "
                                         f"{points.shape}")
    x, y = points[:, 0], points[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    area = cross.sum() / 2
    if not abs(area) > 0:
        raise SolidInputError("outline", "a long axis needs a polygon of non-zero area")
    cx, cy = ((x + xn) * cross).sum() / (6 * area), ((y + yn) * cross).sum() / (6 * area)
    sxx = (x * x + x * xn + xn * xn) @ cross / 12 - area * cx * cx
    syy = (y * y + y * yn + yn * yn) @ cross / 12 - area * cy * cy
    sxy = (x * yn + 2 * x * y + 2 * xn * yn + xn * y) @ cross / 24 - area * cx * cy
    values, vectors = np.linalg.eigh(np.array([[sxx, sxy], [sxy, syy]]) * np.sign(area))
    axis = vectors[:, int(np.argmax(values))]
    if axis[1] < -1e-12 or (abs(axis[1]) <= 1e-12 and axis[0] < 0):
        axis = -axis
    return np.array([cx, cy]), axis / np.linalg.norm(axis)


def lug_thickness(housing) -> float:
    """A lug's thickness (mm) on each side of a cut: the flange half's, ``max(wall, 1.5 d)``."""
    return flange_thickness(housing.wall, housing.bolt_size)


def _frame(housing):
    """``(centroid, axis n, across d)``: u = (p - centroid) . n along, v = ... . d across."""
    centroid, axis = long_axis(housing.flange_outline)
    return centroid, axis, np.array([-axis[1], axis[0]])


def _crossings(outline, origin, normal, across, at) -> np.ndarray:
    """(m, 2) least and greatest ``v`` where the lines ``u = at`` (m,) cross a polygon (NaN: none)."""
    local = (np.asarray(outline, dtype=float) - origin) @ np.column_stack([normal, across])
    u, v = local[:, 0], local[:, 1]
    un, vn = np.roll(u, -1), np.roll(v, -1)
    at = np.asarray(at, dtype=float)[:, None]
    straddles = (np.minimum(u, un) <= at) & (at <= np.maximum(u, un)) & (u != un)
    with np.errstate(invalid="ignore", divide="ignore"):
        crossing = v + (at - u) * (vn - v) / (un - u)
    low = np.where(straddles, crossing, np.inf).min(axis=1)
    high = np.where(straddles, crossing, -np.inf).max(axis=1)
    bad = ~np.isfinite(low)
    low[bad], high[bad] = np.nan, np.nan
    return np.column_stack([low, high])


def _seat_bands(housing, centroid, normal, thickness) -> list:
    """``[(u_low, u_high, seat)]`` along the axis a cut must keep out of, one per seat."""
    bands = []
    for seat in housing.seats:
        u = float((np.asarray(seat.xy, dtype=float) - centroid) @ normal)
        reach = float(seat.seat_diameter) / 2 + SEAT_RIM_MIN + thickness
        bands.append((u - reach, u + reach, seat))
    return sorted(bands, key=lambda band: band[0])


def _lugs(housing, point, direction, thickness):
    """The four lug blocks of a cut: ``[(side, piece side, (4, 2) corners, bolt xy)]``.

    ``side`` is -1 / +1 along the cut line (the two long walls), ``piece side`` -1 for
    the piece before the cut (along the axis), +1 after it.
    """
    direction = np.asarray(direction, dtype=float)
    normal = np.array([direction[1], -direction[0]])
    point = np.asarray(point, dtype=float)
    wall, width = float(housing.wall), LUG_WIDTH_HOLES * float(housing.bolt_hole_diameter)
    cross = _crossings(housing.outer_outline, point, normal, direction, [0.0, -thickness, thickness])
    lugs = []
    for side, column in ((-1, 0), (1, 1)):
        at_cut = cross[0, column]
        for piece_side in (-1, 1):
            near = cross[1 if piece_side < 0 else 2, column]
            # reach one wall into the wall wherever it is closest, so the block is fused to it
            inner = (min(at_cut, near) - wall) if side > 0 else (max(at_cut, near) + wall)
            outer = at_cut + side * width
            u0, u1 = sorted((0.0, piece_side * thickness))
            v0, v1 = sorted((inner, outer))
            corners = np.array([[u0, v0], [u1, v0], [u1, v1], [u0, v1]])
            xy = point + corners[:, :1] * normal + corners[:, 1:] * direction
            bolt = point + (at_cut + side * width / 2) * direction
            lugs.append((side, piece_side, xy, bolt))
    return lugs


def _half_heights(housing) -> dict:
    """``{"base": (z low, z high, bolt z), "cover": ...}``: each half's span and splice bolt height.

    The bolt is in the middle of the height the half has beside the flange when that is
    at least two hole diameters (about an ISO 7089 washer's outside diameter, so the
    washer and nut clear the flange next to the lug), else in the middle of the half.
    """
    hole = float(housing.bolt_hole_diameter)
    spans = {"base": (housing.z_bottom, housing.parting_z, housing.z_bottom, housing.flange_z[0]),
             "cover": (housing.parting_z, housing.z_top, housing.flange_z[1], housing.z_top)}
    out = {}
    for half, (low, high, free_low, free_high) in spans.items():
        bolt = (free_low + free_high) / 2 if free_high - free_low >= 2 * hole else (low + high) / 2
        out[half] = (float(low), float(high), float(bolt))
    return out


def _check_cuts(housing, cuts) -> list:
    """The cuts as ``[(u, point, unit direction)]`` sorted along their common normal."""
    cuts = list(cuts)
    out = []
    reference = None
    for index, cut in enumerate(cuts):
        try:
            point, direction = (np.asarray(v, dtype=float).reshape(2) for v in cut)
        except (TypeError, ValueError):
            raise SolidInputError(f"cuts[{index}]", f"a cut is (point (2,), direction (2,)), "
                                                    f"not {cut!r}") from None
        length = float(np.linalg.norm(direction))
        if not (np.isfinite(point).all() and np.isfinite(direction).all() and length > 0):
            raise SolidInputError(f"cuts[{index}]", f"a cut needs a finite point and a non-zero "
                                                    f"direction, not {cut!r}")
        direction = direction / length
        if reference is None:
            reference = direction
        elif abs(reference[0] * direction[1] - reference[1] * direction[0]) > 1e-9:
            raise SolidInputError(f"cuts[{index}]", f"the cuts must be parallel; "
                                                    f"{direction.tolist()} is not "
                                                    f"{reference.tolist()}")
        direction = direction if direction @ reference > 0 else -direction
        normal = np.array([direction[1], -direction[0]])
        cross = _crossings(housing.outer_outline, point, normal, direction, [0.0])
        if np.isnan(cross).any():
            raise SolidInputError(f"cuts[{index}]", f"the cut through {point.tolist()} along "
                                                    f"{direction.tolist()} misses the housing")
        out.append((float(point @ normal), point, direction))
    out.sort(key=lambda item: item[0])
    for (u0, *_), (u1, *_) in zip(out[:-1], out[1:]):
        if u1 - u0 <= 1e-9:
            raise SolidInputError("cuts", f"two cuts lie on one plane (u = {u0:g} mm)")
    return out


def segment_extents(housing, cuts) -> list:
    """Each piece's box ``(along, across, height)`` (mm) between the cuts, lugs included.

    The footprint is the flange outline between the piece's cuts with its lugs, measured
    along and across the cuts' normal; the height is the taller half's.
    """
    import shapely

    checked = _check_cuts(housing, cuts)
    heights = _half_heights(housing)
    height = max(high - low for low, high, _ in heights.values())
    centroid, normal, across = _frame(housing)
    if checked:
        direction = checked[0][2]
        normal = np.array([direction[1], -direction[0]])
        across = direction
    thickness = lug_thickness(housing)
    to_local = np.column_stack([normal, across])
    flange = shapely.Polygon((np.asarray(housing.flange_outline) - centroid) @ to_local)
    (x0, y0, x1, y1) = flange.bounds
    ends = [x0 - _BEYOND] + [float((p - centroid) @ normal) for _, p, _ in checked] + [x1 + _BEYOND]
    lugs = [[] for _ in range(len(ends) - 1)]
    for index, (_, point, direction) in enumerate(checked):
        for _, piece_side, corners, _ in _lugs(housing, point, direction, thickness):
            lugs[index + (piece_side > 0)].append(shapely.Polygon((corners - centroid) @ to_local))
    out = []
    for (a, b), blocks in zip(zip(ends[:-1], ends[1:]), lugs):
        footprint = shapely.union_all([flange.intersection(shapely.box(a, y0 - 1, b, y1 + 1)),
                                       *blocks])
        bx0, by0, bx1, by1 = footprint.bounds
        out.append((bx1 - bx0, by1 - by0, height))
    return out


def _misfit(along, across, height, build_volume, margin):
    """How far (mm, summed over the axes) boxes stick out of the bed in their better turn; 0: fits."""
    bx, by, bz = (float(v) - margin for v in build_volume)
    over = lambda size, room: np.maximum(np.asarray(size, dtype=float) - room, 0.0)  # noqa: E731
    tall = over(height, bz)
    return tall + np.minimum(over(along, bx) + over(across, by), over(along, by) + over(across, bx))


def _check_build_volume(build_volume, margin):
    volume = np.asarray(build_volume, dtype=float).reshape(-1)
    if volume.shape != (3,) or not (np.isfinite(volume).all() and (volume > 0).all()):
        raise SolidInputError("build_volume", f"a build volume is three finite sizes > 0 mm, not "
                                              f"{build_volume!r}")
    if not (math.isfinite(float(margin)) and 0 <= float(margin) < volume.min()):
        raise SolidInputError("margin", f"the margin must be >= 0 mm and smaller than the build "
                                        f"volume, not {margin!r}")
    return volume, float(margin)


def segment_cuts(housing, build_volume, *, margin: float = SEGMENT_MARGIN,
                 step: float = CUT_STEP) -> list:
    """The fewest cuts across a housing's long axis, between its seats, so every piece fits.

    Parameters
    ----------
    housing : SplitHousing
    build_volume : (3,) float
        The printer's x, y, z (mm).
    margin : float
        mm kept free along each axis of the build volume.
    step : float
        Spacing (mm) of the cut positions tried (the gaps' midpoints are always tried).

    Returns
    -------
    list of (point (2,), direction (2,))
        Cut lines in the housing's xy frame, in order along the long axis; empty when
        the housing fits whole. When no placement fits, the one whose largest piece
        sticks out least (:func:`segment_problems` reports it).
    """
    volume, margin = _check_build_volume(build_volume, margin)
    if not (math.isfinite(float(step)) and float(step) > 0):
        raise SolidInputError("step", f"the step must be a finite length > 0 mm, not {step!r}")
    centroid, normal, across = _frame(housing)
    thickness = lug_thickness(housing)
    heights = _half_heights(housing)
    height = max(high - low for low, high, _ in heights.values())
    u_flange = (np.asarray(housing.flange_outline, dtype=float) - centroid) @ normal
    low_end, high_end = float(u_flange.min()), float(u_flange.max())
    # a piece holds at least its lugs: no cut closer than two lug thicknesses to an end
    first, last = low_end + 2 * thickness, high_end - 2 * thickness
    bands = _seat_bands(housing, centroid, normal, thickness)
    gaps, start = [], first
    for band_low, band_high, _ in bands + [(last, math.inf, None)]:
        if band_low > start:
            gaps.append((start, min(band_low, last)))
        start = max(start, band_high)
    candidates, cost = [], []
    outer_gap = [not any(b[1] <= g[0] for b in bands) or not any(b[0] >= g[1] for b in bands)
                 for g in gaps]
    for (a, b), end_gap in zip(gaps, outer_gap):
        if b <= a:
            continue
        mid, half = (a + b) / 2, (b - a) / 2
        at = np.unique(np.concatenate([[mid], np.arange(mid, b, step), np.arange(mid, a, -step)]))
        candidates.append(at)
        cost.append(np.abs(at - mid) / half + (1.0 if end_gap else 0.0))
    bolts_u = (np.asarray(housing.bolt_positions, dtype=float).reshape(-1, 2) - centroid) @ normal
    keep_clear = thickness + LUG_WIDTH_HOLES * float(housing.bolt_hole_diameter) / 2
    u = np.concatenate([[low_end]] + candidates + [[high_end]])
    pen = np.concatenate([[0.0]] + cost + [[0.0]])
    if len(bolts_u):
        pen += FLANGE_BOLT_PENALTY * (np.abs(u[:, None] - bolts_u[None, :]) < keep_clear).any(axis=1)
    order = np.argsort(u, kind="stable")
    u, pen = u[order], pen[order]
    # the footprint's width between two cuts: the flange outline's across-extent, sampled at
    # the cut positions and the outline's vertices in between
    samples = np.unique(np.concatenate([u, np.clip(u_flange, low_end, high_end)]))
    cross = _crossings(housing.flange_outline, centroid, normal, across, samples)
    cross = np.where(np.isnan(cross), [np.inf, -np.inf], cross)
    index = np.searchsorted(samples, u)
    count = len(u)
    across_size = np.full((count, count), np.inf)
    for i in range(count):
        lows = np.minimum.accumulate(cross[index[i]:, 0])
        highs = np.maximum.accumulate(cross[index[i]:, 1])
        across_size[i, i:] = (highs - lows)[index[i:] - index[i]]
    along = u[None, :] - u[:, None]
    cost_edge = _misfit(along, across_size, height, volume, margin)
    cost_edge[np.tril_indices(count)] = np.inf
    # least largest misfit over the pieces (a bottleneck path in a DAG), ...
    worst = np.full(count, np.inf)
    worst[0] = 0.0
    for j in range(1, count):
        worst[j] = np.min(np.maximum(worst[:j], cost_edge[:j, j]))
    allowed = cost_edge <= worst[-1] + 1e-9
    # ... then the fewest cuts reaching it, then the least cost (midpoints, flange bolts clear)
    big = 10.0 * (float(pen.sum()) + 1.0)
    score = np.full(count, np.inf)
    score[0] = 0.0
    previous = np.zeros(count, dtype=int)
    for j in range(1, count):
        reach = np.where(allowed[:j, j], score[:j], np.inf)
        best = int(np.argmin(reach))
        score[j] = reach[best] + (0.0 if j == count - 1 else big + pen[j])
        previous[j] = best
    path, j = [], count - 1
    while j != 0:
        j = previous[j]
        if j:
            path.append(u[j])
    direction = across
    return [(centroid + position * normal, direction.copy()) for position in sorted(path)]


def segment_problems(housing, cuts, build_volume, *, margin: float = SEGMENT_MARGIN,
                     name: str = "housing") -> list:
    """Problems of a split: a cut through a seat, a piece that does not fit; ``[]`` when none.

    Each at ``manufacturing.build_volume`` (the printer the split answers to).
    """
    volume, margin = _check_build_volume(build_volume, margin)
    checked = _check_cuts(housing, cuts)
    thickness = lug_thickness(housing)
    problems = []
    for _, point, direction in checked:
        normal = np.array([direction[1], -direction[0]])
        for seat in housing.seats:
            distance = abs(float((np.asarray(seat.xy, dtype=float) - point) @ normal))
            reach = float(seat.seat_diameter) / 2 + SEAT_RIM_MIN + thickness
            if distance < reach - 1e-9:
                problems.append(Problem(
                    _PATH, "cut_through_seat",
                    f"cannot split {name} between its bearing seats to fit the build volume: "
                    f"the cut through ({point[0]:.6g}, {point[1]:.6g}) mm passes {distance:.3g} mm "
                    f"from the {seat.wall} seat of shaft {seat.shaft}, within its radius, rim and "
                    f"lug ({reach:.3g} mm)"))
    extents = segment_extents(housing, cuts)
    misfits = [float(_misfit(a, c, h, volume, margin)) for a, c, h in extents]
    if max(misfits) > 0:
        worst = extents[int(np.argmax(misfits))]
        room = " x ".join(f"{v:g}" for v in volume)
        problems.append(Problem(
            _PATH, "segments_too_big",
            f"cannot split {name} between its bearing seats to fit the build volume {room} mm "
            f"(less {margin:g} mm margin): the best split, {len(extents)} piece(s), leaves a piece "
            f"of {worst[0]:.1f} x {worst[1]:.1f} x {worst[2]:.1f} mm (along x across x height)"))
    return problems


# ------------------------------------------------------------------ solids (manifold3d)


def _prism(corners, z_low, z_high):
    """A vertical prism on a convex quadrilateral's (4, 2) corners, manifold3d."""
    from cadgen.solids.extrude import manifold3d_engine

    m3d = manifold3d_engine()

    corners = np.asarray(corners, dtype=float)
    (ax, ay), (bx, by) = corners[1] - corners[0], corners[2] - corners[0]
    if ax * by - ay * bx < 0:   # manifold3d wants counter-clockwise outlines
        corners = corners[::-1]
    section = m3d.CrossSection([corners.tolist()])
    return m3d.Manifold.extrude(section, z_high - z_low).translate((0.0, 0.0, z_low))


def _slab(point_low, point_high, normal, reach, z_low, z_high):
    """The region between two cut planes (None: unbounded that way), as a prism."""
    across = np.array([-normal[1], normal[0]])
    a = float(point_low @ normal) if point_low is not None else -reach
    b = float(point_high @ normal) if point_high is not None else reach
    corners = [a * normal - reach * across, b * normal - reach * across,
               b * normal + reach * across, a * normal + reach * across]
    return _prism(corners, z_low, z_high)


def _bolt_hole(centre, axis, length, diameter, segments):
    """A cylinder (a ``segments``-gon) of ``diameter`` along ``axis``, centred on ``centre``."""
    from cadgen.solids.extrude import manifold3d_engine

    m3d = manifold3d_engine()

    hole = m3d.Manifold.cylinder(length, diameter / 2, diameter / 2, segments, True)
    angle = math.degrees(math.atan2(axis[1], axis[0]))
    return hole.rotate((0.0, 90.0, 0.0)).rotate((0.0, 0.0, angle)).translate(tuple(centre))


def segment_housing(housing, cuts, *, segments: int, name: str = "housing") -> SegmentedHousing:
    """A split housing cut into pieces along ``cuts``, joined by bolted splice lugs.

    Parameters
    ----------
    housing : SplitHousing
    cuts : sequence of (point (2,), direction (2,))
        Parallel vertical cut lines in the housing's xy frame (:func:`segment_cuts`).
    segments : int
        Sides of the splice bolt holes' polygons, >= 3.
    name : str
        The housing's name, for the problems.

    Returns
    -------
    SegmentedHousing
        ``pieces`` in order along the cuts' normal, suffixed ``"1"``, ``"2"``, ...; one
        joint per cut with its bolts (two per half).

    Raises
    ------
    DesignError
        ``cut_through_seat`` at ``manufacturing.build_volume``: a cut too close to a
        bearing seat for the seat and the lugs.
    SolidInputError
        For cuts that are not parallel lines crossing the housing, or bad ``segments``.
    """
    from cadgen.solids.extrude import manifold3d_engine

    m3d = manifold3d_engine()

    if isinstance(segments, bool) or int(segments) != segments or segments < 3:
        raise SolidInputError("segments", f"segments must be an integer >= 3, not {segments!r}")
    checked = _check_cuts(housing, cuts)
    problems = [p for p in segment_problems(housing, cuts, (1e9, 1e9, 1e9), margin=0.0, name=name)
                if p.code == "cut_through_seat"]
    if problems:
        raise DesignError(problems)
    thickness = lug_thickness(housing)
    hole = float(housing.bolt_hole_diameter)
    heights = _half_heights(housing)
    outline = np.asarray(housing.flange_outline, dtype=float)
    reach = 2.0 * float(np.abs(outline).max()) + 4 * thickness + 10.0
    normal = (np.array([checked[0][2][1], -checked[0][2][0]]) if checked
              else long_axis(housing.flange_outline)[1])
    # flange bolt holes a lug may cover: drilled again through the lugs
    from cadgen.solids.extrude import extrude
    from cadgen.solids.outline import circle

    flange_holes = [extrude(circle(hole / 2, housing.bolt_segments, xy),
                            housing.flange_z[1] - housing.flange_z[0], z0=housing.flange_z[0],
                            path=f"{name}.flange_bolts")
                    for xy in np.asarray(housing.bolt_positions, dtype=float).reshape(-1, 2)]
    flange_drill = (m3d.Manifold.batch_boolean(flange_holes, m3d.OpType.Add) if flange_holes
                    else None)
    lugs = [_lugs(housing, point, direction, thickness) for _, point, direction in checked]
    joints = []
    pieces = {"base": [], "cover": []}
    for half, solid in (("base", housing.base), ("cover", housing.cover)):
        z_low, z_high, z_bolt = heights[half]
        drills = []
        for (_, point, direction), blocks in zip(checked, lugs):
            for _, piece_side, _, xy in blocks:
                if piece_side < 0:   # one hole per bolt, through both lugs
                    drills.append(_bolt_hole((*xy, z_bolt), normal, 2 * thickness + 2.0, hole,
                                             int(segments)))
        drill = m3d.Manifold.batch_boolean(drills, m3d.OpType.Add) if drills else None
        bounds = [None] + [point for _, point, _ in checked] + [None]
        for index in range(len(bounds) - 1):
            piece = solid ^ _slab(bounds[index], bounds[index + 1], normal, reach,
                                  z_low - 1.0, z_high + 1.0)
            added = []
            for cut_index, blocks in enumerate(lugs):
                for _, piece_side, corners, _ in blocks:
                    # the lug before a cut is the earlier piece's, the one after the later's
                    if cut_index + (piece_side > 0) == index:
                        added.append(_prism(corners, z_low, z_high))
            if added:
                lug = m3d.Manifold.batch_boolean(added, m3d.OpType.Add) - housing.cavity
                piece = piece + lug
                if flange_drill is not None:
                    piece = piece - flange_drill
                piece = piece - drill
            pieces[half].append(piece)
    for (_, point, direction), blocks in zip(checked, lugs):
        bolts = [(*xy, heights[half][2]) for half in ("base", "cover")
                 for _, piece_side, _, xy in blocks if piece_side < 0]
        joints.append(SpliceJoint(point.copy(), direction.copy(), np.array(bolts, dtype=float),
                                  normal.copy(), str(housing.bolt_size), hole, 2 * thickness))
    out = [SegmentPiece(str(i + 1), base, cover)
           for i, (base, cover) in enumerate(zip(pieces["base"], pieces["cover"]))]
    return SegmentedHousing(out, joints)
