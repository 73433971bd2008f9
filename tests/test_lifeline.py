"""No orphans: every process cadgen starts ends with the process that started it.

The end-to-end tests start a command with a tag in its environment (every process it
starts inherits it), kill the command's own process with SIGKILL (nothing of it runs
after: no handler, no cleanup) at a moment named by its progress, its output folder or
the studio's events, then look in /proc, not at anything the command kept, for a process
still carrying the tag. They allow :data:`GONE_SECONDS` for the last one to end (it takes
a few hundredths of a second on an idle machine: the kernel sends the parent-death signal
as the parent dies, and a lifeline pipe ends at once), polling, so a busy core does not
fail them. SIGTERM and SIGHUP end a command as Ctrl-C does, with 128 + the signal's number.
The unit tests drive :mod:`cadgen.processes.lifeline` with small stand-ins.
"""

from __future__ import annotations

import json
import os
import queue
import re
import signal
import subprocess
import sys
import textwrap
import threading
import time
import uuid
from pathlib import Path

import pytest

from cadgen.processes import lifeline as lifeline_module
from cadgen.processes import stop_pool, watch_lifeline
from tests.helpers import (TAG_VARIABLE, reference_text, start_studio_build,
                           tagged_processes, with_keys)

ROOT = Path(__file__).resolve().parents[1]
CADGEN = Path(sys.executable).with_name("cadgen")
PLANTER = ROOT / "params" / "xin2024-planter.toml"
LINUX = pytest.mark.skipif(not sys.platform.startswith("linux"),
                           reason="reads /proc; the parent-death signal is Linux's")
#: Bounds a hang (a moment that never comes, a command that does not end), not a latency.
TIMEOUT = 120
#: How long the last tagged process may take to end once its ancestor was killed: generous
#: (it takes hundredths of a second), so a core held by another process does not fail it.
GONE_SECONDS = 5.0


# ----------------------------------------------------------------------------- /proc
def gone_within(tag: str, seconds: float = GONE_SECONDS) -> float:
    """Seconds until no process carries ``tag`` (polling /proc); fails after ``seconds``."""
    start = time.monotonic()
    while (left := tagged_processes(tag)) and time.monotonic() - start < seconds:
        time.sleep(0.02)
    assert not left, f"alive {seconds:g} s after their ancestor was killed: {left}"
    return time.monotonic() - start


def _dies_with_the_test() -> None:
    """A command the test starts: SIGINT and SIGHUP handled as in a terminal's foreground
    job (whatever the test run ignores), and SIGTERM (it stops as on Ctrl-C) if the test's
    process dies first."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.signal(signal.SIGHUP, signal.SIG_DFL)
    lifeline_module.die_with_parent(os.getppid(), signal.SIGTERM)


lifeline_module._prctl()   # looked up here, before any fork (see _prctl)


class Command:
    """``cadgen ARGS`` in its own session, tagged, its stderr read line by line."""

    def __init__(self, args, tmp_path: Path):
        self.tag = uuid.uuid4().hex
        self.lines: list[str] = []
        self._queue: queue.Queue = queue.Queue()
        self.process = subprocess.Popen(
            [str(CADGEN), *map(str, args)], cwd=tmp_path, text=True,
            env={**os.environ, TAG_VARIABLE: self.tag}, stdout=subprocess.PIPE,
            stderr=subprocess.PIPE, start_new_session=True, preexec_fn=_dies_with_the_test)
        for stream in (self.process.stdout, self.process.stderr):
            threading.Thread(target=self._read, args=(stream,), daemon=True).start()

    def _read(self, stream) -> None:
        for line in stream:
            self._queue.put(line)
        self._queue.put(None)

    def wait_for(self, pattern: str, timeout: float = TIMEOUT) -> str:
        """The first line (stdout or stderr) from now that matches ``pattern``."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                line = self._queue.get(timeout=max(0.0, deadline - time.monotonic()))
            except queue.Empty:
                break
            if line is None:
                break
            self.lines.append(line)
            if re.search(pattern, line):
                return line
        raise AssertionError(f"no line matching {pattern!r} within {timeout} s; "
                             f"exit {self.process.poll()}; output:\n{self.output()[-3000:]}")

    def output(self) -> str:
        while True:
            try:
                line = self._queue.get_nowait()
            except queue.Empty:
                return "".join(self.lines)
            if line is not None:
                self.lines.append(line)

    def kill(self) -> float:
        """SIGKILL the command's own process (not its group); seconds until every process
        it started has ended."""
        os.kill(self.process.pid, signal.SIGKILL)
        self.process.wait(TIMEOUT)
        return gone_within(self.tag)

    def end(self, timeout: float = TIMEOUT) -> int:
        """Wait for the command to end (killed, with everything tagged, if it does not)."""
        try:
            return self.process.wait(timeout)
        except subprocess.TimeoutExpired:
            self.close()
            raise AssertionError(f"did not end within {timeout} s:\n{self.output()[-3000:]}")

    def close(self) -> None:
        """Whatever the test's outcome: nothing tagged left running."""
        for line in tagged_processes(self.tag):
            try:
                os.kill(int(line.split()[0]), signal.SIGKILL)
            except OSError:
                pass
        if self.process.poll() is None:
            self.process.kill()
        self.process.wait(TIMEOUT)


