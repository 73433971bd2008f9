"""Batch builds (cadgen.batch): grid files, local processes and Dask, the summary, and
designs that fail, time out or kill their process."""

from __future__ import annotations

import argparse
import csv
import html
import io
import json
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from cadgen.export.atomic import staged_directory
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
    run_design_isolated,
    summary_csv,
    summary_html,
    write_summary,
)
from cadgen.batch.isolated import _clean_staging
from cadgen.params import validate_data
from kinematics.errors import DesignError, Problem

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = ROOT / "params" / "xin2024-planter.toml"
KERNEL_A = ROOT / "params" / "kernel-a.toml"
INVALID = ROOT / "tests" / "invalid" / "missing_key.toml"  # name "bad-example", train.R missing
FAST = {"effects": ["metrics"]}   # keyword arguments of cadgen.pipeline.build.build: a fast build


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
    from cadgen.pipeline.build import build

    return build(params, output_root=output_root, **FAST)


FAULT_GRID = '[grid]\n"train.R" = { start = 35.0, stop = 37.0, num = 6 }\n'
FAULTS = {"f-002": "collides", "f-003": "timeout", "f-004": "worker_died", "f-005": "worker_died"}


def fault_build(params, output_root, *, pid_dir=None, **kwargs):
    """Designs f-002 to f-005 fail four ways; the others build (metrics only).

    f-002 raises a DesignError. The others first half write their folder; then f-003
    starts a worker of its own (its pid in ``pid_dir``) and hangs past any timeout here,
    f-004 exits with code 3 and f-005 kills itself with SIGKILL.
    """
    number = params.name.rsplit("-", 1)[1]
    if number == "002":
        raise DesignError([Problem("planter.L2", "collides", "the arm hits the housing")])
    if number in ("003", "004", "005"):
        with staged_directory(Path(output_root) / params.name) as staging:
            (staging / "report.json").write_text("{")
            if number == "003":
                helper = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
                (Path(pid_dir) / f"{params.name}.pid").write_text(str(helper.pid))
                time.sleep(60)
            elif number == "004":
                os._exit(3)
            os.kill(os.getpid(), signal.SIGKILL)
    from cadgen.pipeline.build import build

    return build(params, output_root=output_root, **kwargs)


def gone(pid: int, wait: float = 5.0) -> bool:
    """Has process ``pid`` ended (a zombie left for init to reap counts)?"""
    deadline = time.monotonic() + wait
    while True:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return True
        try:  # where init does not reap (a container), the killed worker stays a zombie
            state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
        except OSError:  # no /proc, or it has just been reaped
            state = "?"
        if state == "Z":
            return True
        if time.monotonic() > deadline:
            return False
        time.sleep(0.05)


def fault_batch(directory: Path, timeout: float, **options):
    """The six designs of FAULT_GRID through ``run_batch`` with fault_build; f-003 has a
    previous build's folder. ``(output root, summaries, pid folder)``."""
    grid = write_grid(directory, FAULT_GRID, name="f")
    out, pids = directory / "out", directory / "pids"
    (out / "f-003").mkdir(parents=True)
    (out / "f-003" / "report.json").write_text('{"previous": true}')
    pids.mkdir()
    seen = []
    summaries = run_batch(expand_grid(grid), out, build=fault_build, timeout=timeout,
                          build_kwargs={"pid_dir": str(pids), **FAST}, on_result=seen.append,
                          **options)
    assert len(seen) == 6
    return out, summaries, pids


@pytest.fixture(scope="module")
def faultless(tmp_path_factory):
    """f-001 and f-006 built by the plain build, no faults beside them: reports and rows."""
    directory = tmp_path_factory.mktemp("faultless")
    grid = write_grid(directory, FAULT_GRID, name="f")
    jobs = [job for job in expand_grid(grid) if job.name not in FAULTS]
    summaries = run_batch(jobs, directory / "out", workers=2, build_kwargs=FAST)
    reports = {s["name"]: (directory / "out" / s["name"] / "report.json").read_text()
               for s in summaries}
    return reports, rows(summary_csv(summaries))


def without_timings(report_text: str) -> dict:
    report = json.loads(report_text)
    for stage in report["stages"]:
        stage.pop("seconds")
    return report


