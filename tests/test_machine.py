"""Machine design: catalogues, ISO 281 life, the shaft beam and formula, and both bundled designs."""

import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from cadgen.design import build_mechanism, pricking_design
from cadgen.machine.bearings import l10_hours, select_bearing
from cadgen.machine.catalogue import (CatalogueError, bearings_with_bore, clearance_hole,
                                      key_for_shaft, key_length, nut, preferred_diameters,
                                      screw_length, socket_screw, washer)
from cadgen.machine.drivetrain import drivetrain, drivetrain_report
from cadgen.machine.fits import process_fits
from cadgen.machine.loads import planting_speeds
from cadgen.machine.model import KeySize
from cadgen.machine.shafts import (beam_reactions, bending_moments, choose_diameter,
                                   key_pressure, max_bending, required_diameter)
from cadgen.params import load_params

REPO = Path(__file__).resolve().parents[1]
PAPER = REPO / "params" / "xin2024-planter.toml"
KERNEL_B = REPO / "params" / "kernel-b.toml"


def _design(params):
    return build_mechanism(params) if params.mechanism == "planting" else pricking_design(params)


def _variant(tmp_path, source: Path, table: str, **keys):
    from tests.helpers import with_keys

    path = tmp_path / source.name
    path.write_text(with_keys(source.read_text(encoding="utf-8"), table, **keys),
                    encoding="utf-8")
    params = load_params(path)
    return params, drivetrain(params, _design(params))


@pytest.fixture(scope="module", params=[PAPER, KERNEL_B], ids=["xin2024", "kernel-b"])
def bundled(request):
    params = load_params(request.param)
    return params, drivetrain(params, _design(params))


# ------------------------------------------------------------------ catalogue
@pytest.mark.parametrize("designation, d, D, B, C, C0", [
    ("6204", 20, 47, 14, 13.5, 6.55),   # SKF product table 6204
    ("6000", 10, 26, 8, 4.75, 1.96),    # SKF 6000
    ("6005", 25, 47, 12, 11.9, 6.55),   # SKF 6005
    ("6210", 50, 90, 20, 37.1, 23.2),   # SKF 6210
    ("608", 8, 22, 7, 3.45, 1.37),      # SKF 608
], ids=lambda v: str(v))
def test_catalogue_bearings_are_skfs(designation, d, D, B, C, C0):
    bearing = next(b for b in bearings_with_bore(d) if b.designation == designation)
    assert (bearing.bore, bearing.outside, bearing.width) == (d, D, B)
    assert (bearing.dynamic_load_kn, bearing.static_load_kn) == (C, C0)


def test_preferred_diameters_are_the_bores():
    assert preferred_diameters() == (6, 8, 10, 12, 15, 17, 20, 25, 30, 35, 40, 45, 50)


@pytest.mark.parametrize("d, b, h, t1, t2", [
    (20, 6, 6, 3.5, 2.8),     # DIN 6885-1: over 17 up to 22
    (17, 5, 5, 3.0, 2.3),     # 17 is the upper bound of "over 12 up to 17"
    (25, 8, 7, 4.0, 3.3),
    (50, 14, 9, 5.5, 3.8),
], ids=lambda v: str(v))
def test_din_6885_keys(d, b, h, t1, t2):
    key = key_for_shaft(d)
    assert (key.width, key.height, key.shaft_depth, key.hub_depth) == (b, h, t1, t2)


@pytest.mark.parametrize("d", [5.0, 60.0])
def test_key_outside_the_table_is_a_clear_error(d):
    with pytest.raises(CatalogueError, match=f"{d:g} mm shaft"):
        key_for_shaft(d)


def test_key_lengths_and_fasteners():
    assert key_length(15.0) == 14 and key_length(16.5) == 16 and key_length(80) == 80
    with pytest.raises(CatalogueError, match="widen the hub"):
        key_length(5.0)
    assert clearance_hole("M6") == 6.6 and clearance_hole("M8", "fine") == 8.4   # ISO 273
    assert clearance_hole("M10", "coarse") == 12.0
    screw = socket_screw("M8")                                                   # ISO 4762
    assert (screw["head_diameter"], screw["head_height"]) == (13.0, 8.0)
    assert screw_length("M5", 13.0) == 16.0
    assert nut("M10") == {"thread": "M10", "m": 8.4, "s": 16.0}                  # ISO 4032
    assert washer("M6")["d2"] == 12.0                                            # ISO 7089
    with pytest.raises(CatalogueError, match="M7"):
        nut("M7")


# ------------------------------------------------------------------ bearing life
def test_l10_hand_calculation():
    # 6204: C = 13.5 kN, P = 1350 N -> C/P = 10 -> L10 = 10^3 = 1000 million revolutions;
    # at 100 r/min: 1e9 / (60 * 100) = 166 666.7 h
    assert l10_hours(13.5, 1350.0, 100.0) == pytest.approx(1e9 / 6000, rel=1e-12)
    assert l10_hours(13.5, 0.0, 100.0) == math.inf


