"""A built drivetrain checked again under other loads over the turn: keys, shaft stress, bearing life.

The drivetrain is sized before the solids exist, from the dynamics with masses estimated from
the parameters (:mod:`cadgen.machine.cycle_loads`). Once the solids are built the dynamics run
again with their masses; :func:`recheck` takes those loads and checks the machine as built
(every diameter, key, bearing and flange as chosen, nothing re-chosen) by the sizing's own
rules: the shaft's strength (its core under the keyseat against the diameter the loads need),
every key's flank pressure (the gears', the coupling's, the planter's hub), the carrying
flanges' screws, every bearing's ISO 281 life with the cycle-equivalent load. What no longer
passes is a :class:`kinematics.errors.Problem` at the field to change, as the drivetrain's
own checks are: the build fails. The records then carry the re-checked loads, torques and
lives, each saying which load it came from.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from kinematics.errors import Problem

from cadgen.machine.bearings import l10_hours
from cadgen.machine.cycle_loads import equivalent_load, with_cycles
from cadgen.machine.fastening import flange_problems
from cadgen.machine.fits import process_fits
from cadgen.machine.shafts import key_pressure

__all__ = ["recheck"]


def _widths(shaft) -> tuple:
    """The built bearings' widths, floor and roof (a roof pair: one seat of two)."""
    widths = tuple(seat.bearing.width for seat in shaft.seats)
    return widths * 2 if len(widths) == 1 else widths


def recheck(params, design, built, cycles: dict, source: str):
    """``built`` (a :class:`~cadgen.machine.model.Drivetrain`) checked under ``cycles``.

    Parameters
    ----------
    params : PlantingParameters
    design : kinematics.planting.PlantingMechanism
    built : Drivetrain
        As :func:`cadgen.machine.drivetrain.drivetrain` sized it.
    cycles : dict
        ``{axis: CycleLoads}``, the loads to check with.
    source : str
        What they came from (``cycle_loads.SOLID_MASSES``), for the records and messages.

    Returns
    -------
    Drivetrain
        ``built`` with each re-checked shaft's torque, bending, required diameter, hub torques
        and bearing loads and lives from ``cycles``, and the problems of what fails added.
    """
    from cadgen.machine.drivetrain import _core, _size
    from cadgen.machine.layouts import planting_axes

    machine = params.machine
    axes, cavities, _, bases, _ = planting_axes(params, design, built.drive)
    axes = with_cycles(axes, cycles, machine.service_factor)
    walls = {name: (stack.floor_wall, stack.roof_wall) for name, stack in built.stacks.items()}
    base = bases(walls)
    clearance = process_fits(params.manufacturing.process).running_clearance
    shafts = {(s.name, s.side): s for s in built.shafts}
    sized, problems = {}, []
    for axis in axes:
        shaft = shafts[axis.name, axis.side]
        if axis.loads.cycle is None:
            continue
        inner = sized.get((axis.inside, axis.side)) if axis.inside else None
        size = _size(axis, cavities, walls, base, _widths(shaft), shaft.diameter, machine,
                     inner, clearance)
        sized[axis.name, axis.side] = size
        updated, found = _checked(axis, shaft, size, machine, source, _core(shaft.diameter))
        shafts[axis.name, axis.side] = updated
        if axis.side == 1:   # side 2 is side 1 half a turn later: the same figures
            problems += found
    planter, found = _planter_hub(built.fixings.get("planter"), shafts.get(("E", 1)), machine,
                                  source)
    problems += found
    fixings = dict(built.fixings)
    if planter is not None:
        fixings["planter"] = planter
    rules = dict(built.rules)
    rules["recheck"] = {"load_source": source, "passed": not problems,
                        "problems": [p.as_dict() for p in problems]}
    return dataclasses.replace(built, shafts=tuple(shafts[s.name, s.side] for s in built.shafts),
                               problems=tuple(built.problems) + tuple(problems), rules=rules,
                               fixings=fixings)


