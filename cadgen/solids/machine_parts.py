"""The drivetrain's solids shared by both mechanisms: split housings from stacks, bolts, shafts.

The sizing (:mod:`cadgen.machine`) decides every number: a housing's end walls,
cavity height and parting plane (:class:`~cadgen.machine.model.HousingStack`), its
bearing seats, and each shaft's diameter, length beyond the housing and keys
(:class:`~cadgen.machine.model.Shaft`). This module turns those records into solids
(:mod:`cadgen.solids.split_housing`) and assembly parts; it sizes nothing but the
flange bolts, from the housing's side wall when the file does not name them.

Heights. A stack's and a seat's heights are from the housing's cavity floor; the
parts are built in their body's frame, so every height is offset by the cavity
floor's ``z`` in that frame.

A shaft turns with its gears (given their placements) and has a keyseat under each
keyed gear's keyway: the keyseats' relative angles are the gears' phasing on the shaft.
"""

from __future__ import annotations

import math

import numpy as np

from cadgen.solids.parts import Part, planar_transform

__all__ = ["BOLT_BY_WALL", "housing_bolt", "stack_housing", "with_dowels", "dowel_positions",
           "housing_parts",
           "printed_housing_parts", "printer_cuts", "shaft_part", "shaft_ends", "spacer_parts",
           "keyseat_turns", "side2_shaft", "SAME_KEYSEAT_RAD"]

#: The bolt of a housing's flange from its side wall (mm): ``(wall below, size)``, else M6.
BOLT_BY_WALL = ((4.0, "M3"), (6.0, "M4"), (8.0, "M5"))


def housing_bolt(params, wall: float) -> tuple:
    """``(bolt size, clearance hole diameter mm)`` of a housing's flange.

    The size is ``params.housing.bolt_size`` or, when the file leaves it out, the
    side wall's: M3 below 4 mm, M4 below 6 mm, M5 below 8 mm, else M6 (a bolt's
    nominal diameter about the wall's thickness, so the flange it needs, 1.5 d per
    half, stays in proportion with the wall). The hole is ISO 273 in the process's
    series (:func:`cadgen.machine.catalogue.clearance_hole`) plus the process's
    extra (printed holes shrink, :func:`cadgen.machine.fits.process_fits`).
    """
    size = getattr(params.housing, "bolt_size", None)
    if size is None:
        size = next((bolt for below, bolt in BOLT_BY_WALL if wall < below), "M6")
    from cadgen.machine.catalogue import clearance_hole
    from cadgen.machine.fits import process_fits

    fits = process_fits(params.manufacturing.process)
    return size, clearance_hole(size, fits.bolt_hole_series) + fits.bolt_hole_extra


def stack_housing(params, circles, shell, stack, seats, *, z_cavity_bottom: float, segments: int,
                  path: str = "housing", passages=(), tapped=()):
    """The split housing of one stack round some swept discs.

    Parameters
    ----------
    params : Parameters
        For the bolts (``housing.bolt_size``, ``manufacturing.process``).
    circles : (k, 3) array_like
        Swept discs ``(cx, cy, r)`` in the body frame (mm).
    shell : ShellSize
        ``clearance`` and side ``wall`` (:mod:`cadgen.solids.housings`).
    stack : HousingStack
        End walls, cavity height, parting plane (from the cavity floor).
    seats : sequence of BearingSeat
    passages, tapped : sequence
        Holes with no bearing: :func:`~cadgen.solids.split_housing.split_housing`'s.
    z_cavity_bottom : float
        The cavity floor's height in the body frame (mm).
    segments : int
    path : str

    Returns
    -------
    SplitHousing
        With its dowels; printed, a :class:`~cadgen.solids.flange_chamfer.ChamferedHousing`
        (45 deg gussets under the flange halves, clear of the splices of the segments it is
        printed in, :func:`printer_cuts`).
    """
    from cadgen.solids.split_housing import split_housing

    size, hole = housing_bolt(params, shell.wall)
    housing = split_housing(circles, clearance=shell.clearance, wall=shell.wall,
                            floor_wall=stack.floor_wall, roof_wall=stack.roof_wall,
                            cavity_height=stack.cavity_height, z_cavity_bottom=z_cavity_bottom,
                            parting_z=z_cavity_bottom + stack.parting_z,
                            seats=seats, bolt_size=size,
                            bolt_hole_diameter=hole, segments=segments, path=path,
                            passages=passages, tapped=tapped)
    housing = with_dowels(housing)
    if params.manufacturing.process != "printed":
        return housing
    from cadgen.solids.flange_chamfer import chamfer_flanges

    return chamfer_flanges(housing, cuts=printer_cuts(housing, params,
                                                      name=path.rsplit(".", 1)[-1]))


