"""The whole transmission: train 1's two sets, the drive, the joint graph, and motion read from
the solids' placements (not from the formulas that place them)."""

import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from cadgen.design import build_mechanism
from cadgen.gears.circular import train1_set_radii
from cadgen.params import load_params


@pytest.fixture(scope="module")
def paper():
    params = load_params("params/xin2024-planter.toml")
    return params, build_mechanism(params)


@pytest.fixture(scope="module")
def train(paper):
    from cadgen.gears.trains import planting_train
    from cadgen.machine.drivetrain import drivetrain

    return planting_train(*paper, drive=drivetrain(*paper).drive)   # as a build cuts it


def test_set_i_of_the_paper_by_hand(train):
    # the check figure: R = 36, i12 = 1.2, i13 = 1.1, n = 3: sun 2R/3 = 24, idler A
    # R(1 + i12) - 24 = 55.2, idler B 82.8 - 55.2 = 27.6, planet 4R/3 = 48: module 2.4 gives
    # 20/46/23/40 teeth
    from cadgen.gears.trains import train_report

    sets = {s["key"]: s for s in train_report(train)["sets"]}
    teeth = [sets["I"]["meshes"][0]["driver_teeth"]] + [m["driven_teeth"]
                                                         for m in sets["I"]["meshes"]]
    assert teeth == [20, 46, 23, 40]
    assert sets["I"]["meshes"][0]["module_mm"] == pytest.approx(2.4)
    # the axis distances from the spec's carrier radii, by hand: OA = 79.2, AB = 82.8, BC = 75.6
    for key in ("I", "II"):
        distances = [m["axis_distance_mm"] for m in sets[key]["meshes"]]
        assert distances == pytest.approx([79.2, 82.8, 75.6], abs=1e-9)
        for mesh in sets[key]["meshes"]:
            # working centre distance of standard gears: m (z1 + z2) / 2
            working = mesh["module_mm"] * (mesh["driver_teeth"] + mesh["driven_teeth"]) / 2
            assert abs(working - mesh["axis_distance_mm"]) < 0.01
    # converted ratios: three external meshes, -z_sun / z_planet; -1 and -1/2 for n = 3
    assert Fraction(-20, 40) == Fraction(sets["I"]["converted_ratio_teeth"]).limit_denominator(100)
    assert sets["I"]["ratio_exact"] and sets["II"]["ratio_exact"]
    assert sets["II"]["converted_ratio"] == -1.0


@settings(max_examples=60, deadline=None)
@given(R=st.floats(10, 80), i12=st.floats(0.5, 2.0), i13=st.floats(0.5, 2.0),
       n=st.floats(1.5, 6.0))
def test_set_radii_meet_the_axes_and_the_ratio(R, i12, i13, n):
    from types import SimpleNamespace

    mechanism = SimpleNamespace(R=R, i12=i12, i13=i13, n=n)
    OA, AB, BC = R * (1 + i12), R * (i12 + i13), 2 * R * (1 + i12 + i13) - R * (1 + 2 * i12 + i13)
    for key, carrier_factor in (("II", -1.0), ("I", 0.0)):
        s, a, b, p = train1_set_radii(mechanism, key)
        assert s + a == pytest.approx(OA) and a + b == pytest.approx(AB)
        assert b + p == pytest.approx(BC)
        # the planet's absolute speed from Willis: w_p = w_c + (-s/p)(n w_c - w_c), w_c = 1
        assert 1.0 - s / p * (n - 1.0) == pytest.approx(carrier_factor, abs=1e-9)


def test_joint_graph_mobility_by_hand_and_a_missing_key(paper, train):
    from cadgen.assembly.machine import planting_model
    from cadgen.machine.drivetrain import drivetrain

    model = planting_model(drivetrain(*paper), [s.generated.pair.names for s in train.stages])
    # by hand: bodies frame, input, O, carrier 1 (+ sleeve), and per arm A, idler 1-I, B,
    # idler 2-I, C (+ gearbox 2), C2, D, E (+ planter), two blades: N = 4 + 2 x 10 = 24;
    # revolutes 3 + 2 x 10 = 23; meshes 2 + 2 x 8 and cam contacts 2 x 2: 22
    # M = 3 (24 - 1) - 2 x 23 - 22 = 1
    report = model.mobility_report()
    assert (report["bodies"], report["lower_pairs"], report["higher_pairs"]) == (24, 23, 22)
    assert model.mobility() == 1 and model.unconnected() == []
    key = next(j for j in model.joints if j.kind == "fixed" and j.a == "planet-I-side1")
    assert model.without(key).unconnected() == ["planet-I-side1"]


