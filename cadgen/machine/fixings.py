"""How the arms' parts are fixed to what carries them: a keyed hub on a shaft, a plate screwed to a
housing, a needle clamped in its holder.

- :func:`keyed_hub`: the planter on shaft E, the pricking rocker on the planet shaft. A DIN 6885
  form-A key in a hub boss: the shortest standard key whose flank pressure under the joint's
  torque stays within ``machine.key_pressure_mpa``, never shorter than the longest that fits the
  plate itself; the hub is that key plus a chamfer at each end, at least the plate's thickness.
- :func:`screwed_plate`: the cam on gearbox 2's cover. ISO 4762 screws sunk in DIN 974-1
  counterbores of the cam (the planter turns 2 mm above its face), into tapped holes of the
  cover's roof, on the smallest circle that clears the roof's bearing seat.
- :func:`needle_clamp`: the pricking needle in a holder at the rocker's end, held by an ISO 4027
  set screw (the needle's reach can be set by sliding it before tightening).

Each rule gives the fixing's sizes (a plain dict for the report and the solids) and the problems
of its check (:class:`kinematics.errors.Problem`). Numbers only: the solids cut what they say.
"""

from __future__ import annotations

import math

from kinematics.errors import Problem

from cadgen.machine.catalogue import (CatalogueError, clearance_hole, key_lengths, screw_length,
                                     socket_screw)
from cadgen.machine.fastening import flange_problems
from cadgen.machine.shafts import KEYLESS_BELOW, FLAT_DEPTH_RATIO, key_for_shaft, key_pressure

__all__ = ["keyed_hub", "screwed_plate", "needle_clamp", "arm_fixings", "fixings_report",
           "dowel_pins", "seat_misalignment", "BEARING_MISALIGNMENT_ARCMIN", "TAP_DRILL",
           "COUNTERBORE", "cam_bore_problems",
           "HUB_CHAMFER", "HUB_OUTSIDE_RATIO", "HUB_LENGTH_MAX_RATIO"]

#: Tap drill diameters for coarse threads, ISO 2306 (mm).
TAP_DRILL = {"M3": 2.5, "M4": 3.3, "M5": 4.2, "M6": 5.0, "M8": 6.8}
#: DIN 974-1 counterbore diameters for ISO 4762 heads (medium clearance holes), mm; the depth is
#: the head's height plus 0.4 mm.
COUNTERBORE = {"M3": 6.5, "M4": 8.0, "M5": 10.0, "M6": 11.0}
COUNTERBORE_EXTRA_DEPTH = 0.4
#: ISO 4027 set screws (hexagon socket, cone point): standard lengths (mm).
SET_SCREW_LENGTHS = {"M3": (3, 4, 5, 6, 8, 10, 12), "M4": (4, 5, 6, 8, 10, 12, 16, 20),
                     "M5": (5, 6, 8, 10, 12, 16, 20, 25)}
#: A keyed hub's chamfer at each end (mm): the key is no longer than the hub less both.
HUB_CHAMFER = 1.0
#: A hub boss's outside diameter in shaft diameters: the usual 1.8 to 2 d of a keyed steel or
#: aluminium hub (Roloff/Matek), the upper end.
HUB_OUTSIDE_RATIO = 2.0
#: The longest hub (in shaft diameters) a fixing may grow to before its key is reported overloaded.
HUB_LENGTH_MAX_RATIO = 2.5
#: Least wall (mm) between a tapped hole and a bearing seat or an edge.
WALL_MIN = 2.0
#: The needle's slide in its holder beyond the process's hub allowance (mm, diametral).
NEEDLE_SLIDE = 0.05
#: The screws a plate may take, smallest first, and how many.
PLATE_THREADS, PLATE_SCREWS = ("M3", "M4", "M5"), 3
#: A screw's thread engages this many diameters in an aluminium housing's tapped hole.
ENGAGEMENT = 1.5


