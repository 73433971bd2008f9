"""The drivetrain of a mechanism: every shaft, its bearings and seats, its hubs, and each housing's stack.

:func:`drivetrain` puts the rules of :mod:`cadgen.machine.loads` (torque chain),
:mod:`cadgen.machine.shafts` (beam, diameter, keys), :mod:`cadgen.machine.bearings`
(ISO 281 life) and :mod:`cadgen.machine.fits` (the process's allowances) together
for both mechanism kinds, numbers only; the solids are built from its records
(:mod:`cadgen.machine.model`). Failing checks are collected as
:class:`kinematics.errors.Problem` items, never raised, so a report lists them all.

Layouts (:mod:`cadgen.machine.layouts`) follow the solids (:mod:`cadgen.solids.planting`,
:mod:`cadgen.solids.pricking`): gearbox 1 has two gear layers (train 1's set I at ``gap``,
set II at ``2 gap + face_I``), gearbox 2 the non-circular pair and the 1:1 pair, the frame
the drive's two pairs; the pricking case stage 1 and stage 2. A shaft may reach into another
housing (O from the frame's floor to gearbox 1's roof, C2 from gearbox 1's floor to gearbox
2's roof) or be hollow and carry the next housing on a bolted flange, in a pair of bearings
in its housing's roof (the sleeve S carries gearbox 1, C carries gearbox 2). The end walls
must hold the bearings, whose widths depend on the loads, whose heights depend on the walls:
the sizing is repeated until bearings and walls no longer change.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from kinematics.errors import Problem

from cadgen.gears.circular import DRIVE_SLEEVE_DIAMETER, planting_modules
from cadgen.gears.drive import DEDENDUM_MODULES, RIM_MODULES
from cadgen.machine.bearings import journal_bore, select_bearing
from cadgen.machine.case_drive import pricking_case_drive
from cadgen.machine.catalogue import (CatalogueError, bearings, bearings_with_bore,
                                      preferred_diameters)
from cadgen.machine.cycle_loads import ASSUMED_TIP_FORCE, cycle_size, with_cycles
from cadgen.machine.fits import process_fits
from cadgen.machine.fastening import coupling_key, flange_problems, free_bearing
from cadgen.machine.fixings import arm_fixings, cam_bore_problems, fixings_report
from cadgen.machine.layouts import (HOLLOW_WALL_MIN, _mount_fields, carry_flange, planting_axes,
                                    pricking_axes)
from cadgen.machine.model import BearingSeat, Drivetrain, GearMount, HousingStack, Shaft
from cadgen.machine.retention import drivetrain_retention
from cadgen.machine.shafts import (RULES as SHAFT_RULES, beam_reactions, choose_diameter,
                                   hollow_required, hub_key, key_pressure, max_bending,
                                   required_diameter, shaft_core)

__all__ = ["drivetrain", "drivetrain_report", "RULES", "MAX_ITERATIONS"]

#: Rounds of bearing choice and wall sizing before giving up on a fixed point (each round can
#: only pick the next bearing series, so a handful suffices).
MAX_ITERATIONS = 8
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
class _Sized:
    diameter: float
    required: float
    bending: float
    reactions: tuple
    bearings: tuple               # (floor, roof): (Bearing, life, passed)
    overhang: float               # height of the external load from the cavity floor (or None)
    bore: float = 0.0             # a hollow shaft's bore
    peak: tuple = ()              # over the dynamics' cycle: each bearing's peak load (N)
    carried: tuple | None = None  # (housing, (n, 2) N): the roof bearing's load on that housing


# ------------------------------------------------------------------ sizing
def _span(axis, cavities, base, widths) -> tuple:
    """Heights (mm, from the axis housing's cavity floor) of its two bearings' centres."""
    h = axis.housing
    height = cavities[h].height
    if axis.roof_pair:   # side by side in the roof, from its inner face (first round: 10 mm)
        w0, w1 = (width or 10.0 for width in widths)
        return height + w0 / 2, height + w0 + w1 / 2
    top = axis.roof_housing or h
    return -widths[0] / 2, base[top] - base[h] + cavities[top].height + widths[1] / 2


def _size(axis, cavities, walls, base, widths, given, machine, inner=None,
          clearance=0.0) -> _Sized:
    h = axis.housing
    z1, z2 = _span(axis, cavities, base, widths)
    loads = []
    for mount in axis.mounts:
        gear, z, face, housing, _ = _mount_fields(mount)
        offset = base[housing] - base[h] if housing else 0.0
        loads.append((offset + z + face / 2, axis.loads.gears[gear].radial_n))
    overhang = None
    if axis.loads.external is not None:
        overhang = axis.external_above(walls, base) - base[h]
        loads.append((overhang, axis.loads.external[1]))
    cycle, peak, carried = axis.loads.cycle, (), None
    if cycle is not None:   # the dynamics' forces at every pose (cycle_loads), not one bound
        heights = {_mount_fields(m)[0]: z for m, (z, _) in zip(axis.mounts, loads)}
        through = inner.carried[1] if inner is not None and inner.carried is not None \
            and inner.carried[0] == axis.carries else None
        # a carried housing's loads reach the shaft through that housing: at its mid-height
        at = overhang if axis.carries is None else \
            base[axis.carries] - base[h] + cavities[axis.carries].height / 2
        bending, reactions, peak, forces = cycle_size(axis, z1, z2, heights, at,
                                                      machine.service_factor, through)
        reactions, peak = tuple(float(v) for v in reactions), tuple(float(v) for v in peak)
        if axis.roof_housing is not None:
            carried = (axis.roof_housing, -forces[1])
    else:
        bending = max_bending(z1, z2, loads)
        reactions = tuple(abs(v) for v in beam_reactions(z1, z2, loads))
    bore = 0.0
    if axis.inside is not None and inner is not None:
        bore = inner.diameter + clearance
        required = hollow_required(bending, axis.loads.torque_nmm, bore, machine)
        # the smallest bearing bore whose tube (under its keyseat) is strong enough and whose
        # keys carry the torque within key_pressure_mpa: a hollow shaft carries a housing's
        fits_tube = [b for b in preferred_diameters()
                     if _core(b) >= required - 1e-9 and _core(b) - bore >= 2 * HOLLOW_WALL_MIN
                     and _keys_hold(axis, b, machine)]
        d = float(given) if given is not None else (fits_tube[0] if fits_tube
                                                     else preferred_diameters()[-1])
    else:
        required = required_diameter(bending, axis.loads.torque_nmm, machine.shaft_yield_mpa,
                                     machine.shaft_safety_factor)
        if given is not None:
            d = float(given)
        else:   # the smallest bearing bore strong enough whose keys carry their torques
            strong = choose_diameter(required) or preferred_diameters()[-1]
            d = next((b for b in preferred_diameters()
                      if b >= strong and _keys_hold(axis, b, machine)), strong)
    bore_j = journal_bore(d)
    if axis.roof_pair:   # a pair is two of one bearing: chosen for the larger reaction
        pick = select_bearing(bore_j, max(reactions), axis.loads.speed_rpm,
                              machine.bearing_life_min_h, min_width=max(widths))
        from cadgen.machine.bearings import l10_hours

        chosen = tuple((pick[0], life, life >= machine.bearing_life_min_h) for life in
                       (l10_hours(pick[0].dynamic_load_kn, load, axis.loads.speed_rpm)
                        for load in reactions))
    else:
        # never a narrower bearing than the last round's: a bearing near its life target could
        # flip between two widths (a wider wall moves the reactions); growing only, on a finite
        # catalogue, the rounds settle (and the span is always the chosen bearings')
        chosen = tuple(select_bearing(bore_j, load, axis.loads.speed_rpm,
                                      machine.bearing_life_min_h, min_width=width)
                       for load, width in zip(reactions, widths))
    return _Sized(d, required, bending, reactions, chosen, overhang, bore, peak, carried)


def _keys_hold(axis, d: float, machine) -> bool:
    """Whether every keyed hub on the axis carries its torque on a shaft of ``d``."""
    for mount in axis.mounts:
        gear, _, face, _, free = _mount_fields(mount)
        if free:
            continue
        try:
            key = hub_key(d, face)
        except CatalogueError:
            return False
        torque = axis.loads.gears[gear].torque_nmm
        if key is not None and key_pressure(torque, d, key) > machine.key_pressure_mpa:
            return False
    return True


def _seat_walls(axis) -> tuple:
    """``((housing, wall), (housing, wall))`` of the axis's two bearings."""
    if axis.roof_pair:
        return (axis.housing, "roof"), (axis.housing, "roof")
    return (axis.housing, "floor"), (axis.roof_housing or axis.housing, "roof")


def _stack_walls(axes, sized, cavities) -> dict:
    deepest = {(name, wall): 0.0 for name in cavities for wall in ("floor", "roof")}
    for axis, size in zip(axes, sized):
        widths = [b[0].width for b in size.bearings]
        if axis.roof_pair:
            key = (axis.housing, "roof")
            deepest[key] = max(deepest[key], widths[0] + widths[1])
            continue
        for key, width in zip(_seat_walls(axis), widths):
            deepest[key] = max(deepest[key], width)
    walls = {}
    for name, cavity in cavities.items():
        shoulder = max(SHOULDER_MIN, SHOULDER_RATIO * cavity.side_wall)
        walls[name] = tuple(max(cavity.side_wall, deepest[name, wall] + shoulder)
                            for wall in ("floor", "roof"))
    return walls


def _fixed_point(axes, cavities, given, machine, bases, clearance=0.0) -> tuple:
    walls = {name: (c.side_wall, c.side_wall) for name, c in cavities.items()}
    widths = [(0.0, 0.0)] * len(axes)
    for iteration in range(1, MAX_ITERATIONS + 1):
        base = bases(walls)
        sized, by_name = [], {}
        for k, axis in enumerate(axes):
            inner = by_name.get((axis.inside, axis.side)) if axis.inside else None
            size = _size(axis, cavities, walls, base, widths[k], given.get(axis.name), machine,
                         inner, clearance)
            sized.append(size)
            by_name[axis.name, axis.side] = size
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


def _mounts(axis, d, fits, machine, report: bool, base=None) -> tuple:
    mounts, problems = [], []
    for mount_tuple in axis.mounts:
        gear, z, face, housing, free = _mount_fields(mount_tuple)
        if housing and base is not None:   # from the shaft's own housing's cavity floor
            z = base[housing] - base[axis.housing] + z
        load = axis.loads.gears[gear]
        torque = load.torque_nmm
        key, flat = None, 0.0
        if free:
            bearing, speed, life, found = free_bearing(axis, gear, face, d, machine, report)
            problems += found
            mounts.append(GearMount(gear, z, face, 0.0, load.radial_n, bearing.outside, None, 0.0,
                                    fits.seat_allowance(bearing.outside), housing or "",
                                    bearing, speed, life))
            continue
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
                                fits.hub_allowance(d), housing or ""))
    return tuple(mounts), problems


