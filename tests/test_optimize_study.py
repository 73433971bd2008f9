"""Study files of ``cadgen optimize`` (cadgen.optimize.study): loading, and every problem at
once, each at its field, exit 2 with nothing written."""

from __future__ import annotations

from pathlib import Path

import pytest

from cadgen.cli import main
from cadgen.optimize.study import DEFAULT_EVALUATIONS, StudyError, load_study

from tests.helpers import REFERENCE, edited

ROOT = Path(__file__).resolve().parents[1]
STUDIES = ROOT / "params" / "studies"
KERNEL_A = ROOT / "params" / "kernel-a.toml"


def write_study(folder: Path, body: str, *, base: str | None = None) -> Path:
    """A study in ``folder/studies/``; its base, the reference file copied, is ``../base.toml``."""
    (folder / "studies").mkdir(parents=True, exist_ok=True)
    if not (folder / "base.toml").exists():
        (folder / "base.toml").write_text(REFERENCE.read_text(encoding="utf-8"), encoding="utf-8")
    head = f'base = "{base if base is not None else "../base.toml"}"\n' if base != "" else ""
    path = folder / "studies" / "study.toml"
    path.write_text(head + body, encoding="utf-8")
    return path


GOOD = """name = "good"
[free]
"planter.L2" = [150.0, 230.0]
pitch_curve.b1 = [24, 31]
[objectives]
maximize = ["min_margin"]
minimize = "hole_width@185"
[budget]
evaluations = 500
seed = 7
"""


def problems_of(path: Path) -> dict:
    with pytest.raises(StudyError) as caught:
        load_study(path)
    return {p.path: p for p in caught.value.problems}


def test_a_good_study_loads_with_its_base_resolved_against_the_study_file(tmp_path):
    study = load_study(write_study(tmp_path, GOOD))
    assert study.base_path == (tmp_path / "base.toml").resolve()
    assert study.kind == "planting" and study.name == "good"
    # bare TOML dotted keys and quoted ones read the same; integers are bounds too
    assert study.free == (("planter.L2", 150.0, 230.0), ("pitch_curve.b1", 24.0, 31.0))
    assert study.objectives == (("min_margin", "max"), ("hole_width@185", "min"))
    assert (study.evaluations, study.seed) == (500, 7)
    assert study.base_params.planter.L2 == 190.0


def test_defaults_and_the_command_lines_budget(tmp_path):
    study = load_study(write_study(tmp_path, '[free]\n"planter.L2" = [150.0, 230.0]\n'
                                             '[objectives]\nmaximize = ["min_margin"]\n'))
    assert study.name == "xin2024-planter"             # the base design's name
    assert study.evaluations == DEFAULT_EVALUATIONS
    assert study.with_budget(evaluations=40, seed=3).evaluations == 40
    with pytest.raises(StudyError) as caught:
        study.with_budget(evaluations=0, seed=-1)
    assert {p.path for p in caught.value.problems} == {"--evaluations", "--seed"}


def test_the_bundled_studies_load():
    for path in sorted(STUDIES.glob("*.toml")):
        study = load_study(path)
        assert study.evaluations >= 1 and study.objectives, path


#: (study body, field, code, words in the message): one problem each
BAD = [
    ('[free]\n"planter.L9" = [1.0, 2.0]\n[objectives]\nmaximize = ["min_margin"]\n',
     'free."planter.L9"', "unknown_key", ["planter.L9", "did you mean 'planter.L2'"]),
    ('[free]\n"planter.L2" = [230.0, 150.0]\n[objectives]\nmaximize = ["min_margin"]\n',
     'free."planter.L2"', "reversed", ["[230.0, 150.0]", "[150.0, 230.0]"]),
    ('[free]\n"planter.L2" = [-20.0, 150.0]\n[objectives]\nmaximize = ["min_margin"]\n',
     'free."planter.L2"', "out_of_range", ["bound low -20", "planter.L2"]),
    ('[free]\n"targets.angle_difference_max_deg" = [10.0, 200.0]\n'
     '[objectives]\nmaximize = ["min_margin"]\n',
     'free."targets.angle_difference_max_deg"', "out_of_range", ["bound high 200"]),
    ('[free]\n"planter.L2" = [150.0, 230.0]\n[objectives]\nmaximize = ["min_margins"]\n',
     "objectives.maximize[0]", "unknown_objective", ['"min_margins"', "min_margin"]),
    ('[free]\n"pitch_curve.teeth" = [30, 40]\n[objectives]\nmaximize = ["min_margin"]\n',
     'free."pitch_curve.teeth"', "not_allowed", ["whole number"]),
    ('[free]\n"pitch_curve.e2" = [0.5, 1.5]\n[objectives]\nmaximize = ["min_margin"]\n',
     'free."pitch_curve.e2"', "not_supported", ["planting screen", "planter.L2"]),
    ('[free]\n"planter.L2" = [150.0, "230"]\n[objectives]\nmaximize = ["min_margin"]\n',
     'free."planter.L2"', "wrong_type", ['"230"']),
    ('[free]\n"planter.L2" = [150.0, 230.0]\n[objectives]\nmaximize = ["min_margin"]\n'
     '[budget]\nevaluations = 0\n', "budget.evaluations", "out_of_range", ["not 0"]),
    ('[free]\n"planter.L2" = [150.0, 230.0]\n[objectives]\nmaximize = ["min_margin"]\n'
     '[budget]\nseed = "one"\n', "budget.seed", "wrong_type", ['"one"']),
    ('[free]\n"planter.L2" = [150.0, 230.0]\n', "objectives", "missing", ["[objectives]"]),
    ('[free]\n"planter.L2" = [150.0, 230.0]\n[objectives]\nmaximize = ["min_margin"]\n'
     'algorithm = "GA"\n', "objectives.algorithm", "unknown_key", ["maximize, minimize"]),
    ('[free]\n"planter.L2" = [150.0, 230.0]\n[objectives]\nmaximize = ["min_margin"]\n'
     '[precision]\n"planter.L1" = 0.5\n', 'precision."planter.L1"', "unknown_key",
     ["not a free path", "planter.L2"]),
    ('[free]\n"planter.L2" = [150.0, 230.0]\n[objectives]\nmaximize = ["min_margin"]\n'
     '[precision]\n"planter.L2" = 80.0\n', 'precision."planter.L2"', "out_of_range",
     ["below its range (80)", "not 80.0"]),
    ('[free]\n"planter.L2" = [150.0, 230.0]\n[objectives]\nmaximize = ["min_margin"]\n'
     '[precision]\n"planter.L2" = "0.5"\n', 'precision."planter.L2"', "wrong_type", ['"0.5"']),
]


