"""Performance of the build, the certified sweep and batch builds, measured in one run.

Run:  python -m benchmarks.performance [--output docs/performance.md] [--quick]

1. **Against the peer, interleaved**: in each of ``--rounds`` rounds (default 5), in turn,
   ncgears 0.3.1 generating one 24-tooth pair as its own command line does
   (``python -m ncgears --centrode "30 + 8*cos(phi)" --teeth 24 --module 2.5``, whole
   process, in its own virtualenv: :mod:`benchmarks.peer_ncgears`), then the full build
   of the paper's planting design with every effect (``cadgen build`` in a fresh
   interpreter, whole process, imports included) with the gear cache cold (emptied
   before the run), the same with the cache warm (the cold run's entries), and the
   metrics-only scene (``--effects metrics``). Medians, spreads (min-max) and the ratio
   of each median to the peer's. The aims: the cold full build <= 0.35 x the
   peer (0.25 x hoped), metrics only <= 0.05 x. The benchmark's gear cache is a temporary
   directory (``CADGEN_CACHE_DIR``), never the user's. The stage times of the last cold
   and warm builds are printed as a second table.
2. **Certified sweep against a plain 3600-pose scan**, both clearances of the
   paper's assembly with the build's own scenes and bounds (blades included), each
   against a reference (the certified sweep at ``atol`` 1e-10 mm): time, ratio, error.
3. **Accuracy presets**: the full build (gear cache cold) at ``--preset`` draft, standard
   (the default) and fine, three interleaved runs each: what the README's preset table quotes.
4. **What each effect costs**: scenes from metrics only to every effect, each adding
   effects to the one before (gear cache cold, five interleaved runs).
5. **Batch throughput**: ``cadgen batch`` over a grid of 8 variants of the paper's
   design (every effect), on 1 and on 2 worker processes, and on 2 with each build
   forking its worker beside its teeth (the reference for the batch's choice of one
   process per build): designs per minute and the speed-up.

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
    """Wall time (s) of one ``cadgen`` command in a fresh interpreter (its CPU time, user and
    system, its forked worker included, is appended to ``_CPU``)."""
    import resource

    environment = dict(os.environ)
    if "directory" in _CACHE:
        environment["CADGEN_CACHE_DIR"] = str(_CACHE["directory"])
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "cadgen", *args], check=False, cwd=cwd,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=environment)
    seconds = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    _CPU.append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
    return seconds


#: CPU seconds of each :func:`_cadgen` command, in order.
_CPU: list = []


def _empty_cache() -> None:
    import shutil

    shutil.rmtree(_CACHE["directory"], ignore_errors=True)


PEER_ARGS = ("-m", "ncgears", "--centrode", "30 + 8*cos(phi)", "--teeth", "24",
             "--module", "2.5")


def _peer(python: Path) -> float:
    """Wall time (s) of the peer's command line in a fresh interpreter (in a scratch folder:
    it writes its files to the working directory)."""
    import resource

    with tempfile.TemporaryDirectory() as scratch:
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        done = subprocess.run([str(python), *PEER_ARGS], cwd=scratch, stdout=subprocess.DEVNULL,
                              stderr=subprocess.PIPE, text=True)
        seconds = time.perf_counter() - start
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    _CPU.append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
    if done.returncode != 0:
        raise RuntimeError(f"ncgears failed (exit {done.returncode}): {done.stderr.strip()}")
    return seconds


def _stages(folder: Path) -> dict:
    report = json.loads((folder / "xin2024-planter" / "report.json").read_text())
    return {s["stage"]: s["seconds"] for s in report["stages"]}


def interleaved_rounds(root: Path, rounds: int, peer_python: Path | None) -> dict:
    """``{scene: [wall seconds per round]}`` for the peer and the three builds, run in turn in
    each round, and ``"stages"``: the stage times of the last cold and warm builds."""
    times = {"peer": [], "cold": [], "warm": [], "metrics": []}
    cpu = {"peer": [], "cold": [], "warm": [], "metrics": []}
    stages = {}
    args = ["build", str(PARAMS), "--output-dir"]
    for index in range(rounds):
        if peer_python is not None:
            times["peer"].append(_peer(peer_python))
            cpu["peer"].append(_CPU[-1])
        _empty_cache()
        times["cold"].append(_cadgen(*args, str(root / "cold")))
        cpu["cold"].append(_CPU[-1])
        stages["cold"] = _stages(root / "cold")
        times["warm"].append(_cadgen(*args, str(root / "warm")))
        cpu["warm"].append(_CPU[-1])
        stages["warm"] = _stages(root / "warm")
        times["metrics"].append(_cadgen(*args, str(root / "metrics"), "--effects", "metrics"))
        cpu["metrics"].append(_CPU[-1])
        print(f"round {index + 1}/{rounds}: " + ", ".join(
            f"{scene} {runs[-1]:.2f} s" for scene, runs in times.items() if runs), flush=True)
    times["stages"], times["cpu"] = stages, cpu
    return times


def _spread(runs) -> str:
    return f"{min(runs):.2f}-{max(runs):.2f}"


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


def _cold_runs(commands: dict, runs: int) -> dict:
    """``{key: (median wall s, spread, median CPU s)}`` of ``cadgen`` commands (``{key: args}``),
    each run with the gear cache emptied first, interleaved: one run of each per round."""
    walls = {key: [] for key in commands}
    cpus = {key: [] for key in commands}
    for _ in range(runs):
        for key, args in commands.items():
            _empty_cache()
            walls[key].append(_cadgen(*args))
            cpus[key].append(_CPU[-1])
    return {key: (statistics.median(walls[key]), _spread(walls[key]),
                  statistics.median(cpus[key])) for key in commands}


def preset_table(root: Path, runs: int = 3) -> list:
    """``[(preset, median wall s, spread, median CPU s)]``: the full build, cache cold."""
    presets = ("draft", "standard", "fine")
    found = _cold_runs({preset: ("build", str(PARAMS), "--preset", preset, "--output-dir",
                                 str(root / f"preset-{preset}")) for preset in presets}, runs)
    rows = [(preset, *found[preset]) for preset in presets]
    for preset, wall, _, _ in rows:
        print(f"preset {preset}: {wall:.2f} s", flush=True)
    return rows


#: Scenes, each adding effects to the one before: what each effect costs in a build of the
#: paper's design (the last is every effect).
SCENES = (("metrics", "metrics"),
          ("+ teeth (ten pairs cut, checked)", "metrics,teeth"),
          ("+ dxf (cutting files)", "metrics,teeth,dxf"),
          ("+ solids, stl (parts, STLs, assembly)", "metrics,teeth,dxf,solids,stl"),
          ("+ arm_interference, ground_clearance (FCL sweeps)",
           "metrics,teeth,dxf,solids,stl,arm_interference,ground_clearance"),
          ("+ report (report.html)",
           "metrics,teeth,dxf,solids,stl,arm_interference,ground_clearance,report"),
          ("+ plots (every effect)",
           "metrics,teeth,dxf,solids,stl,arm_interference,ground_clearance,report,plots"))


def scene_table(root: Path, runs: int = 5) -> list:
    """``[(label, effects, median wall s, spread, median CPU s)]``: the scenes of
    :data:`SCENES`, gear cache cold, interleaved (one run of each scene per round)."""
    found = _cold_runs({effects: ("build", str(PARAMS), "--effects", effects, "--output-dir",
                                  str(root / "scenes")) for _, effects in SCENES}, runs)
    rows = [(label, effects, *found[effects]) for label, effects in SCENES]
    for label, _, wall, _, used in rows:
        print(f"scene {label}: {wall:.2f} s, CPU {used:.2f} s", flush=True)
    return rows


GRID = """base = "{base}"
name = "perf"
[grid]
"planter.L2" = [186.0, 188.0, 190.0, 192.0, 194.0, 196.0, 198.0, 200.0]
"""
#: Designs of :data:`GRID`.
GRID_DESIGNS = 8

#: The batch of :data:`GRID` through the library with each build forking its worker beside its
#: teeth (``parallel=None``: what every build did before a batch with a design on every core
#: asked ``parallel=False``), in a fresh interpreter as ``cadgen batch`` is.
BESIDE_BATCH = """import sys
from cadgen.batch import expand_grid, run_batch
if __name__ == "__main__":
    run_batch(expand_grid(sys.argv[1]), sys.argv[2], workers=2, build_kwargs={"parallel": None})