def _turn(transform):
    return math.atan2(transform[1, 0], transform[0, 0])


def test_motion_read_from_the_placements(paper, train):
    from cadgen.solids.planting import planting_assembly

    params, mechanism = paper
    assembly, _, _ = planting_assembly(params, mechanism, train, None, None)
    angles = np.radians([0.0, 17.0, 61.0, 133.0, 250.0])
    poses = [{name: pose for name, _, pose in assembly.placements(phi)} for phi in angles]
    teeth = {p.name: p.teeth for p, _, _, _ in train.gears}

    def turned(instance, k):   # world rotation since phi = 0 (rad)
        return _turn(poses[k][instance]) - _turn(poses[0][instance])

    def wrap(x):
        return (x + math.pi) % (2 * math.pi) - math.pi

    for k in range(1, len(angles)):
        carrier = turned("gearbox1-base", k)
        # gearbox 2 turns by minus the carrier angle; set I's planet and the central gear keep
        # their orientation (pure translation)
        assert wrap(turned("gearbox2-base-arm1", k) + carrier) == pytest.approx(0.0, abs=1e-9)
        for still in ("planet-I-side1", "central-arm1"):
            assert wrap(turned(still, k)) == pytest.approx(0.0, abs=1e-9)
        # each meshing pair on carrier 1 rolls: relative turns in the inverse ratio of teeth
        for drive, driven, side in (("sun", "idler-1", "side1"), ("idler-1", "idler-2", "side1"),
                                    ("sun-I", "idler-1-I", "side1"),
                                    ("idler-2-I", "planet-I", "side1")):
            a = wrap(turned(f"{drive}-{side}", k) - carrier)
            b = wrap(turned(f"{driven}-{side}", k) - carrier)
            zb = teeth[{"idler-1": "idler 1", "idler-2": "idler 2", "idler-1-I": "idler 1-I",
                        "planet-I": "planet I"}[driven]]
            za = teeth[{"sun": "sun", "idler-1": "idler 1", "sun-I": "sun I",
                        "idler-2-I": "idler 2-I"}[drive]]
            assert wrap(a * za + b * zb) == pytest.approx(0.0, abs=1e-6)


# ------------------------------------------------------------------ the pricking mechanism
@pytest.fixture(scope="module")
def kernel_b():
    from cadgen.design import pricking_design
    from cadgen.machine.drivetrain import drivetrain

    params = load_params("params/kernel-b.toml")
    return params, drivetrain(params, pricking_design(params))


def test_the_pricking_sun_is_held_and_its_case_driven(kernel_b):
    params, machine = kernel_b
    held = machine.rules["case_drive"]
    sprocket = held["sprocket"]
    # ISO 606 08B-1 (p = 12.7 mm): a 19-tooth wheel's pitch diameter is 77.16 mm in the
    # sprocket tables (p / sin(180 deg / z)); its root, pitch less the 8.51 mm roller
    assert sprocket["teeth"] == 19
    assert sprocket["pitch_diameter"] == pytest.approx(77.16, abs=0.005)
    assert sprocket["root_diameter"] == pytest.approx(77.16 - 8.51, abs=0.005)
    # the screws' circle clears the bore and the root by 1.5 screw diameters; 18 teeth would not
    assert sprocket["root_diameter"] / 2 >= sprocket["bolt_circle_radius"] + 7.5
    assert 12.7 / math.sin(math.pi / 18) / 2 - 8.51 / 2 < sprocket["bolt_circle_radius"] + 7.5
    # the chain's pull times the pitch radius is the case's torque
    assert sprocket["chain_pull_n"] * sprocket["pitch_diameter"] / 2 == pytest.approx(
        sprocket["torque_nm"] * 1000.0)
    sun = next(s for s in machine.shafts if s.name == "sun")
    assert sun.coupling_key is not None and sun.coupling_key.length <= sun.extends_below - 4


