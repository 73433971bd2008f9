"""Split gearbox housings (a base and a cover bolted at a flange), bearing seats, shafts.

A split housing is the closed shell of :mod:`cadgen.solids.shell` cut at a
horizontal *parting plane* between two gear layers, so that the gears, shafts and
bearings can be put in:

* the cavity and the outer outline are those of :func:`~cadgen.solids.shell.shell_outlines`
  (the hull of the gears' swept discs grown by the clearance, then by the side wall);
* the end walls have thicknesses of their own (``floor_wall`` below the cavity,
  ``roof_wall`` above), thick enough for the bearing seats bored into them;
* the *base* is everything below the parting plane, the *cover* everything above;
* a *flange* runs round the outside at the parting plane, half on the base (below
  the plane), half on the cover (above), drilled for the bolts that join them;
* each *bearing seat* is a counterbore from the wall's cavity face into the wall,
  as deep as the bearing is wide, with the rest of the wall behind it as the
  shoulder; a seat where the shaft leaves the housing (``through``) has a hole of
  the shaft's running diameter through that shoulder.

Flange rules (documented choices, not a standard's):

* width ``3 d_h`` with ``d_h`` the bolt's clearance hole: the hole sits on the
  flange's mid-line, one hole diameter of material on either side of it (edge
  distance ``1.5 d_h`` from the hole's centre, the usual minimum for bolted plates
  being about ``1.2-1.5 d_h``);
* thickness ``max(wall, 1.5 d)`` per half (``d`` the bolt's nominal diameter), so
  the flange is never thinner than the wall it stiffens and a bolt head or nut
  bears on at least one and a half diameters of material; a half is clipped to
  the housing's height when the plane lies near an end wall;
* bolt count ``max(4, ceil(P / (12 d)))`` with ``P`` the length of the flange's
  mid-line: a bolt pitch of at most 12 bolt diameters, a common rule for a
  gasketed or sealed flange (closer than that the joint stays tight between
  bolts), and at least four bolts so the cover cannot rock. The bolts are spaced
  evenly by arc length along the mid-line.

Every polygon is a fixed function of the inputs (circles are the inscribed regular
polygons of :func:`~cadgen.solids.outline.circle`), so the material volume has a
closed form from polygon areas (:attr:`SplitHousing.volume`) that the meshes must
match.

manifold3d and shapely are imported inside the functions.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from cadgen.solids.errors import SolidInputError
from cadgen.solids.extrude import extrude
from cadgen.solids.outline import circle, offset_outline, signed_area
from cadgen.solids.shell import _shell_problems, shell_outlines
from cadgen.solids.tolerances import ENCLOSURE_VOLUME_ATOL, FLANGE_WIDTH_HOLES, MIN_WALL
from kinematics.errors import DesignError, Problem

__all__ = ["SplitHousing", "split_housing", "split_encloses", "shaft_solid", "bolt_count",
           "flange_width", "flange_thickness", "bolt_nominal_diameter", "SHOULDER_MIN",
           "SEAT_RIM_MIN", "BOLT_PITCH_DIAMETERS", "FLANGE_WIDTH_HOLES", "MIN_BOLTS"]

#: Thinnest shoulder (mm) behind a bearing seat: the rest of the wall the outer ring bears on.
SHOULDER_MIN = 1.0
#: Least material (mm) between a seat's bore and the housing's outside.
SEAT_RIM_MIN = 1.0
#: Largest bolt pitch along the flange, in bolt nominal diameters.
BOLT_PITCH_DIAMETERS = 12.0
#: Largest gap (mm) between a bolt's clearance hole and its polygon (see bolt_hole_segments).
BOLT_HOLE_CHORD = 0.01
#: Fewest bolts on a flange.
MIN_BOLTS = 4
#: Flange half thickness in bolt nominal diameters (at least the wall).
FLANGE_THICKNESS_DIAMETERS = 1.5


@dataclass(frozen=True)
class SplitHousing:
    """A housing parted into a base and a cover, and what is needed to check what it encloses.

    Attributes
    ----------
    base, cover : manifold3d.Manifold
        The material below and above the parting plane (flange halves, seats and
        holes included). They touch on the plane and do not overlap.
    outer : manifold3d.Manifold
        Everything the housing occupies or encloses: the outer prism with the
        flange ring, void filled (bolt holes, seats and cavity filled).
    cavity : manifold3d.Manifold
        The void the gears turn in.
    cavity_outline, outer_outline, flange_outline : (n, 2) float
        Counter-clockwise, mm.
    z_cavity_bottom, cavity_height : float
        mm; the cavity spans ``z_cavity_bottom`` to ``z_cavity_bottom + cavity_height``.
    wall, floor_wall, roof_wall : float
        Side wall, and the end walls below and above the cavity (mm).
    parting_z : float
        Absolute height of the parting plane (mm).
    bolt_positions : (k, 2) float
        Bolt axes (mm), on the flange's mid-line.
    bolt_hole_diameter : float
        Clearance hole (mm).
    bolt_size : str
        ``"M4"``, ...
    flange_thickness : float
        Thickness of each flange half before clipping to the housing's height (mm).
    flange_z : (float, float)
        Bottom and top of the flange after clipping (mm).
    seats : tuple
        The :class:`cadgen.machine.model.BearingSeat` records bored.
    segments : int
        Sides of the circle polygons (seats, holes), so the closed form can rebuild them.
    joints : tuple
        The bolted splices between the pieces of a housing cut into segments to fit a
        printer (:class:`cadgen.solids.segments.SpliceJoint`); empty for a housing made whole.
    """

    base: object
    cover: object
    outer: object
    cavity: object
    cavity_outline: np.ndarray
    outer_outline: np.ndarray
    flange_outline: np.ndarray
    z_cavity_bottom: float
    cavity_height: float
    wall: float
    floor_wall: float
    roof_wall: float
    parting_z: float
    bolt_positions: np.ndarray
    bolt_hole_diameter: float
    bolt_size: str
    flange_thickness: float
    flange_z: tuple
    seats: tuple
    segments: int
    joints: tuple = ()
    # holes with no bearing: ``(x, y, diameter, wall)`` through a wall (a shaft passing it),
    # ``(x, y, diameter, depth, wall)`` tapped from the wall's outer face (a flange's screws)
    passages: tuple = ()
    tapped: tuple = ()
    dowels: tuple = ()   # ``(x, y, diameter)`` reamed through both flange halves

    @property
    def solid(self):
        """The whole housing (base and cover joined), manifold3d."""
        return self.base + self.cover

    @property
    def z_bottom(self) -> float:
        """The floor's outer face (mm)."""
        return self.z_cavity_bottom - self.floor_wall

    @property
    def z_top(self) -> float:
        """The roof's outer face (mm)."""
        return self.z_cavity_bottom + self.cavity_height + self.roof_wall

    @property
    def bolt_segments(self) -> int:
        """Sides of a bolt hole's polygon: :func:`bolt_hole_segments`."""
        return bolt_hole_segments(self.bolt_hole_diameter, self.segments)

    @property
    def volume(self) -> float:
        """Closed-form material volume (mm^3) of base and cover, from polygon areas."""
        height = self.z_top - self.z_bottom
        flange_height = self.flange_z[1] - self.flange_z[0]
        outer_area = signed_area(self.outer_outline)
        bolt_area = sum(signed_area(circle(self.bolt_hole_diameter / 2, self.bolt_segments, xy))
                        for xy in self.bolt_positions)
        volume = (outer_area * height
                  + (signed_area(self.flange_outline) - outer_area) * flange_height
                  - bolt_area * flange_height
                  - signed_area(self.cavity_outline) * self.cavity_height)
        for seat in self.seats:
            wall = self.floor_wall if seat.wall == "floor" else self.roof_wall
            depth = _depth(seat)
            volume -= signed_area(circle(seat.seat_diameter / 2, self.segments, seat.xy)) * depth
            if seat.through:
                volume -= (signed_area(circle(seat.hole_diameter / 2, self.segments, seat.xy))
                           * (wall - depth))
        for x, y, diameter, wall in self.passages:
            volume -= (signed_area(circle(diameter / 2, self.segments, (x, y)))
                       * (self.floor_wall if wall == "floor" else self.roof_wall))
        for x, y, diameter, depth, _ in self.tapped:
            volume -= signed_area(circle(diameter / 2, TAPPED_SEGMENTS, (x, y))) * depth
        for x, y, diameter in self.dowels:
            volume -= signed_area(circle(diameter / 2, TAPPED_SEGMENTS, (x, y))) * flange_height
        return volume


