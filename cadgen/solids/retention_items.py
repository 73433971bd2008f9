"""What holds a part along its shaft, as bought solids: DIN 471 rings and hub set screws.

The axial stacks (:mod:`cadgen.machine.retention`) decide where each shaft has a retaining ring
and which hub is held by a set screw instead (a gear at a shaft's end, where no groove fits).
This module puts those items where they sit, in the made parts that hold them, from the same
records the grooves and the bill come from:

- a **ring** in each groove of a shaft (:func:`ring_items`), its bore on the groove's bottom
  (d2) and its lugs' reach (d4) round it, as thick as the ring (s), on the groove's flank the
  ring bears on, so it rides with its shaft;
- a **set screw** (:func:`set_screw_gears`) in a tapped hole drilled radially through the gear,
  on its keyway's centre line in the middle of its face, its cup point on the key's back (the
  key sits in the shaft's keyseat, so its back is ``t1`` below the shaft's surface plus the
  key's height from the axis). The hole is drilled from the outside, so it runs from the bore
  out through the rim; a screw that would stand proud of the gear fails the hub check
  (:func:`cadgen.machine.hubs.set_screw_clearance`).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from cadgen.solids.bought import BoughtItem, item_frame

__all__ = ["ring_items", "set_screw_gears", "radial_set_screw"]

#: mm the drilled hole runs past the outline, so the cut leaves no skin.
_DRILL_BEYOND = 1.0


def ring_items(shaft, retention, z_floor: float) -> list:
    """The DIN 471 rings of ``shaft``'s stack (``retention``, z from its housing's cavity floor,
    at ``z_floor`` in the body) as bought items of the shaft's part (its axis along z)."""
    if retention is None:
        return []
    from cadgen.machine.catalogue import shaft_ring

    items = []
    for ring in retention.rings:
        size = shaft_ring(shaft.diameter)
        # the stack puts the ring where it sits: on the groove's bottom (its bore, d2), from
        # z0 for its thickness s (the groove, m wide, is cut from the flank it bears on)
        items.append(BoughtItem(
            "retaining ring", ring.designation,
            {"inner": float(ring.bore), "outer": float(ring.outside), "thickness": size["s"]},
            item_frame((0.0, 0.0, z_floor + ring.z0)), f"ring-471-{float(shaft.diameter):g}"))
    return items


def radial_set_screw(designation: str, shaft_diameter: float, key, angle: float, centre,
                     z: float, reach: float, segments: int):
    """A set screw through a hub onto its key: ``(hole, item)``, the tap-drilled hole (a
    manifold from the axis out to ``reach`` + 1 mm along ``angle``, at height ``z``) and the
    screw, radial on the keyway's centre line, its cup point on the key's back."""
    from cadgen.machine.fixings import TAP_DRILL
    from cadgen.solids.bought_places import thread_depth
    from cadgen.solids.extrude import manifold3d_engine

    m3d = manifold3d_engine()
    from cadgen.machine.retention import set_screw_size

    thread, length = set_screw_size(designation)
    direction = np.array([math.cos(angle), math.sin(angle)])
    centre = np.asarray(centre, dtype=float)
    back = shaft_diameter / 2 - key.shaft_depth + key.height
    drill = TAP_DRILL[thread] / 2
    hole = (m3d.Manifold.cylinder(reach + _DRILL_BEYOND, drill, drill, segments)
            .rotate((0.0, 90.0, 0.0)).rotate((0.0, 0.0, math.degrees(angle)))
            .translate((centre[0], centre[1], z)))
    item = BoughtItem("set screw", designation, {"d": float(thread.removeprefix("M")),
                                                 "length": length, "point": "cup"},
                      item_frame((*(centre + back * direction), z), (*direction, 0.0)),
                      f"set-screw-{thread}x{length:g}", (), thread_depth(thread))
    return hole, item


def set_screw_gears(gear_parts, drivetrain, profiles, segments: int) -> list:
    """The gears held along their shafts by a set screw (the drivetrain's retention), each with
    its radial tapped hole cut and its screw as a bought item (:func:`radial_set_screw`).

    ``profiles``: ``{gear name: profile}`` (the keyway's direction and the bore's centre in the
    gear's frame). A gear met on two shafts' copies (both sides) is drilled once. A screw
    that would stand proud of its gear is the hub check's failure
    (:func:`cadgen.machine.hubs.set_screw_clearance`)."""
    by_stem = {part.name: k for k, part in enumerate(gear_parts)}
    parts = list(gear_parts)
    for held in getattr(drivetrain, "retention", ()) or ():
        for gear, designation in held.set_screws:
            stem = gear.replace(" ", "-")
            if stem not in by_stem or gear not in profiles:
                continue
            part = parts[by_stem[stem]]
            if any(item.kind == "set screw" for item in part.bought):
                continue   # a gear both sides' shafts carry: drilled once
            shaft, mount = drivetrain.shaft_of_gear(gear)
            if mount.key is None:
                continue
            profile = profiles[gear]
            centre = np.asarray(profile.centre, dtype=float)
            outline = np.asarray(profile.outline, dtype=float) - centre
            hole, screw = radial_set_screw(
                designation, shaft.diameter, mount.key,
                float(profile.notes.get("keyway_angle_rad", 0.0)), centre, mount.face_width / 2,
                float(np.max(np.hypot(outline[:, 0], outline[:, 1]))), segments)
            parts[by_stem[stem]] = dataclasses.replace(part, solid=part.solid - hole,
                                                       bought=part.bought + (screw,), _mesh=None)
    return parts
