"""Inverse dynamics of a planar one-freedom mechanism driven at constant speed: two routes.

Every body's motion is given as a function of the one coordinate ``phi`` (the carrier
angle) with its analytic first and second derivatives, and ``phi`` turns at a constant
``omega``: velocities are ``x' omega``, accelerations ``x'' omega^2``. From them:

* :func:`newton_euler` writes each body's three equations (force, moment about its centre
  of mass) with its joints' reactions as unknowns (a revolute: two force components; a gear
  mesh: the normal force along its line of action; the drive: the input torque) and solves
  the square linear system at every pose at once (``numpy.linalg.solve`` on a stack);
* :func:`power_balance` needs no reaction at all: input power = d(kinetic + potential
  energy)/dt - the power of the applied loads, each term from the analytic derivatives.

Ideal joints do no work (a mesh's force acts at the pitch point, where the two gears roll
without sliding), so the two routes give the same input torque when the model is right:
their difference is the check. Friction enters both as known couples (from the reactions
of the previous round, see :func:`newton_euler`), so both see the same losses.

Units: m, kg, s, N, N m; ``phi`` in rad. Shapes: ``n`` poses, ``B`` bodies.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["BodyMotion", "Revolute", "Mesh", "PointLoad", "Couple", "Model", "Solution",
           "newton_euler", "system_inverse", "power_balance", "friction_couples",
           "kinetic_energy", "potential_energy", "load_power", "FRAME", "GRAVITY"]

#: The fixed frame's name: a joint to it has no body on its other side.
FRAME = "frame"
#: m/s^2 (standard gravity).
GRAVITY = 9.80665


def _cross(r, f):
    """z of the planar cross product, ``(n, 2) x (n, 2) -> (n,)``."""
    return r[..., 0] * f[..., 1] - r[..., 1] * f[..., 0]


def _perp(r):
    """``J r``: ``r`` turned a quarter turn counter-clockwise."""
    return np.stack([-r[..., 1], r[..., 0]], axis=-1)


@dataclass(frozen=True)
class BodyMotion:
    """A rigid body moving with ``phi``.

    Attributes
    ----------
    name : str
    mass : float
        kg.
    inertia : float
        About the centre of mass, z axis, kg m^2.
    centre, centre_rate, centre_accel : (n, 2) float
        Centre of mass (m) and its derivatives in ``phi`` (m/rad, m/rad^2).
    angle_rate, angle_accel : (n,) float
        The body's absolute angle's derivatives in ``phi`` (rad/rad, rad/rad^2).
    """

    name: str
    mass: float
    inertia: float
    centre: np.ndarray
    centre_rate: np.ndarray
    centre_accel: np.ndarray
    angle_rate: np.ndarray
    angle_accel: np.ndarray

    def point_rate(self, point):
        """Velocity over ``omega`` of the body's material point at ``point`` (n, 2), m/rad."""
        return self.centre_rate + self.angle_rate[:, None] * _perp(point - self.centre)


@dataclass(frozen=True)
class Revolute:
    """A pin between ``body`` and ``base`` (a body's name, or :data:`FRAME`) at ``point``
    (n, 2) m. Its reaction ``R`` acts on ``body``, ``-R`` on ``base``. ``radius`` (m) is the
    journal's, for bearing friction."""

    name: str
    body: str
    base: str
    point: np.ndarray
    radius: float = 0.0


@dataclass(frozen=True)
class Mesh:
    """A gear mesh: ``driven`` gets ``F_n d`` at the pitch ``point``, ``driver`` ``-F_n d``.

    ``tangent`` and ``normal`` (n, 2) are unit vectors of the pitch curves' common tangent
    and normal at the pitch point, ``normal`` pointing from the driver's side into the
    driven gear's (the tooth force always pushes the gears apart). The line of action is
    ``d = s cos(alpha) tangent + sin(alpha) normal``, the flank sign ``s`` the sign of the
    tangential force (:func:`newton_euler`). ``friction_arm`` (m) is the mean sliding distance from the pitch point.
    """

    name: str
    driver: str
    driven: str
    point: np.ndarray
    tangent: np.ndarray
    normal: np.ndarray
    pressure_angle: float
    friction_arm: float = 0.0


@dataclass(frozen=True)
class PointLoad:
    """A known force (n, 2) N on ``body`` at ``point`` (n, 2) m; with ``other`` a body
    name, ``-force`` acts on that body at the same point (an internal pair: the cam)."""

    name: str
    body: str
    point: np.ndarray
    force: np.ndarray
    other: str | None = None


