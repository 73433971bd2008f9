"""Where each bought item sits, from the records that cut its seat or hole.

Each function turns one record the solids already cut a feature from into the
:class:`~cadgen.solids.bought.BoughtItem` placements of what goes into that feature, in the
frame of the part that holds them; the part lists them in its ``bought`` (see
:mod:`cadgen.solids.bought`):

- a split housing (:class:`~cadgen.solids.split_housing.SplitHousing`): a bearing in each seat
  (its ``count`` side by side, from the seat's cavity face outwards), a bolt through each flange
  hole with its two washers and nut, the two dowels in their reamed holes, and a printed
  housing's splice bolts across each cut;
- a shaft (:func:`~cadgen.solids.machine_parts.shaft_part`): a key in each keyseat, the two
  bearings a free gear runs on, a hollow shaft's flange screws into the tapped holes of the
  housing it carries;
- the plates screwed on (the cam, the pricking case's sprocket): their screws into tapped holes;
- the pricking needle's holder: its set screw.

Designations come from the functions that make the bill's rows (:mod:`cadgen.assembly.items`),
sizes from the catalogue (:mod:`cadgen.machine.catalogue`), so a placed solid and its bill row
cannot drift apart. A flange bolt's head is on the cover's side, its nut under the base's
flange; a screw into a tapped hole has its head on the plate it holds.
"""

from __future__ import annotations

import numpy as np

from cadgen.solids.bought import BoughtItem, item_frame

__all__ = ["housing_items", "bolt_stack", "splice_items", "seat_bearings", "flange_bolts",
           "dowels", "tapped_screws", "key_item", "bearing_pair", "set_screw_item",
           "thread_depth"]

_UP, _DOWN = (0.0, 0.0, 1.0), (0.0, 0.0, -1.0)


def thread_depth(thread: str) -> float:
    """How far (mm, radial) a screw's nominal cylinder reaches into the material round its tapped
    hole: half the difference of its nominal and tap-drill diameters (ISO 2306 drills). The
    thread's flanks fill that shell; the overlap check allows a screw that much."""
    from cadgen.machine.fixings import TAP_DRILL

    return (float(thread.removeprefix("M")) - TAP_DRILL[thread]) / 2


def _screw_size(thread: str, length: float) -> dict:
    from cadgen.machine.catalogue import socket_screw

    screw = socket_screw(thread)
    return {"d": float(thread.removeprefix("M")), "length": float(length),
            "head_diameter": screw["head_diameter"], "head_height": screw["head_height"]}


def bolt_stack(frame, head_face: float, nut_face: float, thread: str, grip: float,
               fitted=()) -> list:
    """A through bolt, its washers and its nut, clamping the faces ``nut_face`` < ``head_face``
    (mm along the bolt's axis, +z of ``frame``, a 4x4 in the host's frame): a washer on each
    face, the ISO 4762 screw's head on the upper washer, the ISO 4032 nut under the lower.

    ``grip`` is what the bill sized the screw for (:func:`cadgen.assembly.items.bolt_set`), so
    the screw is the bill's; the faces are where the holes end.
    """
    from cadgen.assembly.items import bolt_set
    from cadgen.machine.catalogue import nut, washer

    names = bolt_set(thread, grip)
    washer_row, nut_row = washer(thread), nut(thread)
    h, m = washer_row["h"], nut_row["m"]
    frame = np.asarray(frame, dtype=float)

    def at(z):
        return frame @ item_frame((0.0, 0.0, z))

    washer_size = {"d1": washer_row["d1"], "d2": washer_row["d2"], "h": h}
    stack = "bolt@" + ",".join(f"{v:.6f}" for v in frame[:3, 3])
    return [
        BoughtItem("plain washer", names["washer"], washer_size, at(head_face),
                   f"washer-{thread}", fitted, stack=stack),
        BoughtItem("socket head cap screw", names["screw"],
                   _screw_size(thread, names["screw_length"]), at(head_face + h),
                   f"screw-{thread}x{names['screw_length']:g}", fitted, stack=stack),
        BoughtItem("plain washer", names["washer"], washer_size, at(nut_face - h),
                   f"washer-{thread}", fitted, stack=stack),
        BoughtItem("hexagon nut", names["nut"],
                   {"d": float(thread.removeprefix("M")), "s": nut_row["s"], "m": m},
                   at(nut_face - h - m), f"nut-{thread}", fitted, stack=stack),
    ]


