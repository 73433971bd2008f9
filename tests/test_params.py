"""Tests of cadgen.params: the parameter file format and its all-problems-at-once validation."""

from __future__ import annotations

import math
from pathlib import Path

import pydantic
import pytest

import cadgen.params.feasibility
from cadgen.params import (
    MECHANISM_KINDS,
    ParameterError,
    PlantingParameters,
    load_params,
    validate_data,
    validate_text,
)
from kinematics.errors import DesignError, MechanismError, Problem

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = ROOT / "params" / "xin2024-planter.toml"
INVALID = Path(__file__).resolve().parent / "invalid"

# The expected (path, code) pairs of each bad file, written down by hand.
EXPECTED = {
    "syntax_error.toml": {("", "toml_syntax")},
    "missing_key.toml": {("train.R", "missing")},
    "missing_table.toml": {("planter", "missing")},
    "missing_mechanism.toml": {("mechanism", "missing")},
    "typo_optional_key.toml": {("field.carier_speed_rpm", "unknown_key")},
    "typo_required_key.toml": {("planter.l1", "unknown_key"), ("planter.L1", "missing")},
    "typo_table.toml": {("feild", "unknown_key"), ("field", "missing")},
    "wrong_type_string.toml": {("train.R", "wrong_type")},
    "wrong_type_bool_and_float_int.toml": {
        ("train.n", "wrong_type"),
        ("pitch_curve.teeth", "wrong_type"),
    },
    "wrong_type_table.toml": {("planter", "wrong_type")},
    "wrong_type_array_item.toml": {("field.plant_spacings.1", "wrong_type")},
    "out_of_range.toml": {
        ("train.R", "out_of_range"),
        ("train.n", "out_of_range"),
        ("pitch_curve.teeth", "out_of_range"),
    },
    "not_finite.toml": {("pitch_curve.b1", "not_finite"), ("planter.L2", "not_finite")},
    "unknown_mechanism.toml": {("mechanism", "unknown_mechanism")},
    "unknown_pitch_curve_kind.toml": {("pitch_curve.kind", "unknown_kind")},
    "bad_e2.toml": {("pitch_curve.e2", "inconsistent")},
    "duplicate_spacings.toml": {("field.plant_spacings.2", "duplicate")},
    "empty_spacings.toml": {("field.plant_spacings", "empty")},
    "bad_name.toml": {("name", "invalid_name")},
    "housing_keys.toml": {
        ("housing.wall", "wall_too_thin"),
        ("housing.gearbox1.D", "unknown_key"),
        ("housing.gearbox1.B", "out_of_range"),
    },
    "resolution_range.toml": {
        ("resolution.steps_per_revolution", "out_of_range"),
        ("resolution.closure_rtol", "out_of_range"),
    },
    "several_tables.toml": {
        ("name", "invalid_name"),
        ("pitch_curve.a1", "wrong_type"),
        ("train.i13", "out_of_range"),
        ("planter.L2", "not_finite"),
        ("field.depht", "unknown_key"),
        ("field.depth", "missing"),
        ("targets.module_min", "out_of_range"),
        ("resolution.steps_per_revolution", "wrong_type"),
    },
}


def _problems(path_or_text, **kwargs) -> list[Problem]:
    with pytest.raises(ParameterError) as caught:
        if isinstance(path_or_text, Path):
            load_params(path_or_text, **kwargs)
        else:
            validate_text(path_or_text, "test.toml", **kwargs)
    return caught.value.problems


def _reference_text() -> str:
    return REFERENCE.read_text(encoding="utf-8")


def _replace(text: str, old: str, new: str) -> str:
    assert text.count(old) == 1, old
    return text.replace(old, new)


# --------------------------------------------------------------------------- bad files


def test_every_invalid_file_has_an_expectation():
    assert sorted(p.name for p in INVALID.glob("*.toml")) == sorted(EXPECTED)