# ------------------------------------------------------------------ rules
#: Sides of a tapped hole's polygon (a few mm across: its chord error is below 0.01 mm).
TAPPED_SEGMENTS = 48


def _depth(seat) -> float:
    """How deep a seat is bored: its bearings side by side (a pair: two widths)."""
    return float(getattr(seat, "depth", seat.bearing.width))



def bolt_nominal_diameter(bolt_size: str) -> float:
    """Nominal diameter (mm) of an ISO metric bolt size such as ``"M4"`` or ``"M2.5"``."""
    match = re.fullmatch(r"M(\d+(?:\.\d+)?)", str(bolt_size).strip())
    if not match or float(match.group(1)) <= 0:
        raise SolidInputError("bolt_size", f"an ISO metric bolt size is 'M<d>' (e.g. 'M4'), "
                                           f"not {bolt_size!r}")
    return float(match.group(1))


def bolt_hole_segments(bolt_hole_diameter: float, segments: int) -> int:
    """Sides of a bolt's clearance hole: within :data:`BOLT_HOLE_CHORD` of its circle, at most
    ``segments``. A clearance hole is no fit (ISO 273 medium is H13: +0.18 mm on 4.5 mm), so
    0.01 mm is ample; 96 sides on a 3.4 mm hole tripled the housings' triangles and the
    sweeps' cost for nothing."""
    from cadgen.solids.outline import segments_for

    return min(int(segments), segments_for(float(bolt_hole_diameter) / 2, BOLT_HOLE_CHORD,
                                           minimum=12))