def dowel_positions(housing) -> list:
    """Where a split housing's two dowels go: in the flange between two bolts, the two gaps
    farthest apart (the cover is then located across its whole length), each on the flange's
    middle line (half way between the housing's outer outline and the flange's)."""
    import shapely

    bolts = np.asarray(housing.bolt_positions, dtype=float)
    outer = shapely.LinearRing(housing.outer_outline)
    flange = shapely.LinearRing(housing.flange_outline)
    gaps = []
    for a, b in zip(bolts, np.roll(bolts, -1, axis=0)):
        chord = shapely.Point(0.5 * (a + b))
        near = [ring.interpolate(ring.project(chord)) for ring in (outer, flange)]
        gaps.append(0.5 * (np.array(near[0].coords[0]) + np.array(near[1].coords[0])))
    pairs = [(i, j) for i in range(len(gaps)) for j in range(i + 1, len(gaps))]
    i, j = max(pairs, key=lambda ij: float(np.linalg.norm(gaps[ij[0]] - gaps[ij[1]])))
    return [tuple(map(float, gaps[i])), tuple(map(float, gaps[j]))]


def with_dowels(housing):
    """``housing`` with its two ISO 8734 dowels' holes reamed through both flange halves
    (:func:`cadgen.machine.fixings.dowel_pins` sizes them)."""
    from dataclasses import replace

    from cadgen.machine.fixings import dowel_pins
    from cadgen.solids.extrude import manifold3d_engine
    from cadgen.solids.split_housing import TAPPED_SEGMENTS

    if len(housing.bolt_positions) < 2:
        return housing
    m3d = manifold3d_engine()
    low, high = housing.flange_z
    pins = dowel_pins(housing.bolt_size, high - low)
    radius = pins["diameter"] / 2
    holes, dowels = None, ()
    for x, y in dowel_positions(housing):
        hole = m3d.Manifold.cylinder(high - low + 2.0, radius, radius, TAPPED_SEGMENTS
                                     ).translate((x, y, low - 1.0))
        holes = hole if holes is None else holes + hole
        dowels += ((x, y, pins["diameter"]),)
    return replace(housing, base=housing.base - holes, cover=housing.cover - holes,
                   dowels=dowels)


def housing_parts(name: str, housing, body: str) -> list:
    """``[<name>-base, <name>-cover]`` parts of kind ``housing`` on ``body`` (their copies are
    the assembly model's to place); the base holds the housing's bought items (the seats'
    bearings, the flange's bolts, the dowels: :func:`~cadgen.solids.bought_places.housing_items`)."""
    from cadgen.solids.bought_places import housing_items

    parts = []
    for piece, solid in (("base", housing.base), ("cover", housing.cover)):
        stem = f"{name}-{piece}"
        # seen along z a half is its flange's outline (the holes through it aside)
        parts.append(Part(stem, "housing", body, solid, footprint=housing.flange_outline))
    parts[0].bought = tuple(housing_items(name, housing))
    return parts


