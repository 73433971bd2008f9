"""Inverse dynamics of the pricking mechanism over one carrier turn.

:func:`pricking_dynamics` puts the model together (:mod:`cadgen.dynamics.pricking`: the gear
case, the intermediate and the planet with the rocker and needle; their pins and the two
non-circular meshes; :mod:`cadgen.dynamics.pricking_mass`: their masses), with gravity (the
mechanism's plane taken vertical, as the planting mechanism's), the soil's resistance on the
needle while it is in the soil, bearing and mesh friction, and solves it by both routes of
:mod:`kinematics.rigid_dynamics` at the file's carrier speed. It returns the planting path's
:class:`~cadgen.dynamics.analysis.DynamicsResult`, so report.json's ``dynamics``, the figures,
the summary line, the motor and the flywheel are the same code.

The input is the gear case (the transplanter's chain turns its sprocket at the carrier speed):
``input_torque`` is the torque on it in its own turning sense (positive drives it), so
``input_power = input_torque * omega`` whichever way the carrier turns. The grid is the
carrier progress from the outer (R max) dead centre, the solids' start pose.
"""

from __future__ import annotations

import math

import numpy as np

from kinematics.rigid_dynamics import (Model, kinetic_energy, potential_energy, power_balance,
                                       system_inverse)

from cadgen.dynamics.analysis import DynamicsResult, MeshLoad, _grid, _solve
from cadgen.dynamics.pricking import (CASE, PRICKING_MESHES, PRICKING_BODIES, pricking_bodies,
                                      pricking_joints, pricking_motion, soil_loads)

__all__ = ["pricking_dynamics", "CARRIER_ANGLE_LABEL"]

#: The figures' carrier-angle axis (the solids' and the clearance sweep's origin).
CARRIER_ANGLE_LABEL = "carrier turn after the outer (R max) dead centre (deg)"
#: Which body each gear of the meshes turns with (the sun: the frame).
_GEAR_BODY = {"sun": None, "intermediate 1": "intermediate", "intermediate 2": "intermediate",
              "planet": "planet"}


def _model(params, design, kinematics, masses, drivetrain, field, carrier_rpm):
    """``(Model, contacts, notes)`` at ``carrier_rpm``."""
    settings = params.dynamics
    omega = 2 * math.pi * carrier_rpm / 60.0
    journals = {s.name: s.diameter for s in drivetrain.shafts} if drivetrain is not None else {}
    revolutes, meshes, contacts = pricking_joints(
        kinematics, params.gears.pressure_angle_rad, design.modules, journals)
    loads, notes = [], []
    if drivetrain is None:
        notes.append("no drivetrain: the journals' diameters are unknown, no bearing friction")
    if settings.load_case == "planting":
        if field and settings.soil_force_n > 0:
            first = field[0]
            loads += soil_loads(design, kinematics, omega=omega,
                                # the chain turns the case from the ground wheel: the
                                # forward speed keeps its ratio to the carrier speed
                                forward_speed=params.field.forward_speed * carrier_rpm
                                / params.field.carrier_speed_rpm,
                                surface_level=first.surface_level,
                                inclination_deg=first.inclination_deg,
                                depth=params.field.depth, force_n=settings.soil_force_n)
            notes.append(f"soil at the first inclination, {first.inclination_deg:g} deg "
                         "(its surface line in the mechanism plane)")
        elif not field:
            notes.append("no soil (a bench run): no soil reaction")
    notes.append("gravity along -y: the mechanism's plane taken vertical (at an inclination "
                 "theta the in-plane part is g cos(theta), the rest loads the bearings axially)")
    model = Model(kinematics.progress, omega, pricking_bodies(kinematics, masses), revolutes,
                  meshes, CASE, tuple(loads))
    return model, contacts, notes


