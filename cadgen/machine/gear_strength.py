"""The tooth strength of a mechanism's gear trains under its loads (:mod:`cadgen.gears.strength`).

:func:`train_strength` builds each mesh of a cut train over its cycle: each gear's signed
pitch-curve radius of curvature at the contact (analytic: the planting central gear's
``polar_curvature`` of ``r1(t)``, the intermediate's from ``a - r1`` and the ratio law's
derivative, the pricking gears' from their contact functions' closed-form second
derivatives; a circular gear its working pitch radius), its material from the process
(:mod:`cadgen.machine.fits`), and the normal tooth force at each pose:

- by default the **assumed static design load** of the drivetrain (:mod:`cadgen.machine.loads`:
  the tip load times the service factor at its worst lever, passed back through the gears). A
  circular mesh carries its tangential force ``Ft``, ``Fn = Ft / cos(alpha)``; a non-circular
  mesh its driven gear's torque ``T`` at every pose, ``Fn = T / (rho cos(alpha + mu))``,
  ``rho`` the driven gear's contact radius and ``mu = atan(|drho| / |rho dpsi|)`` the tilt of
  the pitch tangent (the line of action's lever about the gear's centre is ``rho cos(alpha +
  mu)`` on the worse flank), so the force varies over the cycle as the radii do;
- or the forces given in ``mesh_forces`` (the dynamics' over the carrier turn): ``{(drive,
  driven): (pose, normal force N)}``, ``pose`` the mesh's own cycle parameter
  (:class:`cadgen.gears.pairs.PitchPair`'s ``tau``: the carrier angle for the planting
  non-circular pair, the drive's turn for a circular one).
"""

from __future__ import annotations

import math

import numpy as np

from kinematics.pitch_curves import parametric_curvature, polar_curvature

from cadgen.gears.gear_materials import gear_material
from cadgen.gears.strength import MeshGear, MeshLoad, RackProfile, StrengthFactors, mesh_strength
from cadgen.gears.strength_summary import train_strength_summary

__all__ = ["train_strength", "contact_curvatures", "dynamics_mesh_forces", "STRENGTH_POSES",
           "ASSUMED_LOAD", "DYNAMICS_LOAD"]

#: Poses of a mesh's cycle the strength is evaluated at (uniform): 0.25 deg of the carrier for
#: the planting non-circular pair; cheap (vectorised), and the curvature's extremes are broad.
STRENGTH_POSES = 1440
#: What the default forces are, for the report.
ASSUMED_LOAD = ("assumed static design load: machine.tip_load_n x machine.service_factor at "
                "its worst lever, passed back through the gears (cadgen.machine.loads), at "
                "every pose; not the dynamics")


def contact_curvatures(params, design) -> dict:
    """``{gear: tau -> signed curvature (1/mm)}`` of the non-circular gears at the contact,
    over each pair's cycle parameter ``tau``, from closed-form derivatives."""
    if params.mechanism == "pricking":
        return design.cycle_curvatures()
    curve, closure = design.pitch_curve, design.closure
    a = closure.centre_distance

    def intermediate(t):
        # the intermediate's contact: rho = a - r1(t) at polar angle pi - F(t), F' = w
        r, dr, ddr = curve.radius_derivatives(t)
        w, dw = closure.law.ratio(t)
        return parametric_curvature(a - r, -dr, -ddr, -w, -dw)

    return {"central": lambda t: polar_curvature(curve, t), "intermediate": intermediate}


def _loads(params, design, train) -> dict:
    """``{gear: GearLoad}`` of the drivetrain's static design load."""
    from cadgen.machine.loads import planting_loads, pricking_loads

    alpha, rpm = params.gears.pressure_angle_rad, params.field.carrier_speed_rpm
    if params.mechanism == "pricking":
        axes = pricking_loads(design, params.machine, alpha, rpm)
    else:
        axes = planting_loads(design, params.machine, alpha, rpm, train.drive)
    return {name: load for axis in axes.values() for name, load in axis.gears.items()}


def _tip_radius(profile) -> float:
    centre = np.asarray(getattr(profile, "centre", (0.0, 0.0)), dtype=float)
    return float(np.linalg.norm(np.asarray(profile.outline) - centre, axis=1).max())


def _circular_mesh(stage, names, materials, idlers, loads, pose, face):
    generated = stage.generated
    pair, system = generated.pair, generated.system
    drive, driven = generated.profiles
    module = float(drive.module)
    reference = tuple(module * p.teeth / 2 for p in (drive, driven))
    # shifts not summing to zero mesh on the working circles at the axis distance
    cosine = (reference[0] + reference[1]) * math.cos(system.pressure_angle) / \
        pair.centre_distance
    working = math.acos(min(1.0, cosine))
    gears = tuple(MeshGear(name, np.full(pose.shape, float(radius)), materials,
                           float(check.profile_shift), int(profile.teeth), _tip_radius(profile),
                           name in idlers)
                  for name, radius, check, profile in zip(names, pair.radii, generated.checks,
                                                          generated.profiles))
    tangential = max(loads[name].tangential_n for name in names if name in loads)
    force = np.full(pose.shape, tangential / math.cos(system.pressure_angle))
    return gears, force, working, reference