@pytest.fixture
def command(tmp_path):
    started = []

    def start(*args):
        started.append(Command(args, tmp_path))
        return started[-1]

    yield start
    for each in started:
        each.close()


def staging_left(out: Path) -> list[str]:
    """Staging or set-aside folders (``.<name>.staging-...``, ``.<name>.old-...``) in ``out``."""
    return sorted(p.name for p in out.iterdir() if p.name.startswith(".")) if out.exists() \
        else []


def wait_for_staging(out: Path, process, timeout: float = TIMEOUT) -> str:
    """The first staging folder to appear in ``out`` (a build writing its outputs)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and process.poll() is None:
        found = [name for name in staging_left(out) if ".staging-" in name]
        if found:
            return found[0]
        time.sleep(0.005)
    raise AssertionError(f"no staging folder in {out} (exit {process.poll()})")


# ----------------------------------------------------------------------------- units
_MIDDLE = textwrap.dedent("""
    import os, signal, sys, time
    from cadgen.processes.lifeline import _prctl, die_with_parent
    _prctl()
    parent = os.getpid()
    child = os.fork()
    if child == 0:
        if sys.argv[1] == "late":   # the parent dies before the child asks to be told
            while os.getppid() == parent:
                time.sleep(0.01)
        die_with_parent(parent, signal.SIGKILL)
        open(sys.argv[2], "w").close()   # asked in time: it runs on, until its parent dies
        time.sleep(600)
        os._exit(0)
    print(child, flush=True)
    time.sleep(600)
