"""One undercut policy for both mechanisms, the verdict's warnings, rows that name their cause,
the bundled grid and the batch CSV of a design whose stage failed.

The root-thickness limit is checked against a hand calculation: 1.25 modules, i.e. 2.5 mm at
module 2. Circular gears cut by the standard rack (alpha 20 deg, ha* 1) with fewer than
2 / sin^2(20 deg) = 17.1 teeth are undercut; the gear checks count every tooth of a 7- and an
8-tooth gear, the 8-tooth one keeping more than 1.25 m of root and the 7-tooth one less.
"""

from __future__ import annotations

import csv
import io
import math
import tomllib
from pathlib import Path

import pytest

from cadgen.gears.pairs import MIN_ROOT_THICKNESS, circle_pair, generate_pair
from cadgen.gears.teeth import ToothSystem
from cadgen.gears.circular import circular_module
from cadgen.gears.trains import GearStage, GearTrain, train_report
from cadgen.report.content import failures, verdict_text, check_warnings
from cadgen.report.html import overall_checks, render_html

ROOT = Path(__file__).resolve().parents[1]
MODULE = 2.0
LIMIT_MM = 1.25 * MODULE       # hand calculation: 1.25 modules at module 2


def _circle_report(teeth: int) -> dict:
    """A report holding one rack-cut circular pair: ``teeth`` on the pinion, 3x on the wheel."""
    radius = teeth * MODULE / 2
    pair = circle_pair(("pinion", "wheel"), radius, 3 * radius)
    generated = generate_pair(pair, (teeth, 3 * teeth), system=ToothSystem(MODULE))
    from cadgen.gears.meshing import meshing_check

    meshing = meshing_check(generated.profiles[0], generated.profiles[1], pair, poses=8,
                            span=pair.period / teeth)
    train = GearTrain((GearStage("pair", generated, meshing, (0.0, (0.0, 0.0))),))
    report = {"design": f"z{teeth}", "mechanism": "planting", "metrics": [],
              "gear_train": train_report(train)}
    report["check_warnings"] = check_warnings(report)
    report["failures"] = failures(report)
    report["passed"] = not report["failures"]
    return report


def _neck_by_arcs(teeth: int) -> float:
    """A second method for the undercut neck: the narrowest arc width of one tooth inside the
    cut outline (shapely), over radii from one module below the pitch circle up to it."""
    import numpy as np
    import shapely

    radius = teeth * MODULE / 2
    pair = circle_pair(("pinion", "wheel"), radius, 3 * radius)
    profile = generate_pair(pair, (teeth, 3 * teeth), system=ToothSystem(MODULE)).profiles[0]
    outline = shapely.Polygon(profile.outline - np.asarray(profile.centre))
    turn = np.linspace(0.0, 2 * np.pi, 4000)
    widths = [shapely.LineString(r * np.c_[np.cos(turn), np.sin(turn)]).intersection(outline).length
              / teeth for r in np.linspace(radius - MODULE, radius, 200)]
    return float(min(widths))


def test_the_limit_is_the_stated_policy_and_the_neck_is_measured_right():
    assert MIN_ROOT_THICKNESS * MODULE == pytest.approx(LIMIT_MM)   # 1.25 modules (README)
    for teeth in (7, 8):   # both undercut by the rack: fewer than 2 / sin^2(20 deg) = 17.1 teeth
        measured = _circle_report(teeth)["gear_train"]["gears"][0]
        by_arcs = _neck_by_arcs(teeth)
        assert measured["undercut_root_thickness_min_mm"] == pytest.approx(by_arcs, abs=0.05)
        assert (by_arcs < LIMIT_MM) is (teeth == 7)


@pytest.mark.parametrize("teeth, fails", [(8, False), (7, True)], ids=["z8-above", "z7-below"])
def test_an_undercut_gear_either_side_of_the_root_thickness_limit(teeth, fails):
    report = _circle_report(teeth)
    pinion = report["gear_train"]["gears"][0]
    # every tooth of a 7- or 8-tooth rack-cut gear is undercut (the gear check's count)
    assert pinion["undercut_teeth"] == list(range(teeth))
    assert pinion["root_thickness_limit_mm"] == pytest.approx(LIMIT_MM)
    assert (pinion["undercut_root_thickness_min_mm"] < LIMIT_MM) is fails
    checks = overall_checks(report)
    failing = [name for name, ok, _ in checks if not ok]
    if fails:
        assert report["passed"] is False
        assert failing == ["gear checks: pinion undercut below the root-thickness limit"]
        assert verdict_text(report) == "FAIL, 1 failure"
        assert [p["code"] for p in pinion["problems"]] == ["undercut_root_too_thin"]
    else:
        assert report["passed"] is True and failing == []
        assert verdict_text(report) == "PASS, 1 warning"
        assert [p["code"] for p in pinion["problems"]] == ["undercut"]
    assert "report verdict" not in {name for name, _, _ in checks}
    page = render_html(report, {})
    assert ("verdict fail" if fails else "verdict pass") in page


