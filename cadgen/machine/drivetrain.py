"""The drivetrain of a mechanism: every shaft, its bearings and seats, its hubs, and each housing's stack.

:func:`drivetrain` puts the rules of :mod:`cadgen.machine.loads` (torque chain),
:mod:`cadgen.machine.shafts` (beam, diameter, keys), :mod:`cadgen.machine.bearings`
(ISO 281 life) and :mod:`cadgen.machine.fits` (the process's allowances) together
for both mechanism kinds, numbers only; the solids are built from its records
(:mod:`cadgen.machine.model`). Failing checks are collected as
:class:`kinematics.errors.Problem` items, never raised, so a report lists them all.

Layouts follow the solids (:mod:`cadgen.solids.planting`, :mod:`cadgen.solids.pricking`):
gearbox 1 has one gear layer at ``z = gap`` (cavity ``face_c + 2 gap``); gearbox 2
the non-circular pair at ``gap`` and the 1:1 pair at ``2 gap + face_nc`` (cavity
``face_nc + face_c + 3 gap``); the pricking case stage 1 at ``gap`` and stage 2 at
``2 gap + face_1`` (cavity ``face_1 + face_2 + 3 gap``). The end walls must hold
the bearings, whose widths depend on the loads, whose heights depend on the walls:
the sizing is repeated until bearings and walls no longer change.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from kinematics.errors import Problem

from cadgen.gears.circular import planting_modules
from cadgen.machine.bearings import select_bearing
from cadgen.machine.catalogue import CatalogueError, bearings, bearings_with_bore, preferred_diameters
from cadgen.machine.fits import process_fits
from cadgen.machine.loads import planting_loads, pricking_loads
from cadgen.machine.model import BearingSeat, Drivetrain, GearMount, HousingStack, Shaft
from cadgen.machine.shafts import (RULES as SHAFT_RULES, beam_reactions, choose_diameter,
                                   hub_key, key_pressure, max_bending, required_diameter,
                                   shaft_core)

__all__ = ["drivetrain", "drivetrain_report", "RULES", "MAX_ITERATIONS"]

#: Rounds of bearing choice and wall sizing before giving up on a fixed point (each round can
#: only pick the next bearing series, so a handful suffices).
MAX_ITERATIONS = 8
#: A drive shaft's stub below the floor: twice its diameter for a coupling's hub, plus 20 mm to
#: reach past the frame plate it is fixed to.
STUB_DIAMETERS, STUB_EXTRA = 2.0, 20.0
#: The shoulder a seat needs behind its bearing: at least 2 mm, or half the side wall.
SHOULDER_MIN, SHOULDER_RATIO = 2.0, 0.5

RULES = {
    **SHAFT_RULES,
    "bearing_life": "ISO 281 L10h = (C / P)^3 1e6 / (60 n), P = Fr (spur gears), the load "
                    "taken as acting all revolution (conservative)",
    "bearing_choice": "the smallest (outside diameter, then width) catalogue bearing of the "
                      "shaft's bore reaching bearing_life_min_h",
    "seat": "seat bore = bearing OD + the process's seat allowance",
    "end_wall": "max(side wall, deepest bearing in the wall + shoulder), shoulder = "
                "max(2 mm, 0.5 side wall)",
    "through_hole": "shaft + the process's running clearance",
}


@dataclass(frozen=True)
class _Axis:
    """An axis to size: where it is, what it carries, where it leaves its housing."""

    name: str
    housing: str
    side: int
    xy: tuple
    loads: object                 # loads.AxisLoads
    mounts: tuple                 # (gear, z_bottom, face_width), ...
    floor_through: bool
    roof_through: bool
    below: object                 # d -> mm beyond the floor's outer face
    above: float
    external_above: object        # walls -> height of the external load above the roof face
    note: str = ""


@dataclass(frozen=True)
class _Cavity:
    side_wall: float
    height: float
    parting_z: float
    layers: tuple


@dataclass(frozen=True)
class _Sized:
    diameter: float
    required: float
    bending: float
    reactions: tuple
    bearings: tuple               # (floor, roof): (Bearing, life, passed)
    overhang: float               # height of the external load from the cavity floor (or None)


# ------------------------------------------------------------------ layouts
def _cam_bore_problems(params, shafts) -> list:
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


def _planting_axes(params, mechanism) -> tuple:
    housing, gears = params.housing, params.gears
    gap = housing.axial_gap
    module_nc, module_c = planting_modules(mechanism, params.pitch_curve.teeth,
                                           gears.circular_module)
    face_nc, face_c = gears.face_width_for(module_nc), gears.face_width_for(module_c)
    box1 = face_c + 2 * gap
    box2 = face_nc + face_c + 3 * gap
    layer2 = 2 * gap + face_nc
    cavities = {
        "gearbox1": _Cavity(housing.wall_for(module_c), box1, box1, ((gap, face_c),)),
        "gearbox2": _Cavity(housing.wall_for(max(module_nc, module_c)), box2,
                            gap + face_nc + gap / 2, ((gap, face_nc), (layer2, face_c))),
    }
    loads = planting_loads(mechanism, params.machine, gears.pressure_angle_rad,
                           params.field.carrier_speed_rpm)
    cam, arm = params.cam.thickness, params.planter.arm_thickness
    a, r = float(mechanism.centre_distance), float(mechanism.r)
    line = (math.cos(mechanism.phi0), math.sin(mechanism.phi0))
    radii = mechanism.carrier_radii

    def planter_plane(walls):   # the planter plate's mid-plane above gearbox 2's roof
        return gap + cam + gap + arm / 2

    def gearbox2_planter(walls):   # the same plane, seen from gearbox 1's roof (C carries box 2)
        floor2, roof2 = walls["gearbox2"]
        return gap + floor2 + box2 + roof2 + planter_plane(walls)

    stub = lambda d: STUB_DIAMETERS * d + STUB_EXTRA   # noqa: E731
    none = lambda d: 0.0   # noqa: E731
    axes = [_Axis("O", "gearbox1", 1, (0.0, 0.0), loads["O"], (("sun", gap, face_c),),
                  True, False, stub, 0.0, None,
                  "drive input: the central shaft to the machine's drive")]
    for side, sign in ((1, 1.0), (2, -1.0)):
        for axis, gear in (("A", "idler 1"), ("B", "idler 2"), ("C", "train-1 planet")):
            xy = (sign * radii[axis] * line[0], sign * radii[axis] * line[1])
            carries = axis == "C"
            axes.append(_Axis(axis, "gearbox1", side, xy, loads[axis], ((gear, gap, face_c),),
                              False, carries, none, gap if carries else 0.0,
                              gearbox2_planter if carries else None,
                              "carries gearbox 2" if carries else ""))
    axes += [
        _Axis("C2", "gearbox2", 1, (0.0, 0.0), loads["C2"], (("central", gap, face_nc),),
              True, False, none, 0.0, None,
              "driven through the hollow shaft C by train 1's second set (not modelled)"),
        _Axis("D", "gearbox2", 1, (a, 0.0), loads["D"],
              (("intermediate", gap, face_nc), ("gear D", layer2, face_c)),
              False, False, none, 0.0, None),
        _Axis("E", "gearbox2", 1, (a + 2 * r, 0.0), loads["E"],
              (("planet gear E", layer2, face_c),), False, True, none,
              gap + cam + gap + arm, planter_plane,
              "carries the planter; the cam, fixed to gearbox 2, is bored clear of it"),
    ]
    return axes, cavities, loads


def _pricking_axes(params, design) -> tuple:
    housing, gears = params.housing, params.gears
    gap = housing.axial_gap
    faces = [gears.face_width_for(m) for m in design.modules]
    cavity = faces[0] + faces[1] + 3 * gap
    layer2 = 2 * gap + faces[0]
    cavities = {"gear-case": _Cavity(housing.wall_for(max(design.modules)), cavity,
                                     gap + faces[0] + gap / 2,
                                     ((gap, faces[0]), (layer2, faces[1])))}
    loads = pricking_loads(design, params.machine, gears.pressure_angle_rad,
                           params.field.carrier_speed_rpm)
    link = design.linkage
    start = design.motion.phi1_start
    centre = [float(v) for v in link.centre]

    def at(distance):
        return (centre[0] + distance * math.cos(start), centre[1] + distance * math.sin(start))

    rocker = params.linkage.rocker_thickness
    axes = [
        _Axis("sun", "gear-case", 1, at(0.0), loads["sun"], (("sun", gap, faces[0]),),
              True, False, lambda d: STUB_DIAMETERS * d + STUB_EXTRA, 0.0, None,
              "fixed to the frame: the case turns about it"),
        _Axis("intermediate", "gear-case", 1, at(link.a), loads["intermediate"],
              (("intermediate 1", gap, faces[0]), ("intermediate 2", layer2, faces[1])),
              False, False, lambda d: 0.0, 0.0, None),
        _Axis("planet", "gear-case", 1, at(2 * link.a), loads["planet"],
              (("planet", layer2, faces[1]),), False, True, lambda d: 0.0, gap + rocker,
              lambda walls: gap + rocker / 2, "carries the rocker and the needle"),
    ]
    return axes, cavities, loads


# ------------------------------------------------------------------ sizing
def _journal_bore(d: float) -> float:
    """The bore the bearings of a shaft of ``d`` have: ``d``, or (off the catalogue) the largest
    bore below it (the journals turned down to it), else the smallest bore."""
    bores = preferred_diameters()
    if d in bores:
        return d
    below = [b for b in bores if b <= d]
    return below[-1] if below else bores[0]


def _size(axis, cavity, walls, widths, given, machine) -> _Sized:
    floor_wall, roof_wall = walls[axis.housing]
    z1, z2 = -widths[0] / 2, cavity.height + widths[1] / 2
    loads = [(z + face / 2, axis.loads.gears[gear].radial_n) for gear, z, face in axis.mounts]
    overhang = None
    if axis.loads.external is not None:
        overhang = cavity.height + roof_wall + axis.external_above(walls)
        loads.append((overhang, axis.loads.external[1]))
    bending = max_bending(z1, z2, loads)
    required = required_diameter(bending, axis.loads.torque_nmm, machine.shaft_yield_mpa,
                                 machine.shaft_safety_factor)
    if given is not None:
        d = float(given)
    else:
        d = choose_diameter(required) or preferred_diameters()[-1]
    reactions = tuple(abs(v) for v in beam_reactions(z1, z2, loads))
    bore = _journal_bore(d)
    # never a narrower bearing than the last round's: a bearing near its life target could
    # flip between two widths (a wider wall moves the reactions); growing only, on a finite
    # catalogue, the rounds settle (and the span is always the chosen bearings')
    chosen = tuple(select_bearing(bore, load, axis.loads.speed_rpm, machine.bearing_life_min_h,
                                  min_width=width)
                   for load, width in zip(reactions, widths))
    return _Sized(d, required, bending, reactions, chosen, overhang)


def _stack_walls(axes, sized, cavities) -> dict:
    walls = {}
    for name, cavity in cavities.items():
        shoulder = max(SHOULDER_MIN, SHOULDER_RATIO * cavity.side_wall)
        deepest = [0.0, 0.0]
        for key, axis in enumerate(axes):
            if axis.housing == name:
                for k in (0, 1):
                    deepest[k] = max(deepest[k], sized[key].bearings[k][0].width)
        walls[name] = tuple(max(cavity.side_wall, depth + shoulder) for depth in deepest)
    return walls


def _fixed_point(axes, cavities, given, machine) -> tuple:
    walls = {name: (c.side_wall, c.side_wall) for name, c in cavities.items()}
    widths = [(0.0, 0.0)] * len(axes)
    for iteration in range(1, MAX_ITERATIONS + 1):
        sized = [_size(axis, cavities[axis.housing], walls, widths[k], given.get(axis.name),
                       machine) for k, axis in enumerate(axes)]
        new_widths = [tuple(b[0].width for b in s.bearings) for s in sized]
        new_walls = _stack_walls(axes, sized, cavities)
        if new_widths == widths and new_walls == walls:
            return sized, walls, iteration, True
        widths, walls = new_widths, new_walls
    return sized, walls, MAX_ITERATIONS, False


# ------------------------------------------------------------------ records
def _core(d: float) -> float:
    """The diameter under the keyseat or flat; ``d`` itself off the key table."""
    try:
        return shaft_core(d)[0]
    except CatalogueError:
        return d


def _mounts(axis, d, fits, machine, report: bool) -> tuple:
    mounts, problems = [], []
    for gear, z, face in axis.mounts:
        load = axis.loads.gears[gear]
        torque = load.torque_nmm
        key, flat = None, 0.0
        if d < 10.0:
            flat = shaft_core(d)[2]
        else:
            try:
                key = hub_key(d, face)
            except CatalogueError as error:
                if report:
                    problems.append(Problem("gears.face_width", "hub_without_key",
                                            f"the hub of the gear {gear!r} on the {d:g} mm shaft "
                                            f"{axis.name} takes no key: {error}"))
                flat = 0.1 * d
        if key is not None and report:
            pressure = key_pressure(torque, d, key)
            if pressure > machine.key_pressure_mpa:
                problems.append(Problem(
                    "gears.face_width", "key_overloaded",
                    f"the key of the gear {gear!r} ({key.width:g} x {key.height:g} x {key.length:g} on "
                    f"the {d:g} mm shaft {axis.name}) carries {torque / 1000:.1f} N m at a flank "
                    f"pressure of {pressure:.0f} MPa, above machine.key_pressure_mpa = "
                    f"{machine.key_pressure_mpa:g} MPa: widen the gear's face (gears.face_width), "
                    "give a larger shaft (machine.shafts), or lower the design load "
                    "(machine.tip_load_n, machine.service_factor)"))
        mounts.append(GearMount(gear, z, face, torque / 1000.0, load.radial_n, d, key, flat,
                                fits.hub_allowance(d)))
    return tuple(mounts), problems


def _shaft_problems(axis, sized, given, machine, both_sides) -> list:
    problems = []
    d = sized.diameter
    path = f"machine.shafts.{axis.name}"
    sides = " (both sides)" if both_sides else ""
    core = _core(d)
    if given is not None and core < sized.required - 1e-9:
        problems.append(Problem(path, "shaft_too_weak",
                                f"shaft {axis.name}{sides}: {d:g} mm (core {core:.1f} mm under "
                                f"its keyseat or flat) is below the {sized.required:.1f} mm its "
                                f"torque of {axis.loads.torque_nmm / 1000:.1f} N m and bending of "
                                f"{sized.bending / 1000:.1f} N m need"))
    if given is not None and not bearings_with_bore(d):
        problems.append(Problem(path, "shaft_not_catalogue",
                                f"shaft {axis.name}{sides}: no catalogue bearing has a {d:g} mm "
                                f"bore (bores: {', '.join(f'{b:g}' for b in preferred_diameters())}"
                                f"); its journals would be turned down to "
                                f"{_journal_bore(d):g} mm"))
    if given is None and core < sized.required - 1e-9:
        problems.append(Problem("machine.tip_load_n", "shaft_beyond_catalogue",
                                f"shaft {axis.name}{sides} needs {sized.required:.1f} mm, more "
                                f"than the largest catalogue shaft ({d:g} mm) gives: lower the "
                                "design load or the safety factor"))
    for wall, (bearing, life, passed) in zip(("floor", "roof"), sized.bearings):
        if not passed:
            problems.append(Problem(
                "machine.bearing_life_min_h", "bearing_life_short",
                f"shaft {axis.name}{sides}, {wall} bearing {bearing.designation}: L10h "
                f"{life:.0f} h under {sized.reactions[0 if wall == 'floor' else 1]:.0f} N at "
                f"{axis.loads.speed_rpm:.1f} r/min is below {machine.bearing_life_min_h:g} h "
                "(the largest bearing of that bore): give a larger shaft or a lower life target"))
    return problems


def drivetrain(params, design) -> Drivetrain:
    """Every shaft, bearing seat and housing stack of a mechanism, with the rules used.

    Parameters
    ----------
    params : PlantingParameters or PrickingParameters
        Validated parameters (``params.machine``, ``params.manufacturing``, ...).
    design : kinematics.planting.PlantingMechanism or kinematics.pricking.PrickingDesign
        As :func:`cadgen.design.build_mechanism` or :func:`cadgen.design.pricking_design`
        give them.

    Returns
    -------
    Drivetrain
        Its ``problems`` hold every failing check (strength, key pressure, life, given
        diameters off the catalogue).
    """
    machine = params.machine
    fits = process_fits(params.manufacturing.process)
    if params.mechanism == "planting":
        axes, cavities, loads = _planting_axes(params, design)
    elif params.mechanism == "pricking":
        axes, cavities, loads = _pricking_axes(params, design)
    else:
        raise ValueError(f"no drivetrain for mechanism {params.mechanism!r}")
    given = machine.shafts.given()
    sized, walls, iterations, converged = _fixed_point(axes, cavities, given, machine)
    stacks = {name: HousingStack(name, walls[name][0], walls[name][1], c.height, c.parting_z,
                                 c.layers) for name, c in cavities.items()}
    names_with_sides = {a.name for a in axes if a.side == 2}
    shafts, problems = [], []
    for axis, size in zip(axes, sized):
        report = axis.side == 1
        both = axis.name in names_with_sides
        d = size.diameter
        mounts, mount_problems = _mounts(axis, d, fits, machine, report)
        if report:
            problems += mount_problems + _shaft_problems(axis, size, given.get(axis.name),
                                                         machine, both)
        seats = []
        for k, wall in enumerate(("floor", "roof")):
            bearing, life, _ = size.bearings[k]
            through = axis.floor_through if wall == "floor" else axis.roof_through
            seats.append(BearingSeat(
                axis.name, axis.housing, axis.side, axis.xy, wall, bearing,
                bearing.outside + fits.seat_allowance(bearing.outside), through,
                d + fits.running_clearance if through else 0.0, size.reactions[k],
                axis.loads.speed_rpm, life, machine.bearing_life_min_h))
        shafts.append(Shaft(axis.name, axis.housing, axis.side, axis.xy, d, size.required,
                            axis.name in given, axis.loads.torque_nmm / 1000.0, size.bending,
                            axis.loads.speed_rpm, mounts, tuple(seats),
                            float(axis.below(d)) if axis.floor_through else 0.0,
                            axis.above if axis.roof_through else 0.0, axis.note))
    problems += _cam_bore_problems(params, shafts)
    if not converged:
        problems.append(Problem("machine", "drivetrain_not_settled",
                                f"bearings and end walls still changed after {iterations} "
                                "rounds; the last round is reported"))
    rules = {"text": dict(RULES),
             "constants": {"tip_load_n": machine.tip_load_n,
                           "service_factor": machine.service_factor,
                           "design_load_n": machine.tip_load_n * machine.service_factor,
                           "shaft_safety_factor": machine.shaft_safety_factor,
                           "shaft_yield_mpa": machine.shaft_yield_mpa,
                           "shaft_shear_allow_mpa": machine.shaft_yield_mpa / 2,
                           "key_pressure_mpa": machine.key_pressure_mpa,
                           "bearing_life_min_h": machine.bearing_life_min_h,
                           "pressure_angle_deg": params.gears.pressure_angle_deg,
                           "carrier_speed_rpm": params.field.carrier_speed_rpm,
                           "shoulder_min_mm": SHOULDER_MIN, "shoulder_ratio": SHOULDER_RATIO,
                           "catalogue_bearings": len(bearings())},
             "loads": next(iter(loads.values())).formulas,
             "fits": fits.as_dict(), "iterations": iterations, "converged": converged,
             "overhangs_mm": {f"{a.name}-side{a.side}": s.overhang for a, s in zip(axes, sized)
                              if s.overhang is not None}}
    return Drivetrain(params.mechanism, tuple(shafts), stacks, fits.process, rules,
                      tuple(problems))


# ------------------------------------------------------------------ report
def _length(shaft, stack) -> float:
    """Overall shaft length (mm): stubs, the walls it passes or the bearings it ends in, cavity."""
    floor, roof = shaft.seats
    low = stack.floor_wall + shaft.extends_below if floor.through else floor.bearing.width
    high = stack.roof_wall + shaft.extends_above if roof.through else roof.bearing.width
    return low + stack.cavity_height + high


def _finite(value):
    return value if math.isfinite(value) else None


def drivetrain_report(drivetrain: Drivetrain) -> dict:
    """A JSON-ready account of a drivetrain: shafts, bearings, stacks, rules and problems.

    Torques in N m, bending in N mm, lengths in mm, speeds in r/min, lives in h
    (``None`` for an unloaded bearing's infinite life), key pressures in MPa.
    """
    shafts, seats = [], []
    for shaft in drivetrain.shafts:
        stack = drivetrain.stacks[shaft.housing]
        hubs = []
        for mount in shaft.mounts:
            hub = {"gear": mount.gear, "z_bottom_mm": mount.z_bottom,
                   "face_width_mm": mount.face_width, "torque_nm": mount.torque_nm,
                   "radial_load_n": mount.radial_load_n, "hub_bore_mm": mount.hub_bore,
                   "bore_allowance_mm": mount.bore_allowance}
            if mount.key is not None:
                pressure = key_pressure(mount.torque_nm * 1000.0, shaft.diameter, mount.key)
                hub["key"] = {"designation": mount.key.designation, "b": mount.key.width,
                              "h": mount.key.height, "t1": mount.key.shaft_depth,
                              "t2": mount.key.hub_depth, "l": mount.key.length,
                              "pressure_mpa": _finite(pressure)}
            else:
                hub["flat_depth_mm"] = mount.flat_depth
            hubs.append(hub)
        shafts.append({
            "name": shaft.name, "housing": shaft.housing, "side": shaft.side,
            "xy_mm": [float(v) for v in shaft.xy], "diameter_mm": shaft.diameter,
            "required_mm": shaft.required_diameter, "given": shaft.given,
            "core_mm": _core(shaft.diameter),
            "torque_nm": shaft.torque_nm, "bending_nmm": shaft.bending_nmm,
            "speed_rpm": shaft.speed_rpm, "length_mm": _length(shaft, stack),
            "extends_below_mm": shaft.extends_below, "extends_above_mm": shaft.extends_above,
            "strength_passed": shaft.strength_passed, "note": shaft.note, "hubs": hubs})
        for seat in shaft.seats:
            b = seat.bearing
            seats.append({
                "shaft": seat.shaft, "housing": seat.housing, "side": seat.side,
                "wall": seat.wall, "designation": b.designation, "d_mm": b.bore,
                "D_mm": b.outside, "B_mm": b.width, "C_kn": b.dynamic_load_kn,
                "C0_kn": b.static_load_kn, "seat_diameter_mm": seat.seat_diameter,
                "through": seat.through, "hole_diameter_mm": seat.hole_diameter,
                "load_n": seat.load_n, "speed_rpm": seat.speed_rpm,
                "l10_h": _finite(seat.life_h), "target_h": seat.life_min_h,
                "passed": seat.life_passed})
    stacks = {name: {"floor_wall_mm": s.floor_wall, "roof_wall_mm": s.roof_wall,
                     "cavity_height_mm": s.cavity_height, "parting_z_mm": s.parting_z,
                     "layers": [list(layer) for layer in s.layers]}
              for name, s in drivetrain.stacks.items()}
    return {"mechanism": drivetrain.mechanism, "process": drivetrain.process,
            "shafts": shafts, "bearings": seats, "stacks": stacks, "rules": drivetrain.rules,
            "problems": [p.as_dict() for p in drivetrain.problems],
            "passed": not drivetrain.problems}
