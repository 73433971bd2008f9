"""How long Ctrl-C takes to end each command, at many moments of its run.

    python scripts/interrupt_latency.py [--busy] [--delays 0.2,0.4,...] [--commands build,batch]

Starts the installed ``cadgen`` in a process group of its own (as a terminal runs a foreground
job), sends SIGINT to the whole group after each delay (as Ctrl-C does), and measures the time
from the signal to the command's exit; checks the exit (130), the one line on stderr, that no
output folder or staging folder was left (batch: only designs already built), and that no
process of the group is alive a second later. ``--busy`` runs a CPU-bound process on one core
meanwhile. Prints one line per run and a summary per command (median and largest time).
"""

from __future__ import annotations

import argparse
import os
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
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


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--busy", action="store_true", help="keep one core busy meanwhile")
    parser.add_argument("--delays", default=",".join(map(str, DELAYS)))
    parser.add_argument("--commands", default=",".join(COMMANDS))
    args = parser.parse_args(argv)
    hog = (subprocess.Popen([sys.executable, "-c", "while True: pass"]) if args.busy else None)
    try:
        runs = []
        for command in args.commands.split(","):
            for delay in map(float, args.delays.split(",")):
                run = once(command, delay)
                runs.append(run)
                print(f"{'ok ' if run['good'] else 'BAD'} {command:<8} signal at {delay:4.1f} s: "
                      f"ended {run['seconds']:.2f} s later, exit {run['exit']}"
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
              f"median {statistics.median(times):.2f} s, largest {max(times):.2f} s, "
              f"{bad} not clean")
    return 1 if any(not r["good"] for r in runs) else 0


if __name__ == "__main__":
    raise SystemExit(main())