""")


@LINUX
@pytest.mark.parametrize("when", ["set", "late"])
def test_a_child_dies_with_its_parent(when, tmp_path):
    tag, marker = uuid.uuid4().hex, tmp_path / "running"
    middle = subprocess.Popen([sys.executable, "-c", _MIDDLE, when, str(marker)],
                              env={**os.environ, TAG_VARIABLE: tag, "PYTHONPATH": str(ROOT)},
                              stdout=subprocess.PIPE, text=True)
    try:
        child = middle.stdout.readline().strip()
        assert child.isdigit(), child
        if when == "set":
            deadline = time.monotonic() + TIMEOUT
            while not marker.exists() and time.monotonic() < deadline:
                time.sleep(0.01)
            assert marker.exists()
        middle.kill()
        middle.wait(TIMEOUT)
        gone_within(tag)
        assert marker.exists() == (when == "set")   # a late child ends before any work
    finally:
        if middle.poll() is None:
            middle.kill()
            middle.wait(TIMEOUT)
        for line in tagged_processes(tag):
            os.kill(int(line.split()[0]), signal.SIGKILL)


def test_a_lifeline_ends_when_its_write_end_closes():
    reading, writing = os.pipe()
    ended = threading.Event()
    try:
        watch_lifeline(reading, ended.set)
        assert not ended.wait(0.05)
        os.close(writing)
        assert ended.wait(TIMEOUT)
    finally:
        os.close(reading)


def _sleep(seconds: float) -> float:
    time.sleep(seconds)
    return seconds


@LINUX
def test_a_stopped_pool_does_not_wait_for_its_tasks():
    import multiprocessing

    pool = lifeline_module.process_pool(1, multiprocessing.get_context("fork"))
    future = pool.submit(_sleep, 600)
    processes = list(pool._processes.values())
    manager = pool._executor_manager_thread
    stop_pool(pool)
    assert not any(process.is_alive() for process in processes)
    manager.join(TIMEOUT)   # it saw its worker end: nothing holds the process's exit
    assert not manager.is_alive() and future.done()


_STUCK_EXIT = textwrap.dedent("""
    import signal, threading
    import cadgen.cli as cli
    threading.Thread(target=threading.Event().wait).start()   # never ends, not a daemon
    cli.main = lambda: 128 + signal.SIG{name}
    cli.entry()
