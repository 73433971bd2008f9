"""A build's progress as it runs (cadgen.pipeline.progress, cadgen.report.progress), the batch's
running and queued designs, and the summary's verdict and file count."""

from __future__ import annotations

import io
import re
import subprocess
import sys
import time
from pathlib import Path

import pytest

import cadgen.pipeline.figures
from cadgen.batch import Progress, expand_grid, run_batch
from cadgen.params import load_params
from cadgen.pipeline.build import SWEEP_STAGES, build, plan
from cadgen.pipeline.progress import ProgressEvent
from cadgen.report.progress import ProgressPrinter, progress_bar
from cadgen.report.summary import format_verdict

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = ROOT / "params" / "xin2024-planter.toml"
#: Teeth and both sweeps, no figures: the stages that run side by side.
SIDE_BY_SIDE = ["teeth", "arm_interference", "ground_clearance"]


@pytest.fixture(scope="module")
def params():
    return load_params(REFERENCE)


def run_with_events(params, effects, output_root=None, cache=True):
    events = []
    result = build(params, output_root, effects=effects, progress=events.append, cache=cache)
    return result, events


def check_teeth_steps(events, report):
    steps = [e for e in events if e.stage == "teeth" and e.state == "step"]
    pairs = [m["stage"] for m in report["gear_train"]["meshes"]]
    assert [e.step for e in steps] == list(range(1, len(pairs) + 1))   # monotone, one per pair
    assert {e.steps for e in steps} == {len(pairs)}
    assert [e.detail for e in steps] == pairs
    assert all(a.seconds <= b.seconds for a, b in zip(steps, steps[1:]))


def test_stages_start_and_finish_in_plan_order_in_one_process(params, monkeypatch):
    monkeypatch.setattr(cadgen.pipeline.figures, "_can_fork", lambda: False)
    result, events = run_with_events(params, SIDE_BY_SIDE)
    stages, _ = plan(SIDE_BY_SIDE, "planting", "field")
    assert [(e.stage, e.state) for e in events if e.state != "step"] == [
        (stage, state) for stage in stages for state in ("started", "finished")]
    assert not any(e.beside for e in events)
    records = {r["stage"]: r for r in result.report["stages"]}
    for event in (e for e in events if e.state == "finished"):
        assert (event.status, event.seconds) == (records[event.stage]["status"],
                                                 pytest.approx(records[event.stage]["seconds"],
                                                               abs=1e-6))
    check_teeth_steps(events, result.report)
    assert [e.elapsed for e in events] == sorted(e.elapsed for e in events)


@pytest.mark.skipif(not cadgen.pipeline.figures._can_fork(), reason="needs fork and 2 cores")
def test_the_sweeps_report_from_their_second_process_while_the_teeth_are_cut(params):
    # the gears cut (no cache), so the teeth take their time beside the sweeps
    result, events = run_with_events(params, SIDE_BY_SIDE, cache=False)
    stages, _ = plan(SIDE_BY_SIDE, "planting", "field")
    here = [(e.stage, e.state) for e in events if not e.beside and e.state != "step"]
    assert here == [(s, state) for s in stages if s not in SWEEP_STAGES
                    for state in ("started", "finished")]
    beside = [(e.stage, e.state) for e in events if e.beside]
    assert beside == [("parts", "started"), ("parts", "finished"),
                      ("arm_interference", "started"), ("arm_interference", "finished"),
                      ("ground_clearance", "started"), ("ground_clearance", "finished")]
    # every stage of the plan started and finished once, with the report's status
    records = {r["stage"]: r["status"] for r in result.report["stages"]}
    finished = [e for e in events if e.state == "finished" and (e.stage, e.beside) != ("parts",
                                                                                       True)]
    assert sorted(e.stage for e in finished) == sorted(stages)
    assert {e.stage: e.status for e in finished} == records
    # the second process worked while the teeth were cut: its work (from its first stage, the
    # gearless parts its sweeps need, to its last sweep's end) overlaps the teeth's events. It is
    # forked before the teeth start, so its first event may arrive before theirs or after; and
    # when its sweeps start depends on how long those parts take against the ten pairs, so only
    # the overlap of the two spans is evidence.
    teeth = [k for k, e in enumerate(events) if e.stage == "teeth"]
    second = [k for k, e in enumerate(events) if e.beside]
    assert second[0] < teeth[-1] and teeth[0] < second[-1]
    check_teeth_steps(events, result.report)