@pytest.mark.parametrize("name", sorted(EXPECTED), ids=lambda n: n.removesuffix(".toml"))
def test_invalid_file_reports_exactly_the_expected_problems(name):
    problems = _problems(INVALID / name)
    assert {(p.path, p.code) for p in problems} == EXPECTED[name]
    assert len(problems) == len(EXPECTED[name])  # no problem reported twice
    for problem in problems:
        # our own sentences, not pydantic's raw text
        assert problem.message and "Input should" not in problem.message


def test_n_independent_errors_in_different_tables_are_all_reported():
    text = _reference_text()
    edits = {
        "pitch_curve.d1": ("d1 = 30.5 ", 'd1 = "30.5" '),
        "train.r": ("r = 27.0 ", "r = -27.0 "),
        "planter.L1": ("L1 = 130.0 ", "L1 = inf "),
        "field.carrier_speed_rpm": ("carrier_speed_rpm = 30.0 ", "carrier_speed_rpm = 0 "),
        "housing.axial_gap": ("axial_gap = 2.0 ", "axial_gap = true "),
        "targets.hole_width_max": ("hole_width_max = 30.0 ", "hole_width_max = -30.0 "),
        "resolution.closure_rtol": ("closure_rtol = 1e-13 ", "closure_rtol = 1e-20 "),
    }
    for old, new in edits.values():
        text = _replace(text, old, new)
    problems = _problems(text)
    assert len(problems) == len(edits) == 7
    assert {p.path for p in problems} == set(edits)
    assert len({p.path.split(".")[0] for p in problems}) == 7


def test_syntax_error_names_line_and_column():
    (problem,) = _problems(INVALID / "syntax_error.toml")
    lines = (INVALID / "syntax_error.toml").read_text().splitlines()
    line = next(i for i, text in enumerate(lines, start=1) if text.rstrip() == "R =")
    assert f"line {line}, column 5" in problem.message


def test_unknown_key_suggests_the_close_key():
    (problem,) = _problems(INVALID / "typo_optional_key.toml")
    assert "did you mean 'carrier_speed_rpm'?" in problem.message


def test_unknown_key_with_several_equally_close_keys_names_them_all():
    text = _replace(_reference_text(), "r = 27.0 ", "r = 27.0\nRr = 1.0 ")
    (problem,) = _problems(text)
    assert problem.path == "train.Rr"
    assert "did you mean 'R' or 'r'?" in problem.message


def test_unknown_key_far_from_any_key_lists_the_known_keys():
    problems = _problems(INVALID / "housing_keys.toml")
    (unknown,) = [p for p in problems if p.code == "unknown_key"]
    assert "known keys: O, A, B, C" in unknown.message


def test_unknown_mechanism_lists_the_known_kinds():
    (problem,) = _problems(INVALID / "unknown_mechanism.toml")
    assert '"pricker"' in problem.message
    assert all(f"'{kind}'" in problem.message for kind in MECHANISM_KINDS)


def test_messages_carry_the_bad_value():
    (problem,) = _problems(INVALID / "wrong_type_string.toml")
    assert '"36"' in problem.message and "number" in problem.message
    by_path = {p.path: p for p in _problems(INVALID / "out_of_range.toml")}
    assert "-36.0" in by_path["train.R"].message
    assert "teeth = 4" in by_path["pitch_curve.teeth"].message
    assert "at least 6" in by_path["pitch_curve.teeth"].message


