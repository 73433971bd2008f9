"""How long Ctrl-C takes to end each command, at many moments of its run; and, with
``--kill``, how long the processes a command started outlive it when it is killed.

    python scripts/interrupt_latency.py [--busy] [--kill] [--delays 0.2,0.4,...]
                                        [--commands build,batch]

Starts the installed ``cadgen`` in a process group of its own (as a terminal runs a foreground
job), sends SIGINT to the whole group after each delay (as Ctrl-C does), and measures the time
from the signal to the command's exit; checks the exit (130), the one line on stderr, that no
output folder or staging folder was left (batch: only designs already built), and that no
process of the group is alive a second later. ``--busy`` runs a CPU-bound process on one core
meanwhile. Prints one line per run and a summary per command (median and largest time).

``--kill`` sends SIGKILL to the command's own process instead (the studio: once it has started
a build) and measures the time until no process it started is alive (found by a tag in their
environment, in /proc every 5 ms); checks that none took more than 5 s and that no staging
folder was left but a lone build's own (it cannot remove it, killed; a batch's designs and the
studio's build remove theirs as they end).
"""

from __future__ import annotations

import argparse
import contextlib
import os
import re
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
import uuid
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from tests.helpers import TAG_VARIABLE, start_studio_build, tagged_processes  # noqa: E402

CADGEN = Path(sys.executable).with_name("cadgen")
COMMANDS = {
    "build": ["build", str(ROOT / "params" / "xin2024-planter.toml"), "--no-cache"],
    "batch": ["batch", "--grid", str(ROOT / "params" / "grids" / "l2-sweep.toml"),
              "--workers", "2"],
    "optimize": ["optimize", str(ROOT / "params" / "studies" / "planter-margins.toml"),
                 "--workers", "2"],
    "studio": ["studio", str(ROOT / "params" / "xin2024-planter.toml"), "--no-browser"],
}
DELAYS = (0.3, 0.6, 0.9, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0)
#: ``--kill``: longer than this for the last process to end is a failure (as in the tests).
KILL_LIMIT_SECONDS = 5.0


def _alive_in_group(group: int) -> list[str]:
    alive = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            fields = stat[stat.rindex(")") + 2:].split()
            if int(fields[2]) == group and fields[0] != "Z":
                alive.append(entry.name)
    return alive


def once(command: str, delay: float) -> dict:
    folder = Path(tempfile.mkdtemp(prefix="cadgen-interrupt-"))
    out = folder / "out"
    process = subprocess.Popen([str(CADGEN), *COMMANDS[command], "--output-dir", str(out)],
                               cwd=folder, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True, start_new_session=True)
    time.sleep(delay)
    signalled = time.perf_counter()
    try:
        os.killpg(process.pid, signal.SIGINT)
    except ProcessLookupError:
        pass
    _, stderr = process.communicate(timeout=300)
    seconds = time.perf_counter() - signalled
    time.sleep(1.0)
    alive = _alive_in_group(process.pid)
    lines = [line for line in stderr.splitlines() if not line.startswith("[")]
    left = sorted(p.name for p in out.iterdir()) if out.exists() else []
    stray = [name for name in left if name.startswith(".")] if command == "batch" else left
    shutil.rmtree(folder, ignore_errors=True)
    good = (process.returncode == 130 and lines == ["cadgen: interrupted"] and not stray
            and not alive)
    return {"command": command, "delay": delay, "seconds": seconds, "good": good,
            "exit": process.returncode, "lines": lines[:3], "left": stray, "alive": alive}


def killed(command: str, delay: float) -> dict:
    """SIGKILL the command's own process after ``delay``: how long its processes outlive it."""
    folder = Path(tempfile.mkdtemp(prefix="cadgen-orphans-"))
    out = folder / "out"
    tag = uuid.uuid4().hex
    process = subprocess.Popen([str(CADGEN), *COMMANDS[command], "--output-dir", str(out)],
                               cwd=folder, env={**os.environ, TAG_VARIABLE: tag},
                               stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                               start_new_session=True)
    try:
        if command == "studio":
            url = re.search(r"http://\S+", process.stdout.readline()).group(0)
            start_studio_build(url, None, timeout=120)
        time.sleep(delay)
        before = len(tagged_processes(tag))
        process.kill()
        signalled = time.perf_counter()
        process.wait(120)
        while (alive := tagged_processes(tag)) and time.perf_counter() - signalled < 60:
            time.sleep(0.005)
        seconds = time.perf_counter() - signalled
        left = sorted(p.name for p in out.iterdir() if p.name.startswith(".")) \
            if out.exists() else []
    finally:
        for line in tagged_processes(tag):
            with contextlib.suppress(OSError):
                os.kill(int(line.split()[0]), signal.SIGKILL)
        if process.poll() is None:
            process.kill()
            process.wait()
        shutil.rmtree(folder, ignore_errors=True)
    stray = [] if command == "build" else left   # a lone build's own staging folder
    return {"command": command, "delay": delay, "seconds": seconds, "exit": None,
            "good": not alive and seconds <= KILL_LIMIT_SECONDS and not stray,
            "lines": [f"{before} processes"], "left": left, "alive": alive}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--busy", action="store_true", help="keep one core busy meanwhile")
    parser.add_argument("--delays", default=",".join(map(str, DELAYS)))
    parser.add_argument("--commands", default=",".join(COMMANDS))
    parser.add_argument("--kill", action="store_true",
                        help="SIGKILL the command's process: time until its children end")
    args = parser.parse_args(argv)
    run_once, what = (killed, "killed") if args.kill else (once, "signal")
    hog = (subprocess.Popen([sys.executable, "-c", "while True: pass"]) if args.busy else None)
    try:
        runs = []
        for command in args.commands.split(","):
            for delay in map(float, args.delays.split(",")):
                run = run_once(command, delay)
                runs.append(run)
                print(f"{'ok ' if run['good'] else 'BAD'} {command:<8} {what} at {delay:4.1f} s: "
                      f"ended {run['seconds']:.3f} s later, "
                      + (f"exit {run['exit']}" if run["exit"] is not None else run["lines"][0])
                      + ("" if run["good"] else f" {run['lines']} left {run['left']} alive "
                                                f"{run['alive']}"), flush=True)
    finally:
        if hog is not None:
            hog.kill()
            hog.wait()
    print()
    for command in dict.fromkeys(r["command"] for r in runs):
        times = [r["seconds"] for r in runs if r["command"] == command]
        bad = sum(not r["good"] for r in runs if r["command"] == command)
        print(f"{command:<8} {len(times)} runs{' (one core busy)' if args.busy else ''}: "
              f"median {statistics.median(times):.3f} s, largest {max(times):.3f} s, "
              f"{bad} not clean")
    return 1 if any(not r["good"] for r in runs) else 0


if __name__ == "__main__":
    raise SystemExit(main())