def seat_bearings(housing, fitted=()) -> list:
    """The bearings in a housing's seats: each seat's ``count`` side by side, from the cavity's
    end face into the wall (a floor seat downwards, a roof seat upwards), coaxial with it."""
    from cadgen.assembly.items import bearing_item

    items = []
    top = housing.z_cavity_bottom + housing.cavity_height
    for seat in housing.seats:
        bearing = seat.bearing
        width = float(bearing.width)
        count = int(getattr(seat, "count", 1))
        first = housing.z_cavity_bottom - count * width if seat.wall == "floor" else top
        designation = bearing_item(bearing, 1).designation
        stack = f"seat@{seat.shaft}-{seat.side}-{seat.wall}"
        for k in range(count):
            items.append(BoughtItem(
                "bearing", designation,
                {"bore": bearing.bore, "outside": bearing.outside, "width": width},
                item_frame((*seat.xy, first + k * width)), f"bearing-{designation}-2Z",
                tuple(fitted) + (f"shaft-{seat.shaft}",), stack=stack))
    return items


def flange_bolts(housing, fitted=()) -> list:
    """A bolt set through each of a split housing's flange holes: head and washer on the cover's
    flange, washer and nut under the base's (sized for the bill's grip, both flange halves)."""
    low, high = housing.flange_z
    grip = 2 * float(housing.flange_thickness)
    items = []
    for x, y in np.asarray(housing.bolt_positions, dtype=float):
        items += bolt_stack(item_frame((float(x), float(y), 0.0)), high, low, housing.bolt_size,
                            grip, fitted)
    return items


def dowels(housing, fitted=()) -> list:
    """The ISO 8734 dowels in their reamed holes, across the parting plane (half in each half,
    kept within the flange), their polygon the hole's."""
    from cadgen.assembly.items import dowel_items
    from cadgen.machine.fixings import dowel_pins
    from cadgen.solids.split_housing import TAPPED_SEGMENTS

    if not getattr(housing, "dowels", ()):
        return []
    low, high = housing.flange_z
    pins = dowel_pins(housing.bolt_size, high - low)
    designation = dowel_items(housing)[0].designation
    length = pins["length"]
    bottom = min(max(housing.parting_z - length / 2, low), high - length)
    return [BoughtItem("dowel pin", designation,
                       {"diameter": diameter, "length": length, "sides": TAPPED_SEGMENTS},
                       item_frame((x, y, bottom)), f"dowel-{diameter:g}x{length:g}", fitted)
            for x, y, diameter in housing.dowels]


def splice_items(joints, fitted=()) -> list:
    """The bolt sets across a printed housing's splices (each bolt's axis along the cut's
    normal, the lugs' faces half the grip either side of the cut plane)."""
    items = []
    for joint in joints:
        grip = float(joint.grip)
        for centre in np.asarray(joint.bolts, dtype=float):
            items += bolt_stack(item_frame(centre, _axis3(joint.axis)), grip / 2, -grip / 2,
                                joint.bolt_size, grip, fitted)
    return items


def _axis3(axis) -> np.ndarray:
    """A splice's bolt axis (the cut's normal, in the plane) as a 3-vector."""
    axis = np.asarray(axis, dtype=float).ravel()
    return axis if axis.size == 3 else np.array([axis[0], axis[1], 0.0])


