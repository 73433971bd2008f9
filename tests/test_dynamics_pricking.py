"""The pricking mechanism's dynamics (cadgen.dynamics.pricking*) against closed forms and its
own two routes: the gear case alone with a known unbalance, the whole mechanism's momentum
against the frame's forces, the conservative checks of load case "none", the contact geometry
against the gear stages' pitch curves, and the kinematics' spectral derivatives against the
closed-form derivative of the carrier angle."""

import math
from pathlib import Path

import numpy as np
import pytest

from kinematics.rigid_dynamics import GRAVITY

from cadgen.dynamics import pricking_dynamics
from cadgen.dynamics.mass import BodyMass
from cadgen.dynamics.pricking import CASE, INTERMEDIATE, PLANET, pricking_motion

from tests.helpers import stages_before_dynamics

KERNEL_B = Path(__file__).resolve().parents[1] / "params" / "kernel-b.toml"


@pytest.fixture(scope="module")
def kernel_b():
    """kernel-b through the stages the dynamics reads (no solids: estimated masses)."""
    return stages_before_dynamics(KERNEL_B)


def _dynamics(run, masses=None, field="file", **changes):
    params = run.params
    field_changes = {k: v for k, v in changes.items() if k == "carrier_speed_rpm"}
    rest = {k: v for k, v in changes.items() if k != "carrier_speed_rpm"}
    params = params.model_copy(update={"dynamics": params.dynamics.model_copy(update=rest),
                                       "field": params.field.model_copy(update=field_changes)})
    values = run.values
    return pricking_dynamics(params, values["kinematics"], values["drivetrain"],
                             field=values["metrics"] if field == "file" else field,
                             masses=masses)


def test_the_power_balance_and_newton_euler_agree_on_kernel_b(kernel_b):
    result = _dynamics(kernel_b)
    assert result.mass_source == "estimated"
    assert result.energy_balance_max_rel <= 1e-6
    assert result.route_disagreement_nm <= 1e-9 * np.max(np.abs(result.input_torque))
    assert not result.invalid and result.friction_rounds > 1     # friction did iterate
    assert all(np.all(m.normal_force_n >= 0) for m in result.meshes.values())
    # soil and friction take work out of the drive over a turn
    assert np.mean(result.input_torque) > 0


def test_with_no_load_the_mean_input_torque_over_a_turn_is_zero(kernel_b):
    result = _dynamics(kernel_b, load_case="none")
    peak = np.max(np.abs(result.input_torque))
    assert abs(np.mean(result.input_torque)) <= 1e-9 * peak
    assert result.energy_balance_max_rel <= 1e-12


def test_with_no_load_the_torque_less_gravity_scales_with_speed_squared(kernel_b):
    torque = {rpm: _dynamics(kernel_b, load_case="none", carrier_speed_rpm=rpm,
                             speeds_rpm=(rpm,)).input_torque for rpm in (0.01, 40.0, 80.0)}
    gravity = torque[0.01]
    inertial_40, inertial_80 = torque[40.0] - gravity, torque[80.0] - gravity
    assert np.max(np.abs(inertial_80 - 4.0 * inertial_40)) <= 1e-6 * np.max(np.abs(inertial_80))
    assert np.max(np.abs(inertial_40)) > 1e-2 * np.max(np.abs(gravity))   # not vacuous


@pytest.mark.parametrize("rpm", [0.01, 75.0, 300.0], ids=["still", "file speed", "fast"])
def test_the_case_alone_with_an_unbalance_needs_its_weight_moment(kernel_b, rpm):
    """Only the case has mass, at e from O: at constant speed its kinetic energy is constant,
    so the drive torque is gravity's moment m g e cos(theta) about O, and the frame feels the
    centripetal force outwards and the weight downwards; the massless gears carry nothing."""
    design = kernel_b.values["kinematics"]
    mass, offset, start_angle = 2.5, 0.03, 0.4     # kg, m, rad (the centre at the start pose)
    centre = np.asarray(design.linkage.centre) + 1e3 * offset * np.array(
        [math.cos(start_angle), math.sin(start_angle)])
    masses = {CASE: BodyMass(mass, centre, 123.0)}
    result = _dynamics(kernel_b, masses, load_case="none", carrier_speed_rpm=rpm,
                       speeds_rpm=(rpm,))
    sense = design.motion.sense
    theta = start_angle + sense * result.phi
    omega = 2 * math.pi * rpm / 60
    # the torque in the case's turning sense: sense x (m g e cos theta about +z)
    expected = sense * mass * GRAVITY * offset * np.cos(theta)
    scale = mass * (GRAVITY + offset * omega ** 2) * offset
    assert np.max(np.abs(result.input_torque - expected)) <= 1e-12 * scale
    outward = np.stack([np.cos(theta), np.sin(theta)], axis=-1)
    expected_shaking = mass * (offset * omega ** 2 * outward - np.array([0.0, GRAVITY]))
    assert np.max(np.abs(result.shaking_force - expected_shaking)) <= 1e-12 * scale / offset
    assert all(np.max(m.normal_force_n) <= 1e-12 * scale for m in result.meshes.values())


