"""Inverse dynamics of the planting mechanism over one carrier turn, and what it sizes.

:func:`planting_dynamics` puts the model together (:mod:`cadgen.dynamics.planting`: bodies,
pins and meshes; :mod:`cadgen.dynamics.mass`: their masses; :mod:`cadgen.dynamics.loads`:
cam, seedling, soil), solves it by both routes of :mod:`kinematics.rigid_dynamics` at the
file's carrier speed, and returns a :class:`DynamicsResult`; :func:`dynamics_report` is
report.json's ``dynamics``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from kinematics.rigid_dynamics import Model, newton_euler, power_balance, system_inverse

from cadgen.dynamics.planting import angle_law, planting_bodies, planting_joints
from cadgen.dynamics.loads import (cam_contact, cam_contact_loads, seedling_loads,
                                   soil_loads)

__all__ = ["MeshLoad", "DynamicsResult", "planting_dynamics", "dynamics_report",
           "motor_and_flywheel", "ENERGY_BALANCE_RTOL"]

#: The two routes (power balance, Newton-Euler) must agree within this, relative to the
#: peak input power: both are exact up to rounding.
ENERGY_BALANCE_RTOL = 1e-6


@dataclass(frozen=True)
class MeshLoad:
    """One gear mesh over the carrier-angle grid (see :mod:`cadgen.dynamics`)."""

    gears: tuple                # (driver, driven): the gear train's pair names
    side: int                   # 1, 2: arm; 0: the drive (one for the machine)
    normal_force_n: np.ndarray  # (n,) along the line of action, >= 0
    contact_angle: dict         # {gear: (n,) polar angle of the contact in its own frame, rad}
    contact_radius: dict        # {gear: (n,) distance of the contact from its axis, mm}
    line_of_action: np.ndarray | None = None    # (n, 2) unit: the force's sense on the driven gear
    pitch_parameter: np.ndarray | None = None   # (n,) t of r1(t): the non-circular pair


@dataclass
class DynamicsResult:
    """What the dynamics found over one carrier turn (SI units, angles in rad)."""

    phi: np.ndarray
    carrier_rpm: float
    input_rpm: float
    input_torque: np.ndarray          # N m on the input shaft (Newton-Euler)
    input_power: np.ndarray           # W
    power_route_torque: np.ndarray    # N m (power balance)
    energy_balance_max_rel: float
    route_disagreement_nm: float
    bearings: dict                    # {pin: (n, 2) N on its body}
    meshes: dict                      # {(driver, driven, side): MeshLoad}
    shaking_force: np.ndarray         # (n, 2) N on the frame
    shaking_moment: np.ndarray        # (n,) N m about O on the frame
    kinetic_energy: np.ndarray        # (n,) J
    potential_energy: np.ndarray      # (n,) J
    mass_source: str                  # "solids" or "estimated"
    masses: dict                      # {body: BodyMass}
    load_case: str
    cam: object = None                # CamContact or None
    notes: list = field(default_factory=list)
    friction_rounds: int = 0
    sweep: list = field(default_factory=list)   # [(rpm, peak |T|, rms T)]
    invalid: list = field(default_factory=list)  # what falls outside the model's validity
    #: the gears' tooth strength under these loads (machine.gear_strength), when cut
    strength: object = None
    extra: dict = field(default_factory=dict)    # a mechanism's own report keys (pricking)

    def stats(self, values) -> dict:
        values = np.asarray(values, dtype=float)
        peak = int(np.argmax(np.abs(values)))
        return {"peak": float(abs(values[peak])), "peak_at_deg": float(np.degrees(self.phi[peak])),
                "rms": float(np.sqrt(np.mean(values ** 2))), "mean": float(np.mean(values)),
                "min": float(values.min()), "max": float(values.max())}


def _grid(samples: int) -> np.ndarray:
    return np.linspace(0.0, 2 * math.pi, int(samples), endpoint=False)


def _model(params, mechanism, masses, drivetrain, cam, events, phi, carrier_rpm):
    """``(Model, CamContact or None, notes)`` at ``carrier_rpm``."""
    from cadgen.gears.circular import planting_modules

    settings = params.dynamics
    drive = drivetrain.drive
    omega = 2 * math.pi * carrier_rpm / 60.0
    input_xy = next(s.xy for s in drivetrain.shafts if s.name == "input")
    alpha = params.gears.pressure_angle_rad
    modules = planting_modules(mechanism, params.pitch_curve.teeth, params.gears.circular_module)
    journals = {s.name: s.diameter for s in drivetrain.shafts if s.side in (1, None)}
    bodies = planting_bodies(mechanism, masses, phi, drive, input_xy)
    revolutes, meshes, contacts = planting_joints(mechanism, phi, drive, input_xy, alpha,
                                                  modules, journals)
    loads, notes, contact = [], [], None
    if settings.load_case == "planting":
        contact, why = cam_contact(params, mechanism, cam, drivetrain, phi, carrier_rpm)
        if contact is None:
            notes.append(f"cam contact left out: {why}")
        else:
            loads += cam_contact_loads(contact)
        release = (cam.timing.opening[0] if cam is not None else
                   events.lowest if events is not None else None)
        if release is not None and settings.seedling_mass_kg > 0:
            loads += seedling_loads(mechanism, phi, omega, settings.seedling_mass_kg, release)
        if events is not None and settings.soil_force_n > 0:
            spacing = settings.plant_spacing or params.field.plant_spacings[0]
            loads += soil_loads(mechanism, phi, events.soil_level, params.field.depth, spacing,
                                settings.soil_force_n)
        elif events is None:
            notes.append("no soil (a bench run): no soil reaction")
    model = Model(phi, omega, bodies, revolutes, meshes, "input", tuple(loads))
    return model, contact, contacts, notes


def _solve(params, model, inverse, rtol: float = 1e-13):
    """``(model with its friction couples, solution, rounds, last change)``."""
    settings = params.dynamics
    friction = settings.load_case == "planting"
    solution, model, rounds, change = newton_euler(
        model, inverse=inverse, bearing_friction=settings.bearing_friction if friction else 0.0,
        mesh_friction=settings.mesh_friction if friction else 0.0, rtol=rtol)
    return model, solution, rounds, change


def planting_dynamics(params, mechanism, drivetrain, *, cam=None, events=None, masses=None,
                      mass_source: str = "estimated", skipped=()) -> DynamicsResult:
    """Inverse dynamics of the planting mechanism over one carrier turn.

    Parameters
    ----------
    params : PlantingParameters
    mechanism : kinematics.planting.PlantingMechanism
    drivetrain : cadgen.machine.model.Drivetrain
        Its drive (the input), shafts (journals, the input's axis) and the duckbill's spring.
    cam : cadgen.cam.design.CamDesign, optional
    events : kinematics.metrics.PlantEvents, optional
        The soil level and the lowest point (None: a bench run, no soil).
    masses : dict, optional
        ``{body: BodyMass}`` (from the solids); None: estimated from the parameters.
    """
    from cadgen.dynamics.mass import estimated_mass_properties

    if drivetrain.drive is None:
        raise ValueError("the dynamics need the drive (the drivetrain's input shaft)")
    if masses is None:
        masses, mass_source = estimated_mass_properties(params, mechanism,
                                                        drivetrain.drive), "estimated"
    settings = params.dynamics
    phi = _grid(settings.samples)
    carrier_rpm = params.field.carrier_speed_rpm
    model, contact, contacts, notes = _model(params, mechanism, masses, drivetrain, cam, events,
                                             phi, carrier_rpm)
    inverse = system_inverse(model)     # the geometry's: every speed and round shares it
    model, solution, rounds, change = _solve(params, model, inverse)
    power = power_balance(model)
    rate = model.body("input").angle_rate * model.omega
    ne_power = solution.input_torque * rate
    residual = ne_power - (power["kinetic_rate"] + power["potential_rate"] - power["load_power"])
    scale = max(float(np.max(np.abs(ne_power))), 1e-300)
    invalid = []
    if skipped:
        notes.append("solids left out of the masses: " + ", ".join(p for p, _ in skipped))
    if contact is not None and np.any(contact.force < 0):
        invalid.append("the cam's roller lifts off (negative contact force): the spring is "
                       "too weak at this speed; its loads past lift-off are not modelled")
    if change > 1e-9:
        invalid.append(f"the meshes' separating forces and friction did not settle in "
                       f"{rounds} rounds (last relative change {change:.2g})")
    meshes = _mesh_loads(mechanism, drivetrain.drive, model, solution, contacts)
    result = DynamicsResult(
        phi, carrier_rpm, carrier_rpm * float(rate[0]) / model.omega, solution.input_torque,
        ne_power, power["input_torque"], float(np.max(np.abs(residual))) / scale,
        float(np.max(np.abs(solution.input_torque - power["input_torque"]))),
        solution.reactions, meshes, solution.shaking_force, solution.shaking_moment,
        _kinetic(model), _potential(model), mass_source, masses, settings.load_case, contact,
        notes, rounds, invalid=invalid)
    result.sweep = _speed_sweep(params, mechanism, masses, drivetrain, cam, events, phi,
                                inverse, result)
    return result


def _kinetic(model):
    from kinematics.rigid_dynamics import kinetic_energy

    return kinetic_energy(model)


def _potential(model):
    from kinematics.rigid_dynamics import potential_energy

    return potential_energy(model)


def _speed_sweep(params, mechanism, masses, drivetrain, cam, events, phi, inverse,
                 result) -> list:
    """``[(carrier rpm, peak |T_in|, RMS T_in, mean T_in)]`` over ``dynamics.speeds_rpm``
    (the file's own speed is ``result``'s; the others' friction settled to 1e-9)."""
    rows = []
    for rpm in params.dynamics.speeds_rpm:
        if rpm == result.carrier_rpm:
            torque = result.input_torque
        else:
            model, _, _, _ = _model(params, mechanism, masses, drivetrain, cam, events, phi, rpm)
            torque = _solve(params, model, inverse, rtol=1e-9)[1].input_torque
        rows.append((float(rpm), float(np.max(np.abs(torque))),
                     float(np.sqrt(np.mean(torque ** 2))), float(np.mean(torque))))
    return rows


def _mesh_loads(mechanism, drive, model, solution, contacts) -> dict:
    """Every mesh's :class:`MeshLoad`: its normal force and where the contact sits on each
    gear (the polar angle in the gear's own frame, its frame at the catching pose)."""
    from cadgen.dynamics.planting import MESH_GEARS, _split

    out = {}
    phi = model.phi
    by_name = {m.name: m for m in model.meshes}
    for key, (centre_driver, centre_driven, point) in contacts.items():
        driver_gear, driven_gear, side = key
        mesh = by_name[key]
        angles, radii = {}, {}
        for gear, body, centre in ((driver_gear, mesh.driver, centre_driver),
                                   (driven_gear, mesh.driven, centre_driven)):
            kind, arm = _split(body)
            turned = angle_law(mechanism, kind, phi, arm, drive)[0]
            offset = point - centre
            angles[gear] = np.mod(np.arctan2(offset[:, 1], offset[:, 0]) - turned, 2 * math.pi)
            radii[gear] = np.linalg.norm(offset, axis=1)
        parameter = (np.mod(phi + math.pi * (side - 1), 2 * math.pi)
                     if (driver_gear, driven_gear) == ("central", "intermediate") else None)
        out[key] = MeshLoad((driver_gear, driven_gear), side, solution.mesh_forces[key], angles,
                            radii, solution.mesh_directions[key], parameter)
    assert set(MESH_GEARS) <= {k[:2] for k in out}
    return out


def motor_and_flywheel(result: DynamicsResult, params) -> dict:
    """The motor's rated torque and power covering the RMS and the peak, and the flywheel
    holding the speed fluctuation ``Cs``: ``I = dE / (Cs omega^2)``, ``dE`` the largest swing
    of the input work less its mean over the turn (rectangle rule on the uniform grid)."""
    settings = params.dynamics
    torque = result.input_torque
    rms = float(np.sqrt(np.mean(torque ** 2)))
    peak = float(np.max(np.abs(torque)))
    rated = max(settings.rms_margin * rms, peak / settings.overload_ratio)
    omega_in = 2 * math.pi * result.input_rpm / 60.0
    omega = 2 * math.pi * result.carrier_rpm / 60.0
    step = (2 * math.pi / len(result.phi)) / omega
    work = np.cumsum((result.input_power - result.input_power.mean()) * step)
    swing = float(work.max() - work.min())
    return {"rated_torque_nm": rated, "rated_power_w": rated * abs(omega_in),
            "rms_margin": settings.rms_margin, "overload_ratio": settings.overload_ratio,
            "rule": "rated >= rms_margin x RMS and peak <= overload_ratio x rated",
            "flywheel": {"energy_swing_j": swing, "speed_fluctuation": settings.speed_fluctuation,
                         "inertia_on_input_kgm2": swing / (settings.speed_fluctuation
                                                           * omega_in ** 2),
                         "inertia_on_carrier_kgm2": swing / (settings.speed_fluctuation
                                                             * omega ** 2),
                         "rule": "I = dE / (Cs omega^2)"}}


def _round(values, digits: int = 6):
    values = np.asarray(values, dtype=float)
    return [float(f"{v:.{digits}g}") for v in values.ravel()] if values.ndim == 1 else \
        [[float(f"{v:.{digits}g}") for v in row] for row in values]


def dynamics_report(result: DynamicsResult, params) -> dict:
    """report.json's ``dynamics``: arrays over the carrier-angle grid and the summary (made
    once per result: the figures and the report read the same)."""
    if getattr(result, "_section", None) is not None:
        return result._section
    result._section = _section(result, params)
    return result._section


def _section(result: DynamicsResult, params) -> dict:
    torque, power = result.stats(result.input_torque), result.stats(result.input_power)
    shaking = np.linalg.norm(result.shaking_force, axis=1)
    bearing_peak = {name: float(np.max(np.linalg.norm(f, axis=1)))
                    for name, f in result.bearings.items()}
    mesh_peak = {_mesh_label(k): float(m.normal_force_n.max()) for k, m in result.meshes.items()}
    out = {
        "modelled": True, "load_case": result.load_case,
        "mass_properties_source": result.mass_source,
        "carrier_speed_rpm": result.carrier_rpm, "input_speed_rpm": result.input_rpm,
        "samples": len(result.phi),
        "carrier_angle_deg": _round(np.degrees(result.phi)),
        "input_torque_nm": _round(result.input_torque),
        "input_power_w": _round(result.input_power),
        "bearing_force_n": {name: _round(np.linalg.norm(f, axis=1), 5)
                            for name, f in result.bearings.items()},
        "mesh_normal_force_n": {_mesh_label(k): _round(m.normal_force_n, 5)
                                for k, m in result.meshes.items()},
        "shaking_force_n": _round(result.shaking_force, 5),
        "shaking_moment_nm": _round(result.shaking_moment, 5),
        "summary": {
            "input_torque_nm": torque, "input_power_w": power,
            "carrier_equivalent_torque_nm": {
                k: v * result.input_rpm / result.carrier_rpm if k != "peak_at_deg" else v
                for k, v in torque.items()},
            "bearing_force_peak_n": bearing_peak, "mesh_normal_force_peak_n": mesh_peak,
            "shaking_force_peak_n": float(shaking.max()),
            "shaking_moment_peak_nm": float(np.max(np.abs(result.shaking_moment))),
            "kinetic_energy_range_j": [float(result.kinetic_energy.min()),
                                       float(result.kinetic_energy.max())],
        },
        "energy_balance_max_rel": result.energy_balance_max_rel,
        "route_disagreement_nm": result.route_disagreement_nm,
        "route_disagreement_rel": result.route_disagreement_nm / max(torque["peak"], 1e-300),
        "friction_rounds": result.friction_rounds,
        "speed_sweep": [{"carrier_rpm": rpm, "peak_torque_nm": peak, "rms_torque_nm": rms,
                         "mean_torque_nm": mean} for rpm, peak, rms, mean in result.sweep],
        "motor": motor_and_flywheel(result, params),
        "masses": {name: {"mass_kg": m.mass, "inertia_kgm2": m.inertia * 1e-6,
                          "centre_mm": [float(v) for v in m.centre]}
                   for name, m in sorted(result.masses.items())},
        "notes": list(result.notes), "outside_validity": list(result.invalid),
        "passed": result.energy_balance_max_rel <= ENERGY_BALANCE_RTOL and not result.invalid,
    }
    out.update(result.extra)
    if result.cam is not None:
        force, _, _, spring = result.cam.arm(0)
        out["cam_contact_force_n"] = _round(force, 5)
        out["spring_force_n"] = _round(spring, 5)
    return out


def _mesh_label(key) -> str:
    driver, driven, side = key
    return f"{driver} / {driven}" + (f" (arm {side})" if side else "")
