"""Batch builds (cadgen.batch): grid files, local processes and Dask, the summary."""

from __future__ import annotations

import argparse
import csv
import io
import json
import os
import random
from pathlib import Path

import pytest

from cadgen.atomic import staged_directory
from cadgen.batch import (
    DEFAULT_BUILD,
    EXIT_FAILED,
    EXIT_OK,
    EXIT_PROBLEMS,
    SUMMARY_CSV,
    SUMMARY_HTML,
    GridError,
    Progress,
    add_batch_arguments,
    batch_exit_code,
    expand_grid,
    file_jobs,
    guard_names,
    main_batch,
    run_batch,
    run_design,
    summary_csv,
    summary_html,
    write_summary,
)
from cadgen.params import validate_data

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = ROOT / "params" / "xin2024-planter.toml"
KERNEL_A = ROOT / "params" / "kernel-a.toml"
INVALID = ROOT / "tests" / "invalid" / "missing_key.toml"  # name "bad-example", train.R missing
FAST = {"effects": ["metrics"]}   # keyword arguments of cadgen.build.build: a fast build


def write_grid(directory: Path, body: str, base: Path = REFERENCE, name: str | None = "r-sweep"):
    """A grid file in ``directory`` whose base is given relative to it."""
    head = f'base = "{Path(os.path.relpath(base, directory)).as_posix()}"\n'
    if name is not None:
        head += f'name = "{name}"\n'
    path = directory / "grid.toml"
    path.write_text(head + body, encoding="utf-8")
    return path


def rows(text: str) -> dict[str, dict]:
    return {row["design"]: row for row in csv.DictReader(io.StringIO(text))}


def dying_build(params, output_root, **kwargs):
    """A worker that dies outright (a segfault, the out-of-memory killer)."""
    os._exit(3)


def half_written_build(params, output_root, **kwargs):
    """A build that fails in the middle of writing its folder for design ...-002."""
    if params.name.endswith("-002"):
        with staged_directory(Path(output_root) / params.name) as staging:
            (staging / "report.json").write_text("{")
            raise RuntimeError("engine crashed while writing")
    from cadgen.build import build

    return build(params, output_root=output_root, **FAST)


# --------------------------------------------------------------------------- grid files


def test_grid_expands_the_cartesian_product_in_order(tmp_path):
    grid = write_grid(tmp_path, '[grid]\n"train.R" = [34.0, 36.0, 38.0]\n'
                                '"planter.L2" = { start = 180.0, stop = 200.0, num = 3 }\n')
    jobs = expand_grid(grid)
    assert [job.name for job in jobs] == [f"r-sweep-{k:03d}" for k in range(1, 10)]
    expected = [(r, l2) for r in (34.0, 36.0, 38.0) for l2 in (180.0, 190.0, 200.0)]
    assert [(job.values["train.R"], job.values["planter.L2"]) for job in jobs] == expected
    for job, (r, l2) in zip(jobs, expected):
        params = validate_data(job.data, check_feasibility=False)
        assert params.name == job.name
        assert params.train.R == r and params.planter.L2 == l2
        assert params.train.r == 27.0 and params.planter.L1 == 130.0  # the rest from the base
        assert job.source == str(grid) and job.path is None


def test_grid_dotted_keys_integer_range_and_default_prefix(tmp_path):
    body = "[grid]\ntrain.R = [35.0]\npitch_curve.teeth = { start = 20, stop = 24, num = 3 }\n"
    grid = write_grid(tmp_path, body, name=None)
    jobs = expand_grid(grid)
    assert [job.name for job in jobs] == [f"xin2024-planter-{k:03d}" for k in (1, 2, 3)]
    teeth = [validate_data(job.data, check_feasibility=False).pitch_curve.teeth for job in jobs]
    assert teeth == [20, 22, 24]
    assert all(type(job.values["pitch_curve.teeth"]) is int for job in jobs)