def check_faults(out: Path, summaries, pids: Path, timeout: float, faultless) -> None:
    """Each fault reported as itself, the other designs' outputs as without faults, and
    nothing else left behind."""
    reports, faultless_rows = faultless
    assert [s["name"] for s in summaries] == [f"f-00{k}" for k in range(1, 7)]
    assert {s["name"]: (s["failure"] or {}).get("code") for s in summaries} == {
        "f-001": None, "f-006": None, **FAULTS}
    failure = {s["name"]: s["failure"] for s in summaries if s["failure"]}
    assert failure["f-002"]["message"] == "planter.L2: the arm hits the housing [collides]"
    assert failure["f-003"]["timeout"] == timeout
    assert f"time limit of {timeout:g} s" in failure["f-003"]["message"]
    assert failure["f-004"]["exit_code"] == 3
    assert "exited with code 3" in failure["f-004"]["message"]
    assert failure["f-005"]["exit_code"] == -signal.SIGKILL
    assert "killed by SIGKILL" in failure["f-005"]["message"]
    assert batch_exit_code(summaries) == EXIT_FAILED

    # the timed-out design's own worker was killed with it
    assert gone(int((pids / "f-003.pid").read_text()))
    # no staging left over; the timed-out design's previous folder untouched
    assert sorted(p.name for p in out.iterdir()) == ["f-001", "f-003", "f-006"]
    assert (out / "f-003" / "report.json").read_text() == '{"previous": true}'
    assert list((out / "f-003").iterdir()) == [out / "f-003" / "report.json"]
    # the others: as if there had been no faults
    for name in ("f-001", "f-006"):
        assert without_timings((out / name / "report.json").read_text()) == without_timings(
            reports[name])
    table = rows(summary_csv(summaries))
    assert {name: row["failure_code"] for name, row in table.items()} == {
        "f-001": "", "f-006": "", **FAULTS}
    for name in ("f-001", "f-006"):
        assert {**table[name], "source": ""} == {**faultless_rows[name], "source": ""}
    page = summary_html(summaries)
    assert f"time limit of {timeout:g} s" in page and "[worker_died]" in page


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


# --------------------------------------------------------------------------- the HTML page


def html_grid_build(params, output_root, **kwargs):
    """Design ...-002 fails with a DesignError; the others build their metrics and report."""
    if params.name.endswith("-002"):
        raise DesignError([Problem("planter.L2", "collides", "the arm hits the housing")])
    from cadgen.pipeline.build import build

    return build(params, output_root=output_root, effects=["metrics", "report"])


@pytest.fixture(scope="module")
def html_grid(tmp_path_factory):
    """A 2 x 2 grid (train.R x planter.L2), one design failed, the others with report.html."""
    directory = tmp_path_factory.mktemp("html")
    grid = write_grid(directory, '[grid]\n"train.R" = [35.0, 36.0]\n'
                                 '"planter.L2" = [185.0, 195.0]\n')
    root = directory / "out"
    summaries = run_batch(expand_grid(grid), root, workers=2, build=html_grid_build)
    _, html_path = write_summary(summaries, root)
    return root, summaries, html_path.read_text(encoding="utf-8")


def cells(page: str, row_of: str) -> list[str]:
    """The cell texts (tags removed) of the design row of ``row_of``."""
    import re

    row = re.search(rf'<tr class="design[^"]*"><td class="name">(?:<a [^>]*>)?{row_of}<.*?</tr>',
                    page).group(0)
    return [re.sub(r"<[^>]+>", "", cell) for cell in re.findall(r"<td[^>]*>(.*?)</td>", row)]


def test_html_links_every_built_design_to_its_report(html_grid):
    import re

    root, summaries, page = html_grid
    links = re.findall(r'<a href="([^"]+)">([^<]+)</a>', page)
    assert links == [("r-sweep-001/report.html", "r-sweep-001"),
                     ("r-sweep-003/report.html", "r-sweep-003"),
                     ("r-sweep-004/report.html", "r-sweep-004")]
    for href, name in links:
        report = root / href
        assert report.is_file() and f"{name}" in report.read_text(encoding="utf-8")
    assert '<td class="name">r-sweep-002</td>' in page   # not built: no link


