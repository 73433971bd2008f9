"""45 deg chamfers under a printed housing's flange, so the flange prints without supports.

A split housing (:mod:`cadgen.solids.split_housing`) has a flange round its outside at the
parting plane, ``3 d_h`` wide, half on the base and half on the cover. A printed half lies on
its end wall (the base on its floor, the cover on its roof: on its parting face the end wall
would be a roof over the whole cavity), so the flange's face away from the parting plane faces
the bed with nothing under it: a few thousand mm^2 of overhang per half. Here, for the printed
process only, each half gets a *gusset* on that face: a frustum from the wall's outside to the
flange's edge whose sides are 45 deg from the vertical, which a printer builds layer on layer.

Documented choices (a fitter's, not a standard's):

* **The frustum.** The outer outline ``A`` and the flange outline ``B`` are convex (hulls of
  discs), so the gusset is the convex hull of ``A`` at ``run`` below the flange and ``B`` at the
  flange's face, less the prism of ``A``; ``run`` is the farthest any point of ``B`` is from
  ``A`` (about ``3 d_h``). Every side face then rises at least as steeply as 45 deg; it is made
  :data:`RISE_MARGIN` mm taller than ``run`` so that no rounding tips a face past 45 deg. Where
  the half is shorter than that the frustum is cut off at its end wall's outer face, and stands
  on the bed with the half.
* **The bolts keep a flat seat and their tool.** A nut and washer under the base's flange (a
  screw head over the cover's) bear on the flange's own face: at each bolt the gusset is cut
  away by a slot the washer's diameter plus :data:`SEAT_CLEARANCE` wide, from the wall side of
  the washer out through the flange's edge, so the nut is held with an open-ended spanner from
  outside while the screw is turned from its head. The chamfer is thus only between the holes;
  the slots' roofs (the seats) are what is left of the overhang: short bridges, which a slicer
  spans, but the overhang count (:func:`cadgen.solids.printing.overhang_area`) still counts
  them.
* **Dowels stay through.** Each dowel's reamed hole is continued through the gusset.
* **Splices keep their bolts.** When the housing is cut into segments to fit the printer
  (:mod:`cadgen.solids.segments`), a splice bolt beside the flange is horizontal, along the cut's
  normal, with its head and its nut on the lugs' faces. Where its washer would reach into a
  gusset, that gusset is cut away over the lug and, beyond each lug face, the length of the
  head or of the nut and washer plus one washer diameter (room for the spanner or the key).

Every cut is a vertical prism, so the gusset's volume has a closed form (:attr:`FlangeChamfer.
volume`): over each face of the hull, the area of the gusset's plan inside the face's plan times
the face's height at that piece's centroid (exact: the height is linear over a face). The
housing with its chamfers (:class:`ChamferedHousing`) adds it to the split housing's own.

manifold3d, scipy and shapely are imported inside the functions.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from cadgen.solids.split_housing import SplitHousing

__all__ = ["FlangeChamfer", "ChamferedHousing", "chamfer_flanges", "chamfer_run",
           "seat_slot_width", "RISE_MARGIN", "SEAT_CLEARANCE", "WALL_OVERLAP"]

#: How much taller (mm) a gusset is than it is wide, so its faces are steeper than 45 deg by a
#: margin rounding cannot undo (0.01 mm over a 14 mm flange: 45.02 deg).
RISE_MARGIN = 0.01
#: How far (mm) a gusset reaches into the wall it stands on: the two then cross, rather than
#: touch face to face (coplanar faces left zero-area slivers in the union). The wall is solid
#: there (the cavity is a wall inside, a seat or hole a rim inside), so the material is the same.
WALL_OVERLAP = 0.05
#: A bolt's seat slot is the washer's outside diameter plus this (mm): the washer drops in
#: loose and a spanner's jaws reach the nut past it.
SEAT_CLEARANCE = 1.0


@dataclass(frozen=True)
class FlangeChamfer:
    """The gussets under a housing's flange halves and the cuts in them.

    Attributes
    ----------
    run, rise : float
        The gusset's width from the wall to the flange's edge (its widest, mm) and its full
        height (``run + RISE_MARGIN``).
    gussets : tuple
        ``(half, lower outline (n, 2), z_low, upper outline (m, 2), z_high)`` per chamfered half
        (``"base"``, ``"cover"``): the hull of the two outlines at their heights.
    outer_outline, flange_outline : (n, 2) float
        The wall's outside ``A`` and the flange's outline ``B`` (the gusset's plan is ``B - A``).
    cutouts : tuple
        ``(half, (k, 2) polygon)``: vertical prisms cut from that half's gusset (``"both"``: from
        each): the bolts' seat slots, the dowels' holes, the splices' clearances.
    slot_width : float
        The seat slots' width (mm).
    cuts : tuple
        The cut lines of a housing printed in segments (``(point, direction)``), () when whole.
    """

    run: float
    rise: float
    gussets: tuple
    outer_outline: np.ndarray
    flange_outline: np.ndarray
    cutouts: tuple
    slot_width: float
    cuts: tuple = ()

    def plan(self, half: str):
        """The plan (shapely) of ``half``'s gusset: the flange's ring less its cutouts."""
        import shapely

        ring = shapely.Polygon(self.flange_outline).difference(shapely.Polygon(self.outer_outline))
        cut = [shapely.Polygon(p) for h, p in self.cutouts if h in (half, "both")]
        return ring.difference(shapely.union_all(cut)) if cut else ring

    @property
    def volume(self) -> float:
        """The gussets' material (mm^3), from polygon areas over the hulls' faces."""
        return float(sum(_hull_volume(lower, z_low, upper, z_high, self.plan(half), band)
                         for half, lower, z_low, upper, z_high, band in self.gussets))


@dataclass(frozen=True)
class ChamferedHousing(SplitHousing):
    """A :class:`~cadgen.solids.split_housing.SplitHousing` whose flange halves have their
    printed chamfers (:class:`FlangeChamfer`), in ``base``, ``cover`` and ``outer``."""

    chamfer: FlangeChamfer | None = None

    @property
    def volume(self) -> float:
        """Closed-form material volume (mm^3): the split housing's and its gussets'."""
        return super().volume + (self.chamfer.volume if self.chamfer is not None else 0.0)


# ------------------------------------------------------------------ geometry


def chamfer_run(outer_outline, flange_outline) -> float:
    """How far (mm) the flange outline reaches beyond the outer outline at most (both convex):
    the farthest of its vertices from the outer outline."""
    import shapely

    outer = shapely.Polygon(np.asarray(outer_outline, dtype=float))
    points = shapely.points(np.asarray(flange_outline, dtype=float))
    return float(shapely.distance(points, outer).max())


def seat_slot_width(bolt_size: str) -> float:
    """A bolt's seat slot's width (mm): the ISO 7089 washer's outside diameter plus
    :data:`SEAT_CLEARANCE`."""
    from cadgen.machine.catalogue import washer

    return float(washer(bolt_size)["d2"]) + SEAT_CLEARANCE


def _clip(polygon, coefficients) -> np.ndarray:
    """The part ((m, 2), maybe empty) of a convex ``polygon`` ((n, 2)) where the ``coefficients``
    ``(a, b, c)`` give ``a x + b y + c >= 0`` (Sutherland-Hodgman)."""
    polygon = np.asarray(polygon, dtype=float)
    values = polygon @ np.asarray(coefficients[:2], dtype=float) + coefficients[2]
    out = []
    for i in range(len(polygon)):
        j = (i + 1) % len(polygon)
        if values[i] >= 0:
            out.append(polygon[i])
        if (values[i] >= 0) != (values[j] >= 0):
            t = values[i] / (values[i] - values[j])
            out.append(polygon[i] + t * (polygon[j] - polygon[i]))
    return np.asarray(out, dtype=float).reshape(-1, 2)


def _hull_points(lower, z_low: float, upper, z_high: float) -> np.ndarray:
    """(n + m, 3): the two outlines at their heights, the points a gusset is the hull of."""
    return np.vstack([np.column_stack([lower, np.full(len(lower), z_low)]),
                      np.column_stack([upper, np.full(len(upper), z_high)])])


def _hull_volume(lower, z_low: float, upper, z_high: float, plan, band) -> float:
    """The volume (mm^3) over the region ``plan`` (shapely) of the hull of ``lower`` at
    ``z_low`` and ``upper`` at ``z_high``, within the heights ``band`` (z_min, z_max).

    Over each of its faces the hull's height is linear, so over the part of ``plan`` under a
    face its integral is that part's area times the height at its centroid (exact); an upper
    face adds, a lower one takes away, each clipped to the band (a face above ``z_max`` counts
    as ``z_max`` there: the split at ``z = z_max`` is a straight line in the plan)."""
    import shapely
    from scipy.spatial import ConvexHull

    points = _hull_points(lower, z_low, upper, z_high)
    hull = ConvexHull(points)
    total = 0.0
    for simplex, equation in zip(hull.simplices, hull.equations):
        normal, offset = equation[:3], equation[3]
        if abs(normal[2]) < 1e-12:   # a vertical face has no plan
            continue
        triangle = points[simplex][:, :2]
        piece = shapely.Polygon(triangle).intersection(plan)
        if piece.is_empty or piece.area == 0.0:
            continue
        upward = normal[2] > 0
        clip = band[1] if upward else band[0]  # an upper face cut at the top, a lower at the foot
        # where the face is beyond the band it counts as the band's edge: z - clip is
        # -(a x + b y + offset + n_z clip) / n_z, beyond (above an upper face's clip, below a
        # lower one's) where a x + b y + offset + n_z clip < 0 either way
        outside = _clip(triangle, -np.array([normal[0], normal[1], offset + normal[2] * clip]))
        beyond = (shapely.Polygon(outside).intersection(plan) if len(outside) >= 3
                  else shapely.Polygon())
        within = piece.difference(beyond)
        integral = clip * beyond.area
        if not within.is_empty:
            x, y = within.centroid.x, within.centroid.y
            integral += within.area * -(normal[0] * x + normal[1] * y + offset) / normal[2]
        total += integral if upward else -integral
    return float(total)


def _inset(outline, distance: float) -> np.ndarray:
    """A convex outline moved inwards by ``distance`` (corners kept sharp), counter-clockwise."""
    import shapely

    inner = shapely.Polygon(outline).buffer(-distance, join_style="mitre")
    return np.asarray(shapely.geometry.polygon.orient(inner).exterior.coords)[:-1]


def _as_extruded(outline) -> np.ndarray:
    """An outline as :func:`~cadgen.solids.extrude.extrude` builds it (manifold3d's
    ``CrossSection`` rounds the coordinates to about 1e-8 mm): a gusset meeting the flange's
    face then shares its vertices exactly (those rounded apart left zero-area facets)."""
    from cadgen.solids.extrude import manifold3d_engine

    polygons = manifold3d_engine().CrossSection([np.ascontiguousarray(outline, dtype=float)])
    return np.asarray(polygons.to_polygons()[0], dtype=float)


def _gussets(housing, inner, rise: float) -> tuple:
    """``(half, lower, z_low, upper, z_high, (z_min, z_max))`` of each half with room for a
    gusset: the hull of ``inner`` (the wall's outside, a little inside it) ``rise`` from the
    flange's face and the flange outline on that face, cut off at the half's end wall."""
    flange = _as_extruded(housing.flange_outline)
    low, high = housing.flange_z
    gussets = []
    if low - housing.z_bottom > 1e-9:    # the base's: below the flange, down to the floor
        gussets.append(("base", inner, low - rise, flange, low,
                        (max(housing.z_bottom, low - rise), low)))
    if housing.z_top - high > 1e-9:      # the cover's: above it, up to the roof
        gussets.append(("cover", flange, high, inner, high + rise,
                        (high, min(housing.z_top, high + rise))))
    return tuple(gussets)


def _seat_slots(housing, width: float) -> list:
    """Each flange bolt's seat slot: a stadium ``width`` wide from the bolt's washer on the
    wall side out through the flange's edge, along the wall's normal at the bolt."""
    import shapely

    from cadgen.solids.outline import circle

    outer = shapely.Polygon(housing.outer_outline).exterior
    reach = 4.0 * float(housing.bolt_hole_diameter) + width   # past the flange's edge
    slots = []
    for xy in np.asarray(housing.bolt_positions, dtype=float).reshape(-1, 2):
        foot = np.asarray(outer.interpolate(outer.project(shapely.Point(xy))).coords[0])
        outward = (xy - foot) / np.linalg.norm(xy - foot)
        side = np.array([-outward[1], outward[0]]) * width / 2
        far = xy + reach * outward
        box = shapely.Polygon([xy - side, far - side, far + side, xy + side])
        disc = shapely.Polygon(circle(width / 2, housing.segments, xy))
        slot = shapely.geometry.polygon.orient(box.union(disc))
        slots.append(np.asarray(slot.exterior.coords)[:-1])
    return slots


def _dowel_holes(housing) -> list:
    """The dowels' reamed holes, as :func:`~cadgen.solids.machine_parts.with_dowels` drills them."""
    from cadgen.solids.outline import circle
    from cadgen.solids.split_housing import TAPPED_SEGMENTS

    return [circle(diameter / 2, TAPPED_SEGMENTS, (x, y)) for x, y, diameter in housing.dowels]


def _splice_clearances(housing, cuts, gussets, rise: float, run: float) -> list:
    """``(half, strip)`` for each cut whose splice bolt's washer would reach into that half's
    gusset: the strip over the lugs and the head's or nut's length plus a washer beyond them."""
    import shapely

    from cadgen.machine.catalogue import nut, socket_screw, washer
    from cadgen.solids.segments import _half_heights, _lugs, lug_thickness

    if not cuts:
        return []
    size = housing.bolt_size
    radius = float(washer(size)["d2"]) / 2
    stack = max(socket_screw(size)["head_height"], nut(size)["m"] + washer(size)["h"])
    thickness = lug_thickness(housing)
    reach_along = thickness + stack + 2 * radius
    heights = _half_heights(housing)
    low, high = housing.flange_z
    # the gusset across a straight wall: (distance from the wall, depth from the flange's face)
    profile = shapely.Polygon([(0.0, 0.0), (run, 0.0), (0.0, rise)])
    strips = []
    for point, direction in cuts:
        point, direction = np.asarray(point, dtype=float), np.asarray(direction, dtype=float)
        normal = np.array([direction[1], -direction[0]])
        across = 4.0 * float(np.ptp(housing.flange_outline, axis=0).max())
        ends = [point - across * direction, point + across * direction]
        strip = np.array([ends[0] - reach_along * normal, ends[1] - reach_along * normal,
                          ends[1] + reach_along * normal, ends[0] + reach_along * normal])
        for half, *_ in gussets:
            z_bolt = heights[half][2]
            depth = (low - z_bolt) if half == "base" else (z_bolt - high)
            for _, piece_side, _, bolt in _lugs(housing, point, direction, thickness):
                if piece_side > 0:   # each bolt once (both lugs of a side hold it)
                    continue
                wall = shapely.Polygon(housing.outer_outline).exterior.distance(shapely.Point(bolt))
                if shapely.Point(wall, depth).buffer(radius, 64).intersects(profile):
                    strips.append((half, shapely.geometry.polygon.orient(
                        shapely.Polygon(strip)).exterior.coords[:-1]))
                    break
    return [(half, np.asarray(strip, dtype=float)) for half, strip in strips]


def chamfer_flanges(housing, *, cuts=()) -> ChamferedHousing:
    """``housing`` with a 45 deg gusset under each flange half (see the module notes).

    Parameters
    ----------
    housing : SplitHousing
        With its dowels (:func:`cadgen.solids.machine_parts.with_dowels`), if any.
    cuts : sequence of (point (2,), direction (2,))
        The cut lines it will be printed in segments along
        (:func:`cadgen.solids.segments.segment_cuts`), for the splices' clearances.

    Returns
    -------
    ChamferedHousing
    """
    from cadgen.solids.extrude import extrude, manifold3d_engine
    from cadgen.solids.split_housing import TAPPED_SEGMENTS

    m3d = manifold3d_engine()
    # the frustum starts inside the wall, so its faces cross the wall's rather than meet them
    # at its corners (near-coincident vertices there left zero-area facets)
    inner = _inset(housing.outer_outline, WALL_OVERLAP)
    run = chamfer_run(inner, housing.flange_outline)
    rise = run + RISE_MARGIN
    gussets = _gussets(housing, inner, rise)
    width = seat_slot_width(housing.bolt_size)
    prisms = [("both", slot) for slot in _seat_slots(housing, width)]
    prisms += _splice_clearances(housing, tuple(cuts), gussets, rise, run)
    cutouts = tuple(prisms) + tuple(("both", hole) for hole in _dowel_holes(housing))
    chamfer = FlangeChamfer(run, rise, gussets, np.asarray(housing.outer_outline, dtype=float),
                            np.asarray(housing.flange_outline, dtype=float), cutouts, width,
                            tuple((np.asarray(p, dtype=float), np.asarray(d, dtype=float))
                                  for p, d in cuts))
    solids = {"base": housing.base, "cover": housing.cover}
    outer = housing.outer
    inside = _inset(housing.outer_outline, 2 * WALL_OVERLAP)
    for half, lower, z_low, upper, z_high, (z_min, z_max) in gussets:
        hull = m3d.Manifold.hull_points(_hull_points(lower, z_low, upper, z_high).tolist())
        if z_max - z_min < z_high - z_low:   # cut off at the end wall's outer face
            hull = hull.trim_by_plane((0.0, 0.0, 1.0), z_min).trim_by_plane((0.0, 0.0, -1.0),
                                                                             -z_max)
        outer = outer + hull
        z0, height = z_low - 1.0, z_high - z_low + 2.0
        removed = [extrude(inside, height, z0=z0, path="chamfer.wall")]
        removed += [extrude(polygon, height, z0=z0, path="chamfer.cutout")
                    for h, polygon in prisms if h in (half, "both")]
        # the dowels' holes as with_dowels reams them (the same cylinders' vertices)
        removed += [m3d.Manifold.cylinder(height, d / 2, d / 2, TAPPED_SEGMENTS).translate(
            (x, y, z0)) for x, y, d in housing.dowels]
        gusset = hull - m3d.Manifold.batch_boolean(removed, m3d.OpType.Add)
        solids[half] = solids[half] + gusset
    values = {f.name: getattr(housing, f.name) for f in fields(housing)}
    values.update(base=solids["base"], cover=solids["cover"], outer=outer, chamfer=chamfer)
    return ChamferedHousing(**values)