def printed_housing_parts(name: str, housing, body: str, params) -> tuple:
    """A housing's parts, cut into segments when a printed half does not fit the printer.

    With ``[manufacturing] process = "printed"`` each half's printing pose
    (:func:`cadgen.solids.outcome.printing_pose`) is checked against
    ``manufacturing.build_volume``; when one does not fit, the housing is cut across
    its long axis between its bearing seats (:mod:`cadgen.solids.segments`) and the
    parts are ``<name>-base-1``, ``<name>-base-2``, ..., ``<name>-cover-1``, ... (kind
    ``housing`` on ``body``). Otherwise exactly :func:`housing_parts`. The cuts are the ones
    its chamfers were made clear of (:func:`stack_housing`), else those of :func:`printer_cuts`.

    Returns
    -------
    parts : list of Part
    joints : list of SpliceJoint
        The bolted splices (empty when the housing is not cut).

    Raises
    ------
    DesignError
        At ``manufacturing.build_volume`` when no split between the seats fits.
    """
    parts = housing_parts(name, housing, body)
    if params.manufacturing.process != "printed":
        return parts, []
    chamfer = getattr(housing, "chamfer", None)   # its cuts chosen when it was chamfered
    cuts = chamfer.cuts if chamfer is not None else printer_cuts(housing, params, name=name,
                                                                 parts=parts)
    if not cuts:
        return parts, []
    from cadgen.solids.segments import segment_housing

    split = segment_housing(housing, cuts, segments=housing.segments, name=name)
    parts = []
    for half in ("base", "cover"):
        for piece in split.pieces:
            stem = f"{name}-{half}-{piece.suffix}"
            parts.append(Part(stem, "housing", body, getattr(piece, half)))
    from cadgen.solids.bought_places import housing_items

    # the first base segment holds every bought item of the housing (one body, one frame)
    parts[0].bought = tuple(housing_items(name, housing, split.joints))
    return parts, list(split.joints)


def printer_cuts(housing, params, *, name: str = "housing", parts=None) -> list:
    """The cut lines (:func:`cadgen.solids.segments.segment_cuts`) a printed housing is cut into
    segments along, ``[]`` when each half fits ``manufacturing.build_volume`` whole in its
    printing pose (:func:`cadgen.solids.outcome.printing_pose`). ``parts``: the housing's
    :func:`housing_parts`, when made already (their meshes are cached on them).

    Raises
    ------
    DesignError
        At ``manufacturing.build_volume`` when no split between the seats fits.
    """

    from cadgen.solids.outcome import fits_build_volume, printing_pose

    volume = tuple(float(v) for v in params.manufacturing.build_volume)
    parts = housing_parts(name, housing, "") if parts is None else parts
    if all(fits_build_volume(np.ptp(part.mesh.copy().apply_transform(
            printing_pose(part.mesh)).vertices, axis=0), volume) for part in parts):
        return []
    from cadgen.solids.segments import SEGMENT_MARGIN, segment_cuts, segment_problems
    from kinematics.errors import DesignError

    cuts = segment_cuts(housing, volume, margin=SEGMENT_MARGIN)
    problems = segment_problems(housing, cuts, volume, margin=SEGMENT_MARGIN, name=name)
    if problems:
        raise DesignError(problems)
    return cuts


def shaft_ends(shaft, housing) -> tuple:
    """``(z_bottom, z_top)`` of a shaft in its housing's body frame (mm).

    Each end is the outer end of its bearing seat where the seat is blind (the
    shaft ends against the shoulder), or the end wall's outer face plus the
    extension beyond it where the shaft leaves the housing; without a seat in a
    wall, that wall's outer face.
    """
    z0 = housing.z_cavity_bottom
    if getattr(shaft, "ends", None) is not None:   # it reaches into another housing
        return z0 + shaft.ends[0], z0 + shaft.ends[1]
    z_cavity_top = z0 + housing.cavity_height
    bottom, top = z0 - housing.floor_wall, z_cavity_top + housing.roof_wall
    for seat in shaft.seats:
        if seat.housing != shaft.housing:   # a seat in another housing: not this frame's
            continue
        if seat.wall == "floor":
            bottom = (z0 - housing.floor_wall - shaft.extends_below if seat.through
                      else z0 - seat.depth)
        elif seat.wall == "roof":
            top = (z_cavity_top + housing.roof_wall + shaft.extends_above if seat.through
                   else z_cavity_top + seat.depth)
    return bottom, top


def _turn_of(transform) -> float:
    """The rotation about z (rad) of a 4x4 rigid transform."""
    return math.atan2(transform[1, 0], transform[0, 0])