@dataclass(frozen=True)
class Couple:
    """A known moment (n,) N m on ``body``; ``-moment`` on ``other`` (a body or the frame)."""

    name: str
    body: str
    moment: np.ndarray
    other: str = FRAME


@dataclass(frozen=True)
class Model:
    """The mechanism at ``n`` poses: bodies, joints, the driven body and known loads.

    ``input_body`` carries the unknown input torque (reacted by the frame); its angle rate
    turns the torque into power. ``gravity`` (m/s^2) acts along -y.
    """

    phi: np.ndarray
    omega: float
    bodies: tuple
    revolutes: tuple
    meshes: tuple
    input_body: str
    loads: tuple = ()
    couples: tuple = ()
    gravity: float = GRAVITY

    def index(self) -> dict:
        return {body.name: k for k, body in enumerate(self.bodies)}

    def body(self, name: str) -> BodyMotion:
        return self.bodies[self.index()[name]]


@dataclass
class Solution:
    """What :func:`newton_euler` found at every pose.

    ``input_torque`` (n,) N m on the input body; ``reactions`` ``{revolute: (n, 2)}`` N on
    its body; ``mesh_forces`` ``{mesh: (n,)}`` N along ``mesh_directions[mesh]`` (n, 2) on
    the driven gear; ``shaking_force`` (n, 2) N and ``shaking_moment`` (n,) N m about the
    origin: what the moving bodies and the motor's reaction put on the frame.
    """

    input_torque: np.ndarray
    reactions: dict
    mesh_forces: dict
    mesh_directions: dict
    shaking_force: np.ndarray
    shaking_moment: np.ndarray
    friction_couples: tuple = field(default=())
    tangential: dict = field(default_factory=dict)   # {mesh: (n,) signed F_t along tangent}


def system_inverse(model: Model) -> np.ndarray:
    """The inverse (n, 3B, 3B) of the Newton-Euler system: it depends on the geometry only
    (a mesh's unknown is its tangential force, along the common tangent), so every load case,
    friction round and speed of one model's motion shares it (a product, not a solve)."""
    return np.linalg.inv(_matrix(model))


def newton_euler(model: Model, *, inverse=None, bearing_friction: float = 0.0,
                 mesh_friction: float = 0.0, rtol: float = 1e-13, max_rounds: int = 200):
    """Solve every body's Newton-Euler equations with its joints at every pose.

    A mesh's unknown is its tangential force ``F_t`` (signed, along the common tangent); the
    tooth force's other component, ``tan(alpha) |F_t|`` along the common normal (it always
    pushes the gears apart, whichever flank carries), and Coulomb friction (bearings:
    ``mu_b |R| r``; meshes: ``mu_m F_n s``, :func:`friction_couples`) depend on the answer:
    they are known loads taken from the previous round, until the input torque changes by
    less than ``rtol`` of its peak. Returns ``(solution, model with the final friction
    couples, rounds, last relative change)``: :func:`power_balance` of that model sees the
    same losses.
    """
    inverse = system_inverse(model) if inverse is None else inverse
    base = model.couples
    tangential = {m.name: np.zeros(len(model.phi)) for m in model.meshes}
    current, solution, change = model, None, np.inf
    fixed = _known_rhs(model)      # inertia, gravity and the given loads: the same each round
    for rounds in range(1, max_rounds + 1):
        previous = solution
        solution = _solve(current, inverse, tangential, fixed)
        tangential = solution.tangential
        if previous is not None:
            scale = max(float(np.max(np.abs(solution.input_torque))), 1e-300)
            change = float(np.max(np.abs(solution.input_torque - previous.input_torque))) / scale
            change = max(change, max(
                float(np.max(np.abs(solution.mesh_forces[k] - previous.mesh_forces[k])))
                / max(float(np.max(solution.mesh_forces[k])), 1e-300) for k in tangential)
                if tangential else 0.0)
            if change <= rtol:
                break
        if bearing_friction or mesh_friction:
            couples = friction_couples(model, solution, bearing_friction, mesh_friction)
            current = Model(model.phi, model.omega, model.bodies, model.revolutes, model.meshes,
                            model.input_body, model.loads, base + couples, model.gravity)
    solution.friction_couples = current.couples[len(base):]
    return solution, current, rounds, change


