"""What the dynamics' loads feed: the drivetrain sized from them, and re-checked with the solids.

The dynamics model needs the drivetrain (the drive's gears, the input's axis, the journals'
diameters for bearing friction, the duckbill's spring), so the drivetrain cannot wait for it:

1. the drivetrain is sized from the assumed tip force (:mod:`cadgen.machine.loads`);
2. the dynamics run over a carrier turn with masses estimated from the parameters (the masses
   do not depend on the shafts: :mod:`cadgen.dynamics.mass`);
3. the drivetrain is sized again from those loads (:func:`size_from_dynamics`); should that
   change the drive's gears (their rims clear the hubs of the shafts just sized), steps 2-3
   run again on the new drive, at most ``SIZING_ROUNDS`` times;
4. after the solids, the dynamics stage runs with their masses and :func:`recheck_drivetrain`
   checks keys, shaft stress and bearing lives under those loads, failing what no longer
   passes.

:func:`axis_cycles` reads each shaft's loads off a :class:`DynamicsResult`: each gear's tooth
forces (every mesh's normal force along its line of action, at its pitch point) and their
moments about the gear's axis, the body's pin reaction (the planar resultant of the shaft's
two bearings) and the shaft's speed relative to its housing from the kinematics' angle laws.
"""

from __future__ import annotations

import numpy as np

from kinematics.rigid_dynamics import FRAME

from cadgen.machine.cycle_loads import ESTIMATED_MASSES, SOLID_MASSES, CycleLoads

__all__ = ["GEAR_AXIS", "AXIS_BODY", "axis_cycles", "size_from_dynamics",
           "recheck_drivetrain", "SIZING_ROUNDS"]

#: Rounds of sizing and dynamics while the drive's gears change (each one a new drive).
SIZING_ROUNDS = 3
#: The axis each gear of the planting machine turns on (the gear train's names).
GEAR_AXIS = {"sun": "O", "sun I": "O", "central shaft gear": "O", "idler 1": "A",
             "idler 1-I": "A", "idler 2": "B", "idler 2-I": "B", "train-1 planet": "C",
             "planet I": "C2", "central": "C2", "intermediate": "D", "gear D": "D",
             "planet gear E": "E", "transmission driven gear": "S", "input gear 1": "input",
             "input gear 2": "input"}
#: Each axis's dynamics body (the shaft and what is keyed or bolted to it; arm 1's for the
#: carrier's axes) and the body its bearings sit in (the speed is relative to it).
AXIS_BODY = {"O": ("central shaft", FRAME), "S": ("carrier", FRAME), "input": ("input", FRAME),
             "A": ("idler A 1", "carrier"), "B": ("idler B 1", "carrier"),
             "C": ("gearbox 2 1", "carrier"), "C2": ("central gear 1", "carrier"),
             "D": ("intermediate 1", "gearbox 2 1"), "E": ("planter 1", "gearbox 2 1")}
#: The free-running pair of each idler axis: the two bodies whose relative speed their
#: bearings turn at (either idler may be the free one: the layout chooses).
FREE_PAIR = {"A": ("idler A 1", "idler A-I 1"), "B": ("idler B 1", "idler B-I 1")}
#: Axes both arms load (the carrier's and the frame's); the others are arm 1's (arm 2 is arm
#: 1 half a turn later: the same peaks and equivalent loads).
MACHINE_AXES = ("O", "S", "input")


def _rate(mechanism, body: str, phi, drive) -> np.ndarray:
    """A body's angle rate per rad of carrier angle (the frame: 0)."""
    from cadgen.dynamics.planting import _split, angle_law

    if body == FRAME:
        return np.zeros_like(phi)
    kind, arm = _split(body)
    return np.broadcast_to(angle_law(mechanism, kind, phi, arm, drive)[1], phi.shape)


def _contacts(params, mechanism, drivetrain, phi) -> dict:
    """``{mesh key: (driver centre, driven centre, pitch point)}`` (n, 2) mm each, as the
    dynamics model placed them."""
    from cadgen.dynamics.planting import planting_joints
    from cadgen.gears.circular import planting_modules

    input_xy = next(s.xy for s in drivetrain.shafts if s.name == "input")
    modules = planting_modules(mechanism, params.pitch_curve.teeth, params.gears.circular_module)
    return planting_joints(mechanism, phi, drivetrain.drive, input_xy,
                           params.gears.pressure_angle_rad, modules)[2]


def _cross(offset, force):
    return offset[:, 0] * force[:, 1] - offset[:, 1] * force[:, 0]


