"""Ctrl-C at any moment: one line, exit 130, nothing half-written, no process left.

The end-to-end tests send SIGINT to the command's whole process group, as a terminal's Ctrl-C
does, at moments named by the command's own progress lines (not by a delay, which a busy
second core would shift): the window where a build imports trimesh and matplotlib, each
stage's start, the writing; a batch before its workers are ready, at each design's start.
The unit tests drive :class:`cadgen.processes.Interrupts` with a stand-in for a library
that swallows KeyboardInterrupt (trimesh's ``except BaseException`` around its imports).
"""

from __future__ import annotations

import ast
import json
import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from cadgen.processes import Interrupts, die_with_parent, release_deferred_sigint, sigint_deferred
from cadgen.processes.lifeline import _prctl
from tests.helpers import reference_text, start_studio_build, with_keys

ROOT = Path(__file__).resolve().parents[1]
CADGEN = Path(sys.executable).with_name("cadgen")
POSIX = pytest.mark.skipif(not hasattr(os, "killpg"), reason="process groups (POSIX)")
#: Generous: these bound a hang, not the latency (measured by scripts/interrupt_latency.py).
TIMEOUT = 120


@pytest.fixture(autouse=True)
def sigint_as_in_a_terminal():
    """SIGINT handled as in a foreground command, whatever the suite was started as (a
    background job of a non-interactive shell starts with SIGINT ignored, and so would every
    command the tests start): put back afterwards."""
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, before)


