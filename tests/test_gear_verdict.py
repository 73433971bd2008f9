"""One gear verdict (cadgen.report.gear_verdict) for the page's checks, its gears section and the
terminal: every gear of the train counted once, a pair whose gear cannot be cut counted whole.

The reports here are written by hand in report.json's shape (a pricking train of two pairs,
pitch curves naming its four gears), so the expected counts are read off the input.
"""

from __future__ import annotations

import copy

import pytest

from cadgen.report.gear_verdict import gear_verdict
from cadgen.report.html import overall_checks, render_html
from cadgen.report.summary import format_gear_table

CONCAVE = ("the {gear} gear cannot be cut: the {gear} gear's pitch curve is concave down to a "
           "radius of 0.91 mm (teeth 0, 3, 4): no pinion cutter of at least 10 teeth fits at "
           "module 2.000 mm")
CURVES = [{"name": name, "stage": stage, "role": role, "perimeter_mm": 169.6,
           "radius_min_mm": 23.2, "radius_max_mm": 29.0, "curvature_min_per_mm": -0.098,
           "convex": False, "pressure_angle_deviation_max_deg": 25.5,
           "convex_radius_of_curvature_min_mm": 0.8, "undercut": True}
          for name, stage, role in (("sun", 1, "drive"), ("intermediate 1", 1, "driven"),
                                    ("intermediate 2", 2, "drive"), ("planet", 2, "driven"))]


def _gear(name, stage):
    return {"gear": name, "stage": stage, "teeth": 26, "module_mm": 2.0, "cutter": "rack",
            "shaper_teeth": None, "convex": True, "undercut_teeth": [], "pointed_teeth": [],
            "root_thickness_min_mm": 3.09, "tip_thickness_min_mm": 1.34, "problems": []}


def _failure(gear, stage):
    return {"stage": stage, "path": "gears." + gear.replace(" ", "_"),
            "code": "gear_not_cuttable", "message": CONCAVE.format(gear=gear)}


def _report(cut=(), failing=()):
    """A pricking report whose stages ``failing`` ((gear, stage) pairs) were not cut."""
    return {"design": "k", "mechanism": "pricking", "verified": True,
            "gears": {"pitch_curves": copy.deepcopy(CURVES)},
            "gear_train": {"gears": [_gear(name, stage) for name, stage in cut], "meshes": [],
                           "failures": [_failure(gear, stage) for gear, stage in failing]}}


NONE_CUT = _report(failing=[("intermediate 1", "stage 1"), ("planet", "stage 2")])
HALF_CUT = _report(cut=[("intermediate 2", "stage 2"), ("planet", "stage 2")],
                   failing=[("intermediate 1", "stage 1")])
ALL_CUT = _report(cut=[(c["name"], f"stage {c['stage']}") for c in CURVES])


@pytest.mark.parametrize("report, cut, cannot, mates", [
    (NONE_CUT, 0, ["intermediate 1", "planet"], ["sun", "intermediate 2"]),
    (HALF_CUT, 2, ["intermediate 1"], ["sun"]),
    (ALL_CUT, 4, [], []),
], ids=["none-cut", "half-cut", "all-cut"])
def test_every_gear_of_the_train_is_counted_once(report, cut, cannot, mates):
    verdict = gear_verdict(report)
    assert verdict.total == len(CURVES)                       # the four pitch curves
    assert len(verdict.cut) == cut
    assert [gear for gear, _, _ in verdict.not_cuttable] == cannot
    assert [gear for gear, _, _ in verdict.not_cut_with] == mates
    assert verdict.passed is (not cannot)


def test_the_statement_names_the_gears_and_why():
    assert gear_verdict(NONE_CUT).statement() == (
        "no gear cut: intermediate 1 and planet cannot be cut (concave, no pinion cutter fits), "
        "so their pairs with sun and intermediate 2 were not cut either")
    assert gear_verdict(HALF_CUT).statement() == (
        "2 of 4 gears cut: intermediate 1 cannot be cut (concave, no pinion cutter fits), so its "
        "pair with sun was not cut either")
    assert gear_verdict(ALL_CUT).statement() == "4 gears cut"


def test_a_pair_whose_other_gear_the_report_does_not_name_is_said_so():
    report = copy.deepcopy(NONE_CUT)
    del report["gears"]
    verdict = gear_verdict(report)
    assert verdict.unknown_pairs == ("stage 1", "stage 2") and not verdict.passed
    assert verdict.statement().endswith("so their pairs (stage 1 and stage 2) were not cut")


@pytest.mark.parametrize("report", [NONE_CUT, HALF_CUT, ALL_CUT],
                         ids=["none-cut", "half-cut", "all-cut"])
def test_checks_gears_section_and_terminal_say_the_same(report):
    statement = gear_verdict(report).statement()
    row = {name: (ok, detail) for name, ok, detail in overall_checks(report)}["gears cut"]
    assert row == (not report["gear_train"]["failures"], statement)
    page = render_html(report)
    gears = page.split('<section id="gears">')[1].split("</section>")[0]
    assert f"{statement}</p>" in gears
    text = format_gear_table(report["gear_train"], report)
    assert text.splitlines()[0] == f"gears: {statement}"


@pytest.mark.parametrize("report", [NONE_CUT, HALF_CUT, ALL_CUT],
                         ids=["none-cut", "half-cut", "all-cut"])
def test_no_table_header_without_rows(report):
    text = format_gear_table(report["gear_train"], report)
    lines = text.splitlines()
    rules = [k for k, line in enumerate(lines) if set(line) <= {"-", " "} and "-" in line]
    assert all(k + 1 < len(lines) and lines[k + 1].strip() for k in rules)
    import re

    assert bool(re.search(r"(?m)^gear +teeth", text)) is bool(report["gear_train"]["gears"])
    page = render_html(report)
    gears = page.split('<section id="gears">')[1].split("</section>")[0]
    for table in gears.split("<table>")[1:]:
        assert "<tbody><tr" in table