def test_html_numbers_rounded_and_failure_under_its_design(html_grid):
    import re

    _, summaries, page = html_grid
    numbers = re.findall(r'<td class="num[^"]*"[^>]*>([^<]*)</td>', page)
    assert len(numbers) == 4 * (2 + 12)   # 2 grid values and 12 metrics a design
    assert sum(n == "" for n in numbers) == 12   # the design that was not built
    assert all(re.fullmatch(r"-?\d+(\.\d{1,3})?", n) for n in numbers if n), numbers
    first = {s["name"]: s for s in summaries}["r-sweep-001"]
    row = cells(page, "r-sweep-001")
    assert row[:4] == ["r-sweep-001", "passed", "35", "185"]
    values = [m["value"] for m in first["metrics"].values()]
    assert len(row) == 4 + len(values)
    for text, value in zip(row[4:], values):   # 3 significant digits, at most 3 decimals
        assert float(text) == pytest.approx(value, rel=5e-3, abs=5e-4)
    assert row[4] == f"{first['metrics']['trajectory_height']['value']:.0f}"
    # the failure: a full-width row right under its design, wrapped, not a wide column
    failed = re.search(r'<td class="name">r-sweep-002</td>.*?</tr>\n<tr class="reason failed">'
                       r'<td colspan="(\d+)">([^<]*)</td></tr>', page)
    assert failed and failed.group(2) == "planter.L2: the arm hits the housing [collides]"
    assert int(failed.group(1)) == 4 + 12
    assert "1 failed" in page and "4 designs: 3 built" in page


def png_pixels(data: bytes):
    import numpy as np
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(data)).convert("RGB")).astype(int)


def has_colour(pixels, rgb, tolerance=12) -> bool:
    import numpy as np

    return bool((np.abs(pixels - np.array(rgb)).max(axis=2) <= tolerance).any())


def test_html_plots_every_metric_against_every_grid_key_with_targets(html_grid):
    import base64
    import re

    _, summaries, page = html_grid
    figures = re.findall(r'<img src="data:image/png;base64,([^"]+)" alt="([^"]+)">', page)
    metrics = list(summaries[0]["metrics"])
    assert len(metrics) == 12
    assert [html.unescape(alt) for _, alt in figures] == [
        f"{m} against {k}; target {summaries[0]['metrics'][m]['target']}"
        for m in metrics for k in ("train.R", "planter.L2")]
    plots = {html.unescape(alt): png_pixels(base64.b64decode(data)) for data, alt in figures}
    for alt, pixels in plots.items():
        assert pixels.shape[1] == 540   # 3.6 in at 150 dpi
        assert has_colour(pixels, (0xc0, 0, 0))   # the design that was not built, a red cross
    # a range target as a band (green, alpha 0.12 on white), a bound as a dashed green line
    band = (round(255 - 0.12 * (255 - 0x2a)), round(255 - 0.12 * (255 - 0x9d)),
            round(255 - 0.12 * (255 - 0x2a)))
    assert has_colour(plots["hole_width@150mm against train.R; target 0-30"], band, 3)
    line = plots["trajectory_height against planter.L2; target > 500"]
    assert has_colour(line, (0x2a, 0x9d, 0x2a), 20) and not has_colour(line, band, 3)


def test_html_of_files_has_no_plots_and_shows_every_problem(three_files):
    _, summaries, _, _, page = three_files
    assert "data:image/png" not in page and "Metrics against the grid" not in page
    assert "<a href" not in page   # the fast builds wrote no report.html
    bad = [s for s in summaries if not s["ok"]][0]
    assert html.escape(f"{Problem(**bad['failure']['problems'][0])}") in page
    assert "params/kernel-a.toml" in page   # several sources: under each name


def test_format_number():
    from cadgen.batch.html import format_number, parse_target

    assert [format_number(v) for v in (692.087, 2.733, 0.07342, 185.0, 3, -12.345, 2.1e-05,
                                       0.0, None, "x")] == [
        "692", "2.73", "0.073", "185", "3", "-12.3", "2.1e-05", "0", "", "x"]
    assert [parse_target(t) for t in ("0-20", "> 10", "< 10", "= 1", "about 3", None)] == [
        (0.0, 20.0), (10.0, None), (None, 10.0), (1.0, 1.0), None, None]


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