@pytest.mark.parametrize(
    ("old", "new", "path", "code"),
    [
        ("R = 36.0 ", "R = 1979-05-27 ", "train.R", "wrong_type"),
        ("R = 36.0 ", "R = [36.0] ", "train.R", "wrong_type"),
        ("R = 36.0 ", "R = 1" + "0" * 400 + " ", "train.R", "out_of_range"),
        ('kind = "limacon"', "kind = 3", "pitch_curve.kind", "wrong_type"),
        ('mechanism = "planting"', "mechanism = 1", "mechanism", "wrong_type"),
        ("e2 = 1.0 ", "e2 = 0 ", "pitch_curve.e2", "out_of_range"),
        ("depth = 35.0 ", "depth = -inf ", "field.depth", "not_finite"),
        ("phi0_deg = 90.0 ", "phi0_deg = nan ", "train.phi0_deg", "not_finite"),
        ("[150.0, 185.0, 200.0]", "[150.0, -185.0]", "field.plant_spacings.1", "out_of_range"),
        ("[150.0, 185.0, 200.0]", "150.0", "field.plant_spacings", "wrong_type"),
        ("angle_difference_max_deg = 20.0 ", "angle_difference_max_deg = 200.0 ",
         "targets.angle_difference_max_deg", "out_of_range"),
    ],
    ids=["datetime", "array-for-number", "huge-int", "kind-not-string", "mechanism-not-string",
         "e2-zero", "minus-inf", "nan-angle", "negative-spacing", "scalar-for-array",
         "angle-target"],
)
def test_single_problem_cases(old, new, path, code):
    problems = _problems(_replace(_reference_text(), old, new))
    assert [(p.path, p.code) for p in problems] == [(path, code)]


@pytest.mark.parametrize("e2", [0.5, 1.0, 1.5, 2.0, 3])
def test_e2_with_whole_2e2_is_accepted(e2):
    text = _replace(_reference_text(), "e2 = 1.0 ", f"e2 = {e2} ")
    assert validate_text(text, check_feasibility=False).pitch_curve.e2 == e2


@pytest.mark.parametrize("e2", [0.3, 1.25, 2.0001])
def test_e2_with_fractional_2e2_is_inconsistent(e2):
    text = _replace(_reference_text(), "e2 = 1.0 ", f"e2 = {e2} ")
    assert [(p.path, p.code) for p in _problems(text)] == [("pitch_curve.e2", "inconsistent")]


def test_several_duplicates_each_reported_at_its_index():
    text = _replace(_reference_text(), "[150.0, 185.0, 200.0]", "[150.0, 185, 150, 185.0, 150]")
    assert {(p.path, p.code) for p in _problems(text)} == {
        ("field.plant_spacings.2", "duplicate"),
        ("field.plant_spacings.3", "duplicate"),
        ("field.plant_spacings.4", "duplicate"),
    }


@pytest.mark.parametrize("name", ["abc\n", "", "a b", ".hidden", "a" * 101, "é"])
def test_bad_names(name):
    text = _replace(_reference_text(), '"xin2024-planter"', f'"{name}"'.replace("\n", "\\n"))
    assert [(p.path, p.code) for p in _problems(text)] == [("name", "invalid_name")]


# --------------------------------------------------------------------------- files


def test_missing_file(tmp_path):
    (problem,) = _problems(tmp_path / "nope.toml")
    assert (problem.path, problem.code) == ("", "file_not_found")


def test_directory_is_not_readable(tmp_path):
    (problem,) = _problems(tmp_path)
    assert problem.code == "not_readable"


def test_non_utf8_file(tmp_path):
    path = tmp_path / "latin1.toml"
    text = _reference_text().replace("# pot seedlings", "# pot seedlings \u00e9")
    path.write_bytes(text.encode("latin-1"))
    (problem,) = _problems(path)
    assert problem.code == "not_utf8"
    assert "line 3" in problem.message and "0xe9" in problem.message


def test_byte_order_mark_is_tolerated(tmp_path):
    path = tmp_path / "bom.toml"
    path.write_bytes(b"\xef\xbb\xbf" + REFERENCE.read_bytes())
    assert load_params(path, check_feasibility=False).name == "xin2024-planter"


def test_error_family_and_message(tmp_path):
    with pytest.raises(ParameterError) as caught:
        load_params(INVALID / "out_of_range.toml")
    error = caught.value
    assert isinstance(error, DesignError) and isinstance(error, ValueError)
    assert isinstance(error, MechanismError)
    assert str(INVALID / "out_of_range.toml") in str(error)
    assert "3 problems" in str(error)