@pytest.mark.parametrize("body, field, code, words", BAD,
                         ids=[f"{b[1]}-{b[2]}" for b in BAD])
def test_a_bad_study_names_its_field(tmp_path, body, field, code, words):
    found = problems_of(write_study(tmp_path, body))
    assert list(found) == [field], found
    assert found[field].code == code
    for word in words:
        assert word in found[field].message, found[field].message


def test_a_missing_base_is_a_problem_of_base(tmp_path):
    found = problems_of(write_study(tmp_path, GOOD, base="../nowhere.toml"))
    assert found["base"].code == "file_not_found"
    assert "nowhere.toml" in found["base"].message
    found = problems_of(write_study(tmp_path / "b", GOOD, base=""))
    assert found["base"].code == "missing"


def test_an_invalid_base_lists_its_own_problems(tmp_path):
    (tmp_path / "base.toml").write_text(edited(L2="-5.0"), encoding="utf-8")
    found = problems_of(write_study(tmp_path, GOOD))
    assert found["base"].code == "out_of_range" and "planter.L2" in found["base"].message


EVERY_PROBLEM = """name = "bad name!"
colour = "red"
[free]
"planter.L9" = [1.0, 2.0]
"planter.L2" = [230.0, 150.0]
"train.R" = [-1.0, 40.0]
"pitch_curve.b1" = ["a", 31.0]
[objectives]
maximize = ["min_margin", "height"]
minimize = [3]
[budget]
evaluations = 2.5
seed = -1
"""


def test_every_problem_at_once_exit_2_and_nothing_written(tmp_path, capsys):
    path = write_study(tmp_path, EVERY_PROBLEM)
    found = problems_of(path)
    assert set(found) == {"name", "colour", 'free."planter.L9"', 'free."planter.L2"',
                          'free."train.R"', 'free."pitch_curve.b1"', "objectives.maximize[1]",
                          "objectives.minimize[0]", "budget.evaluations", "budget.seed"}
    out = tmp_path / "out"
    assert main(["optimize", str(path), "--output-dir", str(out)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == len(found)
    assert all(line.startswith(f"{path}: ") for line in err)
    assert not out.exists() or not any(out.iterdir())


def test_pricking_studies_move_the_points_within_a_box(tmp_path):
    study_path = tmp_path / "pricking.toml"
    study_path.write_text(f'base = "{KERNEL_A}"\n[free]\n"trajectory.points" = '
                          '{ box = 3.0, points = [3, 4] }\n[objectives]\n'
                          'maximize = ["convexity"]\n', encoding="utf-8")
    study = load_study(study_path)
    assert study.kind == "pricking" and study.free == {"box": 3.0, "points": [3, 4]}
    count = len(study.base_params.trajectory.points)
    study_path.write_text(f'base = "{KERNEL_A}"\n[free]\n"trajectory.points" = '
                          f'{{ box = -1, points = [0, {count + 1}, 2, 2] }}\n"linkage.rocker" = '
                          '[1.0, 2.0]\n[objectives]\nmaximize = ["convexity", "speed"]\n',
                          encoding="utf-8")
    found = problems_of(study_path)
    assert set(found) == {'free."trajectory.points".box', 'free."trajectory.points".points[0]',
                          'free."trajectory.points".points[1]',
                          'free."trajectory.points".points[3]', 'free."linkage.rocker"',
                          "objectives.maximize[1]"}
    assert found['free."trajectory.points".points[3]'].code == "duplicate"


def test_rounding_steps_by_unit_unless_the_study_gives_one(tmp_path):
    body = GOOD.replace('[free]\n', '[free]\n"pitch_curve.e1" = [2.5, 2.8]\n'
                        '"pitch_curve.f1_rad" = [8.4, 8.7]\n"train.phi0_deg" = [80.0, 100.0]\n')
    study = load_study(write_study(tmp_path, body + '[precision]\n"planter.L2" = 0.5\n'))
    assert study.steps == {"planter.L2": 0.5, "pitch_curve.b1": 0.01, "pitch_curve.e1": 1e-4,
                           "pitch_curve.f1_rad": 1e-4, "train.phi0_deg": 0.01}
    kernel = STUDIES / "kernel-a-convex.toml"
    assert load_study(kernel).steps == {"trajectory.points": 0.01}