def housing_items(name: str, housing, joints=()) -> list:
    """Every bought item a split housing ``name`` holds (its seats' bearings, flange bolts,
    dowels, splice bolts), fitted to its halves (and each bearing to its shaft)."""
    halves = (f"{name}-base", f"{name}-cover")
    return (seat_bearings(housing, halves) + flange_bolts(housing, halves)
            + dowels(housing, halves) + splice_items(joints, halves))


def tapped_screws(thread: str, length: float | None, positions, head_face: float, up: bool,
                  clamped: float = 0.0, fitted=()) -> list:
    """ISO 4762 screws at ``positions`` (x, y) through a plate into tapped holes: the head's
    bearing face at ``head_face``, the shank going down (``up`` False: the head above) or up
    (``up``: the head below, the screw put in from underneath). The bill's screw
    (:func:`cadgen.assembly.items.screw_items` with ``clamped`` and ``length`` as the bill was
    given them: ``length`` None is its rule, the shortest standard length through the plate
    and :data:`~cadgen.machine.fixings.ENGAGEMENT` diameters into the thread); the thread's
    depth allowed where the screw is fitted."""
    from cadgen.assembly.items import screw_items

    if length is None:
        from cadgen.machine.catalogue import screw_length
        from cadgen.machine.fixings import ENGAGEMENT

        length = screw_length(thread, float(clamped)
                              + ENGAGEMENT * float(thread.removeprefix("M")))
    designation = screw_items(thread, clamped, 1, length=length)[0].designation
    size = _screw_size(thread, length)
    return [BoughtItem("socket head cap screw", designation, size,
                       item_frame((float(x), float(y), head_face), _DOWN if up else _UP),
                       f"screw-{thread}x{float(length):g}", fitted, thread_depth(thread))
            for x, y in positions]


def key_item(key, z_from: float, angle: float, shaft_radius: float, fitted=()) -> BoughtItem:
    """A DIN 6885 key in the keyseat of a shaft of ``shaft_radius`` cut ``key.shaft_depth``
    deep towards ``angle`` (rad, in the shaft's frame), from ``z_from`` its length up."""
    from cadgen.assembly.items import key_item as bill_key

    radial = float(shaft_radius) - float(key.shaft_depth)
    origin = (radial * np.cos(angle), radial * np.sin(angle), float(z_from))
    return BoughtItem("key", bill_key(key).designation,
                      {"width": key.width, "height": key.height, "length": key.length},
                      item_frame(origin, _UP, angle),
                      f"key-{key.width:g}x{key.height:g}x{key.length:g}", fitted)


def bearing_pair(bearing, z_middle: float, fitted=()) -> list:
    """The two bearings a free gear runs on, side by side in its hub, centred on ``z_middle``
    (its face's middle) on the shaft's axis."""
    from cadgen.assembly.items import bearing_item

    designation = bearing_item(bearing, 2).designation
    width = float(bearing.width)
    return [BoughtItem("bearing", designation,
                       {"bore": bearing.bore, "outside": bearing.outside, "width": width},
                       item_frame((0.0, 0.0, z_middle - width + k * width)),
                       f"bearing-{designation}-2Z", fitted, stack=f"pair@{z_middle:.6f}")
            for k in range(2)]


def set_screw_item(clamp: dict, x: float, axis_z: float, fitted=()) -> BoughtItem:
    """The needle clamp's ISO 4027 set screw (:func:`cadgen.machine.fixings.needle_clamp`), in
    its tapped hole down through the holder's wall, its point on the bore."""
    thread, length = clamp["thread"], float(clamp["screw_length"])
    return BoughtItem("set screw", clamp["set_screw"],
                      {"d": float(thread.removeprefix("M")), "length": length},
                      item_frame((float(x), 0.0, float(axis_z) + clamp["bore"] / 2)),
                      f"set-screw-{thread}x{length:g}", fitted, thread_depth(thread))
