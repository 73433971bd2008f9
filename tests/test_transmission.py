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