def _keyed_frames(shaft, gears, hubs=()):
    """``(gears, first, turns)``: the shaft's own gears and hubs of ``gears``, the placement
    of the first keyed one (the shaft turns with it; None: no gear placed) and each one's
    keyway direction at phi = 0 in the shaft's frame (rad)."""
    gears = {name: value for name, value in (gears or {}).items()
             if name in {mount.gear for mount in shaft.mounts} | {hub[0] for hub in hubs}}
    # the shaft turns with its keyed gears (a gear running free on its bearings does not)
    first = next((gears[m.gear][0] for m in shaft.mounts
                  if m.gear in gears and getattr(m, "bearing", None) is None), None)
    frame0 = _turn_of(first(0.0)) if first is not None else 0.0
    return gears, first, {name: _turn_of(local(0.0)) + keyway - frame0
                          for name, (local, keyway) in gears.items()}


def keyseat_turns(shaft, gears, hubs=()) -> dict:
    """Each keyed gear's (and hub's) keyseat direction on ``shaft``, rad in [0, 2 pi) from the
    first's: the phasing the workshop cuts (``gears`` as :func:`shaft_part`'s)."""
    _, _, turns = _keyed_frames(shaft, gears, hubs)
    keyed = {m.gear for m in shaft.mounts if m.key is not None} | {
        hub[0] for hub in hubs if hub[3] is not None}
    return {name: float(np.mod(turn, 2 * np.pi)) for name, turn in turns.items()
            if name in keyed}


def shaft_part(shaft, housing, body: str, *, segments: int, gears=None, hubs=(),
               retention=None) -> Part:
    """The shaft of a :class:`~cadgen.machine.model.Shaft` record as a part on ``body``.

    Named ``shaft-<axis>``, kind ``shaft``, built along z at the origin and placed at
    the shaft's ``xy`` in the body frame. A keyseat (a plain box, see
    :func:`~cadgen.solids.split_housing.shaft_solid`) under each keyed gear, the
    key's length centred on the gear's face; a D-flat along the whole length when
    a gear sits on one.

    ``gears`` (``{gear name: (local placement callable, keyway angle rad)}``, the gear
    parts' placements in the body and each bore's keyway direction in the gear's frame)
    makes the shaft turn with its gears and puts each keyseat under its gear's keyway:
    the keyseats' relative angles are the gears' phasing on the shaft, which the workshop
    cuts into it. Without it the shaft is fixed in the body, keyseats towards +x.

    ``hubs``: ``(name, z_bottom, z_top, key[, part])`` of the other parts keyed to the shaft
    (the planter on E, the rocker on the planet shaft; z in the body frame), each with its
    placement and keyway in ``gears`` under ``name``: a keyseat centred on its hub (``part``:
    the hub's part, when its name is not ``name``).

    ``retention`` (:class:`~cadgen.machine.retention.ShaftRetention`): a DIN 471 groove for
    each of its retaining rings.

    The part holds what is bought with it (:mod:`cadgen.solids.bought_places`): a key in each
    keyseat (fitted to its gear or hub), the two bearings of each gear running free on it, a
    hollow shaft's flange screws.
    """
    from cadgen.solids.bought_places import bearing_pair, key_item
    from cadgen.solids.retention_items import ring_items
    from cadgen.solids.split_housing import shaft_solid

    z_bottom, z_top = shaft_ends(shaft, housing)
    gears, first, turns = _keyed_frames(shaft, gears, hubs)

    def direction(name: str) -> float:
        return turns.get(name, 0.0)

    radius = shaft.diameter / 2
    keyseats, flat, flat_angle, bought = [], 0.0, 0.0, []
    for mount in shaft.mounts:
        gear = mount.gear.replace(" ", "-")   # its part's file stem
        middle = housing.z_cavity_bottom + mount.z_bottom + mount.face_width / 2
        if mount.key is not None:
            length = min(mount.key.length, mount.face_width)
            keyseats.append((middle - length / 2, middle + length / 2, mount.key.width,
                             mount.key.shaft_depth, direction(mount.gear)))
            bought.append(key_item(mount.key, middle - mount.key.length / 2,
                                   direction(mount.gear), radius, (gear,)))
        if getattr(mount, "bearing", None) is not None:   # it runs free on two bearings
            bought += bearing_pair(mount.bearing, middle, (gear,))
        if float(mount.flat_depth or 0.0) > flat:
            flat, flat_angle = float(mount.flat_depth), direction(mount.gear)
    for name, z_low, z_high, key, *part in hubs:   # a keyseat centred on each other keyed hub
        if key is not None:
            middle = 0.5 * (z_low + z_high)
            keyseats.append((middle - key.length / 2, middle + key.length / 2, key.width,
                             key.shaft_depth, direction(name)))
            bought.append(key_item(key, middle - key.length / 2, direction(name), radius,
                                   (part[0] if part else name,)))
    coupling = getattr(shaft, "coupling_key", None)
    if coupling is not None:   # the stub's keyseat, centred on the stub below the floor
        stub_top = housing.z_cavity_bottom - housing.floor_wall
        middle = 0.5 * (z_bottom + stub_top)
        keyseats.append((middle - coupling.length / 2, middle + coupling.length / 2,
                         coupling.width, coupling.shaft_depth, 0.0))
        bought.append(key_item(coupling, middle - coupling.length / 2, 0.0, radius))
    solid = shaft_solid(shaft.diameter, z_bottom, z_top, keyseats=keyseats, flat_depth=flat,
                        flat_angle=flat_angle, segments=segments)
    solid = _ring_grooves(solid, shaft, retention, housing.z_cavity_bottom, segments)
    bought += ring_items(shaft, retention, housing.z_cavity_bottom)
    if getattr(shaft, "bore", 0.0) > 0.0:
        solid = _hollow(solid, shaft, z_bottom, z_top, segments)
        bought += flange_screws(shaft.flange, z_top)
    offset = tuple(float(v) for v in shaft.xy)
    if first is None:
        local = (lambda phi, at=planar_transform(0.0, offset): at)
    else:   # the gears on one shaft turn together: the shaft turns with the first of them
        def local(phi, first=first, offset=offset):
            return planar_transform(_turn_of(first(phi)), offset)
    return Part(f"shaft-{shaft.name}", "shaft", body, solid, local, bought=tuple(bought))


