"""``gears.profile_shift``: its syntax, the V-zero rule, every problem at once with its path.

Expected values are written out here: the mates' shifts a V-zero chain gives, the shifted spur
gear's tip thickness (textbook closed form) that decides a pointed tooth.
"""

from __future__ import annotations

import math
import re

import pytest

from cadgen.params import ParameterError, validate_text
from cadgen.params.cutting import PLANTING_MESHES, PRICKING_MESHES
from tests.helpers import REFERENCE, edited, with_keys

KERNEL_B = REFERENCE.parent / "kernel-b.toml"
ALPHA = math.radians(20.0)


def planting(shift: str, text: str | None = None, **gears) -> str:
    return with_keys(text or REFERENCE.read_text(encoding="utf-8"), "gears",
                     profile_shift=shift, **gears)


def problems_of(text: str, **options) -> list:
    with pytest.raises(ParameterError) as error:
        validate_text(text, **options)
    return [(p.path, p.code, p.message) for p in error.value.problems]


def test_one_gears_shift_gives_its_mate_the_opposite():
    params = validate_text(planting("{ intermediate = 0.2 }"))
    shifts = params.gears.profile_shift
    assert shifts.given() == {"intermediate": 0.2}
    assert shifts.resolved() == {"central": -0.2, "intermediate": 0.2, "gear_D": 0.0,
                                 "planet_gear_E": 0.0, "sun": 0.0, "idler_1": 0.0, "idler_2": 0.0,
                                 "train_1_planet": 0.0, "sun_I": 0.0, "idler_1_I": 0.0,
                                 "idler_2_I": 0.0, "planet_I": 0.0, "input_gear_1": 0.0,
                                 "central_shaft_gear": 0.0, "input_gear_2": 0.0,
                                 "transmission_driven_gear": 0.0}
    assert hash(params)                 # still frozen and hashable (cached kinematics)


def test_a_chain_of_meshes_alternates_the_sign():
    # train 1: sun - idler 1 - idler 2 - planet; any one of them sets all four
    shifts = validate_text(planting("{ idler_2 = 0.25 }"),
                           check_feasibility=False).gears.profile_shift.resolved()
    assert (shifts["sun"], shifts["idler_1"], shifts["idler_2"], shifts["train_1_planet"]) == \
        (0.25, -0.25, 0.25, -0.25)
    assert shifts["central"] == shifts["gear_D"] == 0.0


def test_the_keys_are_the_trains_gear_names():
    from cadgen.design import build_mechanism, pricking_design
    from cadgen.gears.trains import planting_train, pricking_train
    from cadgen.params import load_params

    def key(name):
        return name.replace(" ", "_").replace("-", "_")

    for path, meshes, build in ((REFERENCE, PLANTING_MESHES, None),
                                (KERNEL_B, PRICKING_MESHES, None)):
        params = load_params(path)
        train = (planting_train(params, build_mechanism(params)) if params.mechanism == "planting"
                 else pricking_train(params, pricking_design(params)))
        pairs = {tuple(key(n) for n in stage.generated.pair.names) for stage in train.stages}
        assert pairs == set(meshes)
        assert {key(p.name) for p, *_ in train.gears} == set(type(params.gears.profile_shift).model_fields)


def test_two_shifts_of_a_pair_that_do_not_sum_to_zero_are_refused_naming_the_pair():
    found = problems_of(planting("{ central = 0.1, intermediate = 0.3 }"))
    assert [(path, code) for path, code, _ in found] == [
        ("gears.profile_shift.intermediate", "profile_shift_changes_centre_distance")]
    assert "central - intermediate" in found[0][2]
    # opposite: accepted
    validate_text(planting("{ central = -0.2, intermediate = 0.2 }"))


def test_two_shifts_in_one_chain_must_alternate():
    found = problems_of(planting("{ sun = 0.3, idler_2 = 0.2 }"), check_feasibility=False)
    assert [(path, code) for path, code, _ in found] == [
        ("gears.profile_shift.idler_2", "profile_shift_changes_centre_distance")]
    assert "idler_1 - idler_2" in found[0][2] and "+0.3" in found[0][2]
    validate_text(planting("{ sun = 0.3, idler_2 = 0.3 }"), check_feasibility=False)


