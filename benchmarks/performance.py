"""Performance of the build, the certified sweep and batch builds, measured in one run.

Run:  python -m benchmarks.performance [--output docs/performance.md] [--quick]

1. **Full build** of the paper's planting design with every effect (``cadgen build``
   in a fresh interpreter: the whole process, imports included), best and median
   of 3, with the stage times of the last run, with the gear cache cold (emptied
   before each run) and warm (its entries from the run before). Aim: under 3 s on
   2 cores, cold. The benchmark's cache is a temporary directory (``CADGEN_CACHE_DIR``),
   never the user's.
2. **Metrics-only scene** (``--effects metrics``), best and median of 5. Aim: 0.5 s.
3. **Certified sweep against a plain 3600-pose scan**, both clearances of the
   paper's assembly with the build's own scenes and bounds (blades included), each
   against a reference (the certified sweep at ``atol`` 1e-10 mm): time, ratio, error.
4. **Batch throughput**: ``cadgen batch`` over a grid of 4 variants of the paper's
   design (every effect), on 1 and on 2 worker processes: designs per minute and
   the speed-up.

Times are wall times on this machine; the figures in docs/performance.md were
taken on the project's 2-core reference machine.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from ._paper import PARAMS, REPO


#: The benchmark's own gear cache (set in :func:`main`), emptied for a cold run.
_CACHE: dict = {}


def _cadgen(*args, cwd=None) -> float:
    """Wall time (s) of one ``cadgen`` command in a fresh interpreter."""
    environment = dict(os.environ)
    if "directory" in _CACHE:
        environment["CADGEN_CACHE_DIR"] = str(_CACHE["directory"])
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "cadgen", *args], check=False, cwd=cwd,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=environment)
    return time.perf_counter() - start


def _empty_cache() -> None:
    import shutil

    shutil.rmtree(_CACHE["directory"], ignore_errors=True)


def build_times(root: Path, repeat: int, effects=None, cache: str = "cold") -> dict:
    """Wall times of ``repeat`` builds; ``cache`` "cold" empties the gear cache before each,
    "warm" fills it with one build first."""
    runs = []
    if cache == "warm":
        _empty_cache()
        _cadgen("build", str(PARAMS), "--output-dir", str(root))
    for _ in range(repeat):
        args = ["build", str(PARAMS), "--output-dir", str(root)]
        if effects:
            args += ["--effects", effects]
        if cache == "cold":
            _empty_cache()
        runs.append(_cadgen(*args))
    report = json.loads((root / "xin2024-planter" / "report.json").read_text())
    return {"best": min(runs), "median": statistics.median(runs), "runs": runs,
            "stages": {s["stage"]: s["seconds"] for s in report["stages"]}}


def sweep_table() -> list:
    """``[(clearance, method, minimum, error, poses, seconds)]`` with the build's own bounds."""
    from cadgen.pipeline.clearances import SWEEP_ATOL, SWEEP_STEPS
    from cadgen.sweep.search import certified_distance, plain_scan

    from ._paper import sweep_cases

    cases = sweep_cases()
    rows = []
    for label, scene_of, lipschitz, accel, upper in cases:
        reference = certified_distance(scene_of(), lipschitz=lipschitz, acceleration=accel,
                                       upper=upper, atol=1e-10, steps=SWEEP_STEPS)
        scene = scene_of()
        start = time.perf_counter()
        certified = certified_distance(scene, lipschitz=lipschitz, acceleration=accel,
                                       upper=upper, atol=SWEEP_ATOL, steps=SWEEP_STEPS)
        certified_seconds = time.perf_counter() - start
        scene = scene_of()
        start = time.perf_counter()
        plain, _ = plain_scan(scene, poses=3600)
        plain_seconds = time.perf_counter() - start
        rows.append((label, "certified (build default)", certified.minimum,
                     abs(certified.minimum - reference.minimum), certified.evaluations,
                     certified_seconds))
        rows.append((label, "plain scan, 3600 poses over a turn", plain,
                     abs(plain - reference.minimum), 3600, plain_seconds))
        print(f"{label}: certified {certified.minimum:.9f} in {certified_seconds:.2f} s "
              f"({certified.evaluations} poses), plain {plain:.9f} in {plain_seconds:.2f} s, "
              f"reference {reference.minimum:.12f}", flush=True)
    return rows


GRID = """base = "{base}"
name = "perf"
[grid]
"planter.L2" = [186.0, 188.0, 190.0, 192.0]
"""