@settings(max_examples=40, deadline=None)
@given(st.floats(10.0, 10000.0), st.floats(0.1, 10.0), st.floats(1.0, 3000.0))
def test_life_scales_with_the_inverse_cube_of_the_load(load, k, rpm):
    assert l10_hours(9.95, load * k, rpm) == pytest.approx(l10_hours(9.95, load, rpm) / k ** 3,
                                                           rel=1e-9)


def test_bearing_choice_takes_the_smallest_that_lasts():
    bearing, life, passed = select_bearing(20, 1000.0, 30.0, 5000.0)
    assert bearing.designation == "6004" and passed    # 42 mm OD before the 6204's 47
    bearing, life, passed = select_bearing(20, 5000.0, 300.0, 5000.0)
    # 6004: (9.95/5)^3 1e6 / 18000 = 438 h; 6204: (13.5/5)^3 1e6 / 18000 = 1093.5 h: neither lasts
    assert bearing.designation == "6204" and not passed
    assert life == pytest.approx(2.7 ** 3 * 1e6 / 18000)


# ------------------------------------------------------------------ shafts
def test_shaft_formula_hand_calculation():
    # M = 20 N m, T = 15 N m -> sqrt(M^2 + T^2) = 25 000 N mm; yield 355 -> tau = 177.5 MPa;
    # d = (16 * 2 / (pi * 177.5) * 25 000)^(1/3) = (1434.64)^(1/3) = 11.2785 mm
    assert required_diameter(20000.0, 15000.0, 355.0, 2.0) == pytest.approx(11.2785, abs=1e-3)


@settings(max_examples=40, deadline=None)
@given(st.floats(0.0, 1e6), st.floats(0.0, 1e6), st.floats(0.2, 5.0))
def test_required_diameter_scales_with_the_cube_root_of_the_loads(M, T, k):
    base = required_diameter(M, T, 355.0, 2.0)
    assert required_diameter(M * k ** 3, T * k ** 3, 355.0, 2.0) == pytest.approx(
        k * base, rel=1e-9, abs=1e-12)


@settings(max_examples=60, deadline=None)
@given(st.floats(-40.0, 0.0), st.floats(10.0, 120.0),
       st.lists(st.tuples(st.floats(-60.0, 180.0), st.floats(0.0, 5000.0)), min_size=1,
                max_size=5))
def test_beam_is_in_equilibrium(z1, z2, loads):
    loads = np.array(loads)
    R1, R2 = beam_reactions(z1, z2, loads)
    total = loads[:, 1].sum()
    assert R1 + R2 == pytest.approx(total, abs=1e-7 * (1 + total))
    # moments about the floor bearing vanish
    moment = R2 * (z2 - z1) - np.sum(loads[:, 1] * (loads[:, 0] - z1))
    assert moment == pytest.approx(0.0, abs=1e-6 * (1 + total) * 240)
    # beyond every force the moment is zero again (free ends)
    beyond = max(z2, loads[:, 0].max()) + 1.0
    assert bending_moments(z1, z2, loads, [beyond])[0] == pytest.approx(0.0, abs=1e-5 * (1 + total) * 240)
    assert max_bending(z1, z2, loads) >= 0.0


def test_simply_supported_midspan_load():
    # a load P in the middle of a span L: reactions P/2, moment P L / 4
    assert beam_reactions(0.0, 100.0, [(50.0, 1000.0)]) == (500.0, 500.0)
    assert max_bending(0.0, 100.0, [(50.0, 1000.0)]) == pytest.approx(25000.0)
    # an overhang: P at 150 beyond supports at 0 and 100: R1 = -P/2, R2 = 3P/2, M = 50 P
    assert beam_reactions(0.0, 100.0, [(150.0, 1000.0)]) == (-500.0, 1500.0)
    assert max_bending(0.0, 100.0, [(150.0, 1000.0)]) == pytest.approx(50000.0)


def test_diameter_choice_counts_the_keyseat():
    # 16 mm needed: 17 mm leaves 17 - 3.0 = 14 under its key, 20 mm leaves 16.5
    assert choose_diameter(16.0) == 20
    assert choose_diameter(5.0) == 6       # 6 mm with a 0.6 mm flat: core 5.4
    assert choose_diameter(60.0) is None


def test_key_pressure_hand_calculation():
    # T = 51.8 N m on a 20 mm shaft, key 6 x 6 x 16 (t1 3.5): 2 * 51800 / (20 * 2.5 * 10)
    key = KeySize(6, 6, 3.5, 2.8, 16)
    assert key_pressure(51800.0, 20.0, key) == pytest.approx(207.2)