def test_figures_and_files_are_steps(params, tmp_path):
    result, events = run_with_events(params, ["metrics", "plots"], tmp_path)
    figures = [f for f in result.files if f.startswith("plots/")]
    steps = [e for e in events if e.stage == "plots" and e.state == "step"]
    assert [e.step for e in steps] == list(range(1, len(figures) + 1))
    assert sorted(e.detail for e in steps) == sorted(f.removeprefix("plots/") for f in figures)
    write = [e for e in events if e.stage == "write"]
    assert [e.state for e in write] == ["started", "step", "step", "finished"]  # plots, json
    assert write[-1].status == "ok"
    assert write[-1].detail == f"{len(result.files)} files in {tmp_path / params.name}"


def test_a_metrics_only_build_wrote_one_file(params, tmp_path):
    result = build(params, tmp_path, effects=["metrics"])
    assert result.files == ["report.json"]
    assert result.summary_text().splitlines()[-1] == f"wrote 1 file to {tmp_path / params.name}"


# --------------------------------------------------------------------------- the printer


def event(stage, state, step=0, steps=0, seconds=0.0, elapsed=0.0, status="", detail="",
          beside=False):
    return ProgressEvent(stage, state, step, steps, seconds, elapsed, status, detail, beside)


EVENTS = [event("teeth", "started", elapsed=0.1),
          event("arm_interference", "started", elapsed=0.2, beside=True),
          event("teeth", "step", 1, 5, 2.0, 2.1, detail="non-circular pair"),
          event("arm_interference", "finished", seconds=2.5, elapsed=2.7, status="ok",
                beside=True),
          event("teeth", "finished", 1, 5, 3.5, 3.6, status="failed",
                detail="[fractional_teeth] no module\nfits")]


def test_plain_lines_when_not_a_terminal():
    stream = io.StringIO()
    with ProgressPrinter(stream, tty=False) as printer:
        for e in EVENTS:
            printer(e)
    assert stream.getvalue().splitlines() == [
        "[   0.1 s] teeth: started",
        "[   0.2 s] arm_interference (beside): started",
        "[   2.1 s] teeth: 1/5 non-circular pair (2.0 s)",
        "[   2.7 s] arm_interference (beside): ok in 2.500 s",
        "[   3.6 s] teeth: failed in 3.500 s: [fractional_teeth] no module fits"]
    assert "\r" not in stream.getvalue()


def test_on_a_terminal_one_status_line_is_redrawn_and_finished_stages_stay():
    stream = io.StringIO()
    with ProgressPrinter(stream, tty=True) as printer:
        for e in EVENTS[:3]:
            printer(e)
        line = printer.status_line()
        assert line.startswith(f"teeth {progress_bar(1, 5)} 1/5 non-circular pair ")
        assert " | arm_interference (beside) " in line
        for e in EVENTS[3:]:
            printer(e)
    text = stream.getvalue()
    kept = [part for part in text.split("\r\x1b[K") if part.endswith("\n")]
    assert kept == [f"  {'arm_interference (beside)':<25} ok          2.500 s\n",
                    f"  {'teeth':<25} failed      3.500 s  [fractional_teeth] no module fits\n"]
    assert text.endswith("fits\n") and printer.status_line() == ""   # nothing left running
    assert progress_bar(3, 5, 10) == "[######----]" and progress_bar(0, 0, 4) == "[----]"