def pricking_dynamics(params, design, drivetrain, *, field=None, masses=None,
                      mass_source: str = "estimated", skipped=()) -> DynamicsResult:
    """Inverse dynamics of the pricking mechanism over one carrier turn.

    Parameters
    ----------
    params : PrickingParameters
    design : kinematics.pricking.PrickingDesign
    drivetrain : cadgen.machine.model.Drivetrain, optional
        Its shafts' diameters (bearing friction).
    field : list of kinematics.pricking_field.InclinationResult, optional
        The soil's surface (the first inclination's); None: a bench run, no soil.
    masses : dict, optional
        ``{body: BodyMass}`` (from the solids); None: estimated from the parameters.
    """
    from cadgen.dynamics.pricking_mass import estimated_pricking_masses

    if masses is None:
        masses, mass_source = estimated_pricking_masses(params, design), "estimated"
    settings = params.dynamics
    phi = _grid(settings.samples)
    kinematics = pricking_motion(design, phi)
    carrier_rpm = params.field.carrier_speed_rpm
    model, contacts, notes = _model(params, design, kinematics, masses, drivetrain, field,
                                    carrier_rpm)
    inverse = system_inverse(model)     # the geometry's: every speed and round shares it
    model, solution, rounds, change = _solve(params, model, inverse)
    power = power_balance(model)
    sense = kinematics.sense
    ne_power = solution.input_torque * sense * model.omega
    residual = ne_power - (power["kinetic_rate"] + power["potential_rate"] - power["load_power"])
    scale = max(float(np.max(np.abs(ne_power))), 1e-300)
    torque, power_torque = sense * solution.input_torque, sense * power["input_torque"]
    invalid = []
    if skipped:
        notes.append("solids left out of the masses: " + ", ".join(p for p, _ in skipped))
    if change > 1e-9:
        invalid.append(f"the meshes' separating forces and friction did not settle in "
                       f"{rounds} rounds (last relative change {change:.2g})")
    result = DynamicsResult(
        phi, carrier_rpm, carrier_rpm, torque, ne_power, power_torque,
        float(np.max(np.abs(residual))) / scale, float(np.max(np.abs(torque - power_torque))),
        solution.reactions, _mesh_loads(kinematics, model, solution, contacts),
        solution.shaking_force, solution.shaking_moment, kinetic_energy(model),
        potential_energy(model), mass_source, masses, settings.load_case, None, notes, rounds,
        invalid=invalid)
    result.sweep = _speed_sweep(params, design, kinematics, masses, drivetrain, field, inverse,
                                result)
    result.extra = _extra(design, kinematics, model, solution, field)
    return result


def _speed_sweep(params, design, kinematics, masses, drivetrain, field, inverse,
                 result) -> list:
    """``[(carrier rpm, peak |T|, RMS T, mean T)]`` over ``dynamics.speeds_rpm`` (the file's
    own speed is ``result``'s; the others' friction settled to 1e-9)."""
    rows = []
    for rpm in params.dynamics.speeds_rpm:
        if rpm == result.carrier_rpm:
            torque = result.input_torque
        else:
            model, _, _ = _model(params, design, kinematics, masses, drivetrain, field, rpm)
            torque = kinematics.sense * _solve(params, model, inverse, rtol=1e-9)[1].input_torque
        rows.append((float(rpm), float(np.max(np.abs(torque))),
                     float(np.sqrt(np.mean(torque ** 2))), float(np.mean(torque))))
    return rows


def _mesh_loads(kinematics, model, solution, contacts) -> dict:
    """Each mesh's :class:`~cadgen.dynamics.analysis.MeshLoad`, keyed ``(driver, driven, 0)``:
    the normal force, the contact's radius and polar angle in each gear's own frame (as it
    sits at the start pose) and ``pitch_parameter`` the pair's cycle parameter ``tau`` (the
    gear train's :class:`~cadgen.gears.pairs.PitchPair`'s, the tooth strength's pose)."""
    out = {}
    for pair, (centre_driver, centre_driven, point) in contacts.items():
        angles, radii = {}, {}
        for gear, centre in zip(pair, (centre_driver, centre_driven)):
            body = _GEAR_BODY[gear]
            turned = kinematics.angles[body][0] if body else 0.0
            offset = point - centre
            angles[gear] = np.mod(np.arctan2(offset[:, 1], offset[:, 0]) - turned, 2 * math.pi)
            radii[gear] = np.linalg.norm(offset, axis=1)
        out[(*pair, 0)] = MeshLoad(pair, 0, solution.mesh_forces[pair], angles, radii,
                                   solution.mesh_directions[pair], kinematics.tau)
    assert set(PRICKING_MESHES) == {key[:2] for key in out}
    return out


def _extra(design, kinematics, model, solution, field) -> dict:
    """The pricking section's own keys: the axis label and events of the figures, the torque
    the frame bracket's key holds on the sun (the stage-1 tooth force's moment about O)."""
    mesh = model.meshes[0]
    force = solution.mesh_forces[mesh.name][:, None] * solution.mesh_directions[mesh.name]
    # the sun gets -force at the pitch point; the bracket's key holds it with the opposite
    # moment about O (+z, N m)
    arm = mesh.point - np.asarray(design.linkage.centre, dtype=float) * 1e-3
    sun_torque = arm[:, 0] * force[:, 1] - arm[:, 1] * force[:, 0]
    tip_height = design.motion.curve(design.motion.u(kinematics.v))[:, 1]
    events = {"outer dead centre": 0.0,
              "lowest point": float(np.degrees(kinematics.progress[np.argmin(tip_height)]))}
    if field:
        events["soil entry"] = float(field[0].entry_progress_deg) % 360.0
        events["soil exit"] = float(field[0].exit_progress_deg) % 360.0
    return {"mechanism": "pricking", "bodies": list(PRICKING_BODIES),
            "carrier_angle_label": CARRIER_ANGLE_LABEL, "events_deg": events,
            "sun_holding_torque_nm": [float(f"{t:.6g}") for t in sun_torque],
            "sun_holding_torque_peak_nm": float(np.max(np.abs(sun_torque)))}
