"""The duckbill linkage's bought items where they sit: its clevis pins, the roller, the spring.

The linkage's joints buy them (:func:`cadgen.assembly.machine._duckbill_joints`, from the
drivetrain's ``fixings["duckbill"]``, :mod:`cadgen.machine.duckbill`); this module places each
as a :class:`~cadgen.solids.bought.BoughtItem` in the made part whose hole it is in, in that
part's frame (every linkage part is cut at rest in the planter's frame,
:mod:`cadgen.solids.duckbill`), from the same sizes and layers the holes were cut from:

- an ISO 2341 B clevis pin through each joint's plates (the pin's head on the first plate's
  outer face, its grip the joint's plates and gaps, the bill's length), the ISO 8738 washer on
  the last plate's outer face and the ISO 1234 split pin through the pin's hole ``l_e`` from its
  end (ISO 2341's rule, :func:`cadgen.machine.pins.clevis_pin_length`), its eye towards the
  side with room, its legs straight as they go in. The pin, its washer and its split pin are one
  stack. Host and fit, by the joint:

  ========  ===================  =====================================================
  joint     host (holds it)      through (fitted)
  ========  ===================  =====================================================
  H         planter-shell (lug)  the lever; head under the lever, in the gap above the cam
  G         lever                the push rod's collar slot (and the tube wall's slot,
                                 with room: no fit); head under the lever
  P2        push-rod (its eye)   both links
  J         blade (its crank)    its link; the head on the crank's face away from the link
  O1        planter-shell (ears) its blade's knuckle
  ========  ===================  =====================================================

- the cam roller: the 604-2Z bearing level with the cam (fitted to the cam it runs on), on the
  ISO 2338 pin pressed into the lever, the DIN 471 ring in the pin's groove under it (one stack);
- the return spring (EN 13906-1) round the push rod on the web, as long as it is installed (its
  computed installed length, the room between the web and the collar at rest): a rigid solid,
  so it is exact at rest and the overlap check meets it there (the assembly file's pose).

Every item rides with its host's copies, so the second arm's are the host's second copy.
Designations are the bill's (the fixing's ``items``), letter for letter.
"""

from __future__ import annotations

import numpy as np

from cadgen.solids.bought import BoughtItem, item_frame

__all__ = ["clevis_stack", "roller_items", "spring_item", "linkage_items", "split_pin_frame"]

_UP = np.array([0.0, 0.0, 1.0])
#: How far from normal to its pin (the cosine) a split pin's given direction may be: rounding only.
_NORMAL_ATOL = 1e-12


def _designation(entry: dict, kind: str) -> str:
    """The bill's designation of the item of ``kind`` a joint's pin ``entry`` is bought with."""
    return next(item["designation"] for item in entry["items"] if item["kind"] == kind)


def split_pin_frame(centre, axis, towards) -> np.ndarray:
    """The 4x4 frame of a split pin through a clevis pin's hole, its eye bearing on the pin's
    surface at ``centre`` (3,), the clevis pin along ``axis``: its own +z along ``towards``
    (normal to ``axis``: the eye's side), its +y along ``axis`` (the eye's thin side along the
    pin; :func:`cadgen.solids.bought_makers.split_pin`)."""
    z = np.asarray(towards, dtype=float)
    y = np.asarray(axis, dtype=float)
    if abs(float(z @ y)) > _NORMAL_ATOL or not np.isclose(np.linalg.norm(z), 1.0):
        raise ValueError(f"a split pin goes in across its pin: unit {towards!r} normal to {axis!r}")
    frame = np.eye(4)
    frame[:3, :3] = np.column_stack([np.cross(y, z), y, z])
    frame[:3, 3] = np.asarray(centre, dtype=float)
    return frame


def clevis_stack(entry: dict, xy, head_face: float, direction: int, towards, fitted=(),
                 stack: str = "") -> list:
    """An ISO 2341 B pin, its ISO 8738 washer and ISO 1234 split pin through plates along z.

    Parameters
    ----------
    entry : dict
        The joint's pin (:func:`cadgen.machine.duckbill._pin_entry`): ``d``, ``grip``, ``length``,
        ``head_diameter``, ``head_height``, ``washer_outside``, ``washer_thickness``, ``items``.
    xy : (2,) float
        The pin's axis in the host's frame (mm).
    head_face : float
        z (mm) of the first plate's outer face, where the head bears.
    direction : +1 or -1
        The way the shank goes from the head: +z or -z; the washer bears ``grip`` further on.
    towards : (2,) float
        The split pin's eye's side, a unit vector in the plane (its legs go the other way).
    """
    from cadgen.machine.pins import clevis_pin_length, split_pin

    if direction not in (1, -1):
        raise ValueError(f"a pin's shank goes up (+1) or down (-1), not {direction!r}")
    d, grip = float(entry["d"]), float(entry["grip"])
    pin = clevis_pin_length(d, grip)
    split = split_pin(pin["split_pin"])
    length = float(entry["length"])
    x, y = (float(v) for v in xy)
    along = direction * _UP
    washer_z = head_face + direction * grip
    # the washer's ring is z 0..h in its frame: under the face when the shank goes down
    washer_at = washer_z if direction > 0 else washer_z - entry["washer_thickness"]
    hole = np.array([x, y, head_face + direction * (length - pin["hole_end"])])
    label = f"{d:g}x{length:g}"
    return [
        BoughtItem("clevis pin", _designation(entry, "clevis pin"),
                   {"d": d, "length": length, "head_diameter": entry["head_diameter"],
                    "head_height": entry["head_height"]},
                   item_frame((x, y, head_face), -along), f"clevis-pin-{label}", fitted,
                   stack=stack),
        BoughtItem("washer", _designation(entry, "washer"),
                   {"d1": d, "d2": entry["washer_outside"], "h": entry["washer_thickness"]},
                   item_frame((x, y, washer_at)), f"washer-8738-{d:g}", fitted, stack=stack),
        BoughtItem("split pin", _designation(entry, "split pin"),
                   {"d": split["d_max"], "c": split["c_max"], "length": pin["split_length"]},
                   split_pin_frame(hole + d / 2 * np.array([*towards, 0.0]), _UP,
                                   (*towards, 0.0)),
                   f"split-pin-{pin['split_pin']:g}x{pin['split_length']:g}", fitted,
                   stack=stack),
    ]