def keyed_hub(part: str, shaft: str, d: float, torque_nmm: float, min_length: float,
              allowed_mpa: float, bore_allowance: float, path: str) -> tuple[dict, list]:
    """The keyed hub fixing ``part`` to ``shaft`` (diameter ``d``) against ``torque_nmm``.

    ``min_length``: the plate the hub grows from (the hub is never shorter). Below 10 mm a
    D-flat (no key, no pressure check: said so). Returns ``(hub, problems)``; ``hub`` has
    ``part``, ``shaft``, ``diameter``, ``length``, ``outside``, ``key`` (a KeySize or None),
    ``flat_depth``, ``bore_allowance``, ``torque_nm``, ``pressure_mpa`` (None unchecked),
    ``allowed_mpa``.
    """
    d, torque = float(d), float(torque_nmm)
    hub = {"part": part, "shaft": shaft, "diameter": d, "outside": HUB_OUTSIDE_RATIO * d,
           "bore_allowance": float(bore_allowance), "torque_nm": torque / 1000.0,
           "allowed_mpa": float(allowed_mpa), "key": None, "flat_depth": 0.0,
           "length": float(min_length), "pressure_mpa": None}
    if d < KEYLESS_BELOW:
        hub["flat_depth"] = FLAT_DEPTH_RATIO * d
        return hub, []
    longest = HUB_LENGTH_MAX_RATIO * d
    fits_plate = [n for n in key_lengths() if n <= min_length - 2 * HUB_CHAMFER + 1e-9]
    candidates = [n for n in key_lengths() if n <= max(longest, min_length) - 2 * HUB_CHAMFER]
    if not candidates:
        return hub, [Problem(path, "hub_without_key",
                             f"the hub of the {part} on the {d:g} mm shaft {shaft} takes no key "
                             f"within {longest:g} mm")]
    try:
        keys = [key_for_shaft(d, n) for n in candidates]
    except CatalogueError as error:
        return hub, [Problem(path, "hub_without_key",
                             f"the hub of the {part} on shaft {shaft} takes no key: {error}")]
    passing = [k for k in keys if key_pressure(torque, d, k) <= allowed_mpa]
    floor = fits_plate[-1] if fits_plate else 0.0
    key = (max(passing[0], key_for_shaft(d, floor), key=lambda k: k.length) if passing
           else keys[-1])
    pressure = key_pressure(torque, d, key)
    hub.update(key=key, length=max(float(min_length), key.length + 2 * HUB_CHAMFER),
               pressure_mpa=pressure)
    if passing:
        return hub, []
    return hub, [Problem(path, "key_overloaded",
                         f"the key of the {part} on shaft {shaft} ({key.designation}, the longest "
                         f"its {hub['length']:g} mm hub takes) carries {torque / 1000:.1f} N m at "
                         f"{pressure:.0f} MPa, above machine.key_pressure_mpa = {allowed_mpa:g} MPa:"
                         " give the shaft a larger diameter (machine.shafts) or lower the design "
                         "load (machine.tip_load_n, machine.service_factor)")]


def screwed_plate(part: str, carries: str, seat_radius: float, thickness: float,
                  torque_nmm: float, tapped_depth: float, path: str, *,
                  hole_series: str = "medium", hole_extra: float = 0.0) -> tuple[dict, list]:
    """``part`` (a plate of ``thickness``) screwed onto ``carries`` round a bearing seat.

    The smallest thread of :data:`PLATE_THREADS` whose sunk head leaves at least 0.8 d of plate
    under it, :data:`PLATE_SCREWS` of them on the smallest circle whose tapped holes keep
    :data:`WALL_MIN` from the seat (``seat_radius``), their shear under ``torque_nmm`` checked
    as the carrying flanges' are (:func:`cadgen.machine.fastening.flange_problems`).
    ``tapped_depth``: how deep the housing's wall can be tapped; ``hole_series`` and
    ``hole_extra``: the process's ISO 273 clearance holes. The plate must reach
    ``covers_radius`` (its counterbores and a wall): the caller checks.
    """
    problems = []
    for thread in PLATE_THREADS:
        screw = socket_screw(thread)
        size = float(thread.removeprefix("M"))
        depth = screw["head_height"] + COUNTERBORE_EXTRA_DEPTH
        if thickness - depth >= 0.8 * size - 1e-9:
            break
    else:
        problems.append(Problem(path, "plate_too_thin",
                                f"the {part} ({thickness:g} mm) is too thin to sink even an "
                                f"{PLATE_THREADS[0]} screw head: thicken it"))
    circle = seat_radius + WALL_MIN + TAP_DRILL[thread] / 2
    engaged = min(ENGAGEMENT * size, tapped_depth)
    clamp = thickness - depth
    try:
        length = screw_length(thread, clamp + engaged)
    except CatalogueError as error:
        length = math.nan
        problems.append(Problem(path, "plate_screw_length", f"the {part}'s screws: {error}"))
    if length > clamp + tapped_depth + 1e-9:   # a standard length would bottom in its hole
        shorter = [n for n in screw["lengths"] if n <= clamp + tapped_depth + 1e-9]
        length = shorter[-1] if shorter else length
    plate = {"part": part, "carries": carries, "bolt": thread, "bolts": PLATE_SCREWS,
             "bolt_circle_radius": circle, "bolt_phase": math.pi / 2,
             "counterbore_diameter": COUNTERBORE[thread], "counterbore_depth": depth,
             "clearance_hole": clearance_hole(thread, hole_series) + hole_extra,
             "tap_drill": TAP_DRILL[thread], "tapped_depth": float(tapped_depth),
             "screw_length": length, "screw": f"ISO 4762 {thread} x {length:g} - 8.8",
             "covers_radius": circle + COUNTERBORE[thread] / 2 + WALL_MIN,
             "torque_nm": float(torque_nmm) / 1000.0}
    # the screws' shear, as a carrying flange's (it sets bolt_shear_mpa and its allowance)
    problems += flange_problems(f"the {part}", carries, float(torque_nmm), plate, path=path,
                                code="plate_screws_overloaded")
    return plate, problems


