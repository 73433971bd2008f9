"""Designs per second of the planting population screen against the exact path, and its accuracy knob.

Run:  python -m benchmarks.screen [--designs 4000] [--exact 20] [--knob-designs 200]

The population is a planting study round the paper's design (eight free parameters: both
planter links, four limacon coefficients, the base radius R and the planting depth, each
within +-10 to 15 %), as :class:`cadgen.optimize.planting.PlantingProblem` evaluates it:
the columns, the housing rule, the screen, the margins. Times are the process's CPU time
(the machine is shared; a second core does not help one process) and the wall time, in one
process; the optimiser's runs over workers are ``benchmarks/optimize.py``'s.

* throughput: designs per second of ``PlantingProblem.evaluate`` on the whole population
  and in the chunks a pool of workers would get;
* the exact path: ``PlantingProblem.certify`` per design (``cadgen.validate_data``, which
  runs the feasibility checks, then ``cadgen.evaluate``, as ``cadgen build``'s metrics);
* the knob: grid samples per revolution, each metric's largest error against the exact
  path over the designs both evaluate, and the CPU time per design
  (:func:`knob_rows`; ``benchmarks/accuracy.py`` writes it to docs/accuracy.md).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

REFERENCE = Path(__file__).resolve().parents[1] / "params" / "xin2024-planter.toml"
FREE = [("planter.L1", 110.0, 150.0), ("planter.L2", 160.0, 220.0),
        ("pitch_curve.b1", 24.0, 31.0), ("pitch_curve.d1", 27.0, 34.0),
        ("pitch_curve.c1", -8.0, -3.0), ("pitch_curve.g2", -6.0, -2.0),
        ("train.R", 32.0, 40.0), ("field.depth", 25.0, 45.0)]
OBJECTIVES = [("min_margin", "max")]
KNOB_SAMPLES = (32, 64, 128, 256, 512, 1024)
METRIC_GROUPS = ("trajectory_height", "hole_width", "hole_verticality", "angle_difference",
                 "arm_distance", "ground_clearance", "module")


def study_problem(samples: int | None = None):
    import cadgen
    from cadgen.optimize.planting import PlantingProblem

    extra = {} if samples is None else {"samples": samples}
    return PlantingProblem(cadgen.load_params(REFERENCE), FREE, OBJECTIVES, **extra)


def population(problem, count: int, seed: int = 1) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return problem.lower + (problem.upper - problem.lower) * rng.random((count, len(FREE)))


def throughput(problem, X, chunk: int | None = None) -> dict:
    """CPU and wall designs per second of ``problem.evaluate`` over ``X`` (in chunks)."""
    chunk = chunk or len(X)
    problem.evaluate(X[:chunk])                       # warm numpy's caches
    cpu, wall = time.process_time(), time.perf_counter()
    valid = 0
    for start in range(0, len(X), chunk):
        valid += int(problem.evaluate(X[start:start + chunk])["valid"].sum())
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    return {"designs": len(X), "chunk": chunk, "cpu_s": cpu, "wall_s": wall,
            "per_s_cpu": len(X) / cpu, "per_s_wall": len(X) / wall, "valid": valid}


def exact_throughput(problem, X) -> dict:
    """CPU and wall designs per second of the exact path, one design at a time."""
    from cadgen.design import build_mechanism

    cpu, wall = time.process_time(), time.perf_counter()
    for x in X:
        build_mechanism.cache_clear()                 # every design is new to the exact path
        problem.certify(x)
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    return {"designs": len(X), "cpu_s": cpu, "wall_s": wall, "per_s_cpu": len(X) / cpu,
            "per_s_wall": len(X) / wall}


def knob_rows(count: int = 200, seed: int = 2, samples=KNOB_SAMPLES, log=print) -> dict:
    """Each grid's largest error per metric group against the exact path, and its CPU time.

    A design the grid does not resolve is left invalid here (no finer grid: the knob
    itself is measured) and counted as ``unresolved``.
    """
    from kinematics.population import screen

    problem = study_problem()
    X = population(problem, count, seed)
    exact = [problem.certify(x) for x in X]
    ok = np.array([not e["problems"] for e in exact])
    log(f"exact path: {ok.sum()} of {count} designs evaluated")
    rows = []
    for grid in samples:
        columns, _ = problem.designs_of(X)
        screen(columns, problem.spacings, samples=grid, max_samples=grid)      # warm up
        cpu = time.process_time()
        found = screen(columns, problem.spacings, samples=grid, max_samples=grid)
        cpu = time.process_time() - cpu
        both = ok & found.valid
        worst = {}
        for group in METRIC_GROUPS:
            keys = [k for k in problem.constraint_labels if k.split("@")[0] == group]
            worst[group] = max((abs(found.values[k][row] - exact[row]["values"][k])
                                for k in keys for row in np.flatnonzero(both)), default=np.nan)
        disagree = int((ok != found.valid).sum() - (ok & ~found.valid
                                                     & (found.reason == "closure_unresolved")).sum())
        rows.append({"samples": grid, "errors": worst, "cpu_us": cpu / count * 1e6,
                     "unresolved": int((found.reason == "closure_unresolved").sum()),
                     "validity_disagreements": disagree, "compared": int(both.sum())})
        log(f"{grid:>5} samples: {cpu / count * 1e6:7.1f} us/design, "
            + ", ".join(f"{g} {e:.1e}" for g, e in worst.items())
            + f"; unresolved {rows[-1]['unresolved']}, validity disagreements {disagree}")
    return {"count": count, "evaluated": int(ok.sum()), "rows": rows}


def knob_markdown(knob: dict) -> list:
    """The section of docs/accuracy.md."""
    from kinematics.population import DEFAULT_SAMPLES, MAX_SAMPLES, TOLERANCES

    lines = ["", "## Population screen: grid samples per revolution (the optimiser's screen)", "",
             "`kinematics.population.screen` evaluates a whole population at once for `cadgen "
             "optimize`; the finals are certified by the exact path. Error = each metric's "
             "largest |screen - exact| (mm; angle difference in deg) over "
             f"{knob['count']} random designs of a planting study round the paper's "
             f"({knob['evaluated']} evaluated by the exact path: `cadgen.validate_data`, then "
             "`cadgen.evaluate`); holes over the three spacings. Time = CPU time per design of "
             "the screen on the whole population, one process. `unresolved`: designs whose "
             "ratio law the grid does not resolve (the default grid hands them to doubled grids, "
             f"up to {MAX_SAMPLES}; here each grid is measured alone). Validity disagreements: "
             "designs one path evaluates and the other refuses, unresolved ones aside. Default: "
             f"{DEFAULT_SAMPLES} samples; stated tolerances (`TOLERANCES`, held by "
             "tests/test_population.py): " + ", ".join(f"{k} {v:g}" for k, v in TOLERANCES.items()
                                                       if k != "soil_penetrations")
             + ", soil penetrations exactly.", "",
             "| samples/rev | " + " | ".join(METRIC_GROUPS) + " | unresolved | validity "
             "disagreements | time per design (us) |",
             "|---:|" + "---:|" * (len(METRIC_GROUPS) + 3)]
    for row in knob["rows"]:
        # a grid that resolves none of the designs has no error to show
        errors = " | ".join("-" if np.isnan(row["errors"][g]) else f"{row['errors'][g]:.1e}"
                            for g in METRIC_GROUPS)
        lines.append(f"| {row['samples']} | {errors} | {row['unresolved']} | "
                     f"{row['validity_disagreements']} | {row['cpu_us']:.0f} |")
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--designs", type=int, default=4000)
    parser.add_argument("--exact", type=int, default=20)
    parser.add_argument("--knob-designs", type=int, default=200)
    args = parser.parse_args(argv)

    problem = study_problem()
    X = population(problem, args.designs)
    print(f"screen, one process, {args.designs} designs of the study "
          f"({', '.join(p for p, _, _ in FREE)}):")
    for chunk in (None, 1000, 250, 50):
        r = throughput(problem, X, chunk)
        print(f"  chunks of {r['chunk']:>5}: {r['per_s_cpu']:8.0f} designs/s CPU, "
              f"{r['per_s_wall']:8.0f} designs/s wall ({r['valid']} valid)", flush=True)
    r = exact_throughput(problem, X[:args.exact])
    print(f"exact path (validate_data + evaluate), {args.exact} designs: "
          f"{r['per_s_cpu']:.1f} designs/s CPU, {r['per_s_wall']:.1f} designs/s wall", flush=True)
    if args.knob_designs:
        knob = knob_rows(args.knob_designs)
        print("\n".join(knob_markdown(knob)))


if __name__ == "__main__":
    main()
