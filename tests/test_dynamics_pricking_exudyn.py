"""An independent multibody package, Exudyn, on a reduced pricking model: the gear case turned
about O at the carrier speed, the planet (its gear, the rocker and the needle, lumped) pinned to
it at B and turned by the needle angle phi2. The couple that turns the planet must be the moment
about B our Newton-Euler solve gives the stage-2 mesh's force on the planet (load case "none":
gravity only), to 1e-3 of its peak."""

import math
from pathlib import Path

import numpy as np
import pytest

from kinematics.planting import rotating_offset

from cadgen.dynamics import pricking_dynamics
from cadgen.dynamics.pricking import CASE, INTERMEDIATE, PLANET, pricking_motion

from tests.helpers import exudyn_couple_error, exudyn_prescribe, stages_before_dynamics

exu = pytest.importorskip("exudyn")

KERNEL_B = Path(__file__).resolve().parents[1] / "params" / "kernel-b.toml"


def _ours(run):
    params = run.params
    params = params.model_copy(update={"dynamics": params.dynamics.model_copy(
        update={"load_case": "none", "speeds_rpm": (params.field.carrier_speed_rpm,)})})
    design = run.values["kinematics"]
    result = pricking_dynamics(params, design, run.values["drivetrain"],
                               field=run.values["metrics"])
    mesh = result.meshes[("intermediate 2", "planet", 0)]
    kinematics = pricking_motion(design, result.phi)
    line = np.stack([np.cos(kinematics.phi1), np.sin(kinematics.phi1)], axis=-1)
    contact = kinematics.axes[INTERMEDIATE].position \
        + kinematics.contacts["intermediate 2"][0][:, None] * line
    hub = kinematics.axes[PLANET].position
    force = mesh.normal_force_n[:, None] * mesh.line_of_action
    moment = (contact[:, 0] - hub[:, 0]) * 1e-3 * force[:, 1] \
        - (contact[:, 1] - hub[:, 1]) * 1e-3 * force[:, 0]
    return result, moment


def test_exudyn_turns_the_planet_with_the_couple_our_mesh_force_gives(tmp_path, monkeypatch):
    from exudyn.utilities import (LoadMassProportional, MarkerBodyMass,
                                  MarkerBodyPosition, MarkerNodeCoordinate, NodePointGround,
                                  NodeRigidBody2D, ObjectJointRevolute2D, ObjectRigidBody2D)

    monkeypatch.chdir(tmp_path)     # Exudyn writes its solution folder where it runs
    run = stages_before_dynamics(KERNEL_B)
    design = run.values["kinematics"]
    result, moment = _ours(run)
    omega = 2 * math.pi * result.carrier_rpm / 60.0
    case, planet = result.masses[CASE], result.masses[PLANET]
    start = pricking_motion(design, np.zeros(1))
    hub0 = start.start_axes[PLANET]
    centre0 = start.start_axes[CASE]
    memo = {}

    def poses(t):
        """The case's and the planet's centre (m), velocity (m/s) and angle from the start
        (rad) and the planet's rate (rad/s), from our kinematics at carrier progress w t."""
        if t not in memo:
            kinematics = pricking_motion(design, np.array([omega * t]))
            out = []
            for body, mass, axis0 in ((CASE, case, centre0), (PLANET, planet, hub0)):
                angle, rate, accel = kinematics.angles[body]
                c = rotating_offset(kinematics.axes[body], angle, rate, accel,
                                    np.asarray(mass.centre) - axis0)
                out.append((c.position[0] * 1e-3, c.velocity[0] * 1e-3 * omega,
                            float(angle[0]), float(rate[0]) * omega))
            memo.clear()
            memo[t] = out
        return memo[t]

    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    ground = mbs.AddNode(NodePointGround(referenceCoordinates=[0, 0, 0]))
    ground_marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=ground, coordinate=0))
    nodes, bodies = [], []
    for k, mass in enumerate((case, planet)):
        position, velocity, _, spin = poses(0.0)[k]
        node = mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[*position, 0.0],
                                           initialVelocities=[*velocity, spin]))
        nodes.append(node)
        bodies.append(mbs.AddObject(ObjectRigidBody2D(mass=mass.mass,
                                                      inertia=mass.inertia * 1e-6,
                                                      nodeNumber=node)))

    def prescribe(node_number, coordinate, law):
        return exudyn_prescribe(mbs, ground_marker, node_number, coordinate, law)

    case_start = poses(0.0)[0][0]
    prescribe(nodes[0], 0, lambda t: poses(t)[0][0][0] - case_start[0])
    prescribe(nodes[0], 1, lambda t: poses(t)[0][0][1] - case_start[1])
    prescribe(nodes[0], 2, lambda t: poses(t)[0][2])
    turn = prescribe(nodes[1], 2, lambda t: poses(t)[1][2])
    pins = [mbs.AddMarker(MarkerBodyPosition(
        bodyNumber=body, localPosition=[*((hub0 - np.asarray(mass.centre)) * 1e-3), 0.0]))
        for body, mass in zip(bodies, (case, planet))]
    mbs.AddObject(ObjectJointRevolute2D(markerNumbers=pins))
    for number in bodies:
        mbs.AddLoad(LoadMassProportional(markerNumber=mbs.AddMarker(
            MarkerBodyMass(bodyNumber=number)), loadVector=[0, -9.80665, 0]))
    error, peak = exudyn_couple_error(exu, mbs, turn, omega, result.phi, moment)
    assert error <= 1e-3 * peak, f"{error / peak:.2e} of the peak {peak:.4g} N m"