def roller_items(fixing: dict, cam_bottom: float, lever_top: float) -> list:
    """The cam roller in the lever's frame: the bearing at I level with the cam's top face, its
    ISO 2338 pin from the lever's top face down (pressed into the lever), the DIN 471 ring
    in the pin's groove under the bearing."""
    from cadgen.machine.pins import retaining_ring

    roller = fixing["roller"]
    x, y = (float(v) for v in fixing["points"]["I"])
    ring = retaining_ring(roller["d"])
    bottom = cam_bottom + roller["bottom"]
    stack, length = "roller@I", float(roller["pin_length"])
    return [
        BoughtItem("bearing", roller["designation"],
                   {"bore": roller["d"], "outside": roller["D"], "width": roller["B"]},
                   item_frame((x, y, bottom)), f"bearing-{roller['designation']}-2Z", ("cam",),
                   stack=stack),
        BoughtItem("parallel pin", roller["pin"], {"diameter": roller["d"], "length": length},
                   item_frame((x, y, lever_top - length)),
                   f"parallel-pin-{roller['d']:g}x{length:g}", stack=stack),
        # in its groove (d2), as far out as the fitted ring needs (d4): its envelope
        BoughtItem("retaining ring", ring["designation"],
                   {"inner": ring["groove"], "outer": ring["ring_outside"],
                    "thickness": ring["thickness"]},
                   item_frame((x, y, bottom - ring["thickness"])), f"ring-471-{roller['d']:g}",
                   stack=stack),
    ]


def spring_item(fixing: dict, tube_axis: float) -> BoughtItem:
    """The return spring on the web's top face, round the rod on the duckbill axis, up to the
    collar at rest: its coil's envelope (outside D + d, one wire thick) as long as installed."""
    spring, web = fixing["spring"], fixing["web"]
    seat = web["bottom"] + web["thickness"]
    return BoughtItem("compression spring", fixing["spring_items"][0]["designation"],
                      {"outside": spring["outside_diameter"], "wire": spring["wire"],
                       "length": spring["installed_length"]},
                      item_frame((-fixing["L1"], seat, tube_axis), (0.0, 1.0, 0.0)),
                      f"spring-{spring['wire']:g}x{spring['mean_diameter']:.1f}",
                      ("push-rod",))


def linkage_items(fixing: dict, layout) -> dict:
    """``{made part: [BoughtItem, ...]}``: every bought item of one arm's linkage in the part that
    holds it (module notes), from the fixing's sizes and the layout's layers (mm)."""
    from cadgen.solids.duckbill import _hinges

    points, pins = fixing["points"], fixing["pins"]
    axis = float(layout.tube_axis)
    lever_bottom = float(layout.lever_bottom)
    lever_top = lever_bottom + fixing["lever"]["thickness"]
    crank_half = fixing["crank"]["thickness"] / 2
    hinge = fixing["hinge"]
    ears = hinge["ear_from"] + hinge["ear_thickness"]
    link_far = fixing["link"]["z"][1]
    # the heads under the lever (G's below it too: the tube is above); H's split pin off the
    # plate's lug along it, G's across the tube inside it
    shell = clevis_stack(pins["H"], points["H"], lever_bottom, 1, (0.0, 1.0), ("lever",),
                         "pin@H")
    lever = (clevis_stack(pins["G"], points["G"], lever_bottom, 1, (1.0, 0.0), ("push-rod",),
                          "pin@G")
             + roller_items(fixing, float(layout.cam_bottom), lever_top))
    rod = clevis_stack(pins["P2"], points["P2"], axis - link_far, 1, (1.0, 0.0),
                       ("blade-link-right", "blade-link-left"), "pin@P2")
    items = {"planter-shell": shell, "lever": lever, "push-rod": rod}
    # each blade's hinge O1 and crank pin J where their holes are cut (the left ones mirrored)
    for side, (o1, j) in _hinges(fixing).items():
        sign = 1 if side == "right" else -1
        # the eyes inwards (towards the duckbill axis), the legs outwards into the room
        inwards = (-float(sign), 0.0)
        items["planter-shell"] += clevis_stack(pins["O1"], o1, axis - ears, 1, inwards,
                                               (f"blade-{side}",), f"pin@O1-{side}")
        # each link lies on its own side of the crank: the head on the crank's other face
        items[f"blade-{side}"] = clevis_stack(pins["J"], j, axis - sign * crank_half, sign,
                                              inwards, (f"blade-link-{side}",), f"pin@J-{side}")
    if fixing.get("spring"):
        items["planter-shell"].append(spring_item(fixing, axis))
    return items