def _foreground():
    """A child's SIGINT as a terminal's foreground job has it: handled (not ignored); and
    the child stops (SIGTERM, taken as Ctrl-C) if the test's process dies first."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    die_with_parent(os.getppid(), signal.SIGTERM)


_prctl()   # looked up here, before any fork (see cadgen.processes.lifeline)


# ----------------------------------------------------------------------------- units
def _swallowing(seconds: float) -> bool:
    """A library that catches everything for ``seconds``; True if it ran to its end."""
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        try:
            time.sleep(0.002)
        except BaseException:
            pass
    return True


def _build_like(swallow_seconds: float, work_seconds: float) -> bool:
    """A build: an import that swallows everything (trimesh's ``except BaseException``
    around its optional imports), then normal work; True if it ran to its end."""
    try:
        time.sleep(swallow_seconds)
    except BaseException:
        pass
    end = time.monotonic() + work_seconds
    while time.monotonic() < end:
        time.sleep(0.01)
    return True


@POSIX
def test_an_interrupt_a_library_swallows_is_raised_again():
    with Interrupts(repeat_seconds=0.05) as interrupts:
        threading.Timer(0.1, os.kill, (os.getpid(), signal.SIGINT)).start()
        with pytest.raises(KeyboardInterrupt):
            _build_like(1.0, 60.0)   # the swallowed interrupt must not let it run on
        assert interrupts.seen


@POSIX
def test_a_second_interrupt_does_not_cut_a_cleanup_short():
    steps = []
    with Interrupts(repeat_seconds=0.01) as interrupts:
        with pytest.raises(KeyboardInterrupt):
            try:
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(10)   # interrupted here
            finally:
                # a second Ctrl-C while the first unwinds, and time for the watchdog to look
                os.kill(os.getpid(), signal.SIGINT)
                for step in range(20):
                    time.sleep(0.01)
                    steps.append(step)
        interrupts.stopping = True
    assert steps == list(range(20))


@POSIX
def test_an_inactive_process_only_remembers_the_interrupt():
    busy = {"now": False}
    with Interrupts(repeat_seconds=0.01, active=lambda: busy["now"]) as interrupts:
        os.kill(os.getpid(), signal.SIGINT)
        assert _swallowing(0.2)   # idle: nothing raised, not even by the watchdog
        assert interrupts.seen
        busy["now"] = True
        with pytest.raises(KeyboardInterrupt):   # then busy: the watchdog raises it
            _build_like(0.0, 60.0)
        busy["now"] = False


@POSIX
def test_a_child_started_while_sigint_is_deferred_holds_it_until_released():
    # the child reports what it sees: SIGINT pending (not delivered) until it releases it
    code = ("import os, signal, sys, time\n"
            "signal.signal(signal.SIGINT, lambda *a: print('handled', flush=True))\n"
            "print('ready', flush=True); sys.stdin.readline()\n"
            "print('pending' if signal.SIGINT in signal.sigpending() else 'none', flush=True)\n"
            "from cadgen.processes import release_deferred_sigint\n"
            "release_deferred_sigint(); time.sleep(0.2)\n")
    with sigint_deferred():
        child = subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.PIPE,
                                 preexec_fn=_foreground,
                                 stdout=subprocess.PIPE, text=True)
    try:
        assert _readline(child.stdout, TIMEOUT).strip() == "ready"
        child.send_signal(signal.SIGINT)
        out, _ = child.communicate("go\n", timeout=TIMEOUT)
    finally:
        _end(child)
    assert out.split() == ["pending", "handled"]
    assert child.returncode == 0


@POSIX
def test_the_deferred_sigint_of_this_thread_arrives_as_the_block_ends():
    held = False
    with Interrupts() as interrupts:
        with pytest.raises(KeyboardInterrupt):
            with sigint_deferred():
                # to this thread (a signal to the process may go to another thread, which
                # does not block it: the block is for the children started in this one)
                signal.pthread_kill(threading.get_ident(), signal.SIGINT)
                time.sleep(0.05)   # held back: nothing raised in the block
                held = True
        interrupts.stopping = True
    assert held and interrupts.seen
    release_deferred_sigint()   # (unblocked already: harmless)


# ----------------------------------------------------------------------------- commands
def _readline(stream, timeout: float) -> str:
    """The next line of ``stream``, read in a thread: a child that never writes it fails
    the test after ``timeout`` rather than hanging the suite."""
    lines: list = []
    reader = threading.Thread(target=lambda: lines.append(stream.readline()), daemon=True)
    reader.start()
    reader.join(timeout)
    assert lines, f"no line within {timeout} s"
    return lines[0]


def _end(process) -> None:
    """Whatever the test's outcome: the process's group killed if it still runs, reaped."""
    if process.poll() is None:
        try:
            os.killpg(process.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):   # not a group leader: itself
            process.kill()
    process.wait(TIMEOUT)


def _alive_in_group(group: int) -> list[str]:
    """The processes of ``group`` still alive (zombies are dead), read from /proc."""
    alive = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:
            continue
        fields = stat[stat.rindex(")") + 2:].split()   # state, ppid, pgrp, ...
        if int(fields[2]) == group and fields[0] != "Z":
            alive.append(f"{entry.name} {stat[:stat.rindex(')') + 1]}")
    return alive


def interrupt_at(args, moment: str, tmp_path: Path, after: float = 0.0):
    """Run the real script in its own process group and SIGINT the group once a stderr line
    matches ``moment`` (then ``after`` s more): (exit code, stderr, signalled?)."""
    process = subprocess.Popen([str(CADGEN), *map(str, args)], cwd=tmp_path,
                               preexec_fn=_foreground,
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                               start_new_session=True)
    lines, signalled = [], threading.Event()

    def read():
        for line in process.stderr:
            lines.append(line)
            if not signalled.is_set() and re.search(moment, line):
                time.sleep(after)
                try:
                    os.killpg(process.pid, signal.SIGINT)
                    signalled.set()
                except ProcessLookupError:   # it ended first
                    pass

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    try:   # bounded: a command that does not end fails the test, not the whole suite
        process.wait(timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        _end(process)
        raise AssertionError(f"did not end within {TIMEOUT} s of the start:\n"
                             f"{''.join(lines)[-3000:]}") from None
    reader.join(TIMEOUT)
    deadline = time.monotonic() + 2.0    # every process it started ends with it
    while _alive_in_group(process.pid) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not _alive_in_group(process.pid), _alive_in_group(process.pid)
    return process.returncode, "".join(lines), signalled.is_set()


def _no_traceback_and_one_line(stderr: str) -> None:
    assert "Traceback" not in stderr and "Error" not in stderr, stderr[-3000:]
    lines = [line for line in stderr.splitlines() if not line.startswith("[")]  # progress
    assert lines == ["cadgen: interrupted"], stderr[-3000:]


PLANTER = ROOT / "params" / "xin2024-planter.toml"
#: Build moments: the window where trimesh and matplotlib are imported (between the
#: drivetrain's end and the teeth's start), each later stage's start, and the writing.
BUILD_MOMENTS = [("drivetrain: ok", 0.0), ("drivetrain: ok", 0.15), ("teeth: started", 0.0),
                 ("parts: started", 0.0), (r"plots: (started|1/)", 0.0),
                 ("write: started", 0.0)]


@POSIX
@pytest.mark.parametrize("moment, after", BUILD_MOMENTS,
                         ids=[f"{m.split(':')[0]}+{a}s" for m, a in BUILD_MOMENTS])
def test_ctrl_c_during_a_build_leaves_nothing(moment, after, tmp_path):
    out = tmp_path / "out"
    code, stderr, signalled = interrupt_at(
        ["build", PLANTER, "--output-dir", out, "--no-cache"], moment, tmp_path, after)
    assert signalled, stderr[-2000:]
    assert code == 130, stderr[-3000:]
    _no_traceback_and_one_line(stderr)
    left = sorted(p.name for p in out.iterdir()) if out.exists() else []
    if left:   # the signal came as the folder was swapped in (the commit): it is whole
        assert left == ["xin2024-planter"], left   # no staging folder, no retired one
        report = json.loads((out / left[0] / "report.json").read_text(encoding="utf-8"))
        assert all((out / left[0] / file).is_file() for file in report["files"])
    else:
        assert not re.search(r"write: ok", stderr), stderr   # written, then lost?


GRID = ROOT / "params" / "grids" / "l2-sweep.toml"
#: Batch moments: before any design starts (workers still importing), as the first and
#: the second design start; each design a full build.
BATCH_MOMENTS = [(r"^\[0/\d+\]", 0.0), ("started l2-sweep-001", 0.0),
                 ("started l2-sweep-002", 0.3)]


def _check_batch_interrupted(code, stderr, signalled, out):
    assert signalled, stderr[-2000:]
    assert code == 130, stderr[-3000:]
    _no_traceback_and_one_line(stderr)
    left = sorted(p.name for p in out.iterdir()) if out.exists() else []
    assert not [name for name in left if name.startswith(".")], left   # no staging
    for name in left:   # a design already built is whole (every file its report lists);
        # it may have been swapped in as the signal came, before the batch heard of it
        report = json.loads((out / name / "report.json").read_text(encoding="utf-8"))
        assert all((out / name / file).is_file() for file in report["files"]), name
    return left


@POSIX
@pytest.mark.parametrize("moment, after", BATCH_MOMENTS, ids=["queued", "first", "second"])
def test_ctrl_c_stops_a_batch(moment, after, tmp_path):
    out = tmp_path / "out"
    code, stderr, signalled = interrupt_at(
        ["batch", "--grid", GRID, "--output-dir", out, "--workers", "2"], moment, tmp_path,
        after)
    _check_batch_interrupted(code, stderr, signalled, out)


@POSIX
def test_ctrl_c_after_a_design_finished_keeps_it_whole(tmp_path):
    # metrics-only designs (quick), interrupted as the first one is reported done
    base = tmp_path / "base.toml"
    base.write_text(with_keys(reference_text(), "scene", effects='["metrics"]'),
                    encoding="utf-8")
    grid = tmp_path / "grid.toml"
    grid.write_text(f'base = "{base.name}"\nname = "quick"\n[grid]\n'
                    f'"planter.L2" = [180.0, 182.0, 184.0, 186.0, 188.0, 190.0, 192.0, 194.0]\n',
                    encoding="utf-8")
    out = tmp_path / "out"
    code, stderr, signalled = interrupt_at(
        ["batch", "--grid", grid, "--output-dir", out, "--workers", "2"], r"^\[1/8\] quick",
        tmp_path)
    left = _check_batch_interrupted(code, stderr, signalled, out)
    assert left and len(left) < 8


@POSIX
def test_ctrl_c_stops_an_optimisation(tmp_path):
    study = ROOT / "params" / "studies" / "planter-margins.toml"
    code, stderr, signalled = interrupt_at(
        ["optimize", study, "--workers", "2", "--output-dir", tmp_path / "out"],
        r"generation 1\b", tmp_path)
    assert signalled and code == 130, stderr[-3000:]
    _no_traceback_and_one_line(stderr)
    assert not (tmp_path / "out").exists() or list((tmp_path / "out").iterdir()) == []


def _descendants(pid: int) -> set[int]:
    """Every process descended from ``pid``, from /proc (whatever group it leads)."""
    parents = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            parents[int(entry.name)] = int(stat[stat.rindex(")") + 2:].split()[1])
    found, frontier = set(), {pid}
    while frontier:
        frontier = {child for child, parent in parents.items() if parent in frontier} - found
        found |= frontier
    return found


def _alive(pid: int) -> bool:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat[stat.rindex(")") + 2] != "Z"


@POSIX
@pytest.mark.parametrize("moment", ["drivetrain", "teeth"])
def test_ctrl_c_stops_the_studio_and_its_build(moment, tmp_path):
    server = subprocess.Popen([str(CADGEN), "studio", PLANTER, "--no-browser", "--output-dir",
                               str(tmp_path / "out")], cwd=tmp_path, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True, start_new_session=True,
                              preexec_fn=_foreground)
    try:
        url = re.search(r"http://\S+", _readline(server.stdout, TIMEOUT)).group(0)
        start_studio_build(url, moment, timeout=TIMEOUT)
        started = _descendants(server.pid)   # the build's process and its workers
        assert started
        os.killpg(server.pid, signal.SIGINT)
        _, stderr = server.communicate(timeout=TIMEOUT)
    finally:
        _end(server)
    assert server.returncode == 130, stderr[-3000:]
    assert "Traceback" not in stderr and stderr.strip().splitlines()[-1] == "cadgen: interrupted", \
        stderr[-6000:]
    deadline = time.monotonic() + 2.0
    while any(_alive(pid) for pid in started) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not [pid for pid in started if _alive(pid)]
    out = tmp_path / "out"
    assert not out.exists() or not [p for p in out.iterdir() if p.name != ".gitkeep"], \
        list(out.iterdir())


@POSIX
def test_an_interrupt_another_thread_takes_inside_a_deferred_block_comes_at_its_end():
    # the block holds SIGINT back in this thread only; a thread that does not block it may
    # take the signal, and its Python handler runs here: it must wait for the block's end
    # (a pool half made there once leaked a semaphore)
    waiting = threading.Event()
    other = threading.Thread(target=waiting.wait, args=(5,), daemon=True)
    other.start()
    steps = []
    with Interrupts() as interrupts:
        with pytest.raises(KeyboardInterrupt):
            with sigint_deferred():
                signal.pthread_kill(other.ident, signal.SIGINT)
                for step in range(10):
                    time.sleep(0.01)
                    steps.append(step)
        interrupts.stopping = True
    waiting.set()
    assert steps == list(range(10)) and interrupts.seen


@POSIX
def test_an_idle_process_only_remembers_an_interrupt_taken_in_a_deferred_block():
    # an idle batch worker (active() false) remembers a Ctrl-C and starts no further design;
    # the block's end must not raise it either
    waiting = threading.Event()
    other = threading.Thread(target=waiting.wait, args=(5,), daemon=True)
    other.start()
    raised = False
    with Interrupts(active=lambda: False) as interrupts:
        try:
            with sigint_deferred():
                signal.pthread_kill(other.ident, signal.SIGINT)
                for _ in range(10):
                    time.sleep(0.01)
            time.sleep(3 * interrupts.repeat_seconds)   # nor the watchdog after it
        except KeyboardInterrupt:
            raised = True
        interrupts.stopping = True
    waiting.set()
    assert interrupts.seen and not raised


#: In a fresh interpreter: _decimal's initialiser imports numbers (Python code run from the
#: extension's init, as manifold3d's imports numpy); a SIGINT sent there must wait for the
#: import's end (raised in a pybind11/nanobind initialiser it aborts the process).
_INTERRUPT_INSIDE_AN_EXTENSION_INIT = """
import os, signal, sys, time
from cadgen.processes import Interrupts
from cadgen.processes.interrupts import _initialising_extension

