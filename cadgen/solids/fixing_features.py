"""Where parts are fixed, as solid features: the holes and bosses the machine's fixings need.

The frame's tapped mounting holes, the passages and tapped holes a housing's floor needs for
the shafts and carrying flanges, the cam's bore and its screws' holes, a keyed hub's boss and
bore (:mod:`cadgen.machine.fixings` sizes them; the solids cut what it says).
"""

from __future__ import annotations

import math

import numpy as np

from cadgen.machine.fastening import bolt_circle
from cadgen.machine.fixings import TAP_DRILL

__all__ = ["FRAME_MOUNT_BOLT", "FRAME_MOUNT_HOLES", "mounting_holes", "floor_holes",
           "cam_bore_radius", "cam_screw_holes", "keyed_boss"]


#: The frame's mounting to the transplanter: tapped holes in its floor, from below.
FRAME_MOUNT_BOLT, FRAME_MOUNT_HOLES = "M8", 4


def mounting_holes(discs, shell, seats, floor_wall: float, segments: int) -> tuple:
    """The frame's mounting holes: ``FRAME_MOUNT_HOLES`` tapped ``FRAME_MOUNT_BOLT`` holes in its
    floor, as far apart as the floor allows (the corners of its outline less the side wall and
    1.5 bolt diameters), each clear of the floor's bearing seats by a bolt diameter, two bolt
    diameters deep (at most the floor less 2 mm): the transplanter's frame bolts up into them."""
    import shapely

    from cadgen.solids.shell import shell_outlines

    size = float(FRAME_MOUNT_BOLT.removeprefix("M"))
    _, outer = shell_outlines(discs, clearance=shell.clearance, wall=shell.wall,
                              segments=segments)
    inner = shapely.Polygon(outer).buffer(-(shell.wall + 1.5 * size))
    ring = np.asarray(inner.exterior.coords)[:-1]
    floor_seats = [(np.asarray(seat.xy, dtype=float), seat.seat_diameter / 2)
                   for seat in seats if seat.wall == "floor"]
    clear = [p for p in ring
             if all(np.linalg.norm(p - xy) >= radius + size for xy, radius in floor_seats)]
    chosen = []
    for direction in ((1, 1), (-1, 1), (-1, -1), (1, -1))[:FRAME_MOUNT_HOLES]:
        if clear:
            best = max(clear, key=lambda p: float(np.dot(p, direction)))
            if all(np.linalg.norm(best - q) > 2 * size for q in chosen):
                chosen.append(best)
    drill = TAP_DRILL[FRAME_MOUNT_BOLT]
    depth = min(2.0 * size, floor_wall - 2.0)
    return tuple((float(x), float(y), drill, depth, "floor") for x, y in chosen)


def floor_holes(drivetrain) -> dict:
    """``{housing: (passages, tapped)}``: the holes the seats do not make, for
    :func:`~cadgen.solids.split_housing.split_housing`. A shaft passing a floor with no bearing
    of its own (O through gearbox 1's, C2 through gearbox 2's) passes a hole of its diameter
    plus the running clearance; the flange that carries a housing (the sleeve S carries gearbox
    1, the hollow shaft C gearbox 2) is screwed into tapped holes of its floor, two screw
    diameters deep (at most the floor less 2 mm), on the flange's bolt circle about the axis."""
    from cadgen.machine.fits import process_fits

    clearance = process_fits(drivetrain.process).running_clearance
    floors = {name: stack.floor_wall for name, stack in drivetrain.stacks.items()}
    out = {name: ([], []) for name in drivetrain.stacks}
    for shaft in drivetrain.shafts:
        if shaft.side != 1:
            continue
        passes = {"O": "gearbox1", "C2": "gearbox2"}.get(shaft.name)
        if passes in out:
            out[passes][0].append((0.0, 0.0, shaft.diameter + clearance, "floor"))
        flange = shaft.flange
        if flange and flange["carries"] in out:
            size = float(flange["bolt"].removeprefix("M"))
            depth = min(2.0 * size, floors[flange["carries"]] - 2.0)
            drill = TAP_DRILL[flange["bolt"]]
            out[flange["carries"]][1].extend((x, y, drill, depth, "floor")
                                             for x, y in bolt_circle(flange))
    return {name: (tuple(p), tuple(t)) for name, (p, t) in out.items()}


def cam_bore_radius(params, drivetrain) -> float:
    """The cam's bore radius (mm): the file's ``cam.bore_diameter`` when given, else E's shaft
    running hole where it leaves gearbox 2's roof (E's shaft turns inside the cam, which is
    fixed to gearbox 2); 0 (no bore) without a drivetrain and no value in the file."""
    if params.cam.bore_diameter is not None:
        return params.cam.bore_diameter / 2
    if drivetrain is not None:
        for shaft in drivetrain.shafts:
            if shaft.name == "E":
                for seat in shaft.seats:
                    if seat.wall == "roof" and seat.through and seat.hole_diameter > 0:
                        return seat.hole_diameter / 2
    return 0.0


def cam_screw_holes(drivetrain, turn: float) -> list:
    """``[((x, y), radius)]`` of the cam's screws' clearance holes in the cam's own frame (E at
    the origin, turned by ``turn`` from gearbox 2's): the bolt circle the cover's tapped holes
    are on, seen from the cam. Empty without the cam's fixing."""
    screwed = drivetrain.fixings.get("cam") if drivetrain is not None else None
    if not screwed:
        return []
    c, s = math.cos(-turn), math.sin(-turn)
    return [((c * x - s * y, s * x + c * y), screwed["clearance_hole"] / 2)
            for x, y in bolt_circle(screwed)]


def keyed_boss(plate, hub: dict, z0: float, segments: int):
    """``plate`` with a hub's boss (its outside, from ``z0`` up its length) at the origin and the
    bore with its keyway (or D-flat) through both, the keyway towards +x."""
    from cadgen.machine.hubs import hub_hole
    from cadgen.solids.extrude import extrude, manifold3d_engine

    m3d = manifold3d_engine()
    radius, length = hub["outside"] / 2, hub["length"]
    boss = m3d.Manifold.cylinder(length, radius, radius, segments).translate((0.0, 0.0, z0))
    hole = hub_hole(hub["diameter"], key=hub["key"], flat_depth=hub["flat_depth"],
                    bore_allowance=hub["bore_allowance"], segments=segments)
    bore = extrude(hole, length + 2.0, z0=z0 - 1.0, path="hub bore", outline_path="hub bore")
    return plate + boss - bore