def needle_clamp(needle_diameter: float, holder_length: float, fit_clearance: float,
                 path: str) -> tuple[dict, list]:
    """The needle's holder at the rocker's end and the set screw that clamps it.

    The holder is a sleeve round the needle (``needle_diameter`` plus ``fit_clearance``), its
    wall half a needle diameter and at least 4 mm, ``holder_length`` long (the rocker's width);
    an ISO 4027 set screw (M4 for needles up to 10 mm, else M5) through its wall, the longest
    standard length that stays within the wall (its cone point bites the needle).
    """
    bore = float(needle_diameter) + float(fit_clearance)
    wall = max(4.0, 0.5 * float(needle_diameter))
    thread = "M4" if needle_diameter <= 10.0 else "M5"
    size = float(thread.removeprefix("M"))
    problems = []
    within = [n for n in SET_SCREW_LENGTHS[thread] if n <= wall + 1e-9]
    if wall < size or not within:
        problems.append(Problem(path, "holder_too_thin",
                                f"the needle holder's {wall:g} mm wall is too thin for its "
                                f"{thread} set screw"))
    length = within[-1] if within else SET_SCREW_LENGTHS[thread][0]
    clamp = {"part": "needle", "holder": "rocker", "bore": bore, "wall": wall,
             "outside": bore + 2 * wall, "length": float(holder_length),
             "set_screw": f"ISO 4027 {thread} x {length:g} - 45H", "thread": thread,
             "tap_drill": TAP_DRILL[thread], "screw_length": float(length)}
    return clamp, problems


# ------------------------------------------------------------------ dowels and alignment
#: ISO 8734 dowel pins (hardened, m6): diameters and standard lengths (mm).
DOWEL_DIAMETERS = (2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0)
DOWEL_LENGTHS = (4, 5, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30, 32, 35, 40, 45, 50)
#: What a deep-groove ball bearing accepts between its rings (arc minutes): SKF gives 2' to
#: 10' for deep-groove ball bearings; the upper end, as the bearing runs lightly loaded.
BEARING_MISALIGNMENT_ARCMIN = 10.0


def dowel_pins(bolt: str, flange_height: float) -> dict:
    """Two ISO 8734 dowels locating a cover on its base: as thick as the flange's bolts, the
    longest standard length within both flange halves (a pin flush with the outer faces), in
    H7 holes reamed through both halves; their fit's largest clearance (H7 hole on an m6 pin)."""
    from cadgen.machine.fits import deviation

    size = float(bolt.removeprefix("M"))
    diameter = max(d for d in DOWEL_DIAMETERS if d <= size + 1e-9)
    lengths = [n for n in DOWEL_LENGTHS if n <= flange_height + 1e-9]
    length = float(lengths[-1]) if lengths else float(DOWEL_LENGTHS[0])
    clearance = deviation("H7", diameter)[1] - deviation("m6", diameter)[0]
    return {"diameter": diameter, "length": length, "count": 2,
            "designation": f"ISO 8734 {diameter:g} x {length:g} - A - St",
            "fit": "H7/m6", "clearance_max_mm": clearance}


def seat_misalignment(span: float, dowel_clearance: float, position_tolerance: float) -> float:
    """The largest tilt (arc minutes) between two coaxial bearing seats ``span`` apart, one bored
    in the base and one in the cover: the cover can shift on its dowels by their fit's
    clearance, and each seat may sit off its place by the process's position tolerance."""
    offset = dowel_clearance + 2.0 * position_tolerance
    return math.degrees(math.atan2(offset, span)) * 60.0