def flange_width(bolt_hole_diameter: float) -> float:
    """Flange width (mm) beyond the outer wall: :data:`FLANGE_WIDTH_HOLES` hole diameters."""
    return FLANGE_WIDTH_HOLES * float(bolt_hole_diameter)


def flange_thickness(wall: float, bolt_size: str) -> float:
    """Thickness (mm) of each flange half: the wall, or 1.5 bolt diameters if more."""
    return max(float(wall), FLANGE_THICKNESS_DIAMETERS * bolt_nominal_diameter(bolt_size))


def bolt_count(perimeter: float, bolt_size: str) -> int:
    """Bolts on a flange whose mid-line is ``perimeter`` mm long: pitch <= 12 d, at least 4."""
    pitch = BOLT_PITCH_DIAMETERS * bolt_nominal_diameter(bolt_size)
    return max(MIN_BOLTS, math.ceil(float(perimeter) / pitch))


def _bolt_positions(mid_line: np.ndarray, count: int) -> np.ndarray:
    """``count`` points evenly spaced by arc length on a closed polygon, half a pitch from vertex 0."""
    ring = np.vstack([mid_line, mid_line[:1]])
    lengths = np.linalg.norm(np.diff(ring, axis=0), axis=1)
    cumulative = np.concatenate([[0.0], np.cumsum(lengths)])
    at = (np.arange(count) + 0.5) * cumulative[-1] / count
    return np.column_stack([np.interp(at, cumulative, ring[:, 0]),
                            np.interp(at, cumulative, ring[:, 1])])


# ------------------------------------------------------------------ checks


def _seat_path(path, seat) -> str:
    side = "" if getattr(seat, "side", 1) in (1, None) else f"-side{seat.side}"
    return f"{path}.seats.{seat.shaft}{side}.{seat.wall}"


