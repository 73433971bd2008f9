"""An independent multibody package, Exudyn, on a reduced model of one arm: gearbox 2 moved as
the carrier prescribes, the planter pinned to it at E and turned by the attitude law. The couple
that turns the planter must be the moment about E our Newton-Euler solve gives the 1:1 mesh's
force on the planet gear E (load case "none": gravity only), to 1e-3 of its peak."""

import math

import numpy as np
import pytest

from kinematics.planting import rotating_offset

from cadgen.dynamics import planting_dynamics

from tests.helpers import exudyn_couple_error, exudyn_prescribe, stages_before_dynamics

exu = pytest.importorskip("exudyn")


def _ours(run):
    params = run.params
    params = params.model_copy(update={"dynamics": params.dynamics.model_copy(
        update={"load_case": "none", "speeds_rpm": (params.field.carrier_speed_rpm,)})})
    values = run.values
    result = planting_dynamics(params, values["kinematics"], values["drivetrain"],
                               cam=values["cam"], events=values["metrics"].events)
    mesh = result.meshes[("gear D", "planet gear E", 1)]
    hub = values["kinematics"].motion(result.phi, "E").position
    # the mesh force on gear E and its moment about E (N m)
    force = mesh.normal_force_n[:, None] * mesh.line_of_action
    contact = _contact_point(values["kinematics"], result.phi)
    moment = (contact[:, 0] - hub[:, 0]) * 1e-3 * force[:, 1] \
        - (contact[:, 1] - hub[:, 1]) * 1e-3 * force[:, 0]
    return result, moment


def _contact_point(mechanism, phi):
    d = mechanism.motion(phi, "D").position
    e = mechanism.motion(phi, "E").position
    return d + mechanism.r * (e - d) / np.linalg.norm(e - d, axis=1, keepdims=True)


@pytest.fixture(scope="module")
def stages():
    """The paper's design through the stages the dynamics reads."""
    return stages_before_dynamics()


def test_exudyn_turns_the_planter_with_the_couple_our_mesh_force_gives(stages, tmp_path,
                                                                       monkeypatch):
    from exudyn.utilities import (LoadMassProportional, MarkerBodyMass,
                                  MarkerBodyPosition, MarkerNodeCoordinate, NodePointGround,
                                  NodeRigidBody2D, ObjectJointRevolute2D, ObjectRigidBody2D)

    monkeypatch.chdir(tmp_path)     # Exudyn writes its solution folder where it runs
    result, moment = _ours(stages)
    mechanism = stages.values["kinematics"]
    omega = 2 * math.pi * result.carrier_rpm / 60.0
    box, planter = result.masses["gearbox 2 1"], result.masses["planter 1"]
    hub0 = mechanism.motion(np.zeros(1), "E").position[0]
    centre0 = mechanism.motion(np.zeros(1), "C").position[0]
    box_offset = box.centre - centre0
    psi0 = float(mechanism.attitude(np.zeros(1))[0])

    def box_pose(t):
        phi = np.array([omega * t])
        c = rotating_offset(mechanism.motion(phi, "C"), phi, 1.0, 0.0, box_offset)
        return c.position[0] * 1e-3, c.velocity[0] * 1e-3 * omega, phi[0]

    def planter_pose(t):
        phi = np.array([omega * t])
        psi, rate, accel = mechanism.attitude_derivatives(phi)
        c = rotating_offset(mechanism.motion(phi, "E"), psi - psi0, rate, accel,
                            planter.centre - hub0)
        return c.position[0] * 1e-3, c.velocity[0] * 1e-3 * omega, float(psi[0] - psi0), \
            float(rate[0]) * omega

    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    ground = mbs.AddNode(NodePointGround(referenceCoordinates=[0, 0, 0]))
    box_start, box_velocity, _ = box_pose(0.0)
    box_node = mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[*box_start, 0.0],
                                           initialVelocities=[*box_velocity, omega]))
    box_body = mbs.AddObject(ObjectRigidBody2D(mass=box.mass,
                                               inertia=box.inertia * 1e-6,
                                               nodeNumber=box_node))
    start, velocity, _, spin = planter_pose(0.0)
    node = mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[*start, 0.0],
                                       initialVelocities=[*velocity, spin]))
    body = mbs.AddObject(ObjectRigidBody2D(mass=planter.mass,
                                           inertia=planter.inertia * 1e-6,
                                           nodeNumber=node))
    ground_marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=ground, coordinate=0))

    def prescribe(node_number, coordinate, law):
        return exudyn_prescribe(mbs, ground_marker, node_number, coordinate, law)

    prescribe(box_node, 0, lambda t: box_pose(t)[0][0] - box_start[0])
    prescribe(box_node, 1, lambda t: box_pose(t)[0][1] - box_start[1])
    prescribe(box_node, 2, lambda t: box_pose(t)[2])
    turn = prescribe(node, 2, lambda t: planter_pose(t)[2])
    pin_box = mbs.AddMarker(MarkerBodyPosition(
        bodyNumber=box_body, localPosition=[*((hub0 - box.centre) * 1e-3), 0.0]))
    pin_planter = mbs.AddMarker(MarkerBodyPosition(
        bodyNumber=body, localPosition=[*((hub0 - planter.centre) * 1e-3), 0.0]))
    mbs.AddObject(ObjectJointRevolute2D(markerNumbers=[pin_box, pin_planter]))
    for number in (box_body, body):
        mbs.AddLoad(LoadMassProportional(markerNumber=mbs.AddMarker(
            MarkerBodyMass(bodyNumber=number)), loadVector=[0, -9.80665, 0]))
    error, peak = exudyn_couple_error(exu, mbs, turn, omega, result.phi, moment)
    assert error <= 1e-3 * peak, f"{error / peak:.2e} of the peak {peak:.4g} N m"
