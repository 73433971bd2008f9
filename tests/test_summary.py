"""Plain-text summaries (cadgen.report.summary): every section as a report may hold it, None included."""

from __future__ import annotations

import copy
import json

import pytest

from cadgen.pipeline.build import build
from cadgen.params import load_params
from cadgen.report.summary import format_clearances, format_solids, summary_text
from tests.helpers import REFERENCE


def sweep_row(**changes):
    row = {"label": "gear case ground clearance (solids, FCL)", "minimum_mm": 43.45564894705855,
           "certified_bound_mm": 43.45564813147138, "certified": True,
           "carrier_angle_deg": 358.0638731601398, "nearest": ["gear-case", "ground"],
           "interference_ranges_deg": [], "kinematic_estimate_mm": None, "target_mm": 0.0,
           "passed": True}
    row.update(changes)
    return {"ground_clearance": row}


def test_clearance_without_kinematic_estimate():
    assert format_clearances(sweep_row()) == (
        "gear case ground clearance (solids, FCL): 43.456 mm (certified >= 43.456) at carrier "
        "angle 358.06 deg, gear-case / ground; no kinematic estimate for this mechanism; "
        "target > 0 mm: pass")


def test_clearance_with_estimate_interference_and_no_certificate():
    text = format_clearances(sweep_row(kinematic_estimate_mm=112.6408, certified=False,
                                       minimum_mm=-1.5, passed=False,
                                       interference_ranges_deg=[[10.0, 12.25]]))
    assert ": -1.500 mm (NOT certified, bound 43.456)" in text
    assert "kinematic estimate 112.641 mm" in text
    assert text.endswith("FAIL; IN INTERFERENCE over 10.0..12.2 deg")


def test_clearance_with_missing_numbers():
    text = format_clearances(sweep_row(minimum_mm=None, certified_bound_mm=None,
                                       carrier_angle_deg=float("nan")))
    assert text.startswith("gear case ground clearance (solids, FCL): n/a mm (certified >= n/a) "
                           "at carrier angle n/a deg")


def test_solids_without_cut_gears_and_axial_misfit():
    solids = {"parts": [{"instances": 2}, {"instances": 1}], "total_mass_kg": 1.234,
              "density_kg_m3": 7850.0, "assembly": {"carrier_angle_deg": 0.0},
              "enclosure": [{"housing": "gearbox1", "gears_enclosed": True,
                             "smallest_margin_mm": None, "nearest_gear": None},
                            {"housing": "gearbox2", "gears_enclosed": False,
                             "smallest_margin_mm": 2.5, "nearest_gear": "sun",
                             "axial_fit": False}]}
    lines = format_solids(solids).splitlines()
    assert lines[0] == ("solids: 2 parts (3 placed), total mass 1.23 kg at 7850 kg/m3, "
                        "assembly at carrier angle 0 deg")
    assert "gearbox1: no gears were cut" in lines[1]
    assert lines[2] == ("     gearbox2 DOES NOT enclose its gears (smallest margin 2.50 mm, sun; "
                        "the gears' faces do not fit between its floor and roof)")


def _floats_to_none(value):
    if isinstance(value, dict):
        return {k: _floats_to_none(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_floats_to_none(v) for v in value]
    return None if isinstance(value, float) else value


@pytest.fixture(scope="module")
def reports():
    planting = load_params(REFERENCE)
    pricking = load_params(REFERENCE.with_name("kernel-a.toml"))
    return {"field": build(planting, None, effects=["metrics"]).report,
            "bench": build(planting, None, effects=["metrics"], case="bench").report,
            "pricking": build(pricking, None, effects=["metrics"]).report}


@pytest.mark.parametrize("case", ["field", "bench", "pricking"])
def test_summary_survives_every_number_missing(reports, case):
    """report.json writes a non-finite number as null: a summary read back must still print."""
    report = json.loads(json.dumps(reports[case], default=float))
    full = summary_text(copy.deepcopy(report))
    empty = summary_text(_floats_to_none(report))
    assert empty.splitlines()[0] == full.splitlines()[0]
    assert "n/a" in empty and "n/a" not in full


def test_bench_summary_says_why_there_is_no_soil(reports):
    text = summary_text(reports["bench"])
    assert "bench run: no soil" in text and "attitude Psi" not in text
    assert "centre distance a = 59.9438" in text       # the paper's 59.94 mm
    assert "attitude Psi" in summary_text(reports["field"])