def _seat_problems(seats, outer_outline, floor_wall, roof_wall, path, segments):
    """Every problem of the bearing seats: depth, breakout, shoulder, overlap."""
    import shapely

    problems = []
    outer = shapely.Polygon(outer_outline)
    discs = {"floor": [], "roof": []}
    for seat in seats:
        where = _seat_path(path, seat)
        if seat.wall not in discs:
            problems.append(Problem(where, "seat_wall_unknown",
                                    f"a seat's wall is 'floor' or 'roof', not {seat.wall!r}"))
            continue
        wall = floor_wall if seat.wall == "floor" else roof_wall
        depth, diameter = _depth(seat), float(seat.seat_diameter)
        if not (math.isfinite(diameter) and diameter > 0 and math.isfinite(depth) and depth > 0):
            problems.append(Problem(where, "seat_not_positive",
                                    f"the seat is {diameter!r} mm wide and {depth!r} mm deep; "
                                    f"both must be finite and > 0"))
            continue
        if depth > wall - SHOULDER_MIN + 1e-12:
            problems.append(Problem(where, "seat_too_deep",
                                    f"the seat is {depth:g} mm deep (the bearing's width) in a "
                                    f"{wall:g} mm {seat.wall}: no {SHOULDER_MIN:g} mm shoulder is "
                                    f"left behind it; the wall must be >= {depth + SHOULDER_MIN:g} mm"))
        rim = shapely.Point(seat.xy).buffer(diameter / 2 + SEAT_RIM_MIN, quad_segs=64)
        if not outer.contains(rim):
            outside = rim.difference(outer).area
            problems.append(Problem(where, "seat_breaks_out",
                                    f"the {diameter:g} mm seat at ({seat.xy[0]:.6g}, "
                                    f"{seat.xy[1]:.6g}) mm with a {SEAT_RIM_MIN:g} mm rim leaves "
                                    f"the housing's outer outline ({outside:.3g} mm^2 outside)"))
        if seat.through:
            hole = float(seat.hole_diameter)
            if not (math.isfinite(hole) and 0 < hole < diameter):
                problems.append(Problem(where, "no_shoulder",
                                        f"the through hole is {hole:g} mm for a {diameter:g} mm "
                                        f"seat: it must be > 0 and narrower than the seat, or "
                                        f"nothing holds the bearing"))
        disc = shapely.Polygon(circle(diameter / 2, segments, seat.xy))
        for other, other_disc in discs[seat.wall]:
            if disc.intersects(other_disc):
                problems.append(Problem(where, "seats_overlap",
                                        f"the seat overlaps the seat of shaft {other.shaft} "
                                        f"(side {other.side}) in the {seat.wall}"))
        discs[seat.wall].append((seat, disc))
    return problems


def _split_problems(circles, cavity_height, clearance, wall, floor_wall, roof_wall,
                    z_cavity_bottom, parting_z, bolt_hole_diameter, min_wall, path):
    problems = _shell_problems(circles, cavity_height, clearance, wall, min_wall, z_cavity_bottom,
                               path)
    for name, value in (("floor_wall", floor_wall), ("roof_wall", roof_wall)):
        if not math.isfinite(value):
            problems.append(Problem(f"{path}.{name}", "not_finite",
                                    f"{name} must be finite, not {value!r}"))
        elif value < min_wall or value <= 0:
            problems.append(Problem(f"{path}.{name}", "wall_too_thin",
                                    f"the {name.replace('_', ' ')} is {value:g} mm thick; the "
                                    f"minimum is {min_wall:g} mm"))
    top = z_cavity_bottom + cavity_height
    if not (math.isfinite(parting_z) and z_cavity_bottom <= parting_z <= top):
        problems.append(Problem(f"{path}.parting_z", "parting_outside_cavity",
                                f"the parting plane at z = {parting_z!r} mm must lie in the "
                                f"cavity, {z_cavity_bottom:g} to {top:g} mm"))
    if not (math.isfinite(bolt_hole_diameter) and bolt_hole_diameter > 0):
        problems.append(Problem(f"{path}.bolt_hole_diameter", "not_positive",
                                f"the bolt clearance hole must be > 0 mm, not "
                                f"{bolt_hole_diameter!r}"))
    return problems


# ------------------------------------------------------------------ solids