seen = []

class Finder:
    def find_spec(self, name, path=None, target=None):
        seen.append((name, _initialising_extension(sys._getframe())))
        if name == "numbers":
            os.kill(os.getpid(), signal.SIGINT)
            for _ in range(200000):   # bytecodes, where a handler would raise
                pass
        return None

with Interrupts() as interrupts:
    sys.meta_path.insert(0, Finder())
    assert "_decimal" not in sys.modules and "numbers" not in sys.modules
    try:
        import _decimal
        imported = True
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:   # the watchdog raises it again here
            pass
        print("not interrupted")
    except KeyboardInterrupt:
        print("interrupted", "imported" if "_decimal" in sys.modules else "not imported")
    interrupts.stopping = True
print(seen)
"""


@POSIX
def test_an_interrupt_inside_an_extension_modules_initialiser_comes_after_it():
    result = subprocess.run([sys.executable, "-S", "-c", _INTERRUPT_INSIDE_AN_EXTENSION_INIT],
                            cwd=ROOT, env={**os.environ, "PYTHONPATH": str(ROOT)},
                            capture_output=True, text=True, timeout=TIMEOUT,
                            preexec_fn=_foreground)
    assert result.returncode == 0, result.stderr
    outcome, seen = result.stdout.splitlines()
    assert outcome == "interrupted imported"
    # the import of _decimal itself is not inside an initialiser; numbers' is
    seen = ast.literal_eval(seen)
    assert ("_decimal", False) in seen and ("numbers", True) in seen
