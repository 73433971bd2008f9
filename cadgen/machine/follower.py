"""The duckbill linkage's dynamics over a revolution: the force that keeps the roller on the cam.

The linkage has one freedom relative to the planter, the lever angle ``lambda`` (the cam law
``lambda(theta)``, ``theta = F(phi)``): every body of it (lever, roller, push rod, both links,
both blades) moves as a function of ``lambda`` alone
(:class:`~kinematics.duckbill.DuckbillLinkage`).
Lagrange's equation in ``lambda`` with the planter frame moving (E accelerating, the planter
turning at ``Psi'``):

    Q_inertia = sum m a_c . dc/dlambda + I theta'' dtheta/dlambda
              = Q_cam - F_spring ds/dlambda + Q_field

* ``Q_inertia`` from each body's centre ``c(lambda)`` and angle ``theta(lambda)`` and the
  law's ``lambda' = lambda_theta F' omega``, ``lambda'' = (lambda_thetatheta F'^2 +
  lambda_theta F'') omega^2`` at the file's carrier speed ``omega``;
* ``Q_field``: gravity and the planter frame's own acceleration (E's acceleration, the turn's
  ``Psi''`` and ``Psi'^2`` terms, and ``Psi''`` on each body's own inertia) as loads in that
  frame; the Coriolis loads do no work in a one-freedom motion (``(J v) . v = 0``);
* ``Q_cam >= 0``: the cam can only push the roller outwards (``lambda`` growing);
* the spring pushes the push rod up (closing) with ``F_spring`` against its travel
  ``s = l_HG sin(lambda)``.

So the roller stays on the cam when ``F_spring >= (Q_field - Q_inertia) / (ds/dlambda)``. Gravity
is taken in the worst direction at every pose (``g |sum m dc/dlambda|``: a tilted machine, a
bump), the frame's acceleration as it is, and the largest need over the revolution is
multiplied by :data:`CONTACT_SAFETY_FACTOR` for the spring's least force. The roller's contact
force is ``Q_cam / (n . dI/dlambda)`` with ``n`` the cam's normal at the contact.

Derivatives in ``lambda`` are central differences of the closed-form positions (step
:data:`LAMBDA_STEP`); everything is vectorised over the carrier-angle samples.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Body", "FollowerForces", "follower_forces", "CONTACT_SAFETY_FACTOR", "GRAVITY"]

#: The spring's least force over the one the motion needs at worst: friction in the hinge pins
#: and the guide, soil in the blades and the masses' estimate are not in the model.
CONTACT_SAFETY_FACTOR = 2.0
#: m/s^2.
GRAVITY = 9.81
#: Step (rad) of the central differences in the lever angle: the positions are closed forms,
#: so the truncation error (~h^2) is far below the rounding one at this step.
LAMBDA_STEP = 1e-4
#: Carrier-angle samples per revolution.
SAMPLES = 3600


@dataclass(frozen=True)
class Body:
    """A rigid body of the linkage: its mass (kg), its moment of inertia about its centre of
    mass (kg m^2), and how it moves: ``motion`` is ``"lever"``, ``"roller"``, ``"rod"``,
    ``"blade-right"``, ``"blade-left"``, ``"link-right"`` or ``"link-left"``; ``centre`` its
    centre of mass at rest in the planter frame (mm; a link's in its own frame: x from J
    towards P2)."""

    name: str
    motion: str
    mass: float
    inertia: float
    centre: tuple


@dataclass(frozen=True)
class FollowerForces:
    """The linkage's loads over one revolution (N, at the file's carrier speed)."""

    phi: np.ndarray                # carrier angles, rad
    needed_spring_force: np.ndarray   # F_spring the contact needs (gravity at worst), N
    required_preload: float        # safety factor x the largest need, N
    contact_force_high: np.ndarray     # roller on cam with the spring, gravity pressing it on
    contact_force_low: np.ndarray      # the same, gravity pulling it off (the worst for contact)
    contact_force_actual: np.ndarray   # the same with gravity where it is
    rod_travel: np.ndarray         # s(phi), mm
    inertia_range: tuple           # generalised inertia about the lever angle, kg m^2

    def as_dict(self) -> dict:
        worst = int(np.argmax(self.needed_spring_force))
        return {"needed_spring_force_max_n": float(self.needed_spring_force[worst]),
                "needed_at_carrier_deg": float(np.degrees(self.phi[worst])),
                "safety_factor": CONTACT_SAFETY_FACTOR,
                "required_preload_n": self.required_preload,
                "contact_force_max_n": float(self.contact_force_high.max()),
                "contact_force_min_n": float(self.contact_force_low.min()),
                "contact_force_actual_max_n": float(self.contact_force_actual.max()),
                "contact_force_actual_min_n": float(self.contact_force_actual.min()),
                "generalised_inertia_kgm2": [float(v) for v in self.inertia_range]}


def _rotate(v, angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]], axis=-1)


def _mirror(point, L1):
    """A point's mirror in the duckbill axis ``x = -L1``."""
    point = np.asarray(point, dtype=float)
    return np.stack([-2.0 * L1 - point[..., 0], point[..., 1]], axis=-1)