#: rad: side 2's keyseats within this of side 1's are cut alike (one shaft part for both).
SAME_KEYSEAT_RAD = 1e-6


def side2_shaft(shaft, housing, retention, side1, side2, segments: int) -> list:
    """Side 2's own copy of a carrier-1 shaft whose keyseats are phased otherwise than side
    1's (``side1``, ``side2``: its gears' placements and keyways seen from ``carrier1`` and
    from ``carrier1:mirrored``, as :func:`shaft_part`'s ``gears``). C2 is one: planet I turns
    with side 2 about O, arm 2's central gear does not. Named ``shaft-<axis>-arm2``, placed
    on ``carrier1:mirrored``; none when side 1's part fits both sides."""
    from dataclasses import replace

    one, two = keyseat_turns(shaft, side1), keyseat_turns(shaft, side2)
    apart = [abs(math.remainder(two[name] - one[name], 2 * math.pi)) for name in one]
    if max(apart, default=0.0) <= SAME_KEYSEAT_RAD:
        return []
    part = shaft_part(shaft, housing, "carrier1:mirrored", segments=segments, gears=side2,
                      retention=retention)
    return [replace(part, name=f"{part.name}-arm2")]


def flange_screws(flange, z_top: float) -> list:
    """A hollow shaft's flange screws (the bill's) put in from under its flange (its top at
    ``z_top``) through the clearance holes of :func:`flange_bolt_holes` into the tapped holes
    of the housing it carries, on the same bolt circle."""
    if not flange:
        return []
    from cadgen.machine.fastening import bolt_circle
    from cadgen.solids.bought_places import tapped_screws

    thickness = float(flange["thickness"])
    return tapped_screws(flange["bolt"], None, bolt_circle(flange), z_top - thickness, up=True,
                         clamped=thickness, fitted=(f"{flange['carries']}-base",))