def test_the_frame_feels_the_bodies_momentum_change_and_weight(kernel_b):
    """Newton for the whole mechanism, no load: the force on the frame (the case's pin and
    the fixed sun's tooth force) is sum m (-g y - a), from the bodies' motion alone."""
    result = _dynamics(kernel_b, load_case="none")
    design = kernel_b.values["kinematics"]
    from cadgen.dynamics.pricking import pricking_bodies

    omega = 2 * math.pi * result.carrier_rpm / 60
    bodies = pricking_bodies(pricking_motion(design, result.phi), result.masses)
    expected = sum(b.mass * (-b.centre_accel * omega ** 2 - np.array([0.0, GRAVITY]))
                   for b in bodies)
    assert np.max(np.abs(result.shaking_force - expected)) <= 1e-9 * np.max(np.abs(expected))


def test_the_mesh_api_puts_the_contact_on_both_pitch_curves(kernel_b):
    design = kernel_b.values["kinematics"]
    result = _dynamics(kernel_b)
    functions, _ = design.cycle_functions()
    assert set(result.meshes) == {("sun", "intermediate 1", 0), ("intermediate 2", "planet", 0)}
    for key, mesh in result.meshes.items():
        for gear in key[:2]:
            rho = functions[gear](mesh.pitch_parameter)[0]
            assert np.allclose(mesh.contact_radius[gear], rho, rtol=0, atol=1e-9)
        assert np.allclose(np.linalg.norm(mesh.line_of_action, axis=1), 1.0)
    # the fixed sun's contact goes once round it per carrier turn: its polar angle (in the
    # sun's frame, the world's) is the carrier angle
    sun = result.meshes[("sun", "intermediate 1", 0)].contact_angle["sun"]
    phi1 = design.motion.phi1_start + design.motion.sense * result.phi
    assert np.allclose(np.mod(sun - phi1 + np.pi, 2 * np.pi) - np.pi, 0.0, atol=1e-12)


def test_the_spectral_carrier_rate_matches_its_closed_form(kernel_b):
    """phi1 = alpha + s arccos(c): away from the dead centres (|c| < 0.95) the closed form
    alpha' + s (-c' / sqrt(1 - c^2)) is well conditioned; the kinematics' Chebyshev
    derivative must agree with it."""
    design = kernel_b.values["kinematics"]
    motion, link = design.motion, design.linkage
    v = np.linspace(0.0, motion.period, 4001, endpoint=False)
    point = motion.curve(motion.u(v)) - np.asarray(link.centre)
    slope = motion.curve(motion.u(v), 1)
    radius = np.linalg.norm(point, axis=1)
    alpha_rate = (point[:, 0] * slope[:, 1] - point[:, 1] * slope[:, 0]) / radius ** 2
    radius_rate = np.sum(point * slope, axis=1) / radius
    a, l = link.a, link.l
    c = (radius ** 2 + 4 * a * a - l * l) / (4 * a * radius)
    c_rate = (radius ** 2 - 4 * a * a + l * l) / (4 * a * radius ** 2) * radius_rate
    w = np.mod(v - link.u_max, motion.period)
    w_min = np.mod(link.u_min - link.u_max, motion.period)
    branch = np.where(w < w_min, motion.sense, -motion.sense)
    closed = alpha_rate - branch * c_rate / np.sqrt(1.0 - c ** 2)
    keep = np.abs(c) < 0.95
    error = np.max(np.abs(motion.phi1_rate(v)[keep] - closed[keep]))
    assert error <= 1e-9 * np.max(np.abs(closed[keep]))


def test_a_bench_run_has_no_soil_and_says_so(kernel_b):
    result = _dynamics(kernel_b, field=None)
    assert any("no soil" in note for note in result.notes)


def test_the_report_section_is_modelled_with_the_pricking_events(kernel_b):
    from cadgen.dynamics import dynamics_report

    result = _dynamics(kernel_b)
    section = dynamics_report(result, kernel_b.params)
    assert section["modelled"] and section["passed"]
    assert set(section["bearing_force_n"]) == {CASE, INTERMEDIATE, PLANET}
    assert {"soil entry", "soil exit", "lowest point"} <= set(section["events_deg"])
    assert len(section["speed_sweep"]) == len(kernel_b.params.dynamics.speeds_rpm)