@pytest.mark.parametrize("body, base, path, code, words", [
    ('[grid]\n"train.Rr" = [34.0]\n', REFERENCE, "grid.train.Rr", "unknown_key", "mean 'R'"),
    ('[grid]\n"train.R" = [36.0, "38"]\n', REFERENCE, "grid.train.R", "wrong_type", "value 2 of 2"),
    ('[grid]\n"train.R" = []\n', REFERENCE, "grid.train.R", "empty", "train.R"),
    ('[grid]\n"train.R" = 36.0\n', REFERENCE, "grid.train.R", "wrong_type", "array"),
    ('[grid]\n"planter.L2" = { start = 180.0, stop = 200.0 }\n', REFERENCE, "grid.planter.L2.num",
     "missing", "num"),
    ('[grid]\n"train.R" = [36.0]\n', ROOT / "params" / "no-such-file.toml", "base",
     "file_not_found", "no-such-file.toml"),
    ('[grid]\n"name" = ["a", "b"]\n', REFERENCE, "grid.name", "not_allowed", "cannot be swept"),
], ids=["unknown-key", "wrong-type", "empty-list", "not-an-array", "range-without-num",
        "missing-base", "name-swept"])
def test_bad_grid_names_the_key(tmp_path, body, base, path, code, words):
    grid = write_grid(tmp_path, body, base=base)
    with pytest.raises(GridError) as caught:
        expand_grid(grid)
    found = [p for p in caught.value.problems if p.path == path and p.code == code]
    assert found, caught.value.problems
    assert words in found[0].message


def test_bad_grid_lists_every_problem_at_once(tmp_path):
    (tmp_path / "grid.toml").write_text('[grid]\n"train.Rr" = [1.0]\n"planter.L1" = []\n')
    with pytest.raises(GridError) as caught:
        expand_grid(tmp_path / "grid.toml")
    assert {(p.path, p.code) for p in caught.value.problems} == {
        ("base", "missing"), ("grid.planter.L1", "empty")}


def test_bad_name_prefix(tmp_path):
    grid = write_grid(tmp_path, '[grid]\n"train.R" = [36.0]\n', name="../escape")
    with pytest.raises(GridError) as caught:
        expand_grid(grid)
    assert [(p.path, p.code) for p in caught.value.problems] == [("name", "invalid_name")]


def test_bad_grid_exits_2_before_anything_runs(tmp_path, capsys):
    grid = write_grid(tmp_path, '[grid]\n"train.Rr" = [34.0]\n')
    out = tmp_path / "out"
    status = main_batch(parse(["--grid", str(grid), "--output-dir", str(out)]))
    assert status == EXIT_PROBLEMS
    assert "grid.train.Rr" in capsys.readouterr().err
    assert not out.exists()


# --------------------------------------------------------------------------- local processes


@pytest.fixture(scope="module")
def three_files(tmp_path_factory):
    """Two good designs and one invalid file, fast builds in two local processes."""
    root = tmp_path_factory.mktemp("local")
    jobs = guard_names(file_jobs([str(REFERENCE), str(KERNEL_A), str(INVALID)]))
    seen = []
    summaries = run_batch(jobs, root, workers=2, build_kwargs=FAST, on_result=seen.append)
    csv_path, html_path = write_summary(summaries, root)
    return root, summaries, seen, csv_path.read_text(), html_path.read_text()


def test_one_invalid_file_fails_alone(three_files):
    root, summaries, seen, text, _ = three_files
    assert len(seen) == 3  # every result was reported as it came
    assert [s["name"] for s in summaries] == ["bad-example", "kernel-a", "xin2024-planter"]
    assert [s["ok"] for s in summaries] == [False, True, True]
    assert batch_exit_code(summaries) == EXIT_FAILED
    bad = summaries[0]["failure"]
    assert bad["code"] == "missing" and bad["exception"] == "ParameterError"
    assert {"path": "train.R", "code": "missing"}.items() <= bad["problems"][0].items()
    table = rows(text)
    assert table["bad-example"]["status"] == "failed"
    assert table["bad-example"]["failure_code"] == "missing"
    assert "train.R" in table["bad-example"]["failure"]
    assert table["xin2024-planter"]["passed"] == "yes"
    assert float(table["xin2024-planter"]["hole_width@150mm"]) == pytest.approx(
        summaries[2]["metrics"]["hole_width@150mm"]["value"])
    assert float(table["xin2024-planter"]["module"]) > 2.5