#: Rounds of drive redesign round its shafts' hubs (each can only grow the gears).
DRIVE_ROUNDS = 4


def _hub_diameter(d: float, face: float) -> float:
    """The diameter a keyed hub's bore and keyway reach on a shaft of ``d``: ``d + 2 t2``."""
    try:
        key = hub_key(d, face)
    except CatalogueError:
        return d
    return d + 2 * key.hub_depth if key is not None else d


def _drive_round_hubs(params, design, axes, sized, drive, keep=False):
    """The drive redesigned round the hubs of the shafts just sized, or None if it fits them
    (``keep``: None while its gears' rims clear them, rather than the least drive that does)."""
    from cadgen.gears.circular import planting_drive

    by_name = {axis.name: size for axis, size in zip(axes, sized) if axis.side == 1}
    face = params.gears.face_width_for(drive.module_1)
    hubs = tuple(_hub_diameter(by_name[name].diameter, face)
                 for name in ("input", "O", "input", "S"))
    module_c = planting_modules(design, params.pitch_curve.teeth, params.gears.circular_module)[1]
    if keep and all(z * drive.module_1 / 2 - (DEDENDUM_MODULES + RIM_MODULES) * drive.module_1
                    >= hub / 2 - 1e-9 for z, hub in zip(drive.teeth, hubs)):
        return None   # kept while it clears them: sized again, the shafts only shrank
    need = planting_drive(design, module_c, params.gears.circular_module,
                          params.field.carrier_speed_rpm, params.gears.pressure_angle_rad,
                          hubs=hubs)
    return None if need.teeth == drive.teeth else need


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
                                f"{journal_bore(d):g} mm"))
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


