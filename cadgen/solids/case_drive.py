"""The solids that hold the pricking mechanism's sun to the frame and drive its gear case.

From the drivetrain's ``case_drive`` record (:mod:`cadgen.machine.case_drive`): the frame
bracket (a plate with the transplanter's mounting holes and a boss whose keyed bore takes the
sun shaft's stub; fixed, body ``frame``) and the chain sprocket bolted to the case's floor
(a bought plate wheel, shown as its tip-circle envelope with its bore and screw holes; body
``case``). Both are centred on the sun's axis, below the case's floor.
"""

from __future__ import annotations

import math

import numpy as np

from cadgen.machine.catalogue import clearance_hole
from cadgen.machine.fastening import bolt_circle
from cadgen.solids.parts import Part, planar_transform

__all__ = ["case_drive_parts", "sprocket_tapped_holes"]


def sprocket_tapped_holes(held: dict, centre, floor_wall: float) -> tuple:
    """The tapped holes of the sprocket's screws in the case's floor, for
    :func:`~cadgen.solids.split_housing.split_housing` (two screw diameters deep, at most the
    floor less 2 mm)."""
    from cadgen.machine.fixings import TAP_DRILL

    sprocket = held["sprocket"]
    size = float(sprocket["bolt"].removeprefix("M"))
    depth = min(2.0 * size, floor_wall - 2.0)
    drill = TAP_DRILL[sprocket["bolt"]]
    return tuple((float(x), float(y), drill, depth, "floor")
                 for x, y in bolt_circle(sprocket, tuple(centre)))


def case_drive_parts(held: dict, sun_shaft, sun_part, centre, floor_wall: float, gap: float,
                     segments: int) -> list:
    """``[frame-bracket, case-sprocket]``: the bracket round the sun's stub, its keyway under the
    stub's keyseat (the sun shaft does not turn in the world), and the sprocket."""
    from cadgen.machine.hubs import hub_hole
    from cadgen.solids.extrude import extrude
    from cadgen.solids.outline import circle

    bracket, sprocket = held["bracket"], held["sprocket"]
    centre = np.asarray(centre, dtype=float)
    stub_bottom = -floor_wall - sun_shaft.extends_below
    # the stub's keyseat points along the shaft's x: in the world, where the shaft's frame is
    # at the start (the shaft stays put: its sun is fixed to the frame)
    pose = sun_part.local(0.0)
    keyway = math.atan2(pose[1, 0], pose[0, 0])
    bore = hub_hole(sun_shaft.diameter, key=sun_shaft.coupling_key, angle=keyway,
                    segments=segments) + centre
    half = bracket["plate"] / 2
    square = np.array([[-half, -half], [half, -half], [half, half], [-half, half]]) + centre
    mounts = [circle(bracket["mount_hole"] / 2, segments, tuple(centre + np.asarray(xy)))
              for xy in bracket["mount_holes"]]
    plate = extrude(square, bracket["plate_thickness"], holes=[bore, *mounts], z0=stub_bottom,
                    path="case_drive.bracket")
    boss_bottom = stub_bottom + bracket["plate_thickness"]
    boss = extrude(circle(bracket["boss_diameter"] / 2, segments, tuple(centre)),
                   bracket["boss_length"], holes=[bore], z0=boss_bottom,
                   path="case_drive.bracket")
    held_by = ()
    if sun_shaft.coupling_key is not None:   # the set screw through the boss onto the key
        from cadgen.machine.retention import set_screw
        from cadgen.solids.retention_items import radial_set_screw

        hole, screw = radial_set_screw(set_screw(sun_shaft.coupling_key), sun_shaft.diameter,
                                       sun_shaft.coupling_key, keyway, centre,
                                       boss_bottom + bracket["boss_length"] / 2,
                                       bracket["boss_diameter"] / 2, segments)
        boss, held_by = boss - hole, (screw,)
    # the screws' clearance holes (ISO 273 medium), where the case's tapped holes are
    hole = clearance_hole(sprocket["bolt"], "medium")
    screws = [circle(hole / 2, 24, (float(x), float(y)))
              for x, y in bolt_circle(sprocket, tuple(centre))]
    wheel = extrude(circle(sprocket["tip_diameter"] / 2, segments, tuple(centre)),
                    sprocket["width"],
                    holes=[circle(sprocket["bore"] / 2, segments, tuple(centre)), *screws],
                    z0=-floor_wall - sprocket["width"], path="case_drive.sprocket")
    fixed = planar_transform(0.0)
    # the sprocket is bought whole (its bill row's designation): its screws go up from under
    # it into the case floor's tapped holes
    from cadgen.assembly.items import sprocket_items
    from cadgen.solids.bought import BoughtPart
    from cadgen.solids.bought_places import tapped_screws

    screws = tapped_screws(sprocket["bolt"], None, bolt_circle(sprocket, tuple(centre)),
                           -floor_wall - sprocket["width"], up=True, clamped=sprocket["width"],
                           fitted=("gear-case-base",))
    return [Part("frame-bracket", "housing", "frame", plate + boss, lambda angle: fixed,
                 bought=held_by),
            BoughtPart("case-sprocket", "sprocket", "case", wheel, lambda angle: fixed,
                       bought=tuple(screws), designation=sprocket_items(held)[0].designation)]