def test_outputs_complete_and_none_for_the_failed_design(three_files):
    root, summaries, _, _, _ = three_files
    assert sorted(p.name for p in root.iterdir()) == sorted(
        [SUMMARY_CSV, SUMMARY_HTML, "kernel-a", "xin2024-planter"])  # no staging left over
    for summary in summaries[1:]:
        folder = Path(summary["output_dir"])
        assert folder == root / summary["name"]
        assert summary["files"] and "report.json" in summary["files"]
        for name in summary["files"]:
            assert (folder / name).is_file() and (folder / name).stat().st_size > 0
        assert json.loads((folder / "report.json").read_text())["design"] == summary["name"]


def test_summary_is_deterministic(three_files, tmp_path):
    _, summaries, _, text, page = three_files
    shuffled = list(summaries)
    random.Random(7).shuffle(shuffled)
    assert summary_csv(shuffled) == text
    assert summary_html(shuffled) == page
    csv_path, _ = write_summary(shuffled, tmp_path)
    assert csv_path.read_text() == text
    assert "seconds" not in text.splitlines()[0]
    assert page.startswith("<!DOCTYPE html>") and "<script" not in page and "http" not in page


def test_a_crashing_build_leaves_nothing_and_the_batch_goes_on(tmp_path):
    grid = write_grid(tmp_path, '[grid]\n"train.R" = [35.0, 36.0, 37.0]\n')
    out = tmp_path / "out"
    summaries = run_batch(expand_grid(grid), out, workers=2, build=half_written_build)
    assert [s["ok"] for s in summaries] == [True, False, True]
    failure = summaries[1]["failure"]
    assert failure["code"] == "exception" and "RuntimeError: engine crashed" in failure["message"]
    assert "half_written_build" in failure["traceback"]
    assert sorted(p.name for p in out.iterdir()) == ["r-sweep-001", "r-sweep-003"]
    assert rows(summary_csv(summaries))["r-sweep-002"]["failure_code"] == "exception"


def test_a_dead_worker_is_reported_not_raised(tmp_path):
    jobs = file_jobs([REFERENCE])
    summaries = run_batch(jobs, tmp_path, workers=1, build=dying_build)
    assert [(s["ok"], s["failure"]["code"]) for s in summaries] == [(False, "worker_error")]
    assert "BrokenProcessPool" in summaries[0]["failure"]["message"]
    assert list(tmp_path.iterdir()) == []


def test_a_build_given_as_a_path(tmp_path):
    job = file_jobs([REFERENCE])[0]
    summary = run_design(job, tmp_path, build=DEFAULT_BUILD, build_kwargs=FAST)
    assert summary["ok"] and summary["passed"] is True
    assert summary["metrics"]["soil_penetrations"] == {
        "value": 1.0, "unit": "", "target": "= 1", "passed": True}
    assert (tmp_path / "xin2024-planter" / "report.json").is_file()


def test_a_repeated_name_is_not_built(tmp_path):
    copy = tmp_path / "copy.toml"
    copy.write_text(REFERENCE.read_text())
    first, second, third = guard_names(file_jobs([REFERENCE, copy, REFERENCE]))
    assert first.blocked_by is None and "rename one" in second.blocked_by
    assert "given twice" in third.blocked_by
    summary = run_design(second, tmp_path, build_kwargs=FAST)
    assert not summary["ok"] and summary["failure"]["code"] == "duplicate_name"
    assert not (tmp_path / "xin2024-planter").exists()
    # its own problems come first
    bad = guard_names(file_jobs([INVALID, INVALID]))[1]
    assert run_design(bad, tmp_path)["failure"]["code"] == "missing"


def test_strict_fails_on_a_missed_target(tmp_path):
    grid = write_grid(tmp_path, '[grid]\n"targets.module_min" = [2.5, 3.0]\n')
    summaries = [run_design(job, tmp_path / "out", build_kwargs=FAST) for job in expand_grid(grid)]
    assert [(s["ok"], s["passed"]) for s in summaries] == [(True, True), (True, False)]
    assert batch_exit_code(summaries) == EXIT_OK
    assert batch_exit_code(summaries, strict=True) == EXIT_FAILED
    assert rows(summary_csv(summaries))["r-sweep-002"]["missed_targets"] == "module"


# --------------------------------------------------------------------------- Dask


