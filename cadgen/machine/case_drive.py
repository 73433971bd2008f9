"""What holds the pricking mechanism's sun to the frame and drives its gear case: numbers only.

The sun gear does not turn: its shaft's stub, below the gear case's floor, is keyed into
the bore of a frame bracket (a boss on a plate with the transplanter's mounting holes). The
gear case turns on that shaft in its own bearings and is driven by a chain sprocket bolted to
its floor, round the bracket's boss: the transplanter's chain turns it at the carrier speed.

Sprocket: ISO 606 roller chain 08B-1 (pitch 12.7 mm, roller 8.51 mm), a plate wheel whose
tooth count is the least at or above ``SPROCKET_MIN_TEETH`` that leaves its root circle
room for the bolt circle round its bore: pitch diameter ``p / sin(180 deg / z)``, root
``pitch - d1``, tip ``p (0.6 + cot(180 deg / z))`` (ISO 606's largest tip).
"""

from __future__ import annotations

import math

from cadgen.machine.catalogue import clearance_hole

__all__ = ["case_drive", "pricking_case_drive", "CHAIN", "SPROCKET_MIN_TEETH", "BRACKET_PLATE", "MOUNT_BOLT"]

#: ISO 606 roller chain 08B-1: pitch p, roller diameter d1, inner width b1, sprocket width.
CHAIN = {"designation": "08B-1", "pitch": 12.7, "roller": 8.51, "inner_width": 7.75,
         "sprocket_width": 7.2}
#: Fewest sprocket teeth (ISO 606 recommends 17 and more for smooth running).
SPROCKET_MIN_TEETH = 17
#: The bracket's plate: thickness (mm) and margin beyond the boss in boss diameters.
BRACKET_PLATE = {"thickness": 12.0, "width_bosses": 3.0}
#: The bracket's mounting to the transplanter: clearance holes for 4 screws of this size.
MOUNT_BOLT = "M8"
#: The sprocket's screws into tapped holes of the case's floor.
SPROCKET_BOLT, SPROCKET_BOLTS = "M5", 4


def _sprocket(teeth: int) -> dict:
    p, d1 = CHAIN["pitch"], CHAIN["roller"]
    half = math.pi / teeth
    pitch = p / math.sin(half)
    return {"teeth": teeth, "pitch_diameter": pitch, "root_diameter": pitch - d1,
            "tip_diameter": p * (0.6 + 1.0 / math.tan(half))}


def case_drive(sun_diameter: float, hub_depth: float, stub: float, case_torque_nmm: float,
               carrier_rpm: float, gap: float) -> dict:
    """The bracket holding the sun's stub and the sprocket driving the case.

    ``sun_diameter`` and its coupling key's hub depth ``t2`` size the bracket's boss (bore
    ``d``, keyway, and 6 mm of wall beyond it); the sprocket's bore clears the boss by
    ``2 gap``; its screws stand on a circle 1.5 screw diameters outside the bore, and its root
    circle 1.5 screw diameters outside them. Returns a JSON-ready dict (mm, N m, r/min)."""
    boss = sun_diameter + 2 * hub_depth + 12.0
    bore = boss + 2 * gap
    screw = float(SPROCKET_BOLT.removeprefix("M"))
    bolt_circle = bore / 2 + 1.5 * screw
    teeth = SPROCKET_MIN_TEETH
    while _sprocket(teeth)["root_diameter"] / 2 < bolt_circle + 1.5 * screw:
        teeth += 1
    sprocket = _sprocket(teeth)
    chain_pull = case_torque_nmm / (sprocket["pitch_diameter"] / 2)
    plate = BRACKET_PLATE["width_bosses"] * boss
    mount = float(MOUNT_BOLT.removeprefix("M"))
    holes = plate / 2 - 1.5 * mount   # the mounting holes' offset from the axis, each way
    return {
        "rule": "sun stub keyed into the bracket's boss; the case driven by an ISO 606 "
                f"{CHAIN['designation']} chain on a plate-wheel sprocket bolted to its floor",
        "chain": dict(CHAIN),
        "sprocket": {**sprocket, "bore": bore, "width": CHAIN["sprocket_width"],
                     "bolt": SPROCKET_BOLT, "bolts": SPROCKET_BOLTS,
                     "bolt_circle_radius": bolt_circle, "bolt_phase": math.pi / 4, "speed_rpm": float(carrier_rpm),
                     "torque_nm": case_torque_nmm / 1000.0, "chain_pull_n": chain_pull},
        "bracket": {"boss_diameter": boss, "boss_length": stub - BRACKET_PLATE["thickness"]
                    - gap, "plate": plate, "plate_thickness": BRACKET_PLATE["thickness"],
                    "bore": sun_diameter, "mount_bolt": MOUNT_BOLT,
                    "mount_hole": clearance_hole(MOUNT_BOLT, "medium"),
                    "mount_holes": [(sx * holes, sy * holes) for sx, sy in
                                    ((1, 1), (-1, 1), (-1, -1), (1, -1))]},
    }


def pricking_case_drive(params, design, shafts, loads) -> tuple:
    """The bracket holding the sun's stub and the sprocket driving the gear case
    (:func:`cadgen.machine.case_drive.case_drive`), and its screws' check. The case's torque:
    the moments about O on it, the sun's reaction and the tool's load at its largest reach,
    ``T_case = T_sun + F (2 a + l)``."""
    from cadgen.machine.fastening import flange_problems
    from cadgen.machine.loads import design_load

    sun = next(s for s in shafts if s.name == "sun")
    if sun.coupling_key is None:
        return None, []
    link = design.linkage
    torque = loads["sun"].torque_nmm + design_load(params.machine) * (2 * link.a + link.l)
    held = case_drive(sun.diameter, sun.coupling_key.hub_depth, sun.extends_below, torque,
                      params.field.carrier_speed_rpm, params.housing.axial_gap)
    screws = dict(held["sprocket"])
    found = flange_problems("the gear case", "its sprocket", torque, screws)
    held["sprocket"].update({k: screws[k] for k in ("stress_area_mm2", "bolt_shear_mpa",
                                                    "bolt_shear_allow_mpa")})
    return held, found
