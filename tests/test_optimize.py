"""``cadgen optimize`` (cadgen.optimize): the search, its certification and its files.

The figures the tests compare with come from elsewhere: the exact evaluator
(``cadgen.evaluate``), ``cadgen.build`` on the written best.toml, the margins' one
definition (kinematics.margins) and the study file's own bounds.
"""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import cadgen
from cadgen.cli import main
from cadgen.optimize.outputs import write_outputs
from cadgen.optimize.problem import PopulationEvaluator, make_problem
from cadgen.optimize.progress import OptimizePrinter
from cadgen.optimize.run import optimize_study, population_size
from cadgen.optimize.study import load_study
from kinematics.margins import bounds_of, is_equality, margins, min_margin

from tests.helpers import REFERENCE, edited

ROOT = Path(__file__).resolve().parents[1]


def write_study(folder: Path, base_text: str, body: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "base.toml").write_text(base_text, encoding="utf-8")
    path = folder / "study.toml"
    path.write_text('base = "base.toml"\n' + body, encoding="utf-8")
    return path


def exact_min_margin(params) -> tuple[float, bool]:
    """(smallest normalised margin, every target met) of a design, by the exact evaluator.

    Computed here from the metrics and the margins' definition, not taken from the
    optimiser: a met ``= 1`` target (margin 0 at best) is left out, as the study's
    ``min_margin`` says.
    """
    from cadgen.design import targets_of

    evaluation = cadgen.evaluate(params)
    targets = targets_of(params)
    keys, normalised = [], []
    for metric in evaluation.metrics:
        key = metric.key if metric.spacing is None else f"{metric.key}@{metric.spacing:g}"
        margin, scale = margins(metric.value, *bounds_of(key, targets))
        keys.append(key)
        normalised.append(float(margin / scale))
    return float(min_margin(np.array(normalised), [is_equality(k) for k in keys])), \
        all(m.passed for m in evaluation.metrics)


def free_values(params, paths) -> list[float]:
    values = []
    for path in paths:
        node = params
        for part in path.split("."):
            node = getattr(node, part)
        values.append(float(node))
    return values


# --------------------------------------------------------------------------- evaluation


def test_chunks_over_processes_give_the_rows_of_one_call():
    study_path = ROOT / "params" / "studies" / "planter-margins.toml"
    problem = make_problem(load_study(study_path))
    rng = np.random.default_rng(5)
    X = problem.lower + rng.random((60, len(problem.lower))) * (problem.upper - problem.lower)
    whole = problem.evaluate(X)
    with PopulationEvaluator(problem, workers=2, min_chunk=7) as evaluator:
        chunked = evaluator(X)
    for key in ("F", "G", "valid"):
        np.testing.assert_array_equal(chunked[key], whole[key])
    assert set(chunked["values"]) == set(whole["values"])
    for key, column in whole["values"].items():
        np.testing.assert_array_equal(chunked["values"][key], column)


def test_population_never_exceeds_the_budget():
    assert [population_size(n) for n in (1, 5, 80, 500, 20000)] == [1, 5, 8, 50, 100]


# --------------------------------------------------------------------------- same seed


TWO_OBJECTIVES = """name = "two"
[free]
"planter.L2" = [150.0, 230.0]
"pitch_curve.b1" = [24.0, 31.0]
[objectives]
maximize = ["min_margin"]
minimize = ["hole_width@185"]
[budget]
evaluations = 600
seed = 4
"""


@pytest.fixture(scope="module")
def two_objective_runs(tmp_path_factory):
    """The same two-objective study four times, seed 4: twice on one worker, once on two
    local processes, once on a Dask cluster (in-process, two worker threads)."""
    from distributed import LocalCluster

    folder = tmp_path_factory.mktemp("two")
    study = load_study(write_study(folder, REFERENCE.read_text(encoding="utf-8"),
                                   TWO_OBJECTIVES))
    runs = {}
    for label, workers in (("first", 1), ("again", 1), ("two workers", 2)):
        result = optimize_study(study, workers=workers, max_certified=6)
        runs[label] = (result, write_outputs(result, folder / label))
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                      dashboard_address=None) as cluster:
        result = optimize_study(study, scheduler=cluster.scheduler_address, max_certified=6)
        runs["dask"] = (result, write_outputs(result, folder / "dask"))
    return study, runs