def _known_rhs(model: Model) -> np.ndarray:
    """The right-hand side of the bodies' inertia, gravity and given loads (not the couples)."""
    index = model.index()
    n, size = len(model.phi), 3 * len(model.bodies)
    rhs = np.zeros((n, size))
    omega2 = model.omega ** 2
    for k, body in enumerate(model.bodies):
        rhs[:, 3 * k:3 * k + 2] = body.mass * body.centre_accel * omega2
        rhs[:, 3 * k + 1] += body.mass * model.gravity
        rhs[:, 3 * k + 2] = body.inertia * body.angle_accel * omega2

    for load in model.loads:           # known: to the right-hand side
        for name, sign in ((load.body, 1.0), (load.other, -1.0)):
            if name is None or name == FRAME:
                continue
            k = index[name]
            rhs[:, 3 * k:3 * k + 2] -= sign * load.force
            rhs[:, 3 * k + 2] -= sign * _cross(load.point - model.bodies[k].centre, load.force)
    return rhs


def _solve(model: Model, inverse, tangential: dict, fixed) -> Solution:
    """One linear solve with the meshes' separating forces from ``tangential`` and the
    model's couples known (``fixed``: :func:`_known_rhs`)."""
    index = model.index()
    n = len(model.phi)
    rhs = fixed.copy()
    for couple in model.couples:
        rhs[:, 3 * index[couple.body] + 2] -= couple.moment
        if couple.other != FRAME:
            rhs[:, 3 * index[couple.other] + 2] += couple.moment
    for mesh in model.meshes:          # the separating component, from the last round
        push = np.tan(mesh.pressure_angle) * np.abs(tangential[mesh.name])[:, None] * mesh.normal
        for name, sign in ((mesh.driven, 1.0), (mesh.driver, -1.0)):
            if name != FRAME:
                k = index[name]
                rhs[:, 3 * k:3 * k + 2] -= sign * push
                rhs[:, 3 * k + 2] -= sign * _cross(mesh.point - model.bodies[k].centre, push)
    unknowns = np.einsum("nij,nj->ni", inverse, rhs)
    reactions, forces, directions, along = {}, {}, {}, {}
    shaking_force = np.zeros((n, 2))
    shaking_moment = -unknowns[:, -1]        # the motor's stator reacts on the frame
    column = 0
    for joint in model.revolutes:
        reactions[joint.name] = unknowns[:, column:column + 2]
        if joint.base == FRAME:
            shaking_force -= reactions[joint.name]
            shaking_moment -= _cross(joint.point, reactions[joint.name])
        column += 2
    for mesh in model.meshes:
        along[mesh.name] = unknowns[:, column]
        alpha = mesh.pressure_angle
        forces[mesh.name] = np.abs(along[mesh.name]) / np.cos(alpha)
        flank = np.where(along[mesh.name] < 0, -1.0, 1.0)[:, None]
        directions[mesh.name] = flank * np.cos(alpha) * mesh.tangent + np.sin(alpha) * mesh.normal
        if FRAME in (mesh.driver, mesh.driven):
            # a gear fixed to the frame (the pricking sun) passes its tooth force on to it
            on_driven = forces[mesh.name][:, None] * directions[mesh.name]
            on_frame = -on_driven if mesh.driver == FRAME else on_driven
            shaking_force += on_frame
            shaking_moment += _cross(mesh.point, on_frame)
        column += 1
    for couple in model.couples:
        if couple.other == FRAME:
            shaking_moment -= couple.moment
    return Solution(unknowns[:, -1], reactions, forces, directions, shaking_force,
                    shaking_moment, model.couples, along)


def _matrix(model: Model) -> np.ndarray:
    """The (n, 3B, 3B) coefficients: each body's force and moment rows, each joint's columns
    (a revolute's two force components, a mesh's tangential force, the input torque last)."""
    index = model.index()
    n, count = len(model.phi), len(model.bodies)
    size = 3 * count
    columns = 2 * len(model.revolutes) + len(model.meshes) + 1
    if columns != size:
        raise ValueError(f"{count} bodies need {size} unknowns, the joints give {columns}: "
                         "the mechanism must have exactly one freedom")
    matrix = np.zeros((n, size, size))

    def put_force(name, column, vector, point, sign=1.0):
        if name == FRAME:
            return
        k = index[name]
        arm = point - model.bodies[k].centre
        if vector is None:      # a revolute: two columns, x and y
            matrix[:, 3 * k, column] += sign
            matrix[:, 3 * k + 1, column + 1] += sign
            matrix[:, 3 * k + 2, column] += -sign * arm[:, 1]
            matrix[:, 3 * k + 2, column + 1] += sign * arm[:, 0]
        else:
            matrix[:, 3 * k, column] += sign * vector[:, 0]
            matrix[:, 3 * k + 1, column] += sign * vector[:, 1]
            matrix[:, 3 * k + 2, column] += sign * _cross(arm, vector)

    column = 0
    for joint in model.revolutes:
        put_force(joint.body, column, None, joint.point)
        put_force(joint.base, column, None, joint.point, -1.0)
        column += 2
    for mesh in model.meshes:
        put_force(mesh.driven, column, mesh.tangent, mesh.point)
        put_force(mesh.driver, column, mesh.tangent, mesh.point, -1.0)
        column += 1
    matrix[:, 3 * index[model.input_body] + 2, column] = 1.0
    return matrix


