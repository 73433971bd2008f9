"""Tests of cadgen.params for mechanism kind 2, ``mechanism = "pricking"``.

The bad files live in ``tests/invalid/pricking/`` (not directly in ``tests/invalid/``,
whose file list tests/test_params.py pins to the planting cases).
"""

from __future__ import annotations

import math
import re
import subprocess
import sys
from pathlib import Path

import pydantic
import pytest

from cadgen.params import (
    EQUAL_PERIMETER,
    MECHANISM_KINDS,
    GearParameters,
    LinkageParameters,
    ParameterError,
    PrickingFieldParameters,
    PrickingParameters,
    PrickingResolutionParameters,
    TrajectoryParameters,
    load_params,
    validate_data,
    validate_text,
)
from kinematics.errors import Problem

ROOT = Path(__file__).resolve().parents[1]
KERNEL_A = ROOT / "params" / "kernel-a.toml"
KERNEL_B = ROOT / "params" / "kernel-b.toml"
INVALID = Path(__file__).resolve().parent / "invalid" / "pricking"

# The spec's type-value points (pricking-mechanism.md, "Example designs"), typed in as
# printed there: machine travelling towards -x. This project's frame has x = forward
# travel, so the example files must hold them mirrored in x, in the same order.
SPEC_KERNEL_A = [
    (-120, -135), (-110, -180), (-80, -215), (-45, -255), (5, -288), (60, -262),
    (95, -215), (125, -160), (125, -110), (85, -78), (10, -70), (-75, -92),
]
SPEC_KERNEL_B = [
    (-112.6, -139.3), (-105.5, -187.5), (-82.6, -223.4), (-41.9, -265.5), (8.6, -290.1),
    (57.3, -272.6), (100.7, -223.4), (129.1, -169.0), (128.0, -117.4), (85.8, -87.3),
    (14.0, -79.0), (-72.7, -98.4),
]


def _mirrored(points):
    return tuple((float(-x), float(y)) for x, y in points)


# The expected (path, code) pairs of each bad file, written down by hand.
EXPECTED = {
    "pricking_too_few_points.toml": {("trajectory.points", "out_of_range")},
    "pricking_pair_of_three.toml": {("trajectory.points.3", "wrong_type")},
    "pricking_string_in_pair.toml": {("trajectory.points.5", "wrong_type")},
    "pricking_nan_point.toml": {("trajectory.points.4", "not_finite")},
    "pricking_degree_4.toml": {("trajectory.degree", "not_allowed")},
    "pricking_split_exponent_typo.toml": {("gears.split_exponent", "not_allowed")},
    "pricking_split_exponent_range.toml": {("gears.split_exponent", "out_of_range")},
    "pricking_empty_inclinations.toml": {("field.inclinations_deg", "empty")},
    "pricking_duplicate_inclinations.toml": {
        ("field.inclinations_deg.2", "duplicate"),
        ("field.inclinations_deg.3", "duplicate"),
    },
    "pricking_inclination_90.toml": {("field.inclinations_deg.1", "out_of_range")},
    "pricking_missing_forward_speed.toml": {("field.forward_speed", "missing")},
    "pricking_typo_key.toml": {("linkage.roker", "unknown_key"), ("linkage.rocker", "missing")},
    "pricking_several_tables.toml": {
        ("name", "invalid_name"),
        ("trajectory.points", "out_of_range"),
        ("trajectory.points.1", "wrong_type"),
        ("trajectory.degree", "wrong_type"),
        ("trajectory.sun_centre", "wrong_type"),
        ("linkage.rocker", "out_of_range"),
        ("linkage.centre_distance", "not_finite"),
        ("gears.split_exponent", "out_of_range"),
        ("gears.module", "wrong_type"),
        ("gears.pressure_angle_deg", "out_of_range"),
        ("field.carrier_speed_rpm", "out_of_range"),
        ("field.depht", "unknown_key"),
        ("field.depth", "missing"),
        ("field.inclinations_deg.1", "out_of_range"),
        ("resolution.inverse_grid", "out_of_range"),
        ("targets", "unknown_key"),
    },
}