def test_a_dying_design_costs_only_itself(tmp_path):
    jobs = file_jobs([REFERENCE, KERNEL_A])
    summary = run_design_isolated(jobs[0], tmp_path, build=dying_build)
    assert (summary["ok"], summary["failure"]["code"]) == (False, "worker_died")
    assert summary["failure"]["exit_code"] == 3
    assert summary["failure"]["message"] == "its process exited with code 3 before it gave a result"
    # the default: one worker, which lives on to build the next design
    summaries = run_batch(jobs, tmp_path, workers=1, build=dying_build)
    assert [s["failure"]["code"] for s in summaries] == ["worker_died", "worker_died"]
    assert list(tmp_path.iterdir()) == []


def test_in_process_a_dead_worker_is_reported_not_raised(tmp_path):
    jobs = file_jobs([REFERENCE])
    summaries = run_batch(jobs, tmp_path, workers=1, build=dying_build, isolate=False)
    assert [(s["ok"], s["failure"]["code"]) for s in summaries] == [(False, "worker_error")]
    assert "BrokenProcessPool" in summaries[0]["failure"]["message"]
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(ValueError, match="own process"):
        run_batch(jobs, tmp_path, timeout=5, isolate=False)
    with pytest.raises(ValueError, match="positive"):
        run_batch(jobs, tmp_path, timeout=0)


@pytest.mark.skipif(os.name != "posix", reason="process groups and SIGKILL")
def test_faults_locally(tmp_path, faultless):
    """A design that fails, one that times out (and its own worker), one that exits, one
    killed: the batch finishes, reports each, and keeps the others' outputs."""
    # 5 s: a design of a metrics-only build ends well within it on a busy 2-core machine
    out, summaries, pids = fault_batch(tmp_path, timeout=5.0, workers=2)
    check_faults(out, summaries, pids, 5.0, faultless)
    assert summaries[2]["seconds"] < 13


def test_staging_of_killed_builds_is_cleaned(tmp_path):
    for name in (".a.staging-abcd_123", ".b.old-x1y2z3w4/b", ".c.old-aaaaaaaa/c",
                 ".z.staging-abcdefgh", "a", "c", ".a.staging-short"):
        (tmp_path / name).mkdir(parents=True)
    (tmp_path / ".c.old-aaaaaaaa" / "c" / "old").write_text("")
    removed = _clean_staging(tmp_path, ["a", "b", "c"])
    assert removed == [".a.staging-abcd_123", ".b.old-x1y2z3w4", ".c.old-aaaaaaaa"]
    # b was set aside when its build was killed: put back; c's new folder is kept
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        ".a.staging-short", ".z.staging-abcdefgh", "a", "b", "c"]
    assert list((tmp_path / "c").iterdir()) == []


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


@pytest.fixture(scope="module")
def dask_scheduler():
    """A local Dask cluster (two worker processes) for this module's tests; a worker that
    dies fails its task at once (no retry on another worker)."""
    dask = pytest.importorskip("dask")
    distributed = pytest.importorskip("dask.distributed")
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                      dashboard_address=None) as cluster:
            yield cluster.scheduler_address


def test_dask_cluster_gives_the_same_summary(three_files, dask_scheduler, tmp_path):
    _, summaries, _, text, _ = three_files
    jobs = guard_names(file_jobs([str(REFERENCE), str(KERNEL_A), str(INVALID)]))
    on_dask = run_batch(jobs, tmp_path, scheduler=dask_scheduler, build_kwargs=FAST)
    assert summary_csv(on_dask) == text

    def stable(summary):
        return {k: v for k, v in summary.items() if k not in ("seconds", "output_dir")}

    assert [stable(s) for s in on_dask] == [stable(s) for s in summaries]
    assert not (tmp_path / "bad-example").exists()


@pytest.mark.skipif(os.name != "posix", reason="process groups and SIGKILL")
def test_faults_on_dask(dask_scheduler, tmp_path, faultless):
    """The fault scenario on Dask: each design's process is a new interpreter (a Dask
    worker has threads); the Dask workers survive every fault, nothing is retried."""
    # 8 s: each design is a new interpreter here (imports of about a second, two on a busy
    # 2-core machine) before its metrics-only build
    out, summaries, pids = fault_batch(tmp_path, timeout=8.0, scheduler=dask_scheduler)
    check_faults(out, summaries, pids, 8.0, faultless)