# ------------------------------------------------------------------ drivetrains
def test_every_seat_fits_its_shaft_and_the_process(bundled):
    params, train = bundled
    fits = process_fits(params.manufacturing.process)
    assert train.process == "machined"
    for shaft in train.shafts:
        assert shaft.diameter in preferred_diameters() and not shaft.given
        assert shaft.strength_passed
        if shaft.flange:   # a hollow shaft carrying a housing: a bearing pair in one seat
            assert [(s.wall, s.count) for s in shaft.seats] == [("roof", 2)]
            assert shaft.bore > 0 and shaft.diameter - shaft.bore >= 4.0
        else:
            assert len(shaft.seats) == 2 and [s.wall for s in shaft.seats] == ["floor", "roof"]
        for seat in shaft.seats:
            assert seat.bearing.bore == shaft.diameter
            assert seat.seat_diameter == pytest.approx(
                seat.bearing.outside + fits.seat_allowance(seat.bearing.outside))
            assert seat.hole_diameter == (shaft.diameter + fits.running_clearance
                                          if seat.through else 0.0)
            assert seat.life_passed
        for mount in shaft.mounts:
            if mount.bearing is not None:   # a gear running free on two bearings
                assert mount.bearing.bore == shaft.diameter and mount.key is None
                assert mount.hub_bore == mount.bearing.outside
                assert 2 * mount.bearing.width <= mount.face_width
                continue
            assert mount.hub_bore == shaft.diameter
            if shaft.diameter >= 10:
                assert mount.key is not None and mount.key.length <= mount.face_width
    for name, stack in train.stacks.items():
        for seat in train.seats(name):
            wall = stack.floor_wall if seat.wall == "floor" else stack.roof_wall
            assert wall >= seat.count * seat.bearing.width + 2.0
    report = drivetrain_report(train)
    json.dumps(report)
    # the bundled designs' faces are wide enough for their keys: no check fails
    assert report["problems"] == [] and report["passed"]


def test_planting_names_positions_and_stack():

    params = load_params(PAPER)
    mechanism = build_mechanism(params)
    train = drivetrain(params, mechanism)
    assert {m.gear for s in train.shafts for m in s.mounts} == {
        "central", "intermediate", "gear D", "planet gear E", "sun", "idler 1", "idler 2",
        "train-1 planet", "sun I", "idler 1-I", "idler 2-I", "planet I", "input gear 1",
        "central shaft gear", "input gear 2", "transmission driven gear"}
    assert sorted((s.name, s.side) for s in train.shafts) == sorted(
        [("O", 1), ("S", 1), ("input", 1), ("A", 1), ("A", 2), ("B", 1), ("B", 2), ("C", 1),
         ("C", 2), ("C2", 1), ("C2", 2), ("D", 1), ("E", 1)])
    shaft, mount = train.shaft_of_gear("planet gear E")
    a, r = mechanism.centre_distance, mechanism.r
    assert shaft.name == "E" and shaft.xy == pytest.approx((a + 2 * r, 0.0))
    c2 = next(s for s in train.shafts if s.name == "C" and s.side == 2)
    assert c2.xy == pytest.approx((0.0, -mechanism.carrier_radii["C"]), abs=1e-9)
    # by hand from the file: faces 25 mm (gears.face_width), gaps 2 mm (housing.axial_gap);
    # gearbox 1 two layers (set I, set II), gearbox 2 two, the frame two (the drive's pairs),
    # a gap below, between and above the layers
    face, gap = params.gears.face_width, params.housing.axial_gap
    assert (face, gap) == (25.0, 2.0)
    for housing in ("gearbox1", "gearbox2", "frame"):
        assert train.stacks[housing].cavity_height == pytest.approx(2 * face + 3 * gap)
    assert mount.z_bottom == pytest.approx(2 * gap + face)     # gear E in the second layer
    # the input shaft's stub leaves the frame's floor for a sprocket or coupling, keyed
    drive = next(s for s in train.shafts if s.name == "input")
    assert drive.extends_below == 2 * drive.diameter + 20 and drive.seats[0].through
    assert drive.coupling_key is not None and drive.coupling_key.length <= drive.extends_below - 4
    # O: in the frame's floor and gearbox 1's roof, both blind; it passes gearbox 1's floor
    o = next(s for s in train.shafts if s.name == "O")
    assert [(seat.housing, seat.wall, seat.through) for seat in o.seats] == [
        ("frame", "floor", False), ("gearbox1", "roof", False)]
    # the inner shaft C2: from gearbox 1's floor to gearbox 2's roof, its z range from the
    # stack: gearbox 2's cavity floor above gearbox 1's plus gearbox 2's cavity and roof bearing
    inner = next(s for s in train.shafts if s.name == "C2" and s.side == 1)
    assert [(seat.housing, seat.wall) for seat in inner.seats] == [("gearbox1", "floor"),
                                                                   ("gearbox2", "roof")]
    top = train.bases["gearbox2"] + train.stacks["gearbox2"].cavity_height + \
        inner.seats[1].bearing.width
    assert inner.ends == pytest.approx((-inner.seats[0].bearing.width, top))
    # E reaches through the cam (seated on the roof), a gap, the duckbill lever's layer (the
    # lever and a gap above it) and the planter's keyed hub, and on past the hub for its DIN 471
    # ring: groove m = 1.1 and n = 1.1 beyond it (DIN 471 for 15 mm), rounded up to 2.5 mm
    hub = train.fixings["planter"]
    assert hub["length"] >= params.planter.arm_thickness
    assert shaft.extends_above == pytest.approx(params.cam.thickness + params.housing.axial_gap
                                                + params.cam.lever.thickness
                                                + params.housing.axial_gap + hub["length"] + 2.5)


