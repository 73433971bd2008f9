"""Generated gear pairs and trains: meshing, phasing, checks, hard cases, DXF round trip."""

import ezdxf
import numpy as np
import pytest
import shapely

from cadgen.design import build_mechanism, pricking_design
from cadgen.export.dxf import write_gear_dxf
from cadgen.gears.pairs import circle_pair, generate_pair
from cadgen.gears.trains import planting_train, pricking_train, train_report
from cadgen.gears.meshing import OVERLAP_TOLERANCE, meshing_check
from cadgen.params import load_params
from cadgen.gears.teeth import ToothSystem
from tests.helpers import REFERENCE


@pytest.fixture(scope="module")
def planting():
    params = load_params(REFERENCE)
    return params, planting_train(params, build_mechanism(params))


def test_every_planting_mesh_runs_its_cycle_without_interference(planting):
    _, train = planting
    report = train_report(train)
    assert len(report["meshes"]) == 10 and not report["failures"]
    teeth = {g["gear"]: g["teeth"] for g in report["gears"]}
    for mesh in report["meshes"]:
        module = [g for g in train.stages if g.name == mesh["stage"]][0].generated.system.module
        # stated tolerance: overlap below 20e-6 square modules (the peer's own threshold)
        assert mesh["overlap_area_max_mm2"] <= OVERLAP_TOLERANCE * module**2
        assert mesh["interference_poses"] == 0
        # stated bound: transmission error below 0.02 deg peak to peak at the default resolution
        assert mesh["transmission_error_pp_deg"] < 0.02
        # every pose of a cycle: a circular pair repeats each tooth pitch, so one pitch will do
        assert mesh["poses_per_tooth"] >= 8
        drive_teeth = teeth[mesh["gears"][0]]
        assert mesh["cycle_fraction"] == (1.0 if mesh["stage"] == "non-circular pair"
                                          else pytest.approx(1 / drive_teeth))


def test_non_circular_pair_needs_a_shaper_and_tip_relief(planting):
    _, train = planting
    gears = {g["gear"]: g for g in train_report(train)["gears"]}
    assert "shaper" in gears["central"]["cutter"]             # its concave stretch
    assert gears["central"]["concave_teeth"]
    assert gears["intermediate"]["cutter"] == "rack"          # convex everywhere
    assert gears["intermediate"]["undercut_teeth"]            # its 9.4 mm convex stretch
    relief = train.stages[0].relief
    assert relief and 0 < relief["depth_mm"] < 0.3 * gears["central"]["module_mm"]


def test_perimeters_hold_whole_teeth(planting):
    _, train = planting
    for stage in train.stages:
        for curve, teeth in zip(stage.generated.curves, stage.generated.teeth):
            assert curve.length == pytest.approx(teeth * np.pi * stage.generated.system.module,
                                                 rel=1e-9)


def test_a_gear_in_two_meshes_is_cut_once(planting):
    _, train = planting
    idler_in_first = train.stages[2].generated.profiles[1]
    idler_in_second = train.stages[3].generated.profiles[0]
    assert idler_in_first is idler_in_second


def test_meshing_check_against_brute_force_rotation():
    # second method: turn the driven gear by the reported first-contact angles with shapely
    system = ToothSystem(2.0, backlash=0.05)
    pair = circle_pair(("a", "b"), 24.0, 30.0)
    generated = generate_pair(pair, (24, 30), system=system, flank_points=96)
    report = meshing_check(*generated.profiles, pair, poses=48)
    tau = (np.arange(48) + 0.382) * (pair.period / 48)
    theta_a, theta_b = pair.rotations(tau)
    drive, driven = (shapely.Polygon(p.outline) for p in generated.profiles)
    for k in (0, 17, 33):
        placed_a = shapely.affinity.rotate(drive, theta_a[k], origin=(0, 0), use_radians=True)
        for phi, sign in ((np.radians(report.phi_plus_deg[k]), 1), (np.radians(report.phi_minus_deg[k]), -1)):
            for factor, overlaps in ((0.98, False), (1.05, True)):
                turned = shapely.affinity.rotate(driven, theta_b[k] + phi * factor, origin=(0, 0),
                                                 use_radians=True)
                placed_b = shapely.affinity.translate(turned, pair.centre_distance, 0.0)
                assert (placed_a.intersection(placed_b).area > 1e-9) == overlaps, (k, sign, factor)
    # backlash of 0.05 mm per gear: about 0.1 mm of arc at the pitch circle
    assert report.backlash_arc_max == pytest.approx(0.1, rel=0.15)