def test_the_command_line_prints_stages_on_stderr_and_the_summary_on_stdout(tmp_path):
    result = subprocess.run([sys.executable, "-m", "cadgen", "build", str(REFERENCE),
                             "--effects", "metrics", "--output-dir", str(tmp_path)],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode in (0, 1), result.stderr
    stages, _ = plan(["metrics"], "planting", "field")
    said = [re.sub(r" \(\d+\.\d s\)$", "", line.split("] ", 1)[1].split(" in ")[0])
            for line in result.stderr.splitlines()]
    assert said == [text for stage in stages for text in (f"{stage}: started", f"{stage}: ok")] \
        + ["write: started (" + str(tmp_path / "xin2024-planter") + ")", "write: 1/1 report.json",
           "write: ok"]
    assert "\r" not in result.stderr and "started" not in result.stdout
    assert result.stdout.splitlines()[-1] == f"wrote 1 file to {tmp_path / 'xin2024-planter'}"


def test_a_callback_that_fails_stops_the_build(params):
    def broken(event):
        raise RuntimeError(f"no room for {event.stage}")

    with pytest.raises(RuntimeError, match="no room for kinematics"):
        build(params, None, effects=["metrics"], progress=broken)


# --------------------------------------------------------------------------- NOT PASSED


def test_not_passed_lists_the_first_reasons_then_counts_the_rest():
    failures = [f"reason {k}: " + "x " * 50 for k in range(1, 9)]
    report = {"passed": False, "failures": failures, "files": ["report.html", "report.json"]}
    lines = format_verdict(report).splitlines()
    assert lines[0] == "NOT PASSED:"
    assert lines[1:6] == [f"  - {' '.join(f.split())}" for f in failures[:5]]
    assert lines[6:] == ["  and 3 more (see report.html)"]
    assert format_verdict({**report, "files": ["report.json"]}).endswith(
        "and 3 more (see report.json)")
    assert format_verdict({**report, "failures": failures[:5]}).splitlines()[-1] == \
        f"  - {' '.join(failures[4].split())}"
    assert format_verdict({"passed": True, "failures": []}) == "PASSED"


# --------------------------------------------------------------------------- batch


def slow_build(params, output_root, **kwargs):
    """A design that takes a while and writes nothing (its report: passed)."""
    time.sleep(0.6)
    return {"passed": True}


def test_progress_line_shows_running_and_queued_designs():
    stream = io.StringIO()
    progress = Progress(5, stream, tty=False)
    for name in ("l2-sweep-004", "l2-sweep-005"):
        progress.started(name)
    assert progress.line() == ("[0/5] 0% ok 0, failed 0, 2 running (l2-sweep-004, -005), "
                               "3 queued")
    progress.update({"name": "l2-sweep-004", "ok": True, "failure": None, "seconds": 2.0})
    assert stream.getvalue().splitlines() == [
        "[0/5] started l2-sweep-004; 1 running (l2-sweep-004), 4 queued",
        "[0/5] started l2-sweep-005; 2 running (l2-sweep-004, -005), 3 queued",
        "[1/5] l2-sweep-004 ok (2.0 s); 1 running (l2-sweep-005), 3 queued"]


def test_a_batch_tells_each_design_as_it_starts(tmp_path):
    grid = tmp_path / "grid.toml"
    grid.write_text(f'base = "{REFERENCE.as_posix()}"\nname = "slow"\n'
                    '[grid]\n"planter.L2" = [185.0, 188.0, 191.0, 194.0, 197.0]\n')
    jobs = expand_grid(grid)
    stream, seen = io.StringIO(), []
    progress = Progress(len(jobs), stream, tty=False)

    def started(name):
        seen.append(("start", name))
        progress.started(name)

    def finished(summary):
        seen.append(("result", summary["name"]))
        progress.update(summary)

    summaries = run_batch(jobs, tmp_path / "out", workers=2, build=slow_build,
                          on_start=started, on_result=finished)
    names = [job.name for job in jobs]
    assert all(s["ok"] for s in summaries)
    assert sorted(n for kind, n in seen if kind == "start") == names
    assert sorted(n for kind, n in seen if kind == "result") == names
    running = set()
    for kind, name in seen:            # each design starts before its result, two at most
        if kind == "start":
            running.add(name)
        else:
            running.remove(name)
        assert len(running) <= 2
    lines = stream.getvalue().splitlines()
    assert len(lines) == 2 * len(jobs)
    assert lines[0].endswith(f"1 running ({seen[0][1]}), {len(jobs) - 1} queued")
    assert any("; 2 running (" in line and f"), {len(jobs) - 2} queued" in line
               for line in lines)
    assert lines[-1].startswith(f"[{len(jobs)}/{len(jobs)}] ")
    assert lines[-1].endswith("; 0 running, 0 queued")


@pytest.mark.skipif(not cadgen.pipeline.figures._can_fork(), reason="needs fork and 2 cores")
def test_figures_without_gears_are_drawn_beside_and_counted_there(params, tmp_path):
    result, events = run_with_events(params, SIDE_BY_SIDE + ["plots"], tmp_path)
    figures = sorted(f.removeprefix("plots/") for f in result.files if f.startswith("plots/"))
    here = [e for e in events if e.stage == "plots" and not e.beside]
    there = [e for e in events if e.stage == "plots" and e.beside]
    for events_of_one_process in (here, there):
        states = [e.state for e in events_of_one_process]
        assert states[0] == "started" and states[-1] == "finished"
        steps = [e for e in events_of_one_process if e.state == "step"]
        assert [e.step for e in steps] == list(range(1, len(steps) + 1))
    drawn_here = {e.detail for e in here if e.state == "step"}
    drawn_there = {e.detail for e in there if e.state == "step"}
    # each figure drawn once; here the assembly view (it needs every part's mesh), there the
    # clearance figure (the sweeps ran there); the others (the gear pairs' from their data
    # sent after the teeth) by either side, whichever is free first
    assert sorted(drawn_here | drawn_there) == figures and not drawn_here & drawn_there
    assert "assembly.png" in drawn_here and "clearance.png" in drawn_there
    record = next(r for r in result.report["stages"] if r["stage"] == "plots")
    assert record["message"].startswith(f"{len(drawn_there)} of {len(figures)} figures drawn "
                                        "beside the teeth, in a second process (")