def test_planting_speeds_follow_the_train():
    mechanism = build_mechanism(load_params(PAPER))
    speeds = planting_speeds(mechanism, 30.0)
    # O turns at n omega in the frame's bearing (its larger relative speed; (n - 1) omega in
    # gearbox 1's); C, set II's planet, (n - 1) omega R / R in carrier 1; n = 3, omega = 30
    assert speeds["O"] == 90.0 and speeds["C"] == 60.0
    assert speeds["A"] == pytest.approx(60.0 / 1.2) and speeds["E"] == 30.0
    assert speeds["S"] == 30.0 and speeds["C2"] == 30.0    # carrier 1 in the frame; planet I


def test_pricking_gears_turn_once_per_carrier_turn():
    params = load_params(KERNEL_B)
    train = drivetrain(params, pricking_design(params))
    for shaft in train.shafts:
        assert shaft.speed_rpm == pytest.approx(params.field.carrier_speed_rpm, rel=1e-6)
    assert {m.gear for s in train.shafts for m in s.mounts} == {
        "sun", "intermediate 1", "intermediate 2", "planet"}
    planet = next(s for s in train.shafts if s.name == "planet")
    assert planet.torque_nm == pytest.approx(
        params.machine.tip_load_n * params.machine.service_factor
        * pricking_design(params).linkage.l / 1000)


def test_a_diameter_given_in_the_file_is_used(tmp_path):
    params, train = _variant(tmp_path, PAPER, "machine.shafts", E="30.0")
    shaft = next(s for s in train.shafts if s.name == "E")
    assert shaft.diameter == 30.0 and shaft.given
    assert all(seat.bearing.bore == 30.0 for seat in shaft.seats)
    assert not [p for p in train.problems if p.path == "machine.shafts.E"]


def test_an_impossible_diameter_is_a_named_problem(tmp_path):
    _, train = _variant(tmp_path, PAPER, "machine.shafts", E="8.0", D="22.0")
    codes = {(p.path, p.code) for p in train.problems}
    assert ("machine.shafts.E", "shaft_too_weak") in codes
    assert ("machine.shafts.D", "shaft_not_catalogue") in codes
    # DIN 471 has no ring in the table for 22 mm: said, not guessed
    assert ("machine.shafts.D.diameter", "no_retaining_ring") in codes


def test_printed_process_gives_printed_seats(tmp_path):
    _, train = _variant(tmp_path, KERNEL_B, "manufacturing", process='"printed"')
    assert train.process == "printed"
    for shaft in train.shafts:
        for seat in shaft.seats:
            assert seat.seat_diameter == pytest.approx(seat.bearing.outside + 0.10)
            if seat.through:
                assert seat.hole_diameter == pytest.approx(shaft.diameter + 1.2)
        for mount in shaft.mounts:
            assert mount.bore_allowance == 0.20


def test_a_short_life_target_is_met_and_a_long_one_is_named(tmp_path):
    _, train = _variant(tmp_path, PAPER, "machine", bearing_life_min_h="900000.0")
    short = [p for p in train.problems if p.code == "bearing_life_short"]
    assert short and all(p.path == "machine.bearing_life_min_h" for p in short)


def test_a_cam_bore_smaller_than_the_e_shafts_hole_is_named(tmp_path):
    """The cam is fixed to gearbox 2 and the E shaft turns in it: a 12 mm bore on the 15 mm
    shaft (its hole 15 + 1.0 mm running clearance, machined) is a failing check; 16 mm is not."""
    params, train = _variant(tmp_path, PAPER, "cam", bore_diameter="12.0")
    (problem,) = [p for p in train.problems if p.code == "cam_bore_too_small"]
    assert problem.path == "cam.bore_diameter" and "16 mm" in problem.message
    _, train = _variant(tmp_path, PAPER, "cam", bore_diameter="16.0")
    assert not [p for p in train.problems if p.code == "cam_bore_too_small"]