# A short valid pricking file (kernel-a's points, every optional key left out).
MINIMAL = """\
mechanism = "pricking"
name = "kernel-a"

[trajectory]
points = [[120.0, -135.0], [110.0, -180.0], [80.0, -215.0], [45.0, -255.0], [-5.0, -288.0],
          [-60.0, -262.0], [-95.0, -215.0], [-125.0, -160.0], [-125.0, -110.0], [-85.0, -78.0],
          [-10.0, -70.0], [75.0, -92.0]]
degree = 3

[linkage]
rocker = 45.0

[field]
forward_speed = 500.0
depth = 70.0
inclinations_deg = [6.5, 20.0, 33.5]
"""

# Kernel-a's first five points, for files that set the points themselves.
FIVE = "[120.0, -135.0], [110.0, -180.0], [80.0, -215.0], [45.0, -255.0], [-5.0, -288.0]"


def _problems(path_or_text, **kwargs) -> list[Problem]:
    with pytest.raises(ParameterError) as caught:
        if isinstance(path_or_text, Path):
            load_params(path_or_text, **kwargs)
        else:
            validate_text(path_or_text, "test.toml", **kwargs)
    return caught.value.problems


def _pairs(problems) -> set[tuple[str, str]]:
    return {(p.path, p.code) for p in problems}


def _with(text: str, key: str, value: str) -> str:
    """``text`` with the one ``key = value`` line (possibly a multi-line array) replaced."""
    pattern = rf"(?m)^{re.escape(key)}\s*=\s*(\[[^=]*?\]\]?|[^\n]*)$"
    new, count = re.subn(pattern, lambda _: f"{key} = {value}", text, count=0)
    assert count == 1, f"key {key!r} found {count} times"
    return new


def _added(text: str, table: str, line: str) -> str:
    """``text`` with ``line`` added at the top of ``[table]`` (the table is created if absent)."""
    header = f"[{table}]\n"
    if header in text:
        return text.replace(header, header + line + "\n", 1)
    return text + f"\n{header}{line}\n"


def _minimal_with(key: str, value: str) -> str:
    return _with(MINIMAL, key, value)


# --------------------------------------------------------------------------- the example files


def test_kernel_a_loads_with_the_spec_values():
    params = load_params(KERNEL_A)
    assert isinstance(params, PrickingParameters)
    assert params.mechanism == "pricking" and params.name == "kernel-a"
    trajectory = params.trajectory
    assert isinstance(trajectory, TrajectoryParameters)
    assert trajectory.points == _mirrored(SPEC_KERNEL_A)
    assert trajectory.points[0] == (120.0, -135.0)  # the spec's (-120, -135), mirrored
    assert trajectory.degree == 3
    assert trajectory.sun_centre == (0.0, 0.0)
    assert isinstance(params.linkage, LinkageParameters)
    assert params.linkage.rocker == 45.0
    assert params.linkage.centre_distance is None and params.linkage.tip_reach is None
    gears = params.gears
    assert isinstance(gears, GearParameters)
    assert gears.split_exponent == EQUAL_PERIMETER == "equal-perimeter"
    assert (gears.module, gears.pressure_angle_deg, gears.addendum, gears.min_ratio) == (
        2.0, 20.0, 1.0, 0.05)
    assert math.isclose(gears.pressure_angle_rad, math.radians(20.0))
    field = params.field
    assert isinstance(field, PrickingFieldParameters)
    assert (field.carrier_speed_rpm, field.forward_speed, field.depth) == (75.0, 530.0, 70.0)
    assert field.inclinations_deg == (6.5, 20.0, 33.5)
    assert field.inclinations_rad == pytest.approx(tuple(map(math.radians, (6.5, 20.0, 33.5))))
    assert isinstance(params.resolution, PrickingResolutionParameters)
    assert params.resolution.inverse_grid == 720