def _checked(axis, shaft, size, machine, source, core) -> tuple:
    """``(the shaft's record under the new loads, problems)``."""
    where = f"shaft {axis.name}, re-checked with the {source}"
    problems = []
    if core < size.required - 1e-9:
        problems.append(Problem(
            f"machine.shafts.{axis.name}", "shaft_too_weak",
            f"{where}: {shaft.diameter:g} mm (core {core:.1f} mm) is below the "
            f"{size.required:.1f} mm its torque of {axis.loads.torque_nmm / 1000:.1f} N m and "
            f"bending of {size.bending / 1000:.1f} N m need: give machine.shafts.{axis.name}"))
    mounts = []
    for mount in shaft.mounts:
        load = axis.loads.gears[mount.gear]
        changes = {"torque_nm": load.torque_nmm / 1000.0, "radial_load_n": load.radial_n}
        if mount.bearing is not None:   # a free gear: its two bearings' life
            cycle = axis.loads.cycle
            each = equivalent_load(np.linalg.norm(cycle.forces[mount.gear], axis=-1),
                                   cycle.free_speed[mount.gear]) / 2
            changes["life_h"] = l10_hours(mount.bearing.dynamic_load_kn, each, mount.speed_rpm)
            if changes["life_h"] < machine.bearing_life_min_h:
                problems.append(Problem(
                    "machine.bearing_life_min_h", "bearing_life_short",
                    f"{where}: the {mount.gear} gear's bearings {mount.bearing.designation}: "
                    f"L10h {changes['life_h']:.0f} h is below {machine.bearing_life_min_h:g} h"))
        elif mount.key is not None:
            pressure = key_pressure(load.torque_nmm, shaft.diameter, mount.key)
            if pressure > machine.key_pressure_mpa:
                problems.append(Problem(
                    "gears.face_width", "key_overloaded",
                    f"{where}: the key of the gear {mount.gear!r} ({mount.key.designation}) "
                    f"carries {load.torque_nmm / 1000:.1f} N m at {pressure:.0f} MPa, above "
                    f"machine.key_pressure_mpa = {machine.key_pressure_mpa:g} MPa"))
        mounts.append(dataclasses.replace(mount, **changes))
    if shaft.coupling_key is not None:
        pressure = key_pressure(axis.loads.torque_nmm, shaft.diameter, shaft.coupling_key)
        if pressure > machine.key_pressure_mpa:
            problems.append(Problem(
                f"machine.shafts.{axis.name}", "key_overloaded",
                f"{where}: the coupling key ({shaft.coupling_key.designation}) carries "
                f"{axis.loads.torque_nmm / 1000:.1f} N m at {pressure:.0f} MPa, above "
                f"machine.key_pressure_mpa = {machine.key_pressure_mpa:g} MPa"))
    flange = shaft.flange
    if flange is not None:
        flange = dict(flange)
        problems += flange_problems(f"shaft {axis.name} ({source})", flange["carries"],
                                    axis.loads.torque_nmm, flange)
    speed = axis.loads.speed_rpm
    lives = [l10_hours(seat.bearing.dynamic_load_kn, load, speed)
             for seat, load in zip(shaft.seats * 2, size.reactions)]
    seats = []
    for k, seat in enumerate(shaft.seats):
        # a roof pair's seat speaks for its more loaded bearing
        worst = max(range(len(size.reactions)), key=lambda j: size.reactions[j]) \
            if seat.count == 2 else k
        seats.append(dataclasses.replace(
            seat, load_n=float(size.reactions[worst]), life_h=lives[worst], speed_rpm=speed,
            load_source=source, peak_load_n=float(size.peak[worst])))
        if lives[worst] < machine.bearing_life_min_h:
            problems.append(Problem(
                "machine.bearing_life_min_h", "bearing_life_short",
                f"{where}, {seat.wall} bearing {seat.bearing.designation}: L10h "
                f"{lives[worst]:.0f} h under an equivalent {size.reactions[worst]:.0f} N at "
                f"{speed:.1f} r/min is below {machine.bearing_life_min_h:g} h"))
    return dataclasses.replace(
        shaft, required_diameter=size.required, torque_nm=axis.loads.torque_nmm / 1000.0,
        bending_nmm=size.bending, speed_rpm=speed, mounts=tuple(mounts), seats=tuple(seats),
        flange=flange, load_source=source), problems


def _planter_hub(hub, shaft, machine, source) -> tuple:
    """The planter's keyed hub on shaft E under the re-checked torque."""
    if hub is None or shaft is None or hub.get("key") is None:
        return hub, []
    hub = dict(hub, torque_nm=shaft.torque_nm,
               pressure_mpa=key_pressure(shaft.torque_nm * 1000.0, hub["diameter"], hub["key"]))
    if hub["pressure_mpa"] <= machine.key_pressure_mpa:
        return hub, []
    return hub, [Problem("planter.arm_thickness", "key_overloaded",
                         f"the key of the planter on shaft E ({hub['key'].designation}), "
                         f"re-checked with the {source}: {shaft.torque_nm:.1f} N m at "
                         f"{hub['pressure_mpa']:.0f} MPa, above machine.key_pressure_mpa = "
                         f"{machine.key_pressure_mpa:g} MPa")]