def test_same_seed_same_files_on_any_number_of_workers(two_objective_runs):
    _, runs = two_objective_runs
    first = runs["first"][1]
    assert runs["dask"][0].where.startswith("Dask scheduler ")
    for label in ("again", "two workers", "dask"):
        for name in ("best.toml", "pareto.csv"):
            assert (runs[label][1] / name).read_bytes() == (first / name).read_bytes(), \
                (label, name)


def test_several_objectives_give_a_certified_front(two_objective_runs):
    study, runs = two_objective_runs
    result, folder = runs["first"]
    assert result.algorithm == "NSGA-II" and result.evaluations == study.evaluations
    assert {p.name for p in folder.iterdir()} >= {"best.toml", "pareto.csv", "pareto.png",
                                                  "convergence.png", "optimize.html",
                                                  "optimize.json"}
    rows = (folder / "pareto.csv").read_text(encoding="utf-8").splitlines()
    assert len(rows) == 1 + len(result.finals) and 1 < len(result.finals) <= 6
    # no certified design dominates another by its exact objectives
    exact = np.array([[-f.exact["objectives"]["min_margin"],
                       f.exact["objectives"]["hole_width@185"]] for f in result.finals if f.passed])
    for a in exact:
        assert not np.any(np.all(exact <= a, axis=1) & np.any(exact < a, axis=1))


def test_one_objective_same_best_on_one_and_two_workers(tmp_path):
    study = load_study(write_study(tmp_path, REFERENCE.read_text(encoding="utf-8"),
                                   FAILING_STUDY.replace("1500", "400")))
    texts = []
    for workers in (1, 2):
        result = optimize_study(study, workers=workers, max_certified=2)
        texts.append((write_outputs(result, tmp_path / str(workers)) / "best.toml").read_bytes())
    assert result.algorithm.startswith("GA") and result.evaluations == 400
    assert texts[0] == texts[1]


# --------------------------------------------------------------------------- from a failing design


FAILING_STUDY = """name = "short-l2"
[free]
"planter.L2" = [60.0, 230.0]
"pitch_curve.b1" = [24.0, 31.0]
[objectives]
maximize = ["min_margin"]
[budget]
evaluations = 1500
seed = 1
"""


@pytest.fixture(scope="module")
def from_failing(tmp_path_factory):
    folder = tmp_path_factory.mktemp("failing")
    # the paper's design with the planter's lower link cut from 190 to 80 mm
    study_path = write_study(folder, edited(L2="80.0"), FAILING_STUDY)
    out = folder / "out"
    status = main(["optimize", str(study_path), "--output-dir", str(out), "--workers", "2"])
    return study_path, out / "short-l2", status


def test_the_base_design_really_misses_targets(from_failing):
    study_path, _, _ = from_failing
    evaluation = cadgen.evaluate(cadgen.load_params(study_path.parent / "base.toml"))
    missed = {(m.key, m.spacing) for m in evaluation.metrics if not m.passed}
    assert ("hole_width", 150.0) in missed


def test_from_a_failing_design_a_design_meeting_every_target(from_failing, tmp_path):
    study_path, folder, status = from_failing
    assert status == 0
    best = cadgen.load_params(folder / "best.toml")
    study = tomllib.loads(study_path.read_text(encoding="utf-8"))
    for path, value in zip(study["free"], free_values(best, study["free"])):
        low, high = study["free"][path]
        assert low <= value <= high, path
    # the exact evaluator, and a metrics build of the written file, both say every target holds
    _, passed = exact_min_margin(best)
    assert passed
    build = cadgen.build(best, output_root=tmp_path, effects=["metrics"])
    assert build.exit_code == 0
    report = json.loads((tmp_path / best.name / "report.json").read_text(encoding="utf-8"))
    assert report["metrics"] and all(m["passed"] for m in report["metrics"])
    # and the build's own checks beyond the targets: no stage refuses it, the duckbill cam
    # passes, and so does the drivetrain (shafts, keys, bearings) on the solved mechanism
    assert not cadgen.stage_problems(best)
    assert cadgen.build(best, output_root=None, effects=["metrics", "cam"]).exit_code == 0
    from cadgen.design import build_mechanism
    from cadgen.machine.drivetrain import drivetrain

    assert drivetrain(best, build_mechanism(best)).problems == ()