def test_kernel_b_loads_with_the_spec_values():
    params = load_params(KERNEL_B)
    assert isinstance(params, PrickingParameters) and params.name == "kernel-b"
    assert params.trajectory.points == _mirrored(SPEC_KERNEL_B)
    assert params.trajectory.points[4] == (-8.6, -290.1)  # the spec's Q5 (8.6, -290.1), mirrored
    assert params.trajectory.degree == 5
    assert params.trajectory.sun_centre == (0.0, 0.0)
    assert params.linkage.rocker == 45.0
    assert params.field.carrier_speed_rpm == 75.0
    assert params.field.forward_speed == 600.0 and params.field.depth == 70.0
    assert params.field.inclinations_deg == (6.5, 20.0, 33.5)


def test_the_two_examples_differ_only_in_name_points_degree_and_speed():
    a, b = load_params(KERNEL_A), load_params(KERNEL_B)
    same = {"mechanism", "linkage", "gears", "field", "resolution", "housing", "ground", "solids",
            "machine", "manufacturing", "dynamics", "scene"}
    # forward speeds differ: each is set so its tip is nearly still over the ground at the bottom
    assert (a.field.forward_speed, b.field.forward_speed) == (530.0, 600.0)
    b = b.model_copy(update={"field": b.field.model_copy(update={"forward_speed": 530.0})})
    assert all(getattr(a, key) == getattr(b, key) for key in same)
    assert a.trajectory.sun_centre == b.trajectory.sun_centre
    assert set(PrickingParameters.model_fields) == same | {"name", "trajectory"}


@pytest.mark.parametrize("path", [KERNEL_A, KERNEL_B], ids=lambda p: p.stem)
def test_example_comments_name_every_quantity(path):
    text = path.read_text(encoding="utf-8")
    checked = 0
    for line in text.splitlines():
        stripped = line.strip()
        if not stripped or stripped.startswith("#") or stripped == "]":
            continue
        if re.fullmatch(r"\[\w+\]", stripped):  # a table header
            continue
        assert "#" in stripped, line  # key = value lines and the point lines
        checked += 1
    # top level 2; [trajectory] 15 (points = [, 12 points, degree, sun_centre); [linkage] 1;
    # [gears] 7; [field] 4; [resolution] 1; [machine] 9 (the tooth safety limits and the gears'
    # material too); [manufacturing] 2
    assert checked == 2 + 15 + 1 + 7 + 4 + 1 + 9 + 2
    assert "mirror" in text.lower()  # the header says the spec's points are mirrored in x
    assert "assumed" in text  # the forward speed is an assumption, not the paper's