def test_every_problem_at_once_with_its_path():
    text = planting('{ intermediat = 0.3, sun = 0.9, idler_2 = "0.1", central = nan, '
                    'gear_D = 0.2, planet_gear_E = 0.1 }')
    found = {(path, code) for path, code, _ in problems_of(text, check_feasibility=False)}
    assert found == {("gears.profile_shift.intermediat", "unknown_key"),
                     ("gears.profile_shift.sun", "out_of_range"),
                     ("gears.profile_shift.idler_2", "wrong_type"),
                     ("gears.profile_shift.central", "not_finite"),
                     ("gears.profile_shift.planet_gear_E",
                      "profile_shift_changes_centre_distance")}
    message = dict(((p, c), m) for p, c, m in problems_of(text, check_feasibility=False))
    assert "did you mean 'intermediate'?" in message["gears.profile_shift.intermediat",
                                                     "unknown_key"]


def test_a_mate_pushed_out_of_range_is_refused_at_the_key_given():
    # the range is -0.5..0.8: 0.6 on one gear would give its mate -0.6
    found = problems_of(planting("{ intermediate = 0.6 }"), check_feasibility=False)
    assert [(path, code) for path, code, _ in found] == [
        ("gears.profile_shift.intermediate", "out_of_range")]
    assert "central -0.6" in found[0][2]


def test_the_pricking_mechanism_has_its_own_gears():
    text = KERNEL_B.read_text(encoding="utf-8")
    shifts = validate_text(with_keys(text, "gears", profile_shift="{ intermediate_1 = 0.1 }"),
                           check_feasibility=False).gears.profile_shift.resolved()
    assert shifts == {"sun": -0.1, "intermediate_1": 0.1, "intermediate_2": 0.0, "planet": 0.0}
    found = problems_of(with_keys(text, "gears", profile_shift="{ central = 0.1 }"),
                        check_feasibility=False)
    assert found[0][:2] == ("gears.profile_shift.central", "unknown_key")
    assert "sun, intermediate_1, intermediate_2, planet" in found[0][2]


def spur_tip_thickness(teeth, module, shift):
    """Textbook: the shifted spur gear's tooth thickness on its tip circle (mm)."""
    inv = lambda a: math.tan(a) - a
    radius = teeth * module / 2
    tip = radius + (1.0 + shift) * module
    thickness = module * (math.pi / 2 + 2 * shift * math.tan(ALPHA))
    return 2 * tip * (thickness / (2 * radius) + inv(ALPHA)
                      - inv(math.acos(radius * math.cos(ALPHA) / tip)))


def test_a_shift_that_points_a_circular_gears_teeth_is_refused():
    # circular module 5.4 mm: gear D (r = 27 mm) has 10 teeth
    assert spur_tip_thickness(10, 5.4, 0.5) < 0.25 * 5.4 < spur_tip_thickness(10, 5.4, 0.3)
    found = problems_of(planting("{ gear_D = 0.5 }", circular_module=5.4))
    assert [(path, code) for path, code, _ in found] == [
        ("gears.profile_shift.gear_D", "profile_shift_pointed")]
    # the mate's side too: its shift comes from gear D's opposite
    found = problems_of(planting("{ planet_gear_E = -0.5 }", circular_module=5.4))
    assert [(path, code) for path, code, _ in found] == [
        ("gears.profile_shift.planet_gear_E", "profile_shift_pointed")]
    largest = float(re.search(r"the largest shift that keeps 0.25 m is ([0-9.]+)",
                              found[0][2]).group(1))
    assert spur_tip_thickness(10, 5.4, largest) >= 0.25 * 5.4 > spur_tip_thickness(
        10, 5.4, largest + 0.02)
    validate_text(planting("{ gear_D = 0.3 }", circular_module=5.4))


def test_the_cut_teeth_refuse_a_shift_that_points_a_non_circular_gear():
    """The intermediate gear of the paper at +0.45: its cut teeth come to a point (measured;
    the 0.25 m rule), which fails the design with the shift's path named."""
    from cadgen.design import build_mechanism
    from cadgen.gears.trains import planting_train, train_report

    params = validate_text(planting("{ intermediate = 0.45 }"))
    report = train_report(planting_train(params, build_mechanism(params)))
    gear = next(g for g in report["gears"] if g["gear"] == "intermediate")
    assert gear["profile_shift"] == 0.45
    assert gear["tip_thickness_min_mm"] < 0.25 * gear["module_mm"]
    codes = {p["code"]: p for p in gear["problems"]}
    assert codes["profile_shift_pointed"]["severity"] == "failure"
    assert "gears.profile_shift.intermediate" in codes["profile_shift_pointed"]["message"]


def test_an_unshifted_file_is_the_file_without_the_table():
    plain = validate_text(edited(teeth=22), check_feasibility=False)
    zero = validate_text(planting("{ }"), check_feasibility=False)
    assert plain == zero and plain.gears.profile_shift.resolved() == dict.fromkeys(
        type(plain.gears.profile_shift).model_fields, 0.0)