def test_pair_assembles_at_the_start_position():
    system = ToothSystem(2.0)
    pair = circle_pair(("a", "b"), 24.0, 30.0)
    generated = generate_pair(pair, (24, 30), system=system)
    drive, driven = generated.profiles
    # drive: a tooth centred on the contact (+x); driven: a space centred on it (-x, at (a, 0))
    tip = drive.outline[np.argmin(np.abs(np.arctan2(drive.outline[:, 1], drive.outline[:, 0])))]
    assert np.linalg.norm(tip) == pytest.approx(24.0 + 2.0, abs=1e-6)
    angle = np.arctan2(driven.outline[:, 1], driven.outline[:, 0])
    root = driven.outline[np.argmin(np.abs(np.abs(angle) - np.pi))]
    assert np.linalg.norm(root) == pytest.approx(30.0 - 2.5, abs=1e-6)


def test_dxf_round_trip_of_a_generated_gear(planting, tmp_path):
    _, train = planting
    profile = train.stages[0].generated.profiles[1]      # the intermediate gear
    summary = write_gear_dxf(tmp_path / "g.dxf", profile, chord_tolerance=0.005)
    document = ezdxf.readfile(tmp_path / "g.dxf")
    auditor = document.audit()
    assert not auditor.has_errors
    outlines = [e for e in document.modelspace() if e.dxf.layer == "OUTLINE"]
    assert len(outlines) == 1 and outlines[0].closed
    points = np.array([p[:2] for p in outlines[0].get_points()])
    written = shapely.Polygon(points)
    dense = shapely.Polygon(profile.outline)
    assert written.is_valid and shapely.LinearRing(points).is_simple
    assert written.area == pytest.approx(dense.area, abs=dense.length * 0.005)
    assert written.length == pytest.approx(dense.length, rel=2e-3)
    assert summary.outline_points_written == len(points)


# ------------------------------------------------------------------------------- hard cases
def test_concave_stretch_tighter_than_any_shaper_is_reported():
    params = load_params(REFERENCE.parent / "kernel-a.toml")
    train = pricking_train(params, pricking_design(params))
    failures = train_report(train)["failures"]
    assert {f["code"] for f in failures} == {"gear_not_cuttable"}
    # the advice names what a file can change: the module would have to be below a practical
    # one (0.9 x the concave radius, over 5, for a 10-tooth cutter: 0.16 and 0.22 mm), so the
    # type-value points are what to move
    assert all("no pinion cutter" in f["message"] and "no practical module" in f["message"]
               and "trajectory.points" in f["message"] for f in failures)


def test_module_too_large_for_the_curvature_reports_undercut_and_root_thickness():
    # 12 teeth on a circle: below the rack's 17-tooth limit
    system = ToothSystem(3.0)
    pair = circle_pair(("small", "big"), 18.0, 60.0)
    generated = generate_pair(pair, (12, 40), system=system)
    small, big = generated.checks
    assert small.undercut_teeth == list(range(12)) and big.undercut_teeth == []
    codes = [code for code, _ in small.problems]
    assert codes == ["undercut"]
    assert "remaining root thickness" in small.problems[0][1]
    # the undercut tooth is thinner at its root than the same tooth cut without undercut
    assert 0 < small.root_thickness_min < big.root_thickness_min


def test_too_many_teeth_for_the_addendum_leaves_pointed_teeth():
    system = ToothSystem(2.0, addendum=1.7, dedendum=1.95, tip_radius=0.1)
    pair = circle_pair(("a", "b"), 8.0, 8.0)   # 8 teeth, a tall addendum: the flanks meet
    generated = generate_pair(pair, 8, system=system)
    check = generated.checks[0]
    assert check.pointed_teeth == list(range(8))
    assert any(code == "pointed_teeth" for code, _ in check.problems)
    assert check.tip_thickness_min < 0.25 * system.module


def test_the_file_can_ask_for_a_shaper_everywhere():
    from tests.helpers import edited, with_keys
    from cadgen.params import validate_text

    text = with_keys(edited(teeth=22), "gears", cutter='"shaper"', meshing_poses=48)
    params = validate_text(text, check_feasibility=False)
    train = planting_train(params, build_mechanism(params))
    assert all("shaper" in g["cutter"] for g in train_report(train)["gears"])


def test_an_idler_with_an_odd_tooth_count_meshes_on_both_sides():
    """R = 35 mm: module 1, idler 2 has 77 teeth. Its two meshes start half a turn apart on it,
    which is half a pitch for an odd count: carried as an arc length, its phase put teeth
    into teeth (every pose interfered); carried as a body angle, both meshes run clean."""
    from cadgen.params import validate_text
    from helpers import edited

    params = validate_text(edited(R="35.0"))
    train = planting_train(params, build_mechanism(params))
    report = train_report(train)
    teeth = {g["gear"]: g["teeth"] for g in report["gears"]}
    assert teeth["idler 2"] == 77
    assert all(mesh["interference_poses"] == 0 for mesh in report["meshes"])