def test_best_toml_keeps_the_base_files_comments_and_names_the_study(from_failing):
    study_path, folder, _ = from_failing
    text = (folder / "best.toml").read_text(encoding="utf-8")
    assert text.startswith("# best.toml of the study 'short-l2' (study.toml)")
    assert "seed 1" in text.splitlines()[1]
    base = (study_path.parent / "base.toml").read_text(encoding="utf-8")
    lines = base.splitlines()
    first_key = next(k for k, line in enumerate(lines) if line and not line.startswith("#"))
    # the comments among the values are kept; the base's header (its description, "check it
    # with: cadgen validate <the base file>") is not: it is not true of this file
    kept = [line for line in lines[first_key:] if line.startswith("#")]
    assert kept and all(line in text for line in kept)
    assert not [line for line in lines[:first_key] if line.strip("# ") and line in text]


def test_best_toml_is_rounded_to_shop_precision_and_certified_as_written(from_failing):
    # every free length to 0.01 mm (the default step of a length), written that way, and the
    # exact evaluator of the file as written gives what optimize.json certified
    study_path, folder, _ = from_failing
    text = (folder / "best.toml").read_text(encoding="utf-8")
    best = cadgen.load_params(folder / "best.toml")
    study = tomllib.loads(study_path.read_text(encoding="utf-8"))
    data = json.loads((folder / "optimize.json").read_text(encoding="utf-8"))
    base = cadgen.load_params(study_path.parent / "base.toml")
    for path, value in zip(study["free"], free_values(best, study["free"])):
        assert round(value * 100) == pytest.approx(value * 100, abs=1e-9), (path, value)
        table, key = path.split(".")
        line = next(line for line in text.splitlines() if line.startswith(f"{key} "))
        written = line.split("=")[1].split("#")[0].strip()
        assert len(written.partition(".")[2]) <= 2, line
        old = getattr(getattr(base, table), key)
        if old != value:   # its comment says what it was
            assert f"(cadgen optimize; base.toml: {old:g})" in line, line
    assert f'name = "{best.name}"' in text and f"outputs/{best.name}/" in text
    evaluation = cadgen.evaluate(best)
    for metric in evaluation.metrics:
        key = metric.key if metric.spacing is None else f"{metric.key}@{metric.spacing:g}"
        certified = data["best"]["exact"]["values"].get(key)
        if certified is not None and metric.value is not None:
            assert metric.value == pytest.approx(certified, rel=1e-12, abs=1e-12), key


def test_the_report_gives_screened_exact_and_their_difference(from_failing):
    _, folder, _ = from_failing
    data = json.loads((folder / "optimize.json").read_text(encoding="utf-8"))
    assert data["found"] and data["exit_code"] == 0
    best = data["best"]
    for key, screened in best["screened"]["values"].items():
        exact = best["exact"]["values"][key]
        if screened is not None and exact is not None:
            assert best["differences"][key] == pytest.approx(exact - screened, abs=1e-12)
    page = (folder / "optimize.html").read_text(encoding="utf-8")
    assert "data:image/png;base64," in page and "A design meeting every target" in page
    assert data["base"]["exact"]["passed"] is False


# --------------------------------------------------------------------------- from the paper


PAPER_STUDY = """name = "paper-margins"
[free]
"planter.L1" = [120.0, 150.0]
"planter.L2" = [170.0, 230.0]
"pitch_curve.b1" = [24.0, 31.0]
[objectives]
maximize = ["min_margin"]
[budget]
evaluations = 1500
seed = 2
"""


def test_from_the_papers_design_a_larger_smallest_margin_then_built(tmp_path, capsys):
    study_path = write_study(tmp_path, REFERENCE.read_text(encoding="utf-8"), PAPER_STUDY)
    out = tmp_path / "out"
    status = main(["optimize", str(study_path), "--output-dir", str(out), "--build"])
    printed = capsys.readouterr().out
    paper, paper_passed = exact_min_margin(cadgen.load_params(REFERENCE))
    best, best_passed = exact_min_margin(
        cadgen.load_params(out / "paper-margins" / "best.toml"))
    with capsys.disabled():
        print(f"\nsmallest normalised margin: the paper's design {paper:.4f}, "
              f"the optimiser's {best:.4f}")
    assert paper_passed and best_passed
    assert best > paper
    # --build: the full build of best.toml (every effect), beside the study's folder, its
    # summary printed: it passes every target and every check (the search kept off the
    # designs whose drive a longer arm overloads: key pressure, a check no target names)
    report = json.loads((out / "paper-margins-best" / "report.json").read_text(encoding="utf-8"))
    assert "design paper-margins-best (planting mechanism): PASS" in printed
    assert report["passed"] and not report["failures"]
    assert status == 0


