"""The drivetrain sized from the dynamics' loads (cadgen.machine.cycle_loads, cadgen.dynamics.sizing)
and re-checked with other loads (cadgen.machine.recheck)."""

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad

from cadgen.machine.bearings import l10_hours
from cadgen.machine.cycle_loads import (ESTIMATED_MASSES, SOLID_MASSES, cycle_beam,
                                        equivalent_load)

REPO = Path(__file__).resolve().parents[1]
PAPER = REPO / "params" / "xin2024-planter.toml"


# ------------------------------------------------------------------ ISO 281 over the cycle
@pytest.mark.parametrize("constant, amplitude", [(400.0, 150.0), (250.0, 250.0), (80.0, 0.0)],
                         ids=["sinusoid", "touching-zero", "constant"])
def test_equivalent_load_of_constant_plus_sinusoid_at_constant_speed(constant, amplitude):
    # mean over a turn of (P0 + P1 sin)^3 = P0^3 + 3/2 P0 P1^2 (odd powers of sin average out)
    phi = np.linspace(0.0, 2 * math.pi, 720, endpoint=False)
    load = constant + amplitude * np.sin(phi)
    by_hand = (constant ** 3 + 1.5 * constant * amplitude ** 2) ** (1 / 3)
    assert np.isclose(equivalent_load(load, np.full_like(phi, 30.0)), by_hand, rtol=1e-12)
    # the life of a 6002 (C = 5.85 kN) at 30 r/min under it, by ISO 281's formula by hand
    life = l10_hours(5.85, equivalent_load(load, 30.0), 30.0)
    assert np.isclose(life, (5850.0 / by_hand) ** 3 * 1e6 / (60 * 30.0), rtol=1e-12)


def test_equivalent_load_weights_each_pose_by_its_speed_against_quad():
    # a non-circular gear's shaft: the speed swings over the turn, and a bearing's revolutions
    # under each load count, not the time (ISO 281 for variable load and speed)
    def load(phi):
        return 300.0 + 120.0 * np.cos(phi) + 40.0 * np.sin(2 * phi)

    def speed(phi):
        return 30.0 * (1.0 + 0.6 * np.cos(phi))

    numerator = quad(lambda p: load(p) ** 3 * speed(p), 0.0, 2 * math.pi, limit=200)[0]
    denominator = quad(speed, 0.0, 2 * math.pi)[0]
    phi = np.linspace(0.0, 2 * math.pi, 720, endpoint=False)
    assert np.isclose(equivalent_load(load(phi), speed(phi)),
                      (numerator / denominator) ** (1 / 3), rtol=1e-10)
    # weighted by speed, not by time: the loads at the fast poses (the large ones) count more
    assert equivalent_load(load(phi), speed(phi)) > 1.01 * equivalent_load(load(phi), 1.0)


def test_cycle_beam_splits_a_turning_force_by_the_lever_rule():
    phi = np.linspace(0.0, 2 * math.pi, 36, endpoint=False)
    magnitude = 200.0 + 50.0 * np.sin(phi)
    force = magnitude[:, None] * np.stack([np.cos(3 * phi), np.sin(3 * phi)], axis=1)
    z1, z2, z = -5.0, 45.0, 15.0
    bending, radial, reactions = cycle_beam(z1, z2, [(z, force)])
    assert np.allclose(radial[0], magnitude * (z2 - z) / (z2 - z1))
    assert np.allclose(radial[1], magnitude * (z - z1) / (z2 - z1))
    assert np.allclose(reactions.sum(axis=0), -force)
    assert np.isclose(bending, magnitude.max() * (z2 - z) * (z - z1) / (z2 - z1))


# ------------------------------------------------------------------ the paper design
@pytest.fixture(scope="module")
def paper():
    from cadgen.cam.design import design_cam
    from cadgen.design import build_mechanism, evaluate
    from cadgen.machine.drivetrain import drivetrain
    from cadgen.params import load_params

    params = load_params(PAPER)
    mechanism = build_mechanism(params)
    events = evaluate(params, mechanism).events
    cam = design_cam(params, mechanism, events)
    return params, mechanism, events, cam, drivetrain(params, mechanism, cam)


def _dynamics(params, mechanism, drivetrain, cam, events, **loads):
    from cadgen.dynamics import planting_dynamics

    settings = params.dynamics.model_copy(update={"speeds_rpm": (30.0,), **loads})
    return planting_dynamics(params.model_copy(update={"dynamics": settings}), mechanism,
                             drivetrain, cam=cam, events=events)