# ------------------------------------------------------------------ the machines' fixings
def arm_fixings(params, shafts, stacks, fits, cam=None) -> tuple[list, dict, list]:
    """Every fixing of a mechanism's arm parts, and its shafts lengthened through their hubs.

    Planting: the planter's keyed hub on shaft E (E then reaches through it) and, given the
    cam design (``cam``: its contour's smallest and largest radius come from it), the cam's
    screws into gearbox 2's cover, checked for the design load acting at the cam's largest
    radius (the follower's force is not modelled: this bounds it while the duckbill linkage
    does not amplify the tip's force). Pricking: the rocker's keyed hub on the planet shaft and
    the needle's clamp. Returns ``(shafts, fixings, problems)``.
    """
    from dataclasses import replace

    from cadgen.machine.loads import design_load

    machine = params.machine
    fixings, problems = {}, []
    if params.mechanism == "planting":
        carrier, plate, path = "E", params.planter.arm_thickness, "planter.arm_thickness"
        part = "planter"
    else:
        carrier, plate, path = "planet", params.linkage.rocker_thickness, "linkage.rocker_thickness"
        part = "rocker"
    shaft = next(s for s in shafts if s.name == carrier)
    hub, found = keyed_hub(part, carrier, shaft.diameter, shaft.torque_nm * 1000.0, plate,
                           machine.key_pressure_mpa, fits.hub_allowance(shaft.diameter), path)
    fixings[part], problems = hub, problems + found
    # the shaft reaches through the hub, not only the plate, and on past it for the ring
    # that holds the hub up (machine.retention)
    from cadgen.machine.catalogue import CatalogueError
    from cadgen.machine.retention import ring_room

    try:
        hub["beyond"] = ring_room(shaft.diameter)
    except CatalogueError:   # no ring for a diameter given off the table: retention says so
        hub["beyond"] = 0.0
    grown = hub["length"] - plate + hub["beyond"]
    shafts = [replace(s, extends_above=s.extends_above + grown) if s.name == carrier else s
              for s in shafts]
    if params.mechanism == "pricking":
        needle = params.linkage.needle_diameter
        # the hub fit's allowance and a little more: the needle slides until it is clamped
        clamp, found = needle_clamp(needle, params.linkage.rocker_width,
                                    fits.hub_allowance(needle) + NEEDLE_SLIDE,
                                    "linkage.needle_diameter")
        fixings["needle"], problems = clamp, problems + found
    elif cam is not None and getattr(cam, "cuttable", False):
        import numpy as np

        contour = np.asarray(cam.profile.working_profile(params.cam.profile_points), dtype=float)
        radii = np.hypot(contour[:, 0], contour[:, 1])
        seat = next(seat for seat in shaft.seats if seat.wall == "roof")
        tapped = stacks["gearbox2"].roof_wall - WALL_MIN
        screwed, found = screwed_plate("cam", "gearbox2", seat.seat_diameter / 2,
                                       params.cam.thickness,
                                       design_load(machine) * float(radii.max()), tapped,
                                       "cam.thickness", hole_series=fits.bolt_hole_series,
                                       hole_extra=fits.bolt_hole_extra)
        problems += found
        if screwed["covers_radius"] > float(radii.min()) + 1e-9:
            problems.append(Problem("cam.base_radius", "cam_too_small_for_screws",
                                    f"the cam's smallest radius {radii.min():.1f} mm does not "
                                    f"cover its {screwed['bolts']} x {screwed['bolt']} screws' "
                                    f"counterbores (they need {screwed['covers_radius']:.1f} mm "
                                    "round E): enlarge the cam's base circle"))
        fixings["cam"] = screwed
    return shafts, fixings, problems


def fixings_report(fixings: dict) -> dict:
    """The fixings as plain JSON (a key as its designation, sizes and pressure)."""
    out = {}
    for name, fixing in fixings.items():
        if name == "duckbill":   # a section of its own (cadgen.machine.duckbill.duckbill_report)
            continue
        entry = {k: v for k, v in fixing.items() if k != "key"}
        key = fixing.get("key")
        if "key" in fixing:
            entry["key"] = None if key is None else {
                "designation": key.designation, "b": key.width, "h": key.height,
                "t1": key.shaft_depth, "t2": key.hub_depth, "l": key.length}
        out[name] = {k: (None if isinstance(v, float) and not math.isfinite(v) else v)
                     for k, v in entry.items()}
    return out


def cam_bore_problems(params, shafts) -> list:
    """A cam bore given in the file that the E shaft does not turn freely in (planting).

    The cam is fixed to gearbox 2 and the E shaft turns inside it, so its bore must be at
    least the shaft's running hole (left out, the bore is that hole)."""
    given = getattr(getattr(params, "cam", None), "bore_diameter", None)
    if params.mechanism != "planting" or given is None:
        return []
    hole = next((seat.hole_diameter for shaft in shafts if shaft.name == "E"
                 for seat in shaft.seats if seat.wall == "roof" and seat.through), None)
    if hole is None or given >= hole - 1e-9:
        return []
    return [Problem("cam.bore_diameter", "cam_bore_too_small",
                    f"the cam's bore of {given:g} mm is smaller than the {hole:g} mm the E shaft "
                    "turns in (its diameter plus the running clearance): leave cam.bore_diameter "
                    "out, or give at least that")]