""")


@pytest.mark.parametrize("name", ["INT", "TERM", "HUP"])
def test_a_stopped_command_does_not_wait_for_a_stuck_thread(name):
    # a pool's manager thread reading a result its killed worker had half sent waits for
    # ever; the interrupted command's exit must not
    result = subprocess.run([sys.executable, "-c", _STUCK_EXIT.replace("{name}", name)],
                            cwd=ROOT, capture_output=True, text=True, timeout=TIMEOUT)
    assert result.returncode == 128 + getattr(signal, f"SIG{name}"), result.stderr


# ----------------------------------------------------------------------------- commands
#: Moments of a build: the worker beside the teeth just forked; the worker making its parts.
BUILD_MOMENTS = ["teeth: started", r"parts \(beside\): started"]
#: A scene whose outputs take long to write (report.html) after a short build: the moment
#: a staging folder exists is easy to catch.
QUICK_SCENE = '["metrics", "curves", "report"]'


@LINUX
@pytest.mark.parametrize("moment", BUILD_MOMENTS, ids=["teeth", "parts"])
def test_a_killed_build_leaves_no_process(moment, command, tmp_path):
    build = command("build", PLANTER, "--output-dir", tmp_path / "out", "--no-cache")
    build.wait_for(moment)
    build.kill()


@LINUX
def test_a_killed_batch_leaves_no_process_and_no_staging(command, tmp_path):
    # killed as a design writes: its worker (sent SIGTERM as the batch dies) kills the
    # design's process group and removes its staging folder, then ends
    base = tmp_path / "base.toml"
    base.write_text(with_keys(reference_text(), "scene", effects=QUICK_SCENE),
                    encoding="utf-8")
    grid = tmp_path / "grid.toml"
    grid.write_text(f'base = "{base.name}"\nname = "quick"\n[grid]\n'
                    '"planter.L2" = [185.0, 190.0]\n', encoding="utf-8")
    out = tmp_path / "out"
    batch = command("batch", "--grid", grid, "--output-dir", out, "--workers", "2")
    wait_for_staging(out, batch.process)
    batch.kill()
    assert staging_left(out) == []


@LINUX
def test_a_batch_killed_while_its_workers_start_leaves_no_process(command, tmp_path):
    batch = command("batch", "--grid", ROOT / "params" / "grids" / "l2-sweep.toml",
                    "--output-dir", tmp_path / "out", "--workers", "2")
    batch.wait_for(r"^\[0/\d+\]")    # the workers still importing
    batch.kill()


@LINUX
def test_a_killed_optimisation_leaves_no_process(command, tmp_path):
    study = ROOT / "params" / "studies" / "planter-margins.toml"
    search = command("optimize", study, "--workers", "2", "--output-dir", tmp_path / "out")
    search.wait_for(r"generation 1\b")
    search.kill()


def _studio_build(studio, moment: str | None, effects: str | None = None) -> None:
    """Start a build from the studio's page API (of the scene ``effects``, a TOML list, if
    given); return once its events reach stage ``moment`` (None: at once)."""
    url = re.search(r"http://\S+", studio.wait_for(r"http://")).group(0)
    start_studio_build(url, moment, timeout=TIMEOUT,
                       effects=json.loads(effects) if effects is not None else None)


def _spare_started(studio) -> None:
    """Wait until the studio has started the next build's process (after a build's end)."""
    deadline = time.monotonic() + TIMEOUT
    while len(tagged_processes(studio.tag)) < 2 and time.monotonic() < deadline:
        time.sleep(0.02)
    assert len(tagged_processes(studio.tag)) >= 2, tagged_processes(studio.tag)


@LINUX
def test_a_killed_studio_leaves_no_build_and_no_staging(command, tmp_path):
    # killed as its build writes: the build's process sees its lifeline end and stops as on
    # the studio's SIGTERM, its staging folder removed
    out = tmp_path / "out"
    studio = command("studio", PLANTER, "--no-browser", "--output-dir", out)
    _studio_build(studio, None, effects=QUICK_SCENE)
    wait_for_staging(out, studio.process)
    studio.kill()
    assert staging_left(out) == []


@LINUX
def test_a_killed_studio_leaves_no_spare(command, tmp_path):
    # the next build's process, importing or waiting for its design, ends at its lifeline's end
    studio = command("studio", PLANTER, "--no-browser", "--output-dir", tmp_path / "out")
    _studio_build(studio, "done", effects=QUICK_SCENE)
    _spare_started(studio)
    studio.kill()


# ----------------------------------------------------------------------------- signals
@LINUX
def test_sigterm_stops_a_build_as_ctrl_c_does(command, tmp_path):
    # to the command alone (a service manager, kill PID): it stops the worker beside its
    # teeth itself; one line, 143, nothing written
    out = tmp_path / "out"
    build = command("build", PLANTER, "--output-dir", out, "--no-cache")
    build.wait_for("teeth: started")
    os.kill(build.process.pid, signal.SIGTERM)
    code = build.end()
    gone_within(build.tag)
    output = build.output()
    assert code == 143, output[-3000:]
    lines = [line for line in output.splitlines() if not line.startswith("[")]   # progress
    assert lines[-1] == "cadgen: terminated by SIGTERM" and "Traceback" not in output, \
        output[-3000:]
    assert staging_left(out) == [] and not (out / "xin2024-planter").exists()


@LINUX
@pytest.mark.parametrize("name", ["SIGTERM", "SIGHUP"])
def test_sigterm_and_sighup_stop_the_studio_and_its_build(name, command, tmp_path):
    # SIGTERM (kill PID) as a build starts: the studio stops it, then ends; SIGHUP (the
    # terminal closed) idle. (Its spare, when one waits, ends with it: see the test above.)
    signum = getattr(signal, name)
    studio = command("studio", PLANTER, "--no-browser", "--output-dir", tmp_path / "out")
    if signum == signal.SIGTERM:
        _studio_build(studio, None, effects=QUICK_SCENE)
    else:
        studio.wait_for(r"http://")
    os.kill(studio.process.pid, signum)
    code = studio.end()
    gone_within(studio.tag)
    assert code == 128 + signum, studio.output()[-3000:]
    assert studio.output().strip().splitlines()[-1] == f"cadgen: terminated by {name}", \
        studio.output()[-3000:]