def _kernel_b_report(tmp_path):
    from cadgen.params import load_params
    from cadgen.pipeline.build import build

    return build(load_params(ROOT / "params" / "kernel-b.toml"), output_root=tmp_path).report


def test_kernel_b_planet_reads_like_the_planting_gears(tmp_path):
    report = _kernel_b_report(tmp_path)
    planet = next(g for g in report["gear_train"]["gears"] if g["gear"] == "planet")
    # the kinematic prediction: rho 17.03 mm < m ha*/sin^2 20 deg = 2 / 0.11698 = 17.10 mm
    finding = next(f for f in report["findings"] if f["path"] == "gears.planet")
    assert finding["code"] == "undercut"
    assert 2.0 / math.sin(math.radians(20)) ** 2 == pytest.approx(17.097, abs=1e-3)
    # the evidence: 5 undercut teeth, root thickness at least 2.5 mm (the cut teeth decide)
    assert len(planet["undercut_teeth"]) == 5
    assert planet["undercut_root_thickness_min_mm"] >= LIMIT_MM
    assert report["passed"] is True and report["failures"] == []
    assert [w["code"] for w in report["check_warnings"]] == ["undercut"]   # counted once
    assert verdict_text(report) == "PASS, 1 warning"
    assert all(ok for _, ok, _ in overall_checks(report))


def test_a_kinematic_prediction_alone_is_a_warning():
    report = {"design": "k", "mechanism": "pricking", "verified": True,
              "findings": [{"path": "gears.planet", "code": "undercut", "message": "bends"}]}
    report["failures"] = failures(report)
    assert report["failures"] == []
    assert [w["code"] for w in check_warnings(report)] == ["undercut"]
    assert verdict_text(report) == "PASS, 1 warning"


def test_a_failure_without_a_row_gets_one_named_by_it():
    report = {"design": "x", "mechanism": "planting", "metrics": [], "passed": False,
              "failures": ["gearbox1 does not enclose its gears (margin -1.00 mm at sun)"]}
    failing = [name for name, ok, _ in overall_checks(report) if not ok]
    assert failing == [report["failures"][0]]


def test_fractional_teeth_names_the_key_and_a_value_that_works():
    radii = [37.0, 37 * 1.2, 37 * 1.1, 37.0, 27.0]
    with pytest.raises(ValueError) as error:
        circular_module(radii)
    message = str(error.value)
    assert "gears.circular_module" in message and "fractional_teeth" in message
    # 0.2 mm divides 74, 88.8, 81.4 and 54 mm (hand: 370, 444, 407, 270 teeth)
    assert "e.g. 0.2 (teeth 370, 444, 407, 370, 270)" in message
    with pytest.raises(ValueError, match=r"gears.circular_module = 1.8 \(teeth 40, 48, 44, 40, 30\)"):
        circular_module([36.0, 43.2, 39.6, 36.0, 27.0], 2.0)


def test_the_bundled_grid_only_holds_radii_with_whole_tooth_counts():
    grid = tomllib.loads((ROOT / "params" / "grids" / "l2-sweep.toml").read_text())
    base = tomllib.loads((ROOT / "params" / "xin2024-planter.toml").read_text())
    train = base["train"]
    assert len(grid["grid"]["planter.L2"]) * len(grid["grid"]["train.R"]) == 6
    for R in grid["grid"]["train.R"]:
        radii = [R, R * train["i12"], R * train["i13"], R, train["r"]]
        module = circular_module(radii)
        # hand: 35 mm -> 1.0 mm (70, 84, 77, 70, 54 teeth), 36 mm -> 1.8 mm (40, 48, 44, 40, 30)
        assert module == {35.0: 1.0, 36.0: 1.8}[R]
        assert all(abs(2 * r / module - round(2 * r / module)) < 1e-9 for r in radii)


def test_csv_row_of_a_design_whose_stage_failed(tmp_path):
    from cadgen.batch.grid import DesignJob
    from cadgen.batch.single import run_design
    from cadgen.batch.summary import summary_csv

    report = {"design": "d", "mechanism": "planting", "passed": False, "metrics": [],
              "failures": ["stage teeth failed: [fractional_teeth] ..."],
              "stages": [{"stage": "teeth", "status": "failed", "seconds": 0.1,
                          "message": "[fractional_teeth] no module ...",
                          "problems": [{"path": "gears.circular_module",
                                        "code": "fractional_teeth",
                                        "message": "no module ..."}]}]}
    job = DesignJob(name="d", source="grid.toml", path=None,
                    data=tomllib.loads((ROOT / "params" / "xin2024-planter.toml").read_text()))
    summary = run_design(job, tmp_path, build=lambda params, output_root: report)
    row = next(csv.DictReader(io.StringIO(summary_csv([summary]))))
    assert row["status"] == "stage_failed" and row["passed"] == "no"
    assert row["failure"].startswith("stage teeth failed: [fractional_teeth]")
    assert row["failure_code"] == "stage_failed;fractional_teeth"