def test_validation_writes_nothing(tmp_path, monkeypatch):
    path = tmp_path / "design.toml"
    path.write_text(_reference_text(), encoding="utf-8")
    bad = tmp_path / "bad.toml"
    bad.write_text((INVALID / "several_tables.toml").read_text(), encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    before = sorted(tmp_path.rglob("*"))
    load_params(path)
    with pytest.raises(ParameterError):
        load_params(bad)
    assert sorted(tmp_path.rglob("*")) == before


# --------------------------------------------------------------------------- the reference design


def test_reference_values_equal_the_spec():
    params = load_params(REFERENCE, check_feasibility=False)
    assert isinstance(params, PlantingParameters)
    assert params.mechanism == "planting" and params.name == "xin2024-planter"
    curve = params.pitch_curve
    assert curve.kind == "limacon"
    assert (curve.a1, curve.b1, curve.c1, curve.d1) == (1.2, 27.5, -5.5, 30.5)
    assert (curve.e1, curve.e2) == (2.66, 1.0)
    assert (curve.f1_rad, curve.f2_rad, curve.g1, curve.g2) == (8.55, 4.24, -6.95, -4.0)
    assert curve.teeth == 22
    train = params.train
    assert (train.i12, train.i13, train.R, train.r, train.n) == (1.2, 1.1, 36.0, 27.0, 3.0)
    assert (train.phi0_deg, train.phic_deg) == (90.0, 90.0)
    assert math.isclose(train.phi0_rad, math.pi / 2) and math.isclose(train.phic_rad, math.pi / 2)
    assert (params.planter.L1, params.planter.L2) == (130.0, 190.0)
    assert params.field.depth == 35.0
    assert params.field.plant_spacings == (150.0, 185.0, 200.0)
    assert params.field.carrier_speed_rpm == 30.0
    assert params.housing.wall is None and params.housing.clearance is None  # derived
    assert params.housing.axial_gap == 2.0
    assert params.housing.gearbox1 is None and params.housing.gearbox2 is None
    targets = params.targets
    assert targets.trajectory_height_min == 500.0
    assert (targets.hole_width_max, targets.hole_verticality_max) == (30.0, 10.0)
    assert (targets.angle_difference_max_deg, targets.arm_distance_min) == (20.0, 10.0)
    assert (targets.ground_clearance_min, targets.module_min) == (20.0, 2.5)
    assert params.resolution.steps_per_revolution == 3600
    assert params.resolution.closure_rtol == 1e-13


def test_reference_file_is_feasible():
    # Runs cadgen.params.feasibility.design_problems on the paper's design: it must pass.
    assert load_params(REFERENCE).name == "xin2024-planter"


def test_reference_comments_name_every_quantity():
    # Every key = value line of the reference example carries a comment.
    for line in _reference_text().splitlines():
        stripped = line.strip()
        if stripped and not stripped.startswith(("#", "[")) and "=" in stripped:
            assert "#" in stripped, line


def test_optional_tables_take_the_defaults():
    text = _reference_text()
    text = text[: text.index("# Gearbox housings")]  # drop [housing] and every table after it
    text = _replace(text, "carrier_speed_rpm = 30.0                # carrier-1 speed, r/min\n", "")
    params = validate_text(text, check_feasibility=False)
    reference = load_params(REFERENCE, check_feasibility=False)
    # the reference spells out every default but its gears' face width (wide enough for keys)
    # and their steel (C45+N's flanks fall below S_H 1 at the design load)
    assert reference.gears.face_width == 25.0
    assert (params.machine.gear_material, reference.machine.gear_material) == (
        None, "steel 42CrMo4+QT")
    steel = params.machine.model_copy(update={"gear_material": "steel 42CrMo4+QT"})
    assert params.model_copy(update={"gears": reference.gears, "machine": steel}) == reference
    assert params.gears == reference.gears.model_copy(update={"face_width": None})


def test_integers_are_accepted_for_floats_and_stored_as_floats():
    text = _replace(_reference_text(), "R = 36.0 ", "R = 36 ")
    text = _replace(text, "[150.0, 185.0, 200.0]", "[150, 185, 200]")
    params = validate_text(text, check_feasibility=False)
    assert type(params.train.R) is float and params.train.R == 36.0
    assert all(type(s) is float for s in params.field.plant_spacings)


def test_explicit_housing_envelopes():
    text = _replace(
        _reference_text(),
        "# gearbox1 = { O = 50.0, A = 50.0, B = 50.0, C = 50.0 }",
        "gearbox1 = { O = 50.0, C = 45 }\ngearbox2 = { D = 52.0 }",
    )
    housing = validate_text(text, check_feasibility=False).housing
    assert (housing.gearbox1.O, housing.gearbox1.A, housing.gearbox1.C) == (50.0, None, 45.0)
    assert housing.gearbox2.D == 52.0 and housing.gearbox2.E is None
    # dict-like lookup, explicit radius over a derived default
    assert housing.gearbox1.get("O", 10.0) == 50.0 and housing.gearbox1.get("A", 10.0) == 10.0
    assert housing.gearbox2.get("D") == 52.0 and housing.gearbox2.get("O") is None


def test_parameters_are_frozen_and_hashable():
    params = load_params(REFERENCE, check_feasibility=False)
    with pytest.raises(pydantic.ValidationError):
        params.train.R = 40.0
    assert hash(params) == hash(load_params(REFERENCE, check_feasibility=False))


def test_validate_data_rejects_a_non_mapping():
    with pytest.raises(ParameterError) as caught:
        validate_data([1, 2])
    assert [p.code for p in caught.value.problems] == ["wrong_type"]


# --------------------------------------------------------------------------- feasibility hook


# (file, model it validates to, a structurally invalid file of the same kind)
HOOK_CASES = {
    "planting": (REFERENCE, "PlantingParameters", INVALID / "bad_e2.toml"),
    "pricking": (ROOT / "params" / "kernel-a.toml", "PrickingParameters",
                 INVALID / "pricking" / "pricking_degree_4.toml"),
}


@pytest.mark.parametrize("kind", HOOK_CASES)
def test_feasibility_problems_join_the_parameter_error(kind, monkeypatch):
    path, model, _ = HOOK_CASES[kind]
    seen = []

    def fake(params):
        seen.append(params)
        return [Problem("pitch_curve.b1", "pointed_pitch_curve", "r1 touches zero")]

    monkeypatch.setattr(cadgen.params.feasibility, "design_problems", fake)
    problems = _problems(path)
    assert [(p.path, p.code) for p in problems] == [("pitch_curve.b1", "pointed_pitch_curve")]
    assert len(seen) == 1 and type(seen[0]).__name__ == model


@pytest.mark.parametrize("kind", HOOK_CASES)
def test_feasibility_design_error_is_folded_in(kind, monkeypatch):
    def fake(params):
        raise DesignError([Problem("train.R", "tiny_intermediate_radius", "a - r1 is tiny")])

    monkeypatch.setattr(cadgen.params.feasibility, "design_problems", fake)
    assert [p.code for p in _problems(HOOK_CASES[kind][0])] == ["tiny_intermediate_radius"]


@pytest.mark.parametrize("kind", HOOK_CASES)
def test_feasibility_is_skipped_when_the_structure_is_wrong_or_when_asked(kind, monkeypatch):
    path, _, invalid = HOOK_CASES[kind]
    calls = []
    monkeypatch.setattr(
        cadgen.params.feasibility, "design_problems", lambda params: calls.append(params) or []
    )
    _problems(invalid)
    load_params(path, check_feasibility=False)
    assert calls == []
    load_params(path)
    assert len(calls) == 1