def _hollow(solid, shaft, z_bottom: float, z_top: float, segments: int):
    """A hollow shaft: its bore through, and its flange (with the screws' clearance holes) at
    the top, where it is bolted to the housing it carries."""
    from cadgen.solids.extrude import manifold3d_engine

    m3d = manifold3d_engine()
    length = z_top - z_bottom
    bore = m3d.Manifold.cylinder(length + 2.0, shaft.bore / 2, shaft.bore / 2, segments)
    solid = solid - bore.translate((0.0, 0.0, z_bottom - 1.0))
    flange = shaft.flange
    if not flange:
        return solid
    thick = float(flange["thickness"])
    disc = (m3d.Manifold.cylinder(thick, flange["radius"], flange["radius"], segments)
            - m3d.Manifold.cylinder(thick + 2.0, shaft.bore / 2, shaft.bore / 2,
                                    segments).translate((0.0, 0.0, -1.0)))
    disc = disc - flange_bolt_holes(flange, thick, segments)
    return solid + disc.translate((0.0, 0.0, z_top - thick))


def flange_bolt_holes(flange: dict, height: float, segments: int, diameter=None):
    """The carrying flange's bolt holes as cylinders from z = -1 to ``height + 1`` (ISO 273
    medium clearance holes, or ``diameter``: a tapped hole's drill), on its bolt circle
    (:func:`cadgen.machine.fastening.bolt_circle`, the rule its housing's tapped holes follow)."""
    from cadgen.machine.catalogue import clearance_hole
    from cadgen.machine.fastening import bolt_circle
    from cadgen.solids.extrude import manifold3d_engine

    m3d = manifold3d_engine()
    hole = diameter if diameter is not None else clearance_hole(flange["bolt"], "medium")
    cylinders = [m3d.Manifold.cylinder(height + 2.0, hole / 2, hole / 2, 24).translate(
        (x, y, -1.0)) for x, y in bolt_circle(flange)]
    return m3d.Manifold.batch_boolean(cylinders, m3d.OpType.Add)


def _tube(inner: float, outer: float, z0: float, z1: float, segments: int):
    """An annulus of radii ``inner < outer`` along z from ``z0`` to ``z1`` at the origin."""
    from cadgen.solids.extrude import manifold3d_engine

    m3d = manifold3d_engine()
    height = z1 - z0
    return (m3d.Manifold.cylinder(height, outer, outer, segments)
            - m3d.Manifold.cylinder(height, inner, inner, segments)).translate((0.0, 0.0, z0))


def _ring_grooves(solid, shaft, retention, z_floor: float, segments: int):
    """The shaft with a DIN 471 groove (diameter d2, width m) for each ring of its stack (z
    from its housing's cavity floor, at ``z_floor`` in the body)."""
    if retention is None or not retention.rings:
        return solid
    from cadgen.machine.catalogue import shaft_ring

    ring = shaft_ring(shaft.diameter)
    cutter = None
    for part in retention.rings:
        # the groove's flank the ring bears on is flush with the part it holds, and the
        # groove runs m (a little more than the ring's thickness) away from that part
        z0 = z_floor + (part.z0 if _bears_below(retention, part) else part.z1 - ring["m"])
        groove = _tube(ring["d2"] / 2, shaft.diameter, z0, z0 + ring["m"], segments)
        cutter = groove if cutter is None else cutter + groove
    return solid - cutter


def _bears_below(retention, ring) -> bool:
    """Whether ``ring`` holds a part just below it (else the part just above it)."""
    return any(abs(p.z1 - ring.z0) < 1e-6 for p in retention.parts if p is not ring)


def spacer_parts(shaft_part: Part, retention, z_floor: float, segments: int) -> list:
    """The turned spacers of a shaft's stack as parts riding with the shaft (``shaft_part``'s
    body and placement): tubes of the stack's bore and outside (z from the cavity floor, at
    ``z_floor`` in the body)."""
    if retention is None:
        return []
    return [Part(f"spacer-{retention.shaft}-{p.ref}", "spacer", shaft_part.body,
                 _tube(p.bore / 2, p.outside / 2, z_floor + p.z0, z_floor + p.z1, segments),
                 shaft_part.local)
            for p in retention.spacers]