def test_dask_cluster_gives_the_same_summary(three_files, tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    _, summaries, _, text, _ = three_files
    jobs = guard_names(file_jobs([str(REFERENCE), str(KERNEL_A), str(INVALID)]))
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        on_dask = run_batch(jobs, tmp_path, scheduler=cluster.scheduler_address,
                            build_kwargs=FAST)
    assert summary_csv(on_dask) == text

    def stable(summary):
        return {k: v for k, v in summary.items() if k not in ("seconds", "output_dir")}

    assert [stable(s) for s in on_dask] == [stable(s) for s in summaries]
    assert not (tmp_path / "bad-example").exists()


# --------------------------------------------------------------------------- progress, CLI


def summary_of(name, ok, seconds=1.0):
    failure = None if ok else {"code": "missing", "message": "m", "problems": [
        {"path": "train.R", "code": "missing", "message": "required key 'R' is missing"}]}
    return {"name": name, "ok": ok, "failure": failure, "seconds": seconds}


def test_progress_without_a_terminal_prints_one_line_per_design():
    stream = io.StringIO()
    progress = Progress(3, stream, tty=False)
    for summary in (summary_of("a", True), summary_of("b", False), summary_of("c", True)):
        progress.update(summary)
    progress.close()
    lines = stream.getvalue().splitlines()
    assert lines == ["[1/3] a ok (1.0 s)",
                     "[2/3] b failed: train.R: required key 'R' is missing [missing] (1.0 s)",
                     "[3/3] c ok (1.0 s)"]


def test_progress_on_a_terminal_redraws_one_line():
    stream = io.StringIO()
    progress = Progress(4, stream, tty=True)
    assert stream.getvalue() == "[0/4] 0% ok 0, failed 0"
    progress.update(summary_of("a", True))
    assert stream.getvalue().startswith("[0/4] 0% ok 0, failed 0\r\x1b[K[1/4] 25% ok 1, "
                                        "failed 0, eta ")
    progress.update(summary_of("b", False))
    progress.close()
    text = stream.getvalue()
    assert "failed b: train.R" in text and text.endswith("[2/4] 50% ok 1, failed 1, eta 00:00\n")
    assert text.count("\n") == 2  # the failure line and the end


def parse(argv):
    parser = argparse.ArgumentParser(prog="cadgen batch")
    add_batch_arguments(parser)
    return parser.parse_args(argv)


def test_arguments():
    args = parse(["a.toml", "b.toml", "--grid", "g.toml", "--workers", "3",
                  "--scheduler", "tcp://host:8786", "--strict", "--output-dir", "o"])
    assert args.files == ["a.toml", "b.toml"] and args.grid == ["g.toml"]
    assert (args.workers, args.scheduler, args.strict, args.output_dir) == (
        3, "tcp://host:8786", True, "o")
    assert args.handler is main_batch
    defaults = parse([])
    assert (defaults.workers, defaults.scheduler, defaults.strict, defaults.output_dir) == (
        None, None, False, "outputs")
    with pytest.raises(SystemExit):
        parse(["--workers", "0"])


def test_no_designs_exits_2(capsys):
    assert main_batch(parse([])) == EXIT_PROBLEMS
    assert "no designs" in capsys.readouterr().err


def test_end_to_end_with_the_default_build(tmp_path, capsys):
    """The real build (gears, cam, solids, plots) on one design, beside an invalid file."""
    out = tmp_path / "out"
    status = main_batch(parse([str(REFERENCE), str(INVALID), "--workers", "2",
                               "--output-dir", str(out)]))
    captured = capsys.readouterr()
    assert status == EXIT_FAILED
    assert "2 designs in" in captured.out and "1 built, 1 failed" in captured.out
    assert str(out / SUMMARY_CSV) in captured.out
    assert "[2/2]" in captured.err
    table = rows((out / SUMMARY_CSV).read_text())
    assert table["xin2024-planter"]["status"] == "ok"
    assert table["bad-example"]["failure_code"] == "missing"
    folder = out / "xin2024-planter"
    report = json.loads((folder / "report.json").read_text())
    assert report["design"] == "xin2024-planter"
    assert list(folder.glob("gears/*.dxf")) and list(folder.glob("solids/*.stl"))
    assert list(folder.glob("plots/*.png"))
    assert not (out / "bad-example").exists()
    assert not [p for p in out.iterdir() if p.name.startswith(".")]