def _noncircular_mesh(stage, names, materials, idlers, loads, pose, curvatures):
    generated = stage.generated
    pair, alpha = generated.pair, generated.system.pressure_angle
    gears = []
    for name, check in zip(names, generated.checks):
        with np.errstate(divide="ignore"):
            radius = 1.0 / np.asarray(curvatures[name](pose), dtype=float)
        gears.append(MeshGear(name, radius, materials, float(check.profile_shift),
                              reversed_bending=name in idlers))
    rho, d_rho, _, d_psi = pair.driven(pose)
    tilt = np.arctan2(np.abs(d_rho), np.abs(rho * d_psi))
    lever = rho * np.cos(np.minimum(alpha + tilt, np.radians(89.0)))
    force = loads[names[1]].torque_nmm / lever
    return tuple(gears), force


#: How the report names the dynamics' loads.
DYNAMICS_LOAD = ("dynamics: each mesh's normal force over the carrier turn (both arms' copies), "
                 "times machine.service_factor for shocks")


def dynamics_mesh_forces(result, service_factor: float) -> dict:
    """The dynamics' tooth forces as :func:`train_strength`'s ``mesh_forces``: ``{(drive,
    driven): (pose, force)}``, each pair's poses over the carrier turn of every copy (both arms'
    gears are one part, so a gear must endure both cycles), the force times
    ``service_factor`` (the dynamics has no shocks: the design load's factor stands for them).

    A pair's pose is its cycle's parameter: for the planting non-circular pair the central
    gear's polar angle of the contact, ``t`` of ``r1(t)``, which is the carrier angle (arm 2
    half a turn on); a circular pair's geometry is the same at every pose, which is taken as
    the carrier angle of arm 1's cycle likewise."""
    phi = np.asarray(result.phi, dtype=float)
    out = {}
    for (drive, driven, side), mesh in result.meshes.items():
        if mesh.pitch_parameter is not None:
            pose = np.mod(np.asarray(mesh.pitch_parameter, dtype=float), 2 * np.pi)
        else:
            pose = np.mod(phi + (np.pi if side == 2 else 0.0), 2 * np.pi)
        force = service_factor * np.asarray(mesh.normal_force_n, dtype=float)
        if (drive, driven) in out:
            before = out[drive, driven]
            pose, force = np.concatenate([before[0], pose]), np.concatenate([before[1], force])
        out[drive, driven] = (pose, force)
    return out


def train_strength(params, design, train, mesh_forces: dict | None = None,
                   poses: int = STRENGTH_POSES, factors: StrengthFactors = StrengthFactors()):
    """Every gear's tooth strength over its meshes' cycles, checked against ``[machine]``.

    Parameters
    ----------
    params : PlantingParameters or PrickingParameters
    design : kinematics.planting.PlantingMechanism or kinematics.pricking.PrickingDesign
    train : cadgen.gears.trains.GearTrain
        As cut (its stages' profiles, checks and pairs).
    mesh_forces : dict, optional
        ``{(drive name, driven name): (pose (n,) rad, normal force (n,) N)}``; a mesh not in
        it carries the assumed static design load.
    poses : int
        Poses per cycle where the design load is used.

    Returns
    -------
    cadgen.gears.strength_summary.TrainStrength
    """
    forces = dict(mesh_forces or {})
    material = gear_material(_process_material(params))
    loads = _loads(params, design, train)
    curvatures = contact_curvatures(params, design) if any(
        not s.generated.pair.radii for s in train.stages) else {}
    count = {}
    for stage in train.stages:
        for name in stage.generated.pair.names:
            count[name] = count.get(name, 0) + 1
    idlers = {name for name, meshes in count.items() if meshes > 1}
    meshes, sources = [], set()
    for stage in train.stages:
        generated = stage.generated
        pair, system = generated.pair, generated.system
        names = tuple(pair.names)
        module = float(generated.profiles[0].module)
        face = float(params.gears.face_width_for(module))
        given = forces.pop(names, None)
        pose = (np.asarray(given[0], dtype=float) if given is not None else
                np.linspace(0.0, pair.period, poses, endpoint=False))
        working, reference = None, None
        if pair.radii:
            gears, force, working, reference = _circular_mesh(stage, names, material, idlers,
                                                              loads, pose, face)
        else:
            gears, force = _noncircular_mesh(stage, names, material, idlers, loads, pose,
                                             curvatures)
        source = ASSUMED_LOAD
        if given is not None:
            force, source = np.asarray(given[1], dtype=float), DYNAMICS_LOAD
        sources.add(source)
        rack = RackProfile(system.pressure_angle, system.addendum, system.dedendum,
                           system.tip_radius)
        meshes.append(mesh_strength(MeshLoad(stage.name, gears, module, face, rack, pose,
                                             pair.period, force, working, reference, source),
                                    factors))
    if forces:
        raise ValueError(f"mesh_forces names meshes the train does not have: "
                         f"{', '.join(map(str, forces))}")
    machine = params.machine
    load = "; ".join(sorted(sources)) if sources else ASSUMED_LOAD
    return train_strength_summary(meshes, machine.bending_safety_min, machine.contact_safety_min,
                                  factors.as_dict(), load,
                                  {"design_load_n": machine.tip_load_n * machine.service_factor,
                                   "poses_per_cycle": poses})


def _process_material(params) -> str:
    from cadgen.machine.fits import design_fits

    return design_fits(params).material("gear").name
