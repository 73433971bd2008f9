"""The planting mechanism as a planar multibody model: bodies, pins, gear meshes.

Every body turns about one axis whose motion the kinematics gives in closed form
(:class:`kinematics.planting.PlantingMechanism`: the carrier points A, B, C, the gearbox-2
points D, E with their analytic velocities and accelerations, ``F' = r1 / (a - r1)`` and
``F''`` from the closure law, the attitude ``Psi``). Each body's absolute angle from the
catching pose, ``dtheta(phi)``, with its derivatives:

==================  =============  ======================================================
body                axis           dtheta(phi)
==================  =============  ======================================================
input               the drive's    ``n z2 / z1 phi``      (the countershaft, in the frame)
central shaft       O              ``-n phi``             (both suns, the drive's gear 2)
carrier             O              ``-phi``               (gearbox 1, sleeve S, gear 4)
idler A / B (II)    A / B          ``(-1 -+ (n - 1) r_s / r) phi``  keyed to its shaft
idler A-I / B-I     A / B          the same with set I's radii, free on the shaft
gearbox 2           C              ``phi``                (set II's planet, shaft C, cam)
central gear        C              ``0``                  (set I's planet, shaft C2)
intermediate        D              ``phi + F(phi) - F(0)``   (shaft D, gear D)
planter             E              ``Psi(phi) - Psi(0)``  (shaft E, gear E, the linkage)
==================  =============  ======================================================

per side of carrier 1 for the last seven (arm 2: the same at ``phi + pi``). A body's centre
of mass is its axis plus its offset at the catching pose turned by ``dtheta``
(:func:`kinematics.planting.rotating_offset`), so its velocity and acceleration are analytic.

Pins (each to the body that holds the bearing, the planar resultant of the shaft's two
bearings): the carrier and the central shaft to the frame at O, the input to the frame, each
idler and gearbox 2 and the central gear to the carrier, each set I idler to its set II idler
(it runs free on that shaft), the intermediate and the planter to gearbox 2. 19 bodies, 19
pins, 18 meshes: one freedom, the input's angle.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from kinematics.planting import PointMotion, rotating_offset
from kinematics.rigid_dynamics import FRAME, BodyMotion, Mesh, Revolute

__all__ = ["SIDE_BODIES", "MACHINE_BODIES", "planting_bodies", "planting_joints",
           "angle_law", "MESH_GEARS"]

#: Bodies of carrier 1's each side (suffix " 1", " 2").
SIDE_BODIES = ("idler A", "idler A-I", "idler B", "idler B-I", "gearbox 2", "central gear",
               "intermediate", "planter")
#: Bodies of the machine as a whole.
MACHINE_BODIES = ("input", "central shaft", "carrier")
#: Each mesh by the gear train's pair names (driver first) and the bodies of its gears.
MESH_GEARS = {
    ("sun", "idler 1"): ("central shaft", "idler A"),
    ("idler 1", "idler 2"): ("idler A", "idler B"),
    ("idler 2", "train-1 planet"): ("idler B", "gearbox 2"),
    ("sun I", "idler 1-I"): ("central shaft", "idler A-I"),
    ("idler 1-I", "idler 2-I"): ("idler A-I", "idler B-I"),
    ("idler 2-I", "planet I"): ("idler B-I", "central gear"),
    ("central", "intermediate"): ("central gear", "intermediate"),
    ("gear D", "planet gear E"): ("intermediate", "planter"),
}
#: The shaft each body turns on, for its journal's diameter (``drivetrain.shafts``).
BODY_SHAFT = {"input": "input", "central shaft": "O", "carrier": "S", "idler A": "A",
              "idler A-I": "A", "idler B": "B", "idler B-I": "B", "gearbox 2": "C",
              "central gear": "C2", "intermediate": "D", "planter": "E"}


def _train_radii(mechanism):
    from cadgen.gears.circular import train1_set_radii

    return train1_set_radii(mechanism, "II"), train1_set_radii(mechanism, "I")


def angle_law(mechanism, body: str, phi, arm: int = 0, drive=None):
    """``(dtheta, dtheta', dtheta'')`` of a body (rad, per rad of ``phi``), each (n,)."""
    phi = np.asarray(phi, dtype=float)
    zero, one = np.zeros_like(phi), np.ones_like(phi)
    shifted = phi + math.pi * arm
    n = mechanism.n
    if body in ("intermediate", "planter"):
        ratio, ratio_rate = mechanism.closure.law.ratio(shifted)
        turned = mechanism.intermediate_rotation(shifted) \
            - mechanism.intermediate_rotation(np.array([math.pi * arm]))[0]
        if body == "intermediate":
            return phi + turned, 1.0 + ratio, ratio_rate
        return phi - turned, 1.0 - ratio, -ratio_rate
    set2, set1 = _train_radii(mechanism)
    rates = {"carrier": -1.0, "central shaft": -n, "gearbox 2": 1.0, "central gear": 0.0,
             "idler A": -1.0 + (n - 1) * set2[0] / set2[1],
             "idler B": -1.0 - (n - 1) * set2[0] / set2[2],
             "idler A-I": -1.0 + (n - 1) * set1[0] / set1[1],
             "idler B-I": -1.0 - (n - 1) * set1[0] / set1[2]}
    if body == "input":
        z1, z2, _, _ = drive.teeth
        rates["input"] = n * z2 / z1
    rate = rates[body]
    return rate * phi, rate * one, zero


def _axis(mechanism, body: str, phi, arm: int, input_xy) -> PointMotion:
    """The motion (mm, per rad) of the axis the body turns about."""
    point = {"idler A": "A", "idler A-I": "A", "idler B": "B", "idler B-I": "B",
             "gearbox 2": "C", "central gear": "C", "intermediate": "D", "planter": "E"}
    if body in point:
        return mechanism.motion(phi, point[body], arm)
    fixed = np.zeros((len(phi), 2)) + (np.asarray(input_xy) if body == "input" else 0.0)
    return PointMotion(fixed, np.zeros_like(fixed), np.zeros_like(fixed))


def _split(name: str):
    """``"planter 2"`` -> ``("planter", 1)``; a machine body -> ``(name, 0)``."""
    head, _, tail = name.rpartition(" ")
    if head in SIDE_BODIES and tail in ("1", "2"):
        return head, int(tail) - 1
    return name, 0


def planting_bodies(mechanism, masses: dict, phi, drive, input_xy) -> tuple:
    """Every body's :class:`~kinematics.rigid_dynamics.BodyMotion` (m, kg) over ``phi``.

    ``masses`` is ``{body: BodyMass}`` (centre in world mm at the catching pose); a body
    missing from it (no part of it built) gets zero mass, so it only carries its joints.
    """
    phi = np.asarray(phi, dtype=float)
    bodies = []
    names = list(MACHINE_BODIES) + [f"{b} {s}" for s in ("1", "2") for b in SIDE_BODIES]
    for name in names:
        kind, arm = _split(name)
        axis = _axis(mechanism, kind, phi, arm, input_xy)
        angle, rate, accel = angle_law(mechanism, kind, phi, arm, drive)
        mass = masses.get(name)
        if mass is None:
            weight, inertia, offset = 0.0, 0.0, np.zeros(2)
        else:
            axis0 = _axis(mechanism, kind, np.zeros(1), arm, input_xy).position[0]
            weight, inertia, offset = mass.mass, mass.inertia, mass.centre - axis0
        centre = rotating_offset(axis, angle, rate, accel, offset)
        bodies.append(BodyMotion(name, weight, inertia * 1e-6, centre.position * 1e-3,
                                 centre.velocity * 1e-3, centre.acceleration * 1e-3, rate, accel))
    return tuple(bodies)


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _perp(v):
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def _circular_mesh(name, driver, driven, centre_driver, centre_driven, radius, alpha, arm_mm):
    """A circular external pair: the pitch point on the line of centres, the common normal
    along it (from the driver to the driven gear)."""
    normal = _unit(centre_driven - centre_driver)
    return Mesh(name, driver, driven, (centre_driver + radius * normal) * 1e-3, _perp(normal),
                normal, alpha, arm_mm * 1e-3)


def mean_sliding_distance(module: float, pressure_angle: float) -> float:
    """The mean distance (mm) of the contact from the pitch point along the path of contact
    for a contact ratio of 1: a quarter of the base pitch, ``pi m cos(alpha) / 4``."""
    return math.pi * module * math.cos(pressure_angle) / 4.0


def planting_joints(mechanism, phi, drive, input_xy, pressure_angle: float, modules: tuple,
                    journal_diameters: dict | None = None) -> tuple:
    """``(revolutes, meshes, contacts)`` of the planting model over ``phi``.

    ``modules`` is ``(non-circular, circular)`` (mm, the mean sliding distance of each mesh);
    ``journal_diameters`` ``{shaft name: diameter mm}`` (bearing friction; missing: 0).
    ``contacts`` is ``{mesh name: (centre of the driver (n, 2) mm, of the driven, contact
    point (n, 2) mm)}`` for the contact positions (:mod:`cadgen.dynamics.analysis`).
    """
    phi = np.asarray(phi, dtype=float)
    journals = journal_diameters or {}
    module_nc, module_c = modules
    set2, set1 = _train_radii(mechanism)
    revolutes, meshes, contacts = [], [], {}

    def pin(body, base, point_mm):
        kind, _ = _split(body)
        radius = 0.5 * journals.get(BODY_SHAFT[kind], 0.0) * 1e-3
        revolutes.append(Revolute(body, body, base, point_mm * 1e-3, radius))

    origin = np.zeros((len(phi), 2))
    inlet = origin + np.asarray(input_xy, dtype=float)
    pin("carrier", FRAME, origin)
    pin("central shaft", FRAME, origin)
    pin("input", FRAME, inlet)
    if drive is not None:
        arm_1 = mean_sliding_distance(drive.module_1, pressure_angle)
        arm_2 = mean_sliding_distance(drive.module_2, pressure_angle)
        for pair, driven, radius, arm in ((("input gear 1", "central shaft gear"),
                                           "central shaft", drive.radii[0], arm_1),
                                          (("input gear 2", "transmission driven gear"),
                                           "carrier", drive.radii[2], arm_2)):
            mesh = _circular_mesh((*pair, 0), "input", driven, inlet, origin, radius,
                                  pressure_angle, arm)
            meshes.append(mesh)
            contacts[mesh.name] = (inlet, origin, mesh.point * 1e3)
    sliding_c = mean_sliding_distance(module_c, pressure_angle)
    for arm in (0, 1):
        side = f" {arm + 1}"
        points = {p: mechanism.motion(phi, p, arm).position for p in "ABCDE"}
        centres = {"central shaft": origin, "idler A": points["A"], "idler A-I": points["A"],
                   "idler B": points["B"], "idler B-I": points["B"], "gearbox 2": points["C"],
                   "central gear": points["C"], "intermediate": points["D"],
                   "planter": points["E"]}
        for body in ("idler A", "idler B", "gearbox 2", "central gear"):
            pin(body + side, "carrier", centres[body])
        pin("idler A-I" + side, "idler A" + side, points["A"])
        pin("idler B-I" + side, "idler B" + side, points["B"])
        pin("intermediate" + side, "gearbox 2" + side, points["D"])
        pin("planter" + side, "gearbox 2" + side, points["E"])
        driver_radius = {("sun", "idler 1"): set2[0], ("idler 1", "idler 2"): set2[1],
                         ("idler 2", "train-1 planet"): set2[2], ("sun I", "idler 1-I"): set1[0],
                         ("idler 1-I", "idler 2-I"): set1[1], ("idler 2-I", "planet I"): set1[2],
                         ("gear D", "planet gear E"): mechanism.r}
        for pair, (driver, driven) in MESH_GEARS.items():
            a, b = (body if body == "central shaft" else body + side for body in (driver, driven))
            if pair == ("central", "intermediate"):
                mesh = _noncircular_mesh(mechanism, phi, arm, a, b, pressure_angle,
                                         mean_sliding_distance(module_nc, pressure_angle))
            else:
                mesh = _circular_mesh(pair, a, b, centres[driver], centres[driven],
                                      driver_radius[pair], pressure_angle, sliding_c)
            mesh = dataclasses.replace(mesh, name=_mesh_name(pair, arm))
            meshes.append(mesh)
            contacts[_mesh_name(pair, arm)] = (centres[driver], centres[driven],
                                               mesh.point * 1e3)
    return tuple(revolutes), tuple(meshes), contacts


def _mesh_name(pair, arm: int) -> tuple:
    """A mesh's key: the pair's gear names and the side (``("sun", "idler 1", 1)``); the
    drive's pairs (one for the machine) have side 0."""
    return (*pair, arm + 1)


def _noncircular_mesh(mechanism, phi, arm, driver, driven, alpha, sliding_mm):
    """The central gear (at C, still) on the intermediate (at D): the pitch point at
    ``r1(t)`` from C along C -> D (``t = phi``, arm 2 ``phi + pi``), the common tangent the
    central pitch curve's, ``r1' e + r1 J e`` (the curve ``C + r1(t) u(phic + t)`` of a gear
    that does not turn), the normal towards D."""
    t = phi + math.pi * arm
    r1, r1_rate, _ = mechanism.pitch_curve.radius_derivatives(t)
    centre = mechanism.motion(phi, "C", arm).position
    direction = np.stack([np.cos(mechanism.phic + t), np.sin(mechanism.phic + t)], axis=-1)
    tangent = _unit(r1_rate[:, None] * direction + r1[:, None] * _perp(direction))
    normal = -_perp(tangent)
    point = centre + r1[:, None] * direction
    return Mesh("central-intermediate", driver, driven, point * 1e-3, tangent, normal, alpha,
                sliding_mm * 1e-3)