def split_housing(circles, *, clearance: float, wall: float, floor_wall: float, roof_wall: float,
                  cavity_height: float, z_cavity_bottom: float, parting_z: float, seats=(),
                  bolt_size: str, bolt_hole_diameter: float, segments: int,
                  path: str = "housing", min_wall: float = MIN_WALL, passages=(),
                  tapped=()) -> SplitHousing:
    """A housing round some gears' swept discs, parted into a base and a cover.

    Parameters
    ----------
    circles : (k, 3) array_like
        ``(cx, cy, r)`` per gear axis, the disc the gear sweeps (mm, housing frame).
    clearance, wall : float
        Gap round the discs and the side wall (mm), as :func:`~cadgen.solids.shell.closed_shell`.
    floor_wall, roof_wall : float
        End walls below and above the cavity (mm), each >= ``min_wall``.
    cavity_height, z_cavity_bottom : float
        mm.
    parting_z : float
        Absolute height of the parting plane (mm), within the cavity.
    seats : sequence of BearingSeat
        Seats bored into the end walls (``xy`` in the housing frame, ``wall``
        ``"floor"`` or ``"roof"``); see :class:`cadgen.machine.model.BearingSeat`.
    bolt_size : str
        ISO metric size, e.g. ``"M4"``.
    bolt_hole_diameter : float
        Clearance hole (mm), e.g. ISO 273 medium.
    segments : int
        Sides per full circle (outlines, seats, holes), >= 3.
    path : str
        Field-path prefix of the problems.
    min_wall : float
        Thinnest wall accepted (mm).

    Returns
    -------
    SplitHousing

    Raises
    ------
    DesignError
        Every problem at once: those of :func:`~cadgen.solids.shell.closed_shell`
        plus ``wall_too_thin`` for an end wall, ``parting_outside_cavity``,
        ``seat_too_deep`` (no :data:`SHOULDER_MIN` behind the seat),
        ``seat_breaks_out`` (the seat plus :data:`SEAT_RIM_MIN` leaves the outer
        outline), ``no_shoulder`` (a through hole as wide as its seat),
        ``seats_overlap``, ``seat_wall_unknown``; each seat's at
        ``path.seats.<shaft>[-side<n>].<wall>``.
    SolidInputError
        For ``segments`` < 3 or a bolt size that is not ``M<d>``.
    """
    from cadgen.solids.extrude import manifold3d_engine

    manifold3d = manifold3d_engine()

    circles = np.asarray(circles, dtype=float)
    if circles.ndim == 1 and circles.size == 3:
        circles = circles[None, :]
    if isinstance(segments, bool) or int(segments) != segments or segments < 3:
        raise SolidInputError("segments", f"segments must be an integer >= 3, not {segments!r}")
    segments = int(segments)
    clearance, wall, floor_wall, roof_wall = (float(v) for v in (clearance, wall, floor_wall,
                                                                  roof_wall))
    cavity_height, z_cavity_bottom, parting_z = (float(v) for v in (cavity_height, z_cavity_bottom,
                                                                     parting_z))
    bolt_hole_diameter = float(bolt_hole_diameter)
    seats = tuple(seats)
    nominal = bolt_nominal_diameter(bolt_size)
    problems = _split_problems(circles, cavity_height, clearance, wall, floor_wall, roof_wall,
                               z_cavity_bottom, parting_z, bolt_hole_diameter, float(min_wall),
                               path)
    if problems:   # the outlines need valid circles and walls
        raise DesignError(problems)
    cavity_outline, outer_outline = shell_outlines(circles, clearance=clearance, wall=wall,
                                                   segments=segments)
    problems = _seat_problems(seats, outer_outline, floor_wall, roof_wall, path, segments)
    if problems:
        raise DesignError(problems)

    width = flange_width(bolt_hole_diameter)
    flange_outline = offset_outline(outer_outline, width, segments, path=f"{path}.outer_outline")
    mid_line = offset_outline(outer_outline, width / 2, segments, path=f"{path}.outer_outline")
    ring = np.vstack([mid_line, mid_line[:1]])
    perimeter = float(np.linalg.norm(np.diff(ring, axis=0), axis=1).sum())
    bolts = _bolt_positions(mid_line, bolt_count(perimeter, bolt_size))
    half = max(wall, FLANGE_THICKNESS_DIAMETERS * nominal)

    z_bottom = z_cavity_bottom - floor_wall
    z_cavity_top = z_cavity_bottom + cavity_height
    z_top = z_cavity_top + roof_wall
    flange_z = (max(z_bottom, parting_z - half), min(z_top, parting_z + half))
    bolt_holes = [circle(bolt_hole_diameter / 2, bolt_hole_segments(bolt_hole_diameter, segments),
                         xy) for xy in bolts]

    # The housing as horizontal slabs, each one extrusion of a 2-D section with holes: the
    # outer (or, within the flange, the flange) outline minus whatever voids span the slab.
    # No boolean ever meets coplanar faces but the slabs' touching ends, so manifold3d leaves
    # no slivers (overlapping prisms unioned at the parting plane did), and every coordinate
    # is exact. The base's slabs end at the parting plane, the cover's start there.
    voids = [(cavity_outline, z_cavity_bottom, z_cavity_top)]
    for seat in seats:
        depth = _depth(seat)
        seat_disc = circle(seat.seat_diameter / 2, segments, seat.xy)
        hole = circle(seat.hole_diameter / 2, segments, seat.xy) if seat.through else None
        if seat.wall == "floor":
            voids.append((seat_disc, z_cavity_bottom - depth, z_cavity_bottom))
            if hole is not None:
                voids.append((hole, z_bottom, z_cavity_bottom - depth))
        else:
            voids.append((seat_disc, z_cavity_top, z_cavity_top + depth))
            if hole is not None:
                voids.append((hole, z_cavity_top + depth, z_top))
    passages = tuple((float(x), float(y), float(d), str(w)) for x, y, d, w in passages)
    tapped = tuple((float(x), float(y), float(d), float(h), str(w)) for x, y, d, h, w in tapped)
    for x, y, diameter, wall_name in passages:
        disc = circle(diameter / 2, segments, (x, y))
        voids.append((disc, z_bottom, z_cavity_bottom) if wall_name == "floor"
                     else (disc, z_cavity_top, z_top))
    for x, y, diameter, depth, wall_name in tapped:
        disc = circle(diameter / 2, TAPPED_SEGMENTS, (x, y))
        voids.append((disc, z_bottom, z_bottom + depth) if wall_name == "floor"
                     else (disc, z_top - depth, z_top))
    levels = sorted({z_bottom, z_top, parting_z, *flange_z,
                     *(z for _, a, b in voids for z in (a, b))})

    def piece(low, high, label):
        slabs, previous = [], None
        for a, b in zip(levels[:-1], levels[1:]):
            if not (low <= a and b <= high):
                continue
            middle = (a + b) / 2
            in_flange = flange_z[0] < middle < flange_z[1]
            holes = tuple(i for i, (_, lo, hi) in enumerate(voids) if lo < middle < hi)
            section = (in_flange, holes)
            if section == previous:   # the same section as the slab below: one taller slab
                slabs[-1][1] = b
            else:
                slabs.append([a, b, section])
            previous = section
        solids = []
        for a, b, (in_flange, holes) in slabs:
            outline = flange_outline if in_flange else outer_outline
            cut = [voids[i][0] for i in holes] + (bolt_holes if in_flange else [])
            solids.append(extrude(outline, b - a, holes=cut, z0=a, path=f"{path}.{label}",
                                  outline_path=f"{path}.{label}.section",
                                  holes_path=f"{path}.{label}.voids"))
        return manifold3d.Manifold.batch_boolean(solids, manifold3d.OpType.Add)

    base = piece(-math.inf, parting_z, "base")
    cover = piece(parting_z, math.inf, "cover")
    outer = (extrude(outer_outline, z_top - z_bottom, z0=z_bottom, path=f"{path}.outer")
             + extrude(flange_outline, flange_z[1] - flange_z[0], z0=flange_z[0],
                       path=f"{path}.flange"))
    cavity = extrude(cavity_outline, cavity_height, z0=z_cavity_bottom, path=f"{path}.cavity")
    return SplitHousing(base=base, cover=cover, outer=outer, cavity=cavity,
                        cavity_outline=cavity_outline, outer_outline=outer_outline,
                        flange_outline=flange_outline, z_cavity_bottom=z_cavity_bottom,
                        cavity_height=cavity_height, wall=wall, floor_wall=floor_wall,
                        roof_wall=roof_wall, parting_z=parting_z, bolt_positions=bolts,
                        bolt_hole_diameter=bolt_hole_diameter, bolt_size=str(bolt_size),
                        flange_thickness=half, flange_z=flange_z, seats=seats,
                        segments=segments, passages=passages, tapped=tapped)