def test_shaft_torque_is_the_inverse_dynamics_mesh_force_times_its_lever(paper):
    from cadgen.dynamics.sizing import axis_cycles
    from cadgen.machine.drivetrain import drivetrain

    params, mechanism, events, cam, static = paper
    result = _dynamics(params, mechanism, static, cam, events)
    cycles = axis_cycles(params, mechanism, static, result, ESTIMATED_MASSES)
    alpha = params.gears.pressure_angle_rad
    mesh = result.meshes[("gear D", "planet gear E", 1)]
    # a circular mesh's force acts along the line of action at the pitch radius r: its moment
    # about the gear's axis is F_n r cos(alpha)
    lever = mechanism.r * math.cos(alpha)
    assert np.allclose(np.abs(cycles["E"].moments["planet gear E"]),
                       mesh.normal_force_n * lever, rtol=1e-9, atol=1e-9)
    sized = drivetrain(params, mechanism, cam, cycles=cycles, drive=static.drive)
    shaft_e = next(s for s in sized.shafts if s.name == "E" and s.side == 1)
    expected = params.machine.service_factor * mesh.normal_force_n.max() * lever / 1000.0
    assert np.isclose(shaft_e.torque_nm, expected, rtol=1e-9)
    assert shaft_e.load_source == shaft_e.sized_from == ESTIMATED_MASSES
    # the shaft's two bearings carry the pin reaction the dynamics solved for its body
    planter = np.asarray(result.bearings["planter 1"])
    central = np.asarray(result.bearings["central gear 1"])
    for axis, body in (("E", planter), ("C2", central)):
        cycle = cycles[axis]
        loads = [(float(k), f) for k, f in enumerate(cycle.forces.values())]
        _, _, reactions = cycle_beam(-3.0, 40.0, loads + [(10.0, cycle.rest)])
        assert np.allclose(reactions.sum(axis=0), body, atol=1e-9 * np.abs(body).max())
    # the shaft C2 carries the non-circular mesh's moment about C into planet I
    noncircular = result.meshes[("central", "intermediate", 1)]
    point = _pitch_point(params, mechanism, static, result, ("central", "intermediate", 1))
    centre = mechanism.motion(result.phi, "C", 0).position
    arm = point - centre
    direction = noncircular.line_of_action
    moment = -(arm[:, 0] * direction[:, 1] - arm[:, 1] * direction[:, 0]) \
        * noncircular.normal_force_n
    assert np.allclose(cycles["C2"].moments["central"], moment, atol=1e-9)


def _pitch_point(params, mechanism, drivetrain, result, key):
    """The non-circular pair's pitch point at r1(t) from C along the central gear's polar angle."""
    t = result.phi + math.pi * (key[2] - 1)
    r1 = mechanism.pitch_curve.radius_derivatives(t)[0]
    centre = mechanism.motion(result.phi, "C", key[2] - 1).position
    return centre + r1[:, None] * np.stack([np.cos(mechanism.phic + t),
                                            np.sin(mechanism.phic + t)], axis=1)


def test_a_heavier_dynamic_load_than_the_static_sizing_fails_the_recheck(paper):
    from cadgen.dynamics.sizing import recheck_drivetrain
    from cadgen.machine.shafts import key_pressure

    params, mechanism, events, cam, static = paper
    # a stony soil: 30 x the default resistance on the duckbill, beyond what 50 N x 1.5 at
    # the tip's full reach sized the planter's shaft E for
    result = _dynamics(params, mechanism, static, cam, events, soil_force_n=1500.0)
    checked = recheck_drivetrain(params, mechanism, static, result)
    shaft = next(s for s in checked.shafts if s.name == "E" and s.side == 1)
    mount = shaft.mounts[0]
    pressure = key_pressure(mount.torque_nm * 1000.0, shaft.diameter, mount.key)
    assert pressure > params.machine.key_pressure_mpa    # the load does exceed the static sizing
    found = [p for p in checked.problems if "re-checked" in p.message]
    assert any(p.path == "gears.face_width" and p.code == "key_overloaded"
               and "planet gear E" in p.message for p in found), found
    assert checked.rules["recheck"]["passed"] is False
    assert all(p.path for p in found)
    assert shaft.load_source == ESTIMATED_MASSES   # the run had estimated masses, and says so
    # the default soil passes the same check on the same drivetrain
    calm = recheck_drivetrain(params, mechanism, static, _dynamics(params, mechanism, static,
                                                                   cam, events))
    assert calm.rules["recheck"]["passed"] is True
    assert SOLID_MASSES != ESTIMATED_MASSES


def test_the_machine_is_the_same_whatever_the_scene_and_the_pricking_one_the_static():
    """A design is the same parts whatever the build is asked: the planting drivetrain is sized
    from its estimated-mass dynamics in a scene without the dynamics effect too (the gear
    files' bores are the full build's), and the pricking drivetrain from the tip force, as
    :func:`drivetrain` sizes it alone."""
    from cadgen.design import pricking_design
    from cadgen.machine.drivetrain import drivetrain, drivetrain_report
    from cadgen.params import load_params
    from cadgen.pipeline.build import build

    params = load_params(PAPER)
    shafts = {}
    for effects in (["metrics", "cam", "teeth"], ["dynamics"]):
        machine = build(params, None, effects=effects).report["machine"]
        assert machine["load_sources"]["sized_from"] == [ESTIMATED_MASSES], effects
        shafts[tuple(effects)] = [(s["name"], s["side"], s["diameter_mm"])
                                  for s in machine["shafts"]]
    assert len(set(map(tuple, shafts.values()))) == 1
    pricking = load_params(REPO / "params" / "kernel-b.toml")
    machine = build(pricking, None, effects=["metrics", "teeth"]).report["machine"]
    assert machine["load_sources"]["sized_from"] == ["assumed tip force"]
    for record in machine["shafts"] + machine["bearings"]:
        assert record["load_source"] == "assumed tip force"
    static = drivetrain_report(drivetrain(pricking, pricking_design(pricking)))
    assert [(s["name"], s["diameter_mm"]) for s in machine["shafts"]] == [
        (s["name"], s["diameter_mm"]) for s in static["shafts"]]


def test_load_case_none_checks_the_model_and_still_sizes_the_machine_for_the_field():
    """``load_case = "none"`` leaves the soil and the seedling out of the report's dynamics,
    not out of the machine: the shafts are those of the default load case."""
    from cadgen.params import load_params, validate_text
    from cadgen.pipeline.build import build

    from helpers import with_keys

    text = PAPER.read_text(encoding="utf-8")
    none = validate_text(with_keys(text, "dynamics", load_case='"none"'))
    sizes = []
    for params in (load_params(PAPER), none):
        machine = build(params, None, effects=["metrics", "cam", "teeth"]).report["machine"]
        sizes.append([(s["name"], s["side"], s["diameter_mm"]) for s in machine["shafts"]])
    assert sizes[0] == sizes[1]
