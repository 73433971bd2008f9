"""The known loads on the planting mechanism's bodies: the cam's contact, the seedling, the soil.

* **Cam contact** (:func:`cam_contact_loads`): the duckbill linkage (lever, roller, push rod,
  links, blades) rides with the planter in the multibody model (its mass is the planter's);
  its motion relative to the planter is :func:`cadgen.machine.follower.follower_forces`'s,
  which gives the roller's contact force with the designed spring, the linkage's own inertia
  and gravity. A massless linkage passes on exactly the resultant of the cam's push, so the
  contact is a force pair at the roller's centre along the cam's outward normal: ``+F`` on
  the planter, ``-F`` on gearbox 2 (the cam's body). Its power is what flows into the
  linkage's relative motion (the spring's energy).
* **Seedling** (:func:`seedling_loads`): its weight and its inertia, ``m (g - a_N)`` at the
  tip N, from the catch until the duckbill starts opening.
* **Soil** (:func:`soil_loads`): while the tip is below the soil surface, a force against
  the tip's velocity over the ground (at the plant spacing), growing in proportion to the
  depth, ``soil_force_n`` at the planting depth.

Arm 2 is arm 1 half a turn later: on an even grid its arrays are arm 1's rolled by half.
"""

from __future__ import annotations

import math

import numpy as np

from kinematics.rigid_dynamics import GRAVITY, PointLoad

__all__ = ["cam_contact_loads", "seedling_loads", "soil_loads", "CamContact"]


class CamContact:
    """The roller's contact over the grid, arm 1 (arm 2: :meth:`arm`): contact force (N),
    its point and direction in the world (m, unit), the spring's force (N)."""

    def __init__(self, force, point, direction, spring):
        self.force, self.point, self.direction, self.spring = force, point, direction, spring

    def arm(self, arm: int):
        shift = -len(self.force) // 2 * arm
        return tuple(np.roll(v, shift, axis=0) for v in (self.force, self.point, self.direction,
                                                         self.spring))


def _rotate(v, angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]], axis=-1)


def cam_contact(params, mechanism, cam, drivetrain, phi, speed_rpm: float):
    """The cam's :class:`CamContact` at ``speed_rpm``, or ``(None, reason)`` when the linkage
    has no designed spring (the drivetrain did not design it)."""
    from cadgen.machine.duckbill import linkage_bodies
    from cadgen.machine.fits import process_fits
    from cadgen.machine.follower import follower_forces

    fixing = drivetrain.fixings.get("duckbill") if drivetrain is not None else None
    if cam is None or fixing is None or fixing.get("spring") is None:
        return None, "no duckbill spring was designed (the cam or the drivetrain did not run)"
    spring = fixing["spring"]
    fits = process_fits(params.manufacturing.process)
    linkage = cam.linkage
    bodies = linkage_bodies(params, linkage, fixing, fits)   # the fixing holds its geometry
    preload, rate = float(spring["preload"]), float(spring["rate"])
    forces = follower_forces(linkage, cam.profile, cam.cam_angle, mechanism, bodies, speed_rpm,
                             spring_force=lambda s: preload + rate * s, samples=len(phi))
    theta = np.asarray(cam.cam_angle(phi), dtype=float)
    lever = cam.profile.program(theta)[0]
    roller = linkage.roller_centre(lever)[0]
    normal = _rotate(cam.profile.outward_normal(theta), theta)
    psi = mechanism.attitude(phi)
    hub = mechanism.motion(phi, "E").position
    point = (hub + _rotate(roller, psi)) * 1e-3
    return CamContact(forces.contact_force_actual, point, _rotate(normal, psi),
                      preload + rate * forces.rod_travel), None


def cam_contact_loads(contact: CamContact) -> list:
    """The contact pair of each arm as :class:`~kinematics.rigid_dynamics.PointLoad`."""
    loads = []
    for arm in (0, 1):
        force, point, direction, _ = contact.arm(arm)
        loads.append(PointLoad(f"cam {arm + 1}", f"planter {arm + 1}", point,
                               force[:, None] * direction, other=f"gearbox 2 {arm + 1}"))
    return loads


def held(phi, release: float, arm: int):
    """Whether arm ``arm`` holds a seedling at each carrier angle: from its catch (``pi arm``)
    to its release (``release`` after the catch)."""
    local = np.mod(np.asarray(phi, dtype=float) - math.pi * arm, 2 * math.pi)
    return local < release


def seedling_loads(mechanism, phi, omega: float, mass_kg: float, release: float) -> list:
    """The seedling's weight and inertia at each arm's tip while it holds one."""
    loads = []
    for arm in (0, 1):
        tip = mechanism.motion(phi, "N", arm)
        accel = tip.acceleration * 1e-3 * omega ** 2
        force = mass_kg * (np.array([0.0, -GRAVITY]) - accel)
        force *= held(phi, release, arm)[:, None]
        loads.append(PointLoad(f"seedling {arm + 1}", f"planter {arm + 1}",
                               tip.position * 1e-3, force))
    return loads


def soil_loads(mechanism, phi, soil_level: float, depth: float, spacing: float,
               force_n: float) -> list:
    """The soil's resistance on each arm's tip while it is below ``soil_level`` (mm)."""
    loads = []
    for arm in (0, 1):
        tip = mechanism.absolute_motion(phi, spacing, "N", arm)
        below = np.clip((soil_level - tip.position[:, 1]) / depth, 0.0, None)
        speed = np.linalg.norm(tip.velocity, axis=1, keepdims=True)
        direction = -tip.velocity / np.where(speed > 0, speed, 1.0)
        relative = mechanism.motion(phi, "N", arm).position * 1e-3
        loads.append(PointLoad(f"soil {arm + 1}", f"planter {arm + 1}", relative,
                               force_n * below[:, None] * direction))
    return loads