def split_encloses(housing, part, *, volume_atol: float = ENCLOSURE_VOLUME_ATOL) -> tuple[bool, float]:
    """Whether a part lies inside a split housing's cavity, and how much of it does not.

    As :func:`cadgen.solids.shell.encloses`, the part must neither stick out of
    ``housing.outer`` nor cut into the material (base or cover). The seats and
    holes are voids in the material but not cavity: a part reaching into a seat
    would pass both of those tests, so the volume is measured as the part minus
    the cavity, which is the sum of those two pieces plus whatever lies in the
    seats, holes and bolt holes. A gear turning in the cavity has none there (the
    seats start at the cavity's end faces), so a seat never makes it look outside,
    nor hides one that is.

    Parameters
    ----------
    housing : SplitHousing
        Or anything with manifold3d ``.cavity``.
    part : manifold3d.Manifold
        In the housing's frame.
    volume_atol : float
        mm^3 outside the cavity still counted as enclosed (coplanar debris).

    Returns
    -------
    enclosed : bool
    outside_volume : float
        mm^3 of the part outside the cavity.
    """
    outside = part - housing.cavity
    volume = 0.0 if outside.is_empty() else max(outside.volume(), 0.0)
    return volume <= volume_atol, float(volume)


def shaft_solid(diameter: float, z_bottom: float, z_top: float, *, keyseats=(),
                flat_depth: float = 0.0, flat_angle: float = 0.0, segments: int):
    """A round shaft along z at the origin, with keyseats and an optional D-flat.

    Parameters
    ----------
    diameter : float
        mm, > 0 (the section is the inscribed regular polygon of ``segments`` sides).
    z_bottom, z_top : float
        Ends (mm), ``z_top > z_bottom``.
    keyseats : sequence of (z_from, z_to, width, depth, angle)
        Each a slot cut from the surface ``depth`` mm deep (t1), ``width`` mm wide,
        from ``z_from`` to ``z_to`` (clipped to the shaft), centred on the direction
        ``angle`` (rad from +x). A DIN 6885 form-A keyseat is end-milled and has
        round ends; here it is a plain box (its length is the key's, so the box is
        the keyseat's straight part extended to the full key length).
    flat_depth : float
        Depth (mm) of a D-flat along the whole length, < the radius; 0 for none.
    flat_angle : float
        Direction (rad from +x) the flat faces (the hub's flat sits there).
    segments : int
        Sides of the section, >= 3.

    Returns
    -------
    manifold3d.Manifold

    Raises
    ------
    SolidInputError
        For a bad dimension (the value in the message).
    """
    from cadgen.solids.extrude import manifold3d_engine

    manifold3d = manifold3d_engine()
    import shapely

    diameter, z_bottom, z_top = float(diameter), float(z_bottom), float(z_top)
    flat_depth = float(flat_depth)
    radius = diameter / 2
    if not (math.isfinite(diameter) and diameter > 0):
        raise SolidInputError("diameter", f"a shaft needs a finite diameter > 0 mm, not {diameter!r}")
    if not (math.isfinite(z_bottom) and math.isfinite(z_top) and z_top > z_bottom):
        raise SolidInputError("z_top", f"a shaft needs z_top > z_bottom, not {z_bottom!r} to {z_top!r}")
    if not (math.isfinite(flat_depth) and 0.0 <= flat_depth < radius):
        raise SolidInputError("flat_depth", f"a D-flat is 0 <= depth < the radius {radius:g} mm, "
                                            f"not {flat_depth!r}")
    section = circle(radius, segments)
    if flat_depth > 0:
        cut = shapely.affinity.rotate(
            shapely.box(radius - flat_depth, -2 * radius, 2 * radius, 2 * radius),
            float(flat_angle), origin=(0.0, 0.0), use_radians=True)
        flat = shapely.Polygon(section).difference(cut)
        section = np.asarray(shapely.geometry.polygon.orient(flat).exterior.coords)[:-1]
    solid = extrude(section, z_top - z_bottom, z0=z_bottom, path="shaft.length",
                    outline_path="shaft section")
    for index, keyseat in enumerate(keyseats):
        z_from, z_to, width, depth, angle = (float(v) for v in keyseat)
        z_from, z_to = max(z_from, z_bottom), min(z_to, z_top)
        if not (z_to > z_from and 0 < width < diameter and 0 < depth < radius):
            raise SolidInputError(f"keyseats[{index}]",
                                  f"a keyseat needs z_to > z_from within the shaft, 0 < width < "
                                  f"{diameter:g} mm and 0 < depth < {radius:g} mm, not {keyseat!r}")
        # the box starts depth below the surface and overshoots it by the radius
        box = manifold3d.Manifold.cube((depth + radius, width, z_to - z_from)).translate(
            (radius - depth, -width / 2, z_from))
        solid = solid - box.rotate((0.0, 0.0, math.degrees(angle)))
    return solid