def test_the_pricking_joint_graph_by_hand(kernel_b):
    from cadgen.assembly.machine import pricking_model

    _, machine = kernel_b
    model = pricking_model(machine, [("sun", "intermediate 1"), ("intermediate 2", "planet")])
    # bodies: the frame (bracket, sun shaft, sun gear), the case (base, cover, sprocket), the
    # intermediate shaft and gears, the planet shaft, gear, rocker and needle: N = 4; three
    # revolutes, two meshes: M = 3 x 3 - 2 x 3 - 2 = 1
    report = model.mobility_report()
    assert (report["bodies"], report["lower_pairs"], report["higher_pairs"]) == (4, 3, 2)
    assert model.mobility() == 1 and model.unconnected() == []
    # without the stub's key nothing holds the mechanism to the frame
    key = next(j for j in model.joints if j.a == "shaft-sun" and j.b == "frame-bracket")
    assert "DIN 6885" in key.detail
    assert set(model.without(key).unconnected()) == set(model.parts) - {"frame-bracket"}


@settings(max_examples=60, deadline=None)
@given(R=st.floats(25, 60), i12=st.floats(0.8, 1.8), i13=st.floats(0.8, 1.8),
       n=st.sampled_from([3.0, 2.5, 4.0, 5.0]))
def test_set_i_meets_its_axes_standard_or_shifted(R, i12, i13, n):
    """Any base radius: set I is standard where whole teeth fit, else profile-shifted; either
    way each mesh's working centre distance, computed back from the teeth, module and shifts
    (ISO 21771's inverse, Newton), is its axis distance to 0.01 mm, the sun-to-planet ratio is
    exactly 1/(n - 1), and no gear is undercut by a rack (x >= 1 - z sin^2(alpha) / 2)."""
    from fractions import Fraction

    from cadgen.gears.circular import TrainAxes, holding_set_design
    from cadgen.gears.trains import working_centre_distance
    from kinematics.errors import DesignError

    alpha = math.radians(20.0)
    try:
        design = holding_set_design(TrainAxes(R, i12, i13, n), None, alpha)
    except DesignError as error:   # refused: it names the field and the reason
        assert error.problems[0].path.startswith("train.")
        return
    z = design.teeth
    assert Fraction(z[0], z[3]) == Fraction(1.0 / (n - 1.0)).limit_denominator(50)
    radii = train1_set_radii(TrainAxes(R, i12, i13, n), "I")
    axes = (radii[0] + radii[1], radii[1] + radii[2], radii[2] + radii[3])
    for k in range(3):
        a_w = working_centre_distance(z[k], z[k + 1], design.module,
                                      design.shifts[k] + design.shifts[k + 1], alpha)
        assert abs(a_w - axes[k]) < 0.01
    if design.shifted:
        assert all(x >= 1 - teeth * math.sin(alpha) ** 2 / 2 - 1e-9
                   for x, teeth in zip(design.shifts, z)), (z, design.shifts)
        assert max(abs(x) for x in design.shifts) <= 0.5


def test_the_drive_steps_its_module_up_where_the_trains_reaches_no_teeth():
    """i13 = 0.2 leaves set II a 0.8 mm module: no teeth up to 150 clear 65 mm hubs and reach
    n = 3 there (at least 7.5 + 65 / 0.8 = 88.75 teeth each; drive_design refuses), so the drive
    takes the next ISO 54 module that does; its teeth still give n exactly and clear the hubs
    (rim rule checked here by hand)."""
    from fractions import Fraction

    from cadgen.gears.circular import DRIVE_SLEEVE_DIAMETER, TrainAxes, planting_drive
    from cadgen.gears.drive import drive_design
    from kinematics.errors import DesignError

    hubs = (65.0, 65.0, 65.0, 65.0)
    with pytest.raises(DesignError):
        drive_design(3.0, 30.0, 0.8, DRIVE_SLEEVE_DIAMETER, hubs=hubs)
    drive = planting_drive(TrainAxes(36.0, 1.2, 0.2, 3.0), 0.8, hubs=hubs)
    assert drive.module_1 == 1.0   # the first of ISO 54's series above 0.8 that works
    z1, z2, z3, z4 = drive.teeth
    assert Fraction(z1 * z4, z2 * z3) == 3
    for z in drive.teeth:   # root circle 2.5 modules clear of a 65 mm hub
        assert z * drive.module_1 / 2 - 1.25 * drive.module_1 - 32.5 >= 2.5 * drive.module_1 - 1e-9
