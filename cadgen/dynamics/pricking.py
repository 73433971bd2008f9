"""The pricking mechanism as a planar multibody model: bodies, pins, gear meshes, loads.

Bodies over the carrier progress ``p`` (the case's turn since the outer, R max, dead centre,
in its own sense: the solids' and the clearance sweep's carrier angle):

==============  ======  ===============================================================
body            axis    absolute angle from the start pose, its rates per rad of ``p``
==============  ======  ===============================================================
gear case       O       ``s p``, ``s``, ``0``  (the sprocket's input; ``s`` = +1 ccw)
intermediate    A       ``s p - (psi1(v) - psi1(v0))``, ``s (1 + i1)``, ``i1_v / phi1_v``
planet          B       ``phi2(v) - phi2(v0)``, ``s (1 - i)``, ``-i_v / phi1_v``
==============  ======  ===============================================================

with ``A = O + a u(phi1)``, ``B = O + 2 a u(phi1)``, ``phi1 = phi1_start + s p``, ``v`` the
curve parameter where the carrier is at ``phi1`` (:meth:`CarrierMotion.invert`), ``psi1`` the
contact's polar angle in the first intermediate gear's frame, ``i1`` stage 1's ratio and ``i``
the total one. The sun is fixed to the frame (its shaft keyed into the bracket): it is the
frame here, and the stage-1 mesh's driver. The intermediate carries both intermediate gears
and their shaft; the planet its gear, shaft, the rocker and the needle (lumped: they are
keyed and clamped to it). 3 bodies, 3 pins (the case on the sun's shaft at O, the
intermediate and the planet in the case at A and B), 2 meshes: one freedom.

Derivatives: along ``v`` every quantity's derivative is the kinematics' own
(:class:`kinematics.pricking_motion.CarrierMotion`'s ``phi1_rate``, ``phi2_rate`` and the gear
stages' closed-form ratio derivatives, :meth:`_ContactFunctions.derivatives`), chained to ``p``
by ``dv/dp = s / phi1_v`` and ``d2v/dp2 = -phi1_vv / phi1_v^3``; no finite difference. The
carrier and needle angles' own ``v``-derivatives have no usable closed form at the two dead
centres (the arccos's ``c' / sqrt(1 - c^2)`` is 0/0 there), so the kinematics hold them as
piecewise Chebyshev interpolants of the closed-form angles (trailing coefficients below 1e-13
of the scale) and differentiate those exactly: spectral derivatives, within 1e-9 rad/unit of
the closed form wherever that form is well conditioned (``tests/test_dynamics_pricking.py``).

A mesh acts at its pitch point on the line of centres (``rho_sun`` from O, ``rho_int2`` from
A), along the pitch curves' common tangent ``rho_v u + rho psi_v J u`` tilted by the pressure
angle, as the planting non-circular pair (:mod:`kinematics.rigid_dynamics`'s ``Mesh``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kinematics.planting import PointMotion, rotating_offset
from kinematics.rigid_dynamics import FRAME, BodyMotion, Mesh, PointLoad, Revolute

from cadgen.dynamics.planting import mean_sliding_distance

__all__ = ["CASE", "INTERMEDIATE", "PLANET", "PRICKING_BODIES", "PRICKING_MESHES",
           "BODY_SHAFT", "PrickingMotion", "pricking_motion", "pricking_bodies",
           "pricking_joints", "soil_loads", "tip_motion"]

CASE, INTERMEDIATE, PLANET = "gear case", "intermediate", "planet"
PRICKING_BODIES = (CASE, INTERMEDIATE, PLANET)
#: Each mesh by the gear train's pair names (driver first) and the bodies of its gears.
PRICKING_MESHES = {("sun", "intermediate 1"): (FRAME, INTERMEDIATE),
                   ("intermediate 2", "planet"): (INTERMEDIATE, PLANET)}
#: The shaft each body's bearings sit on (``drivetrain.shafts``): the case turns on the sun's.
BODY_SHAFT = {CASE: "sun", INTERMEDIATE: "intermediate", PLANET: "planet"}


@dataclass(frozen=True)
class PrickingMotion:
    """The pricking mechanism over the carrier progress grid (mm, rad, per rad of progress).

    ``angles[body]`` is ``(angle from the start pose, rate, acceleration)``, each (n,);
    ``axes[body]`` the :class:`~kinematics.planting.PointMotion` of its axis; ``contacts[gear]``
    ``(rho, psi)``: the pitch point's distance from the gear's axis and its polar angle in the
    gear's own frame; ``start_axes[body]`` (2,) mm its axis at the start pose; ``tangents[pair]`` the unit common tangent (n, 2); ``tau`` the gear
    pairs' cycle parameter (:meth:`PrickingDesign.cycle_functions`).
    """

    progress: np.ndarray
    sense: int
    v: np.ndarray
    tau: np.ndarray
    phi1: np.ndarray
    angles: dict
    axes: dict
    start_axes: dict
    contacts: dict
    tangents: dict


def _unit(angle):
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


def _perp(vector):
    return np.stack([-vector[..., 1], vector[..., 0]], axis=-1)


def _normalised(vector):
    return vector / np.linalg.norm(vector, axis=-1, keepdims=True)


def pricking_motion(design, progress) -> PrickingMotion:
    """Every body's and mesh's motion over ``progress`` (n,) rad, from the design's analytic
    derivatives along the curve parameter (see the module docstring)."""
    progress = np.asarray(progress, dtype=float)
    motion, link = design.motion, design.linkage
    sense = int(motion.sense)
    centre = np.asarray(link.centre, dtype=float)
    phi1 = motion.phi1_start + sense * progress
    v = motion.invert(phi1)
    # at the start pose the bisection lands on v_max to rounding: take it exactly, so the
    # start pose is the solids' (their gears sit at tau = 0)
    v = np.where(progress == 0.0, motion.v_max, v)
    tau = motion.cycle(v)
    rate1 = motion.phi1_rate(v)
    rate1_rate = motion.phi1_rate.derivative()(v)
    dv = sense / rate1                      # dv/dp
    ddv = -rate1_rate / rate1 ** 3          # d2v/dp2
    zero, ones = np.zeros_like(progress), np.ones_like(progress)

    functions, _ = design.cycle_functions()
    derivative = {name: f.derivatives(v) for name, f in design.pitch_functions.items()}
    contacts = {name: (functions[name](tau)[0], functions[name](tau)[2]) for name in functions}
    psi1 = contacts["intermediate 1"][1]
    _, _, _, psi1_v, psi1_vv = derivative["intermediate 1"]
    phi2 = motion.phi2(v)
    phi2_v = motion.phi2_rate(v)
    phi2_vv = motion.phi2_rate.derivative()(v)
    angles = {
        CASE: (sense * progress, sense * ones, zero),
        INTERMEDIATE: (sense * progress - (psi1 - functions["intermediate 1"](0.0)[2]),
                       sense - psi1_v * dv, -(psi1_vv * dv ** 2 + psi1_v * ddv)),
        PLANET: (phi2 - float(motion.phi2(motion.v_max)), phi2_v * dv,
                 phi2_vv * dv ** 2 + phi2_v * ddv),
    }
    line = _unit(phi1)
    turned = sense * _perp(line)            # du/dp
    fixed = np.zeros_like(line) + centre
    axes = {CASE: PointMotion(fixed, np.zeros_like(line), np.zeros_like(line))}
    for body, reach in ((INTERMEDIATE, link.a), (PLANET, 2 * link.a)):
        axes[body] = PointMotion(centre + reach * line, reach * turned, -reach * line)
    tangents = {}
    for pair, gear in ((("sun", "intermediate 1"), "sun"),
                       (("intermediate 2", "planet"), "intermediate 2")):
        rho, rho_v, _, psi_v, _ = derivative[gear]
        # the driver's pitch curve in the world: rho(v) at the line of centres' direction
        tangent = _normalised(rho_v[:, None] * line + (rho * psi_v)[:, None] * _perp(line))
        tangents[pair] = tangent
    start_line = _unit(motion.phi1_start)
    start_axes = {CASE: centre, INTERMEDIATE: centre + link.a * start_line,
                  PLANET: centre + 2 * link.a * start_line}
    return PrickingMotion(progress, sense, v, tau, phi1, angles, axes, start_axes, contacts,
                          tangents)


def pricking_bodies(kinematics: PrickingMotion, masses: dict) -> tuple:
    """Every body's :class:`~kinematics.rigid_dynamics.BodyMotion` (m, kg).

    ``masses`` is ``{body: BodyMass}`` (centre in world mm at the start pose); a body missing
    from it gets zero mass, so it only carries its joints.
    """
    bodies = []
    for name in PRICKING_BODIES:
        axis = kinematics.axes[name]
        angle, rate, accel = kinematics.angles[name]
        mass = masses.get(name)
        if mass is None:
            weight, inertia, offset = 0.0, 0.0, np.zeros(2)
        else:
            weight, inertia = mass.mass, mass.inertia
            offset = np.asarray(mass.centre, dtype=float) - kinematics.start_axes[name]
        centre = rotating_offset(axis, angle, rate, accel, offset)
        bodies.append(BodyMotion(name, weight, inertia * 1e-6, centre.position * 1e-3,
                                 centre.velocity * 1e-3, centre.acceleration * 1e-3, rate, accel))
    return tuple(bodies)


def pricking_joints(kinematics: PrickingMotion, pressure_angle: float, modules: tuple,
                    journal_diameters: dict | None = None) -> tuple:
    """``(revolutes, meshes, contacts)`` over the grid.

    ``modules`` are the two stages' (mm, the mean sliding distance of each mesh);
    ``journal_diameters`` ``{shaft: diameter mm}`` (bearing friction; missing: 0).
    ``contacts`` is ``{pair: (centre of the driver (n, 2) mm, of the driven, contact point)}``.
    """
    journals = journal_diameters or {}
    axes = kinematics.axes
    revolutes = tuple(
        Revolute(body, body, base, axes[body].position * 1e-3,
                 0.5 * journals.get(BODY_SHAFT[body], 0.0) * 1e-3)
        for body, base in ((CASE, FRAME), (INTERMEDIATE, CASE), (PLANET, CASE)))
    line = _unit(kinematics.phi1)
    meshes, contacts = [], {}
    centres = {FRAME: axes[CASE].position, INTERMEDIATE: axes[INTERMEDIATE].position,
               PLANET: axes[PLANET].position}
    for (pair, (driver, driven)), module in zip(PRICKING_MESHES.items(), modules):
        radius = kinematics.contacts[pair[0]][0]
        point = centres[driver] + radius[:, None] * line
        tangent = kinematics.tangents[pair]
        normal = -_perp(tangent)
        # the normal points from the driver into the driven gear: along the line of centres
        normal *= np.where(np.sum(normal * line, axis=1) < 0, -1.0, 1.0)[:, None]
        meshes.append(Mesh(pair, driver, driven, point * 1e-3, tangent, normal, pressure_angle,
                           mean_sliding_distance(module, pressure_angle) * 1e-3))
        contacts[pair] = (centres[driver], centres[driven], point)
    return revolutes, tuple(meshes), contacts


def tip_motion(design, kinematics: PrickingMotion) -> PointMotion:
    """The needle tip D (mm, per rad of progress) as a point of the planet: ``B + l u(phi2)``."""
    link = design.linkage
    planet = kinematics.axes[PLANET]
    angle, rate, accel = kinematics.angles[PLANET]
    start = float(design.motion.phi2(design.motion.v_max))
    return rotating_offset(planet, angle, rate, accel, link.l * np.array([math.cos(start),
                                                                          math.sin(start)]))


def soil_loads(design, kinematics: PrickingMotion, *, omega: float, forward_speed: float,
               surface_level: float, inclination_deg: float, depth: float,
               force_n: float) -> list:
    """The soil's resistance on the needle tip while it is below the surface.

    In the mechanism plane the surface is the line ``y = surface_level`` (mm; it keeps the
    vertical depth as the plane tilts by theta, spec); the force grows in proportion to the
    vertical depth of the tip, ``force_n`` at the pricking depth, against the tip's velocity
    over the ground (the machine moves at ``forward_speed`` mm/s along +x).
    """
    tip = tip_motion(design, kinematics)
    vertical = (surface_level - tip.position[:, 1]) * math.cos(math.radians(inclination_deg))
    below = np.clip(vertical / depth, 0.0, None)
    ground = tip.velocity * omega + np.array([forward_speed, 0.0])
    speed = np.linalg.norm(ground, axis=1, keepdims=True)
    direction = -ground / np.where(speed > 0, speed, 1.0)
    return [PointLoad("soil", PLANET, tip.position * 1e-3, force_n * below[:, None] * direction)]