def test_cli_validates_the_examples():
    result = subprocess.run(
        [sys.executable, "-m", "cadgen", "validate",
         "params/kernel-a.toml", "params/kernel-b.toml"],
        cwd=ROOT, capture_output=True, text=True, timeout=120,
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert result.stdout.splitlines() == ["params/kernel-a.toml: ok", "params/kernel-b.toml: ok"]


def test_cli_reports_a_bad_pricking_file():
    bad = INVALID / "pricking_degree_4.toml"
    result = subprocess.run(
        [sys.executable, "-m", "cadgen", "validate", str(KERNEL_A), str(bad)],
        cwd=ROOT, capture_output=True, text=True, timeout=120,
    )
    assert result.returncode != 0
    lines = result.stdout.splitlines()
    assert lines[0] == f"{KERNEL_A}: ok"
    assert lines[1].startswith(f"{bad}: trajectory.degree: ") and "[not_allowed]" in lines[1]


# --------------------------------------------------------------------------- bad files


def test_every_invalid_pricking_file_has_an_expectation():
    assert sorted(p.name for p in INVALID.glob("*.toml")) == sorted(EXPECTED)


@pytest.mark.parametrize("name", sorted(EXPECTED), ids=lambda n: n.removesuffix(".toml"))
def test_invalid_file_reports_exactly_the_expected_problems(name):
    problems = _problems(INVALID / name)
    assert _pairs(problems) == EXPECTED[name]
    assert len(problems) == len(EXPECTED[name])  # no problem reported twice
    for problem in problems:
        assert problem.message and "Input should" not in problem.message


def test_messages_name_the_bad_value():
    by_path = {p.path: p.message for p in _problems(INVALID / "pricking_several_tables.toml")}
    assert "points has 4 items" in by_path["trajectory.points"]
    assert "at least 5" in by_path["trajectory.points"]
    assert "points[1]" in by_path["trajectory.points.1"]
    assert "boolean true" in by_path["trajectory.points.1"]
    assert "without a decimal point" in by_path["trajectory.degree"]
    assert "-45.0" in by_path["linkage.rocker"]
    assert "did you mean 'depth'?" in by_path["field.depht"]
    assert "inclinations_deg[1] = -1.0" in by_path["field.inclinations_deg.1"]
    (three,) = _problems(INVALID / "pricking_pair_of_three.toml")
    assert "points[3]" in three.message and "3 items" in three.message
    (text,) = _problems(INVALID / "pricking_string_in_pair.toml")
    assert '"-262.0"' in text.message and "without quotes" in text.message
    (nan,) = _problems(INVALID / "pricking_nan_point.toml")
    assert "nan" in nan.message
    (degree,) = _problems(INVALID / "pricking_degree_4.toml")
    assert "degree = 4" in degree.message and "3 or 5" in degree.message
    (typo,) = _problems(INVALID / "pricking_split_exponent_typo.toml")
    assert '"equal"' in typo.message and 'did you mean "equal-perimeter"?' in typo.message
    (high,) = _problems(INVALID / "pricking_split_exponent_range.toml")
    assert "9.0" in high.message and "0 to 4" in high.message
    typo_key = _problems(INVALID / "pricking_typo_key.toml")
    (roker,) = [p for p in typo_key if p.code == "unknown_key"]
    assert "did you mean 'rocker'?" in roker.message
    duplicates = _problems(INVALID / "pricking_duplicate_inclinations.toml")
    assert "give each inclination once" in duplicates[0].message


def test_every_bad_point_is_reported_once_at_its_index():
    points = ('[[1, 2], [true, 2], [1.0], "x", [nan, 1.0], [1, 2], [inf, "y"], [3, 4, 5, 6], '
              '[0, -inf]]')
    problems = _problems(_minimal_with("points", points))
    assert sorted((p.path, p.code) for p in problems) == [
        ("trajectory.points.1", "wrong_type"),
        ("trajectory.points.2", "wrong_type"),
        ("trajectory.points.3", "wrong_type"),
        ("trajectory.points.4", "not_finite"),
        ("trajectory.points.6", "wrong_type"),  # a string beats a non-finite number
        ("trajectory.points.7", "wrong_type"),
        ("trajectory.points.8", "not_finite"),
    ]


@pytest.mark.parametrize("value", ["[-1.0]", "[nan]", "[90.0]"])
def test_a_single_bad_item_is_not_also_reported_as_empty(value):
    # pydantic counts only the items that passed; the array itself was not empty.
    problems = _problems(_minimal_with("inclinations_deg", value))
    assert _pairs(problems) == {("field.inclinations_deg.0", problems[0].code)}
    assert problems[0].code in {"out_of_range", "not_finite"}


def test_a_single_bad_plant_spacing_is_not_also_reported_as_empty():
    # The same fix in the shared mapper, seen from the planting schema.
    text = (ROOT / "params" / "xin2024-planter.toml").read_text(encoding="utf-8")
    text = text.replace("[150.0, 185.0, 200.0]", "[-150.0]")
    assert _pairs(_problems(text, check_feasibility=False)) == {
        ("field.plant_spacings.0", "out_of_range")
    }


def test_too_few_points_and_a_bad_pair_are_both_reported():
    problems = _problems(_minimal_with("points", "[[0, 1], [1, 0], [0, nan]]"))
    assert _pairs(problems) == {
        ("trajectory.points", "out_of_range"),
        ("trajectory.points.2", "not_finite"),
    }


@pytest.mark.parametrize(
    ("key", "value", "path", "code"),
    [
        ("points", "[]", "trajectory.points", "out_of_range"),
        ("points", '"Q1..Q12"', "trajectory.points", "wrong_type"),
        ("points", "12", "trajectory.points", "wrong_type"),
        ("points", f"[{FIVE}, [1, 1" + "0" * 400 + "]]", "trajectory.points.5", "out_of_range"),
        ("degree", "3.0", "trajectory.degree", "wrong_type"),
        ("degree", "true", "trajectory.degree", "wrong_type"),
        ("degree", '"3"', "trajectory.degree", "wrong_type"),
        ("degree", "1", "trajectory.degree", "not_allowed"),
        ("degree", "7", "trajectory.degree", "not_allowed"),
        ("rocker", "0", "linkage.rocker", "out_of_range"),
        ("rocker", "nan", "linkage.rocker", "not_finite"),
        ("forward_speed", "-500.0", "field.forward_speed", "out_of_range"),
        ("depth", '"70"', "field.depth", "wrong_type"),
        ("inclinations_deg", "[6.5, 80]", "field.inclinations_deg.1", "out_of_range"),
        ("inclinations_deg", "[-0.5]", "field.inclinations_deg.0", "out_of_range"),
        ("inclinations_deg", '[6.5, "20"]', "field.inclinations_deg.1", "wrong_type"),
        ("inclinations_deg", "20.0", "field.inclinations_deg", "wrong_type"),
        ("inclinations_deg", "[nan]", "field.inclinations_deg.0", "not_finite"),
        ("name", '"kernel/a"', "name", "invalid_name"),
        ("name", '""', "name", "invalid_name"),
    ],
    ids=["no-points", "points-string", "points-number", "huge-int-in-point",
         "degree-float", "degree-bool", "degree-string", "degree-1", "degree-7", "rocker-zero",
         "rocker-nan", "negative-speed", "depth-string", "inclination-80",
         "negative-inclination", "inclination-string", "inclinations-scalar",
         "inclination-nan", "name-slash", "name-empty"],
)
def test_single_problem_cases(key, value, path, code):
    problems = _problems(_minimal_with(key, value))
    assert [(p.path, p.code) for p in problems] == [(path, code)]


@pytest.mark.parametrize(
    ("table", "line", "path", "code"),
    [
        ("trajectory", "sun_centre = [0.0, 0.0, 0.0]", "trajectory.sun_centre", "wrong_type"),
        ("trajectory", "sun_centre = [nan, 0.0]", "trajectory.sun_centre", "not_finite"),
        ("trajectory", 'sun_centre = ["0", 0]', "trajectory.sun_centre", "wrong_type"),
        ("trajectory", "sun_centre = 0.0", "trajectory.sun_centre", "wrong_type"),
        ("trajectory", "sun_center = [0.0, 0.0]", "trajectory.sun_center", "unknown_key"),
        ("linkage", "centre_distance = -55.0", "linkage.centre_distance", "out_of_range"),
        ("linkage", 'tip_reach = "180"', "linkage.tip_reach", "wrong_type"),
        ("linkage", "l2 = 175.0", "linkage.l2", "unknown_key"),
        ("gears", 'split_exponent = "2"', "gears.split_exponent", "wrong_type"),
        ("gears", "split_exponent = true", "gears.split_exponent", "wrong_type"),
        ("gears", "split_exponent = [1.0]", "gears.split_exponent", "wrong_type"),
        ("gears", "split_exponent = nan", "gears.split_exponent", "not_finite"),
        ("gears", "split_exponent = -0.5", "gears.split_exponent", "out_of_range"),
        ("gears", "split_exponent = 4.000001", "gears.split_exponent", "out_of_range"),
        ("gears", 'split_exponent = "Equal-Perimeter"', "gears.split_exponent", "not_allowed"),
        ("gears", "module = 0", "gears.module", "out_of_range"),
        ("gears", "pressure_angle_deg = 0", "gears.pressure_angle_deg", "out_of_range"),
        ("gears", "addendum = -1.0", "gears.addendum", "out_of_range"),
        ("gears", "min_ratio = 0.0", "gears.min_ratio", "out_of_range"),
        ("gears", "max_scale_change = 0.0", "gears.max_scale_change", "out_of_range"),
        ("gears", "max_scale_change = 0.8", "gears.max_scale_change", "out_of_range"),
        ("gears", "teeth = 30", "gears.teeth", "unknown_key"),
        ("field", "carrier_speed_rpm = -75", "field.carrier_speed_rpm", "out_of_range"),
        ("field", "plant_spacings = [150.0]", "field.plant_spacings", "unknown_key"),
        ("resolution", "inverse_grid = 35", "resolution.inverse_grid", "out_of_range"),
        ("resolution", "inverse_grid = 100001", "resolution.inverse_grid", "out_of_range"),
        ("resolution", "inverse_grid = 720.0", "resolution.inverse_grid", "wrong_type"),
        ("resolution", "steps_per_revolution = 3600", "resolution.steps_per_revolution",
         "unknown_key"),
    ],
    ids=lambda v: v if isinstance(v, str) and "=" in v else None,
)
def test_single_problem_cases_in_optional_keys(table, line, path, code):
    problems = _problems(_added(MINIMAL, table, line))
    assert [(p.path, p.code) for p in problems] == [(path, code)]


def test_planting_tables_in_a_pricking_file_are_unknown():
    text = _added(MINIMAL, "pitch_curve", 'kind = "limacon"')
    text = _added(text, "planter", "L1 = 130.0")
    (pitch_curve, planter) = sorted(_problems(text), key=lambda p: p.path)
    assert (pitch_curve.path, pitch_curve.code) == ("pitch_curve", "unknown_key")
    assert (planter.path, planter.code) == ("planter", "unknown_key")
    assert "unknown table 'pitch_curve' at the top level" in pitch_curve.message


def test_missing_tables_and_keys():
    text = MINIMAL.split("[linkage]")[0].replace("degree = 3\n", "")  # no [linkage], [field]
    assert _pairs(_problems(text)) == {
        ("trajectory.degree", "missing"),
        ("linkage", "missing"),
        ("field", "missing"),
    }
    no_points = MINIMAL.replace(MINIMAL[MINIMAL.index("points"):MINIMAL.index("degree")], "")
    assert _pairs(_problems(no_points)) == {("trajectory.points", "missing")}


def test_unknown_mechanism_lists_both_kinds():
    assert MECHANISM_KINDS == ("planting", "pricking")
    (problem,) = _problems(_with(MINIMAL, "mechanism", '"prickling"'))
    assert (problem.path, problem.code) == ("mechanism", "unknown_mechanism")
    assert "'planting'" in problem.message and "'pricking'" in problem.message


# --------------------------------------------------------------------------- accepted values


def test_optional_keys_and_tables_take_the_defaults():
    params = validate_text(_with(MINIMAL, "forward_speed", "530.0"))
    example = load_params(KERNEL_A)
    # the example spells out every default, widens the gears for their keys and names their
    # steel (C45+N's flanks fall below S_H 1 at the design load)
    assert example.gears.face_width == 20.0
    assert (params.machine.gear_material, example.machine.gear_material) == (
        None, "steel 42CrMo4+QT")
    widened = params.gears.model_copy(update={"face_width": 20.0})
    steel = params.machine.model_copy(update={"gear_material": "steel 42CrMo4+QT"})
    assert params.model_copy(update={"gears": widened, "machine": steel}) == example


@pytest.mark.parametrize("value", ["0", "0.0", "2", "2.5", "4", "4.0"])
def test_split_exponent_numbers_are_accepted_as_floats(value):
    params = validate_text(_added(MINIMAL, "gears", f"split_exponent = {value}"))
    assert type(params.gears.split_exponent) is float
    assert params.gears.split_exponent == float(value)


@pytest.mark.parametrize("theta", ["0", "0.0", "79.9"])
def test_inclination_bounds(theta):
    # structure only: at 79.9 deg the 70 mm depth is 400 mm in the mechanism plane, deeper than
    # the loop, which the feasibility check reports (next test)
    params = validate_text(_minimal_with("inclinations_deg", f"[{theta}]"),
                           check_feasibility=False)
    assert params.field.inclinations_deg == (float(theta),)


def test_integers_are_accepted_for_floats_and_stored_as_floats():
    text = _minimal_with("points",
                         "[[120, -135], [110, -180], [80, -215], [45, -255], [-5, -288]]")
    text = _with(text, "rocker", "45")
    text = _with(text, "inclinations_deg", "[20, 6]")
    text = _added(text, "trajectory", "sun_centre = [1, -2]")
    params = validate_text(text)
    assert params.trajectory.points == ((120.0, -135.0), (110.0, -180.0), (80.0, -215.0),
                                        (45.0, -255.0), (-5.0, -288.0))
    assert all(type(c) is float for point in params.trajectory.points for c in point)
    assert params.trajectory.sun_centre == (1.0, -2.0)
    assert all(type(c) is float for c in params.trajectory.sun_centre)
    assert type(params.linkage.rocker) is float
    assert params.field.inclinations_deg == (20.0, 6.0)  # order kept, not sorted


def test_steep_inclination_deeper_than_the_loop_is_infeasible():
    with pytest.raises(ParameterError) as caught:
        validate_text(_minimal_with("inclinations_deg", "[79.9]"))
    assert _pairs(caught.value.problems) == {("field.depth", "no_soil_crossing")}


def test_exactly_five_points_and_degree_5_pass_the_schema_but_not_the_curve():
    text = _with(_minimal_with("points", f"[{FIVE}]"), "degree", "5")
    params = validate_text(text, check_feasibility=False)
    assert len(params.trajectory.points) == 5 and params.trajectory.degree == 5
    with pytest.raises(ParameterError) as caught:  # a quintic closed curve needs 7 points
        validate_text(text)
    assert _pairs(caught.value.problems) == {("trajectory.points", "too_few_points")}


def test_expert_overrides_of_the_link_lengths():
    text = _added(MINIMAL, "linkage", "centre_distance = 55\ntip_reach = 180.5")
    linkage = validate_text(text, check_feasibility=False).linkage
    assert (linkage.rocker, linkage.centre_distance, linkage.tip_reach) == (45.0, 55.0, 180.5)
    assert type(linkage.centre_distance) is float


def test_geometry_of_the_points_is_not_judged_here():
    # Repeated points and a loop around O are the kinematic model's to report.
    points = "[[0, 0], [0, 0], [10, 0], [10, 10], [0, 10], [0, 0]]"
    params = validate_text(_minimal_with("points", points), check_feasibility=False)
    assert params.trajectory.points[0] == params.trajectory.points[1] == (0.0, 0.0)


def test_parameters_are_frozen_and_hashable():
    params = load_params(KERNEL_A)
    with pytest.raises(pydantic.ValidationError):
        params.linkage.rocker = 50.0
    with pytest.raises(pydantic.ValidationError):
        params.trajectory.points = ()
    assert isinstance(params.trajectory.points, tuple)
    assert all(isinstance(point, tuple) for point in params.trajectory.points)
    assert hash(params) == hash(load_params(KERNEL_A))
    assert params != load_params(KERNEL_B)


def test_validate_data_returns_pricking_parameters():
    data = {
        "mechanism": "pricking", "name": "from-python",
        "trajectory": {"points": [[1, 0], [0, 1], [-1, 0], [0, -1], [0.5, 0.5]], "degree": 5},
        "linkage": {"rocker": 45.0},
        "field": {"forward_speed": 500.0, "depth": 70.0, "inclinations_deg": [20.0]},
    }
    params = validate_data(data, check_feasibility=False)
    assert isinstance(params, PrickingParameters)
    assert params.trajectory.points[4] == (0.5, 0.5)


# The feasibility hook is tested for both mechanism kinds in tests/test_params.py.