def drivetrain(params, design, cam=None, *, cycles=None, drive=None) -> Drivetrain:
    """Every shaft, bearing seat and housing stack of a mechanism, with the rules used.

    Parameters
    ----------
    params : PlantingParameters or PrickingParameters
        Validated parameters (``params.machine``, ``params.manufacturing``, ...).
    design : kinematics.planting.PlantingMechanism or kinematics.pricking.PrickingDesign
        As :func:`cadgen.design.build_mechanism` or :func:`cadgen.design.pricking_design`
        give them.
    cam : cadgen.cam.design.CamDesign, optional
        The planting cam: its screws to gearbox 2 are sized round its contour
        (:func:`cadgen.machine.fixings.arm_fixings`); without it the cam has no fixing.
    cycles : dict, optional
        ``{axis: cycle_loads.CycleLoads}``: the dynamics' loads over the turn, which size those
        axes instead of the assumed tip force (:mod:`cadgen.machine.cycle_loads`).
    drive : cadgen.gears.drive.DriveDesign, optional
        The planting drive to start from (the one ``cycles`` were computed with); with
        ``cycles`` it is kept while its gears clear the shafts' hubs.

    Returns
    -------
    Drivetrain
        Its ``problems`` hold every failing check (strength, key pressure, life, given
        diameters off the catalogue).
    """
    machine = params.machine
    fits = process_fits(params.manufacturing.process)
    if params.mechanism == "planting":
        axes, cavities, loads, bases, drive = planting_axes(params, design, drive)
    elif params.mechanism == "pricking":
        axes, cavities, loads, bases, drive = pricking_axes(params, design)
    else:
        raise ValueError(f"no drivetrain for mechanism {params.mechanism!r}")
    given = machine.shafts.given()
    axes = with_cycles(axes, cycles, machine.service_factor)
    sized, walls, iterations, converged = _fixed_point(axes, cavities, given, machine, bases,
                                                       fits.running_clearance)
    for _ in range(DRIVE_ROUNDS if drive is not None else 0):
        # the drive's gears sit on O, the sleeve and the input: their rims must clear the hubs
        # of the shafts just sized; a larger gear changes the loads, so size again
        bigger = _drive_round_hubs(params, design, axes, sized, drive, keep=cycles is not None)
        if bigger is None:
            break
        drive = bigger
        axes, cavities, loads, bases, drive = planting_axes(params, design, drive)
        axes = with_cycles(axes, cycles, machine.service_factor)
        sized, walls, iterations, converged = _fixed_point(axes, cavities, given, machine,
                                                           bases, fits.running_clearance)
    base = bases(walls)
    stacks = {name: HousingStack(name, walls[name][0], walls[name][1], c.height, c.parting_z,
                                 c.layers) for name, c in cavities.items()}
    names_with_sides = {a.name for a in axes if a.side == 2}
    shafts, problems = [], []
    for axis, size in zip(axes, sized):
        report = axis.side == 1
        both = axis.name in names_with_sides
        source = axis.loads.cycle.source if axis.loads.cycle is not None else ASSUMED_TIP_FORCE
        d = size.diameter
        mounts, mount_problems = _mounts(axis, d, fits, machine, report, base)
        if report:
            problems += mount_problems + _shaft_problems(axis, size, given.get(axis.name),
                                                         machine, both)
        seats = []
        places = _seat_walls(axis)
        for k, (housing, wall) in enumerate(places):
            if axis.roof_pair and k == 1:
                break   # the pair is one seat of two bearings
            bearing, life, _ = size.bearings[k]
            through = axis.floor_through if wall == "floor" else axis.roof_through
            load, life_seat, worst = size.reactions[k], life, k
            if axis.roof_pair:   # the pair's worse bearing speaks for the seat
                worst = max((0, 1), key=lambda j: size.reactions[j])
                load, life_seat = size.reactions[worst], size.bearings[worst][1]
            peak = size.peak[worst] if size.peak else None
            # a seat in another housing sits on this axis there: gearbox 2's is centred on C
            xy = axis.xy if housing == axis.housing else (0.0, 0.0)
            seats.append(BearingSeat(
                axis.name, housing, axis.side, xy, wall, bearing,
                bearing.outside + fits.seat_allowance(bearing.outside), through,
                d + fits.running_clearance if through else 0.0, load,
                axis.loads.speed_rpm, life_seat, machine.bearing_life_min_h,
                2 if axis.roof_pair else 1, source, peak))
        ends = None
        if axis.roof_housing is not None:   # from its floor seat to the other housing's roof
            top = axis.roof_housing
            ends = (-size.bearings[0][0].width,
                    base[top] - base[axis.housing] + cavities[top].height
                    + size.bearings[1][0].width)
        elif axis.roof_pair:   # the hollow shaft: from its gear to its flange on the next
            z_low = min(_mount_fields(m)[1] for m in axis.mounts)
            top = axis.carries
            ends = (z_low, base[top] - base[axis.housing] - walls[top][0])
        flange = None
        if axis.carries is not None:
            flange = carry_flange(d)
            flange["carries"] = axis.carries
            if report:
                problems += flange_problems(f"shaft {axis.name}", axis.carries,
                                            axis.loads.torque_nmm, flange)
        coupling = None
        if axis.floor_through and axis.below(d) > 0:   # a stub for a sprocket or coupling
            coupling, found = coupling_key(axis, d, float(axis.below(d)), machine, report)
            problems += found
        shafts.append(Shaft(axis.name, axis.housing, axis.side, axis.xy, d, size.required,
                            axis.name in given, axis.loads.torque_nmm / 1000.0, size.bending,
                            axis.loads.speed_rpm, mounts, tuple(seats),
                            float(axis.below(d)) if axis.floor_through else 0.0,
                            axis.above if axis.roof_through else 0.0, axis.note,
                            size.bore, ends, flange, coupling, source, source))
    sleeve = next((s for s in shafts if s.name == "S"), None)
    if sleeve is not None and sleeve.diameter > DRIVE_SLEEVE_DIAMETER + 1e-9:
        problems.append(Problem("machine.shafts.S", "sleeve_beyond_drive",
                                f"the sleeve carrying gearbox 1 is {sleeve.diameter:g} mm, more "
                                f"than the {DRIVE_SLEEVE_DIAMETER:g} mm the drive's driven gear "
                                "was designed round"))
    problems += cam_bore_problems(params, shafts)
    shafts, fixings, found = arm_fixings(params, shafts, stacks, fits, cam)
    problems += found
    if params.mechanism == "planting" and cam is not None:   # the duckbill linkage's parts,
        from cadgen.machine.duckbill import duckbill_fixing   # pins, roller and spring

        duckbill, found = duckbill_fixing(params, design, cam, fits)
        problems += found
        fixings.update({"duckbill": duckbill} if duckbill is not None else {})
    held = None
    if params.mechanism == "pricking":
        held, found = pricking_case_drive(params, design, shafts, loads)
        problems += found
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
             "loads": next((a.loads.formulas for a in axes if a.loads.cycle is not None),
                           next(iter(loads.values())).formulas),
             "fits": fits.as_dict(), "iterations": iterations, "converged": converged,
             "overhangs_mm": {f"{a.name}-side{a.side}": s.overhang for a, s in zip(axes, sized)
                              if s.overhang is not None}}
    if drive is not None:
        rules["drive"] = drive.as_report()
        rules["stack_bases_mm"] = base
    if held is not None:
        rules["case_drive"] = held
    retention, found = drivetrain_retention(shafts, stacks, base, fixings, params.housing.axial_gap)
    problems += found
    return Drivetrain(params.mechanism, tuple(shafts), stacks, fits.process, rules,
                      tuple(problems), drive, base, fixings, retention)