def axis_cycles(params, mechanism, drivetrain, result, source: str) -> dict:
    """``{axis: CycleLoads}`` of the planting machine from a dynamics result.

    Each gear's force on its shaft is the sum of its meshes' tooth forces (N, the driven gear
    ``+F_n d``, the driver ``-F_n d``, ``d`` the line of action), its moment that force's about
    the gear's centre at the pitch point (N mm); the rest is the body's pin reaction less its
    gears' forces, negated (what the bearings carry besides the teeth: inertia, weight, the
    planter's soil and seedling, a carried housing's loads).
    """
    phi = np.asarray(result.phi, dtype=float)
    contacts = _contacts(params, mechanism, drivetrain, phi)
    forces, moments = {}, {}
    for key, mesh in result.meshes.items():
        driver, driven, side = key
        centre_driver, centre_driven, point = contacts[key]
        on_driven = mesh.normal_force_n[:, None] * mesh.line_of_action
        for gear, centre, force in ((driver, centre_driver, -on_driven),
                                    (driven, centre_driven, on_driven)):
            axis = GEAR_AXIS[gear]
            if side == 2 and axis not in MACHINE_AXES:
                continue   # arm 2's copy of an arm-1 axis
            forces[gear] = forces.get(gear, 0.0) + force
            moments[gear] = moments.get(gear, 0.0) + _cross(point - centre, force)
    carrier_rpm = float(result.carrier_rpm)
    cycles = {}
    for axis, (body, housing) in AXIS_BODY.items():
        gears = [g for g, a in GEAR_AXIS.items() if a == axis]
        carried = sum(forces[g] for g in gears)
        rest = -np.asarray(result.bearings[body], dtype=float) - carried
        speed = (_rate(mechanism, body, phi, drivetrain.drive)
                 - _rate(mechanism, housing, phi, drivetrain.drive)) * carrier_rpm
        free = {}
        if axis in FREE_PAIR:
            keyed, loose = FREE_PAIR[axis]
            relative = (_rate(mechanism, loose, phi, drivetrain.drive)
                        - _rate(mechanism, keyed, phi, drivetrain.drive)) * carrier_rpm
            free = {g: relative for g in gears}
        cycles[axis] = CycleLoads(source, {g: forces[g] for g in gears},
                                  {g: moments[g] for g in gears}, rest, speed, free)
    return cycles


def _sizing_params(params):
    """The parameters the sizing's dynamics run with: the file's speed alone (the speed sweep
    is the report's, not the sizing's) and the field's loads whatever ``load_case`` the report
    asks (``"none"`` is a check of the model: a machine sized without its soil would break in
    it)."""
    settings = params.dynamics.model_copy(update={
        "speeds_rpm": (float(params.field.carrier_speed_rpm),), "load_case": "planting"})
    return params.model_copy(update={"dynamics": settings})


def size_from_dynamics(params, mechanism, drivetrain, *, cam=None, events=None):
    """The drivetrain sized from the dynamics with estimated masses (see the module's steps).

    Parameters
    ----------
    drivetrain : Drivetrain
        Sized from the assumed tip force (its drive, journals and spring run the dynamics).

    Returns
    -------
    Drivetrain
        Sized from the loads of :data:`ESTIMATED_MASSES`; ``rules["dynamics_sizing"]`` says
        how (rounds, whether the drive settled, the dynamics' notes).
    """
    from cadgen.dynamics.analysis import planting_dynamics
    from cadgen.machine.drivetrain import drivetrain as size

    lean = _sizing_params(params)
    for rounds in range(1, SIZING_ROUNDS + 1):
        result = planting_dynamics(lean, mechanism, drivetrain, cam=cam, events=events)
        cycles = axis_cycles(params, mechanism, drivetrain, result, ESTIMATED_MASSES)
        sized = size(params, mechanism, cam, cycles=cycles, drive=drivetrain.drive)
        settled = sized.drive.teeth == drivetrain.drive.teeth
        drivetrain = sized
        if settled:
            break
    drivetrain.rules["dynamics_sizing"] = {
        "load_source": ESTIMATED_MASSES, "rounds": rounds, "drive_settled": settled,
        "input_torque_peak_nm": float(np.max(np.abs(result.input_torque))),
        "notes": list(result.notes), "outside_validity": list(result.invalid),
        "order": "sized from the assumed tip force; dynamics with estimated masses on that "
                 "drivetrain; sized again from their loads (again while the drive's gears "
                 "change); re-checked with the solids' masses after the solids"}
    return drivetrain


def recheck_drivetrain(params, mechanism, drivetrain, result):
    """The drivetrain checked under ``result``'s loads (:func:`cadgen.machine.recheck.recheck`):
    the solids' masses when the dynamics ran with them, else the estimate again."""
    from cadgen.machine.recheck import recheck

    source = SOLID_MASSES if result.mass_source == "solids" else ESTIMATED_MASSES
    cycles = axis_cycles(params, mechanism, drivetrain, result, source)
    return recheck(params, mechanism, drivetrain, cycles, source)