def _pose(linkage, body: Body, lam):
    """Centre (n, 2) mm and angle (n,) rad of ``body`` at lever angles ``lam`` (n,)."""
    lam = np.asarray(lam, dtype=float)
    centre = np.asarray(body.centre, dtype=float)
    zero = np.zeros_like(lam)
    if body.motion == "lever":
        pivot = linkage.lever_pivot
        return pivot + _rotate(np.broadcast_to(centre - pivot, lam.shape + (2,)), lam), lam
    if body.motion == "roller":
        return linkage.roller_centre(lam)[0], zero
    travel = linkage.rod_arm * np.sin(lam)
    if body.motion == "rod":
        return centre + np.stack([zero, -travel], axis=-1), zero
    beta = linkage.blade_opening(travel)
    if body.motion.startswith("blade"):
        hinge = linkage.hinge
        sign = 1.0
        if body.motion == "blade-left":
            hinge, sign = _mirror(hinge, linkage.L1), -1.0
        arm = np.broadcast_to(centre - hinge, lam.shape + (2,))
        return hinge + _rotate(arm, sign * beta), sign * beta
    if body.motion.startswith("link"):
        pin = linkage.crank_pin(beta)
        end = np.stack([np.full_like(lam, -linkage.L1), linkage.push_rod_end(beta)], axis=-1)
        if body.motion == "link-left":
            pin = _mirror(pin, linkage.L1)
        angle = np.arctan2(end[:, 1] - pin[:, 1], end[:, 0] - pin[:, 0])
        return pin + _rotate(np.broadcast_to(centre, lam.shape + (2,)), angle), angle
    raise ValueError(f"unknown motion {body.motion!r} of {body.name}")


def _derivatives(linkage, body, lam):
    """Centre (m) and angle, and their first two lever-angle derivatives."""
    h = LAMBDA_STEP
    (c0, a0), (cp, ap), (cm, am) = (_pose(linkage, body, lam + dh) for dh in (0.0, h, -h))
    c0, cp, cm = c0 * 1e-3, cp * 1e-3, cm * 1e-3
    return (c0, (cp - cm) / (2 * h), (cp - 2 * c0 + cm) / h**2,
            (ap - am) / (2 * h), (ap - 2 * a0 + am) / h**2)


def follower_forces(linkage, profile, cam_angle, mechanism, bodies, carrier_speed_rpm,
                    spring_force=None, samples: int = SAMPLES) -> FollowerForces:
    """The spring force the roller's contact needs over a revolution, and the contact force.

    Parameters
    ----------
    linkage : kinematics.duckbill.DuckbillLinkage
    profile : kinematics.cam.CamProfile
        Its ``program`` (lever angle over cam angle) and ``outward_normal``.
    cam_angle : callable
        ``F``, carrier angle -> cam angle.
    mechanism : kinematics.planting.PlantingMechanism
        E's motion, the planter's attitude and ``F'``, ``F''`` (``closure.law.ratio``).
    bodies : sequence of Body
    carrier_speed_rpm : float
    spring_force : callable, optional
        ``s (mm) -> F (N)`` of the designed spring, for the contact force; without it the
        spring gives exactly the required preload at every travel.
    """
    omega = 2.0 * np.pi * float(carrier_speed_rpm) / 60.0
    phi = np.linspace(0.0, 2.0 * np.pi, samples, endpoint=False)
    theta = np.asarray(cam_angle(phi), dtype=float)
    lam, lam_t, lam_tt = profile.program(theta)
    rate, rate_rate = mechanism.closure.law.ratio(phi)
    lam_dot = lam_t * rate * omega
    lam_ddot = (lam_tt * rate**2 + lam_t * rate_rate) * omega**2
    psi, psi_d, psi_dd = mechanism.attitude_derivatives(phi)
    turn_rate, turn_acc = psi_d * omega, psi_dd * omega**2
    hub_acc = mechanism.motion(phi, "E").acceleration * 1e-3 * omega**2
    hub_acc_local = _rotate(hub_acc, -psi)   # in the planter frame
    q_inertia = np.zeros_like(phi)
    q_frame = np.zeros_like(phi)
    weight = np.zeros((len(phi), 2))
    generalised = np.zeros_like(phi)
    for body in bodies:
        c, c_l, c_ll, a_l, a_ll = _derivatives(linkage, body, lam)
        accel = c_ll * lam_dot[:, None] ** 2 + c_l * lam_ddot[:, None]
        spin_acc = a_ll * lam_dot**2 + a_l * lam_ddot
        q_inertia += body.mass * np.sum(accel * c_l, axis=1) + body.inertia * spin_acc * a_l
        # the frame's acceleration at the body's centre: E's, plus the turn's
        transport = (hub_acc_local + turn_acc[:, None] * np.stack([-c[:, 1], c[:, 0]], axis=-1)
                     - turn_rate[:, None] ** 2 * c)
        q_frame -= body.mass * np.sum(transport * c_l, axis=1) + body.inertia * turn_acc * a_l
        weight += body.mass * c_l
        generalised += body.mass * np.sum(c_l * c_l, axis=1) + body.inertia * a_l**2
    rod_rate = linkage.rod_arm * np.cos(lam) * 1e-3     # ds/dlambda, m
    gravity_worst = GRAVITY * np.linalg.norm(weight, axis=1)
    down = _rotate(np.array([[0.0, -GRAVITY]]).repeat(len(phi), axis=0), -psi)
    gravity_actual = np.sum(down * weight, axis=1)
    needed = (q_frame + gravity_worst - q_inertia) / rod_rate
    required = CONTACT_SAFETY_FACTOR * max(float(needed.max()), 0.0)
    travel = linkage.rod_arm * np.sin(lam)
    spring = (np.full_like(phi, required) if spring_force is None
              else np.asarray(spring_force(travel), dtype=float))
    # the contact normal in the planter frame (the cam's frame turned by theta)
    normal = _rotate(profile.outward_normal(theta), theta)
    lever_rate = np.sum(normal * linkage.roller_centre(lam)[1], axis=1) * 1e-3
    base = q_inertia + spring * rod_rate - q_frame
    return FollowerForces(phi, needed, required, (base + gravity_worst) / lever_rate,
                          (base - gravity_worst) / lever_rate,
                          (base - gravity_actual) / lever_rate, travel,
                          (float(generalised.min()), float(generalised.max())))