# ------------------------------------------------------------------ report
def _length(shaft, stack) -> float:
    """Overall shaft length (mm): stubs, the walls it passes or the bearings it ends in, cavity."""
    if shaft.ends is not None:
        return shaft.ends[1] - shaft.ends[0]
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
            elif mount.bearing is not None:
                hub["runs_free_on"] = {"designation": mount.bearing.designation, "count": 2,
                                       "speed_rpm": mount.speed_rpm,
                                       "l10_h": _finite(mount.life_h)}
            else:
                hub["flat_depth_mm"] = mount.flat_depth
            if mount.housing:
                hub["housing"] = mount.housing
            hubs.append(hub)
        shafts.append({
            "name": shaft.name, "housing": shaft.housing, "side": shaft.side,
            "xy_mm": [float(v) for v in shaft.xy], "diameter_mm": shaft.diameter,
            "required_mm": shaft.required_diameter, "given": shaft.given,
            "core_mm": _core(shaft.diameter),
            "torque_nm": shaft.torque_nm, "bending_nmm": shaft.bending_nmm,
            "speed_rpm": shaft.speed_rpm, "length_mm": _length(shaft, stack),
            "extends_below_mm": shaft.extends_below, "extends_above_mm": shaft.extends_above,
            "strength_passed": shaft.strength_passed, "note": shaft.note, "hubs": hubs,
            "load_source": shaft.load_source, "sized_from": shaft.sized_from,
            "bore_mm": shaft.bore, "flange": shaft.flange,
            "coupling_key": None if shaft.coupling_key is None else {
                "designation": shaft.coupling_key.designation,
                "pressure_mpa": _finite(key_pressure(shaft.torque_nm * 1000.0, shaft.diameter,
                                                     shaft.coupling_key))}})
        for seat in shaft.seats:
            b = seat.bearing
            seats.append({
                "shaft": seat.shaft, "housing": seat.housing, "side": seat.side,
                "wall": seat.wall, "designation": b.designation, "d_mm": b.bore,
                "D_mm": b.outside, "B_mm": b.width, "C_kn": b.dynamic_load_kn,
                "C0_kn": b.static_load_kn, "seat_diameter_mm": seat.seat_diameter,
                "through": seat.through, "hole_diameter_mm": seat.hole_diameter,
                "count": seat.count,
                "load_n": seat.load_n, "speed_rpm": seat.speed_rpm,
                "l10_h": _finite(seat.life_h), "target_h": seat.life_min_h,
                "passed": seat.life_passed, "load_source": seat.load_source,
                **({} if seat.peak_load_n is None else {"peak_load_n": seat.peak_load_n})})
    stacks = {name: {"floor_wall_mm": s.floor_wall, "roof_wall_mm": s.roof_wall,
                     "cavity_height_mm": s.cavity_height, "parting_z_mm": s.parting_z,
                     "layers": [list(layer) for layer in s.layers]}
              for name, s in drivetrain.stacks.items()}
    return {"mechanism": drivetrain.mechanism, "process": drivetrain.process,
            "shafts": shafts, "bearings": seats, "stacks": stacks, "rules": drivetrain.rules,
            "fixings": fixings_report(drivetrain.fixings),
            "problems": [p.as_dict() for p in drivetrain.problems],
            "passed": not drivetrain.problems}
