"""How parts are held on a shaft beyond its keyed hubs: gears running free on their own bearings,
the bolted flange a hollow shaft carries a housing with, the key of a stub's coupling.

Each rule gives the part's size and the problems of its check (kinematics.errors.Problem),
reported only for side 1 of an axis that exists on both (``report``). Numbers only.
"""

from __future__ import annotations

import math

import numpy as np

from kinematics.errors import Problem

from cadgen.machine.bearings import journal_bore, select_bearing
from cadgen.machine.catalogue import CatalogueError, socket_screw
from cadgen.machine.shafts import hub_key, key_pressure

__all__ = ["free_bearing", "flange_problems", "coupling_key", "bolt_circle", "STUB_CHAMFER",
           "FLANGE_SHEAR_ALLOW"]

#: The stub's chamfer at each end of a coupling's hub (mm): the key is no longer than the rest.
STUB_CHAMFER = 2.0
#: The carrying flange's screws (8.8): allowed shear stress, MPa.
FLANGE_SHEAR_ALLOW = 190.0


def free_bearing(axis, gear, face, d, machine, report):
    """The bearing a free gear runs on (two side by side in its hub), its life and problems."""
    load = axis.loads.gears[gear].radial_n
    speed = axis.loads.free_speeds.get(gear, 0.0) if hasattr(axis.loads, "free_speeds") else 0.0
    cycle = axis.loads.cycle
    if cycle is not None:   # the dynamics': ISO 281's equivalent of its tooth forces
        from cadgen.machine.cycle_loads import equivalent_load

        load = equivalent_load(np.linalg.norm(cycle.forces[gear], axis=-1),
                               cycle.free_speed[gear])
    bearing, life, passed = select_bearing(journal_bore(d), load / 2, speed,
                                           machine.bearing_life_min_h)
    problems = []
    if report and 2 * bearing.width > face + 1e-9:
        problems.append(Problem("gears.face_width", "free_gear_too_narrow",
                                f"the {gear} gear runs free on shaft {axis.name} on two "
                                f"{bearing.designation} bearings ({2 * bearing.width:g} mm side by "
                                f"side), wider than its {face:g} mm face: widen gears.face_width"))
    if report and not passed:
        problems.append(Problem("machine.bearing_life_min_h", "bearing_life_short",
                                f"the {gear} gear's bearings {bearing.designation} on shaft "
                                f"{axis.name}: L10h {life:.0f} h is below "
                                f"{machine.bearing_life_min_h:g} h"))
    return bearing, speed, life, problems


def bolt_circle(bolted: dict, centre=(0.0, 0.0)) -> list:
    """``[(x, y), ...]`` of the screws of a bolted joint (a carrying flange, a sprocket): its
    ``bolts`` evenly on ``bolt_circle_radius`` about ``centre``, the first at ``bolt_phase``
    (rad, default 0) from +x. One rule for the holes in both parts it joins."""
    count, radius = int(bolted["bolts"]), float(bolted["bolt_circle_radius"])
    phase = float(bolted.get("bolt_phase", 0.0))
    return [(centre[0] + radius * math.cos(phase + 2 * math.pi * k / count),
             centre[1] + radius * math.sin(phase + 2 * math.pi * k / count))
            for k in range(count)]


def flange_problems(name: str, carries: str, torque_nmm: float, flange: dict, *,
                    path: str = "machine.shafts", code: str = "flange_bolts_overloaded") -> list:
    """A carrying flange's screws in shear: ``tau = T / (n A_s r)`` (each screw at the bolt circle
    radius ``r``) against ``FLANGE_SHEAR_ALLOW``, about half an 8.8 screw's shear yield (0.577 x
    640 MPa), the service factor already in T. The result rides on ``flange``; a problem is
    reported at ``path`` with ``code`` (a plate screwed on, the cam, says its own)."""
    # ISO 898-1's stress area: pi / 4 ((d2 + d3) / 2)^2, d2 = d - 0.6495 P, d3 = d - 1.2269 P
    bolt, pitch = float(flange["bolt"].removeprefix("M")), socket_screw(flange["bolt"])["pitch"]
    area = math.pi / 4 * ((2 * bolt - 1.8764 * pitch) / 2) ** 2
    flange["stress_area_mm2"] = area
    stress = torque_nmm / (flange["bolts"] * area * flange["bolt_circle_radius"])
    flange["bolt_shear_mpa"] = stress
    flange["bolt_shear_allow_mpa"] = FLANGE_SHEAR_ALLOW
    if stress <= FLANGE_SHEAR_ALLOW:
        return []
    return [Problem(path, code,
                    f"the flange of {name} ({flange['bolts']} x {flange['bolt']}) "
                    f"carrying {carries} shears its screws at {stress:.0f} MPa, above "
                    f"{FLANGE_SHEAR_ALLOW:g} MPa")]


def coupling_key(axis, d: float, stub: float, machine, report: bool) -> tuple:
    """The DIN 6885 key of a shaft's stub (the sprocket's or coupling's hub is the stub less a
    chamfer each end, ``STUB_CHAMFER``), and its flank pressure under the shaft's torque."""
    try:
        key = hub_key(d, stub - 2 * STUB_CHAMFER)
    except CatalogueError as error:
        return None, ([Problem(f"machine.shafts.{axis.name}", "coupling_without_key",
                               f"the {d:g} mm stub of shaft {axis.name} takes no key: {error}")]
                      if report else [])
    if key is None or not report:
        return key, []
    pressure = key_pressure(axis.loads.torque_nmm, d, key)
    if pressure <= machine.key_pressure_mpa:
        return key, []
    return key, [Problem(f"machine.shafts.{axis.name}", "key_overloaded",
                         f"the coupling key of shaft {axis.name} ({key.designation}) carries "
                         f"{axis.loads.torque_nmm / 1000:.1f} N m at {pressure:.0f} MPa, above "
                         f"machine.key_pressure_mpa = {machine.key_pressure_mpa:g} MPa")]