def batch_table(root: Path) -> list:
    """``[(workers, designs, seconds, designs per minute)]``."""
    grid = root / "grid.toml"
    grid.write_text(GRID.format(base=PARAMS.as_posix()))
    rows = []
    for workers in (1, 2):
        _empty_cache()   # cold: the batch's first designs cut the gears the others find
        seconds = _cadgen("batch", "--grid", str(grid), "--workers", str(workers),
                          "--output-dir", str(root / f"w{workers}"))
        rows.append((workers, 4, seconds, 4 / seconds * 60.0))
        print(f"batch of 4 on {workers} worker(s): {seconds:.1f} s", flush=True)
    return rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", type=Path, default=REPO / "docs" / "performance.md")
    parser.add_argument("--quick", action="store_true", help="one run of each build, no batch")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as folder:
        root = Path(folder)
        _CACHE["directory"] = root / "gear-cache"
        full = build_times(root / "full", 1 if args.quick else 3)
        print(f"full build: best {full['best']:.2f} s, median {full['median']:.2f} s", flush=True)
        warm = build_times(root / "warm", 1 if args.quick else 3, cache="warm")
        print(f"full build, warm gear cache: best {warm['best']:.2f} s, median "
              f"{warm['median']:.2f} s", flush=True)
        metrics = build_times(root / "metrics", 1 if args.quick else 5, effects="metrics")
        print(f"metrics only: best {metrics['best']:.2f} s, median {metrics['median']:.2f} s",
              flush=True)
        sweeps = sweep_table()
        batch = [] if args.quick else batch_table(root)
    cores = os.cpu_count()
    lines = ["# Performance", "",
             "Generated by `python -m benchmarks.performance` (do not edit by hand) on a "
             f"{cores}-core machine. Whole-process wall times: `cadgen build` in a fresh "
             "interpreter, imports included.", "",
             "## Build of the paper's planting design", "",
             "| scene | aim | best (s) | median (s) | runs |", "|---|---:|---:|---:|---:|",
             f"| every effect (default scene), gear cache cold | 3 s | {full['best']:.2f} | "
             f"{full['median']:.2f} | {len(full['runs'])} |",
             f"| every effect, gear cache warm | | {warm['best']:.2f} | {warm['median']:.2f} | "
             f"{len(warm['runs'])} |",
             f"| metrics only (`--effects metrics`) | 0.5 s | {metrics['best']:.2f} | "
             f"{metrics['median']:.2f} | {len(metrics['runs'])} |", "",
             "Stages of the full build (last run, seconds; the rest of the wall time is "
             "interpreter start, imports and writing the files), cold and warm gear cache:", "",
             "| stage | cold (s) | warm (s) |", "|---|---:|---:|"]
    lines += [f"| {stage} | {seconds:.3f} | {warm['stages'].get(stage, float('nan')):.3f} |"
              for stage, seconds in full["stages"].items()]
    lines += ["", "## Certified sweep against a plain scan", "",
              "The build's own scenes and bounds; reference: the certified sweep at atol "
              "1e-10 mm. The arm distance repeats every half turn, which the certified sweep "
              "uses and a plain scan of a turn does not.", "",
              "| clearance | method | minimum (mm) | error (mm) | poses | time (s) | "
              "time vs certified |", "|---|---|---:|---:|---:|---:|---:|"]
    for index, (label, method, value, error, poses, seconds) in enumerate(sweeps):
        base = sweeps[index - index % 2][5]
        lines.append(f"| {label} | {method} | {value:.9f} | {error:.1e} | {poses} | "
                     f"{seconds:.2f} | {seconds / base:.1f} |")
    if batch:
        lines += ["", "## Batch throughput", "",
                  "`cadgen batch` over a grid of 4 variants of the paper's design (L2 = 186 to "
                  "192 mm), every effect, local processes, the gear cache emptied before each "
                  "batch (the first designs cut the gears, the others find them).", "",
                  "| workers | designs | wall (s) | designs per minute | speed-up |",
                  "|---:|---:|---:|---:|---:|"]
        for workers, count, seconds, rate in batch:
            lines.append(f"| {workers} | {count} | {seconds:.1f} | {rate:.1f} | "
                         f"{batch[0][2] / seconds:.2f} |")
    lines.append("")
    args.output.parent.mkdir(parents=True, exist_ok=True)
    args.output.write_text("\n".join(lines))
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