# --------------------------------------------------------------------------- none found


def test_impossible_targets_exit_1_with_the_least_violating_design(tmp_path, capsys):
    base = edited(trajectory_height_min="5000.0")
    study_path = write_study(tmp_path, base, FAILING_STUDY.replace("1500", "200"))
    status = main(["optimize", str(study_path), "--output-dir", str(tmp_path / "out")])
    captured = capsys.readouterr()
    assert status == 1
    folder = tmp_path / "out" / "short-l2"
    assert not (folder / "best.toml").exists()
    least = cadgen.load_params(folder / "least-violating.toml")
    assert not exact_min_margin(least)[1]
    data = json.loads((folder / "optimize.json").read_text(encoding="utf-8"))
    assert data["found"] is False and data["best"] is None
    assert "NOT FOUND" in captured.out
    assert "no feasible design yet: smallest constraint violation" in captured.err


def test_progress_lines_in_a_pipe(tmp_path):
    import io

    stream = io.StringIO()
    study = load_study(write_study(tmp_path, REFERENCE.read_text(encoding="utf-8"),
                                   FAILING_STUDY.replace("1500", "300")))
    with OptimizePrinter(stream, tty=False) as printer:
        optimize_study(study, progress=printer, max_certified=2)
    lines = stream.getvalue().splitlines()
    screen = [line for line in lines if "] screen [" in line]
    assert 2 <= len(screen) <= 11 and "300/300 evaluations" in screen[-1]
    assert "best feasible min_margin" in screen[-1]
    assert any("certify" in line for line in lines)


# --------------------------------------------------------------------------- command line


def test_help_names_every_option(capsys):
    with pytest.raises(SystemExit) as exited:
        main(["optimize", "--help"])
    assert exited.value.code == 0
    text = capsys.readouterr().out
    for option in ("--workers", "--scheduler", "--build", "--output-dir", "--evaluations",
                   "--seed", "best.toml", "Exit 0"):
        assert option in text


def test_an_unreachable_scheduler_is_one_line_exit_2(tmp_path, capsys, monkeypatch):
    import cadgen.optimize.problem as problem_module

    monkeypatch.setattr(problem_module, "CONNECT_TIMEOUT", 0.5)
    study_path = write_study(tmp_path, REFERENCE.read_text(encoding="utf-8"), FAILING_STUDY)
    out = tmp_path / "out"
    assert main(["optimize", str(study_path), "--scheduler", "tcp://127.0.0.1:9",
                 "--output-dir", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("cadgen optimize: cannot reach the Dask scheduler tcp://127.0.0.1:9")
    assert not out.exists()


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(-1e3, 1e3), min_size=1, max_size=6),
       st.sampled_from([0.01, 0.25, 0.5, 1e-4, 2.0]), st.floats(-50, 50), st.floats(2, 400))
def test_rounding_snaps_to_the_nearest_step_inside_the_bounds(values, step, low, width):
    # each value goes to a multiple of the step nearest it among those within the bounds (a
    # brute-force scan of the grid; a value halfway may go either way), duplicates dropped,
    # the order kept (the study refuses a step not below its range: a grid point is inside)
    from cadgen.optimize.finals import rounded as _rounded

    high = low + width
    column = np.clip(np.asarray(values), low, high)
    grid = np.arange(np.ceil(low / step - 1e-9), np.floor(high / step + 1e-9) + 1) * step
    one_by_one = [_rounded(np.array([[v]]), np.array([step]), [low], [high])[0, 0]
                  for v in column]
    for value, snapped in zip(column, one_by_one):
        assert np.min(np.abs(grid - snapped)) < 1e-9                     # on the grid
        assert abs(snapped - value) <= np.min(np.abs(grid - value)) + 1e-9   # a nearest one
    out = _rounded(column[:, None], np.array([step]), [low], [high])[:, 0]
    assert list(out) == list(dict.fromkeys(one_by_one))
