"""The dynamics (cadgen.dynamics, kinematics.rigid_dynamics) against closed forms and against
each of its own two routes: a rotating unbalanced disc, the conservative checks of load case
"none" (zero mean torque over a turn, the speed-squared scaling), the power balance against
Newton-Euler on the paper's design."""

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from kinematics.rigid_dynamics import (FRAME, BodyMotion, Model, Revolute, newton_euler,
                                       power_balance)

from cadgen.dynamics import planting_dynamics

from tests.helpers import stages_before_dynamics



def _disc(mass, offset, inertia, omega, samples=64):
    """A disc turning about O at ``omega`` (rad/s), its centre ``offset`` (m) from O."""
    phi = np.linspace(0.0, 2 * np.pi, samples, endpoint=False)
    u = np.stack([np.cos(phi), np.sin(phi)], axis=-1)
    du = np.stack([-np.sin(phi), np.cos(phi)], axis=-1)
    body = BodyMotion("disc", mass, inertia, offset * u, offset * du, -offset * u,
                      np.ones_like(phi), np.zeros_like(phi))
    pin = Revolute("O", "disc", FRAME, np.zeros((samples, 2)))
    return phi, Model(phi, omega, (body,), (pin,), (), "disc")


@settings(max_examples=30, deadline=None)
@given(mass=st.floats(0.01, 50), offset=st.floats(0.0, 0.5), inertia=st.floats(0.0, 5.0),
       omega=st.floats(0.1, 20.0))
def test_an_unbalanced_disc_needs_its_weight_moment_and_its_bearing_the_centripetal_force(
        mass, offset, inertia, omega):
    phi, model = _disc(mass, offset, inertia, omega)
    solution, _, _, _ = newton_euler(model)
    g = model.gravity
    # closed form: at constant speed only gravity's moment m g e cos(phi) needs a torque;
    # the pin gives the centripetal force and carries the weight
    expected_torque = mass * g * offset * np.cos(phi)
    expected_pin = mass * (-offset * omega ** 2 * np.stack([np.cos(phi), np.sin(phi)], -1)
                           + np.array([0.0, g]))
    scale = mass * (g + offset * omega ** 2) * max(offset, 1.0)
    assert np.allclose(solution.input_torque, expected_torque, atol=1e-12 * scale)
    assert np.allclose(solution.reactions["O"], expected_pin, atol=1e-12 * scale)
    assert np.allclose(power_balance(model)["input_torque"], expected_torque, atol=1e-12 * scale)
    # the frame feels the centripetal force outwards and the weight down
    assert np.allclose(solution.shaking_force, -expected_pin, atol=1e-12 * scale)


@pytest.fixture(scope="module")
def paper_stages():
    """The paper's design through the stages the dynamics reads (no solids: estimated)."""
    return stages_before_dynamics()


def _dynamics(run, **changes):
    params = run.params
    if changes:
        field = {k: v for k, v in changes.items() if k == "carrier_speed_rpm"}
        rest = {k: v for k, v in changes.items() if k != "carrier_speed_rpm"}
        params = params.model_copy(update={
            "dynamics": params.dynamics.model_copy(update=rest),
            "field": params.field.model_copy(update=field)})
    values = run.values
    return planting_dynamics(params, values["kinematics"], values["drivetrain"],
                             cam=values["cam"], events=values["metrics"].events)


def test_the_power_balance_and_newton_euler_agree_on_the_paper_design(paper_stages):
    result = _dynamics(paper_stages)
    assert result.mass_source == "estimated"
    assert result.energy_balance_max_rel <= 1e-6
    assert result.route_disagreement_nm <= 1e-9 * np.max(np.abs(result.input_torque))
    assert not result.invalid
    # every mesh force is a compression along its line of action
    assert all(np.all(m.normal_force_n >= 0) for m in result.meshes.values())


def test_with_no_load_the_mean_input_torque_over_a_turn_is_zero(paper_stages):
    result = _dynamics(paper_stages, load_case="none")
    peak = np.max(np.abs(result.input_torque))
    # input work over a turn = change of kinetic + potential energy = 0 (both periodic)
    assert abs(np.mean(result.input_torque)) <= 1e-9 * peak
    assert result.cam is None


def test_with_no_load_the_torque_less_gravity_scales_with_speed_squared(paper_stages):
    torque = {rpm: _dynamics(paper_stages, load_case="none", carrier_speed_rpm=rpm,
                             speeds_rpm=(rpm,)).input_torque for rpm in (0.01, 30.0, 60.0)}
    gravity = torque[0.01]     # (0.01 r/min)^2 of inertia: 1e-7 of the 30 r/min part
    inertial_30, inertial_60 = torque[30.0] - gravity, torque[60.0] - gravity
    assert np.max(np.abs(inertial_60 - 4.0 * inertial_30)) <= 1e-6 * np.max(np.abs(inertial_60))
    assert np.max(np.abs(inertial_30)) > 1e-3 * np.max(np.abs(gravity))   # not a vacuous check


def test_the_mesh_api_gives_force_and_contact_position_for_every_pair(paper_stages):
    result = _dynamics(paper_stages)
    pairs = {key[:2] for key in result.meshes}
    assert ("central", "intermediate") in pairs and ("gear D", "planet gear E") in pairs
    mesh = result.meshes[("central", "intermediate", 1)]
    mechanism = paper_stages.values["kinematics"]
    # the contact sits at r1(t) from the central gear's axis and a - r1(t) from the other's
    r1 = mechanism.pitch_curve.radius(mesh.pitch_parameter)
    assert np.allclose(mesh.contact_radius["central"], r1, rtol=1e-12)
    assert np.allclose(mesh.contact_radius["intermediate"], mechanism.centre_distance - r1,
                       rtol=1e-12)
    # the 1:1 circular pair: the contact on gear D returns after one relative turn
    circular = result.meshes[("gear D", "planet gear E", 1)]
    assert np.allclose(circular.contact_radius["gear D"], mechanism.r)


def test_a_bench_run_has_no_soil_and_says_so(paper_stages):
    values = paper_stages.values
    result = planting_dynamics(paper_stages.params, values["kinematics"], values["drivetrain"],
                               cam=values["cam"], events=None)
    assert any("no soil" in note for note in result.notes)


def test_the_flywheel_and_the_motor_follow_their_rules(paper_stages):
    from cadgen.dynamics import motor_and_flywheel

    result = _dynamics(paper_stages)
    params = paper_stages.params
    motor = motor_and_flywheel(result, params)
    rms = math.sqrt(float(np.mean(result.input_torque ** 2)))
    assert motor["rated_torque_nm"] >= params.dynamics.rms_margin * rms - 1e-12
    assert np.max(np.abs(result.input_torque)) <= params.dynamics.overload_ratio \
        * motor["rated_torque_nm"] + 1e-12
    omega_in = 2 * math.pi * result.input_rpm / 60
    flywheel = motor["flywheel"]
    assert math.isclose(flywheel["inertia_on_input_kgm2"], flywheel["energy_swing_j"]
                        / (params.dynamics.speed_fluctuation * omega_in ** 2))