def kinetic_energy(model: Model) -> np.ndarray:
    """``T(phi)`` (n,) J: ``omega^2 / 2 sum(m |c'|^2 + I theta'^2)``."""
    total = sum(b.mass * np.sum(b.centre_rate ** 2, axis=1) + b.inertia * b.angle_rate ** 2
                for b in model.bodies)
    return 0.5 * model.omega ** 2 * total


def potential_energy(model: Model) -> np.ndarray:
    """``V(phi)`` (n,) J of gravity, ``g sum m y_c``."""
    return model.gravity * sum(b.mass * b.centre[:, 1] for b in model.bodies)


def load_power(model: Model) -> np.ndarray:
    """Power (n,) W the known loads and couples put into the moving bodies."""
    index = model.index()
    power = np.zeros(len(model.phi))
    for load in model.loads:
        for name, sign in ((load.body, 1.0), (load.other, -1.0)):
            if name is not None and name != FRAME:
                velocity = model.bodies[index[name]].point_rate(load.point) * model.omega
                power += sign * np.sum(load.force * velocity, axis=1)
    for couple in model.couples:
        power += couple.moment * model.bodies[index[couple.body]].angle_rate * model.omega
        if couple.other != FRAME:
            power -= couple.moment * model.bodies[index[couple.other]].angle_rate * model.omega
    return power


def power_balance(model: Model) -> dict:
    """The input torque from the power balance, with no reaction computed.

    ``P_in = dT/dt + dV/dt - P_loads``, with ``dT/dt = omega^3 sum(m c'.c'' + I theta'
    theta'')`` and ``dV/dt = omega g sum(m y_c')``, both analytic; ``torque = P_in /
    (theta_in' omega)``. Returns ``{"input_torque", "input_power", "kinetic_rate",
    "potential_rate", "load_power"}`` (n,) each.
    """
    omega = model.omega
    kinetic_rate = omega ** 3 * sum(
        b.mass * np.sum(b.centre_rate * b.centre_accel, axis=1)
        + b.inertia * b.angle_rate * b.angle_accel for b in model.bodies)
    potential_rate = omega * model.gravity * sum(b.mass * b.centre_rate[:, 1]
                                                 for b in model.bodies)
    loads = load_power(model)
    power = kinetic_rate + potential_rate - loads
    rate = model.body(model.input_body).angle_rate * omega
    return {"input_torque": power / rate, "input_power": power, "kinetic_rate": kinetic_rate,
            "potential_rate": potential_rate, "load_power": loads}


def friction_couples(model: Model, solution: Solution, bearing_friction: float,
                     mesh_friction: float) -> tuple:
    """Coulomb friction as couple pairs against each joint's relative rotation.

    A bearing: ``mu_b |R| r_journal`` (the SKF simplified model, ``M = mu F d / 2``); a
    mesh: ``mu_m F_n s`` with ``s`` the mesh's mean sliding distance (``friction_arm``).
    A couple pair does no work on a rigid pair of bodies turning together, and its power
    is ``-M |relative rate|``: always a loss.
    """
    index = model.index()

    def rate(name):
        return 0.0 if name == FRAME else model.bodies[index[name]].angle_rate

    couples = []
    for joint in model.revolutes:
        relative = np.sign(rate(joint.body) - rate(joint.base))
        magnitude = bearing_friction * np.linalg.norm(solution.reactions[joint.name], axis=1) \
            * joint.radius
        couples.append(Couple(f"bearing {joint.name}", joint.body, -magnitude * relative,
                              joint.base))
    for mesh in model.meshes:
        relative = np.sign(rate(mesh.driven) - rate(mesh.driver))
        magnitude = mesh_friction * np.abs(solution.mesh_forces[mesh.name]) * mesh.friction_arm
        couples.append(Couple(f"mesh {mesh.name}", mesh.driven, -magnitude * relative,
                              mesh.driver))
    return tuple(couples)