"""


def batch_table(root: Path) -> list:
    """``[(label, workers, designs, seconds, designs per minute)]``: ``cadgen batch`` on 1 and
    2 workers, and on 2 with each build forking its worker beside (the reference for the
    batch's choice of ``parallel=False``), each with the gear cache emptied first."""
    grid = root / "grid.toml"
    grid.write_text(GRID.format(base=PARAMS.as_posix()))
    rows = []
    for workers in (1, 2):
        _empty_cache()   # cold: the batch's first designs cut the gears the others find
        seconds = _cadgen("batch", "--grid", str(grid), "--workers", str(workers),
                          "--output-dir", str(root / f"w{workers}"))
        rows.append((f"`cadgen batch --workers {workers}`", workers, GRID_DESIGNS, seconds))
    _empty_cache()
    script = root / "beside_batch.py"
    script.write_text(BESIDE_BATCH)
    environment = dict(os.environ)
    if "directory" in _CACHE:
        environment["CADGEN_CACHE_DIR"] = str(_CACHE["directory"])
    start = time.perf_counter()
    subprocess.run([sys.executable, str(script), str(grid), str(root / "beside")], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=environment)
    rows.append(("2 workers, each build forking its worker beside its teeth", 2, GRID_DESIGNS,
                 time.perf_counter() - start))
    rows = [(*row, row[2] / row[3] * 60.0) for row in rows]
    for label, _, count, seconds, _ in rows:
        print(f"batch of {count}, {label}: {seconds:.1f} s", flush=True)
    return rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", type=Path, default=REPO / "docs" / "performance.md")
    parser.add_argument("--rounds", type=int, default=5, help="interleaved rounds (default 5)")
    parser.add_argument("--quick", action="store_true", help="one round, no sweep table, no batch")
    parser.add_argument("--no-peer", action="store_true",
                        help="skip ncgears (it needs PyPI once, for its virtualenv)")
    args = parser.parse_args(argv)
    # A user's first run writes the bytecode of our modules (pip compiled the peer's at its
    # install); where PYTHONDONTWRITEBYTECODE is set, every run would compile ~200 modules
    # again (0.1-0.3 s), so compile them once here, as the first run would.
    import compileall

    for package in ("cadgen", "kinematics"):
        compileall.compile_dir(REPO / package, quiet=1)
    peer_python = None
    if not args.no_peer:
        from .peer_ncgears import ensure_venv

        peer_python = ensure_venv()
    with tempfile.TemporaryDirectory() as folder:
        root = Path(folder)
        _CACHE["directory"] = root / "gear-cache"
        times = interleaved_rounds(root, 1 if args.quick else args.rounds, peer_python)
        sweeps = [] if args.quick else sweep_table()
        presets = [] if args.quick else preset_table(root)
        scenes = [] if args.quick else scene_table(root)
        batch = [] if args.quick else batch_table(root)
    stages, cpu = times.pop("stages"), times.pop("cpu")
    medians = {scene: statistics.median(runs) for scene, runs in times.items() if runs}
    peer = medians.get("peer")
    cores = os.cpu_count()
    lines = ["# Performance", "",
             "Generated by `python -m benchmarks.performance` (do not edit by hand) on a "
             f"{cores}-core machine. Whole-process wall times, each command in a fresh "
             "interpreter, imports included.", "",
             "## Build of the paper's planting design against the peer", "",
             f"{len(times['cold'])} rounds, interleaved: in each round the peer, then the cold "
             "build, the warm build and the metrics-only build. The peer is ncgears 0.3.1 "
             "generating and verifying ONE 24-tooth pair from its command line "
             "(`python -m ncgears --centrode \"30 + 8*cos(phi)\" --teeth 24 --module 2.5`); "
             "our build cuts, checks and meshes the ten pairs of the whole transmission and does "
             "everything else. "
             "The aims: cold full build <= 0.35 x the peer, metrics only <= 0.05 x "
             "(docs/benchmarks.md says why they are not met). "
             "CPU: user and system time of the command and the worker it forks, median.", "",
             "| command | median (s) | spread (s) | x peer (medians) | x peer, each round "
             "(min-max) | aim | CPU (s) |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    labels = {"peer": ("ncgears 0.3.1, one pair (the peer)", ""),
              "cold": ("`cadgen build`, every effect, gear cache cold", "0.35"),
              "warm": ("`cadgen build`, every effect, gear cache warm", ""),
              "metrics": ("`cadgen build --effects metrics`", "0.05")}
    for scene, runs in times.items():
        if not runs:
            continue
        ratio = f"{medians[scene] / peer:.3f}" if peer else "n/a"
        # the machine's speed drifts within a run: each round's ratio, against its own peer
        rounds = [mine / theirs for mine, theirs in zip(runs, times["peer"])]
        each = f"{min(rounds):.3f}-{max(rounds):.3f}" if peer else "n/a"
        label, aim = labels[scene]
        used = f"{statistics.median(cpu[scene]):.2f}" if cpu.get(scene) else ""
        lines.append(f"| {label} | {medians[scene]:.2f} | {_spread(runs)} | {ratio} | {each} "
                     f"| {aim} | {used} |")
    lines += ["", "Stages of the last cold and warm full builds (seconds; the rest of the wall "
              "time is interpreter start, imports and writing the files):", "",
              "| stage | cold (s) | warm (s) |", "|---|---:|---:|"]
    lines += [f"| {stage} | {seconds:.3f} | {stages['warm'].get(stage, float('nan')):.3f} |"
              for stage, seconds in stages["cold"].items()]
    if sweeps:
        lines += ["", "## Certified sweep against a plain scan", "",
                  "The build's own scenes and bounds; reference: the certified sweep at atol "
                  "1e-10 mm. The arm distance repeats every half turn, which the certified "
                  "sweep uses and a plain scan of a turn does not.", "",
                  "| clearance | method | minimum (mm) | error (mm) | poses | time (s) | "
                  "time vs certified |", "|---|---|---:|---:|---:|---:|---:|"]
    for index, (label, method, value, error, poses, seconds) in enumerate(sweeps):
        base = sweeps[index - index % 2][5]
        lines.append(f"| {label} | {method} | {value:.9f} | {error:.1e} | {poses} | "
                     f"{seconds:.2f} | {seconds / base:.1f} |")
    if presets:
        lines += ["", "## Accuracy presets", "",
                  "The full build of the paper's design, every effect, gear cache cold, at "
                  "each `--preset` (three interleaved runs each, median; the knobs each sets "
                  "are in docs/guide.md and cadgen/params/scene.py).", "",
                  "| preset | median (s) | spread (s) | CPU (s) |", "|---|---:|---:|---:|"]
        lines += [f"| {preset} | {wall:.2f} | {spread} | {used:.2f} |"
                  for preset, wall, spread, used in presets]
    if scenes:
        lines += ["", "## What each effect costs", "",
                  "The paper's design, gear cache cold, each scene adding effects to the one "
                  "above (`--effects`; five interleaved runs, median). A scene runs only the "
                  "stages its effects need (docs/guide.md, \"Scenes\"); the second core works "
                  "beside "
                  "the teeth once parts, sweeps or figures follow them.", "",
                  "| scene | median (s) | spread (s) | added (s) | CPU (s) |",
                  "|---|---:|---:|---:|---:|"]
        for index, (label, effects, wall, spread, used) in enumerate(scenes):
            added = f"{wall - scenes[index - 1][2]:+.2f}" if index else ""
            lines.append(f"| {label} | {wall:.2f} | {spread} | {added} | {used:.2f} |")
    if batch:
        lines += ["", "## Batch throughput", "",
                  f"`cadgen batch` over a grid of {GRID_DESIGNS} variants of the paper's design "
                  "(L2 = 186 to 200 mm), every effect, local processes, the gear cache emptied "
                  "before each batch (the first designs cut the gears, the others find them). "
                  "Each worker imports what its designs' builds will before forking the first "
                  "(`cadgen.pipeline.warm`); with a design on every core each build keeps to "
                  "its process (`parallel=False`). The last row is the same batch with each "
                  "build forking its worker beside its teeth, through the library "
                  "in the same run.", "",
                  "| batch | workers | designs | wall (s) | designs per minute | x 1 worker |",
                  "|---|---:|---:|---:|---:|---:|"]
        for label, workers, count, seconds, rate in batch:
            lines.append(f"| {label} | {workers} | {count} | {seconds:.1f} | {rate:.1f} | "
                         f"{batch[0][3] / seconds:.2f} |")
    lines.append("")
    args.output.parent.mkdir(parents=True, exist_ok=True)
    args.output.write_text("\n".join(lines))
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
