"""Run the whole test suite with another CPU-bound process holding one core, several times.

    python scripts/suite_under_load.py [--runs 3] [--no-busy] [pytest arguments ...]

A test that passes only on an idle machine fails a newcomer's first run. This starts a busy
loop (``python -c "while True: pass"``, one core) and runs ``python -m pytest -q`` (the
README's command, every core by pytest-xdist) ``--runs`` times in a row with it, then stops the
loop. Prints each run's result line and wall time and exits 1 if any run failed.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--no-busy", action="store_true", help="no busy loop (the quiet time)")
    args, pytest_args = parser.parse_known_args(argv)
    busy = None if args.no_busy else subprocess.Popen([sys.executable, "-c", "while True: pass"])
    failed = 0
    try:
        for run in range(1, args.runs + 1):
            start = time.perf_counter()
            result = subprocess.run([sys.executable, "-m", "pytest", "-q", *pytest_args],
                                    cwd=ROOT, capture_output=True, text=True)
            seconds = time.perf_counter() - start
            summary = (result.stdout.strip().splitlines() or ["(no output)"])[-1]
            failed += result.returncode != 0
            print(f"run {run}: exit {result.returncode} in {seconds / 60:.1f} min"
                  f"{'' if args.no_busy else ' (one core busy)'}: {summary}", flush=True)
            if result.returncode != 0:
                print("\n".join(line for line in result.stdout.splitlines()
                                if line.startswith(("FAILED", "ERROR"))), flush=True)
    finally:
        if busy is not None:
            busy.kill()
            busy.wait()
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