def test_in_process_on_dask_a_dead_worker_is_reported(dask_scheduler, tmp_path):
    """Without a process per design, a dying design takes its Dask worker: the scheduler
    gives up on the task (KilledWorker; here at once, by default after 3 workers)."""
    jobs = file_jobs([REFERENCE])
    summaries = run_batch(jobs, tmp_path, scheduler=dask_scheduler, build=dying_build,
                          isolate=False)
    assert [(s["ok"], s["failure"]["code"]) for s in summaries] == [(False, "worker_error")]
    assert "KilledWorker" in summaries[0]["failure"]["message"]


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
    assert (defaults.timeout, defaults.in_process) == (None, False)
    assert parse(["--timeout", "2.5"]).timeout == 2.5
    assert parse(["--in-process"]).in_process is True
    for wrong in (["--workers", "0"], ["--timeout", "0"], ["--timeout", "soon"],
                  ["--timeout", "5", "--in-process"]):
        with pytest.raises(SystemExit):
            parse(wrong)


def test_no_designs_exits_2(capsys):
    assert main_batch(parse([])) == EXIT_PROBLEMS
    assert "no designs" in capsys.readouterr().err


def test_end_to_end_with_the_default_build(tmp_path, capsys):
    """The real build (gears, cam, solids, plots) on one design, beside an invalid file."""
    out = tmp_path / "out"
    status = main_batch(parse([str(REFERENCE), str(INVALID), "--workers", "2",
                               "--output-dir", str(out), "--timeout", "300"]))
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


def test_a_grid_file_nested_too_deep_is_a_problem_not_a_crash(tmp_path):
    """The grid reader shares the parameter files' TOML reader (fuzzing found the crash)."""
    from cadgen.batch import GridError, expand_grid

    grid = tmp_path / "deep.toml"
    grid.write_text('base = "x.toml"\n[grid]\n"train.R" = ' + "[" * 2000 + "]" * 2000 + "\n")
    with pytest.raises(GridError) as caught:
        expand_grid(grid)
    assert {p.code for p in caught.value.problems} == {"too_deep"}


def test_progress_on_a_terminal_shows_running_and_queued_in_place():
    stream = io.StringIO()
    progress = Progress(4, stream, tty=True)
    progress.started("r-001")
    progress.started("r-002")
    progress.update(summary_of("r-001", True))
    progress.close()
    text = stream.getvalue()
    assert text.count("\n") == 1 and text.endswith("\n")       # redrawn in place, then ended
    assert text.split("\r\x1b[K")[2] == "[0/4] 0% ok 0, failed 0, 2 running (r-001, -002), 2 queued"
    assert text.split("\r\x1b[K")[-1].startswith("[1/4] 25% ok 1, failed 0, 1 running (r-002), "
                                                 "2 queued, eta ")


@pytest.mark.parametrize("workers, designs, build, told", [
    (2, 4, None, False),                 # a design on every core: no worker beside each
    (1, 4, None, None),                  # a core left: the build forks its worker beside
    (2, 1, None, None),                  # one design: one worker, a core left
    (2, 4, "own", None),                 # a build of the caller's may not take the keyword
])
def test_a_batch_keeps_each_build_to_its_process_when_every_core_has_a_design(
        workers, designs, build, told, monkeypatch, tmp_path):
    import cadgen.batch.run

    monkeypatch.setattr(os, "cpu_count", lambda: 2)
    seen = {}

    def local(jobs, output_root, task, workers, on_result, on_start=None):
        seen["kwargs"] = task[1]
        return []

    monkeypatch.setattr(cadgen.batch.run, "_run_local", local)
    jobs = [cadgen.batch.DesignJob(f"d{i}", "grid.toml", data={}) for i in range(designs)]
    run_batch(jobs, tmp_path, workers=workers, build=_own_build if build == "own" else build,
              build_kwargs={"cache": False})
    assert seen["kwargs"].get("parallel", None) is told
    assert seen["kwargs"]["cache"] is False


def _own_build(params, output_root, **kwargs):
    """A build of a batch's caller (picklable by reference)."""
    raise AssertionError("not run")
