"""Speed of ``cadgen optimize``: the screen on 1 and 2 workers against the exact path, in one run.

Run:  python -m benchmarks.optimize [--output docs/optimize-benchmark.md] [--repeats 5]
                                    [--compare-methods]

1. **Screen** (the planting population screen, :class:`cadgen.optimize.planting.PlantingProblem`
   behind :class:`cadgen.optimize.problem.PopulationEvaluator`): a population of
   ``--population`` designs drawn uniformly from the box of seven free parameters of the
   paper's design (``FREE`` below), evaluated whole on 1 worker (this process) and split
   in chunks over 2 local processes (the pool started and warmed before timing, as a run
   keeps one pool). Designs per second, median of ``--repeats`` (min-max beside).
2. **Exact path**: the same designs, one by one, by ``cadgen.evaluate`` on validated
   parameters (the evaluator ``cadgen build`` uses), and by the optimiser's ``certify``
   (validating the edited file as ``cadgen build`` does, then evaluating).
3. **Whole search**: a single-objective study (maximise min_margin over the seven
   parameters, 6000 evaluations, the default method) on 1 and 2 workers: evaluations per
   second of the screening phase, pymoo's own work and the incumbents' exact build
   checks (:mod:`cadgen.optimize.checks`) included.
4. With ``--compare-methods``: the GA against DE/best/1/bin on three single-objective
   studies, five seeds each: the best feasible screened objective at 1500 and 6000
   evaluations (the measurement behind ``cadgen.optimize.run.SINGLE_OBJECTIVE_METHOD``).

Wall times on this machine (the figures in docs/optimize-benchmark.md: the project's 2-core
reference machine).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from ._paper import PARAMS, REPO

#: Seven free parameters of the paper's design and their bounds (the benchmark's box).
FREE = {"planter.L1": (120.0, 150.0), "planter.L2": (150.0, 230.0),
        "pitch_curve.a1": (0.5, 2.0), "pitch_curve.b1": (24.0, 31.0),
        "pitch_curve.c1": (-8.0, -3.0), "train.phi0_deg": (80.0, 100.0),
        "train.phic_deg": (80.0, 100.0)}

#: The studies of --compare-methods: (name, objectives table).
COMPARED = (("max min_margin, 7 free", 'maximize = ["min_margin"]'),
            ("min hole_width@200, 7 free", 'minimize = ["hole_width@200"]'),
            ("short-l2 (from a failing design)", None))


def _study_text(objectives: str, evaluations: int, seed: int) -> str:
    free = "\n".join(f'"{path}" = [{low}, {high}]' for path, (low, high) in FREE.items())
    return (f'base = "{PARAMS.as_posix()}"\nname = "bench"\n[free]\n{free}\n'
            f"[objectives]\n{objectives}\n[budget]\nevaluations = {evaluations}\nseed = {seed}\n")


def _load(text: str, folder: Path):
    from cadgen.optimize.study import load_study

    path = folder / f"study-{abs(hash(text))}.toml"
    path.write_text(text, encoding="utf-8")
    return load_study(path)


def _rate(count: int, seconds: list) -> tuple[float, float, float]:
    rates = [count / s for s in seconds]
    return statistics.median(rates), min(rates), max(rates)


def screen_rates(study, population: int, repeats: int) -> dict:
    from cadgen.optimize.problem import PopulationEvaluator, make_problem

    problem = make_problem(study)
    rng = np.random.default_rng(1)
    X = problem.lower + rng.random((population, len(problem.lower))) * (problem.upper
                                                                          - problem.lower)
    out = {}
    for workers in (1, 2):
        with PopulationEvaluator(problem, workers=workers) as evaluator:
            evaluator(X[: 4 * evaluator.min_chunk])          # start and warm the pool
            times = []
            for _ in range(repeats):
                start = time.perf_counter()
                result = evaluator(X)
                times.append(time.perf_counter() - start)
        out[workers] = _rate(population, times)
        out[f"valid {workers}"] = int(np.count_nonzero(result["valid"]))
    return out, problem, X


def exact_rates(problem, X, count: int, repeats: int) -> dict:
    import cadgen

    designs = X[:count]
    params = []
    for x in designs:   # validated once, outside the timing: cadgen.evaluate's own cost
        try:
            params.append(cadgen.validate_data(problem.tables_at(x), check_feasibility=False))
        except cadgen.ParameterError:
            continue
    evaluate_times, certify_times = [], []
    for _ in range(repeats):
        from cadgen.design import build_mechanism

        build_mechanism.cache_clear()   # every design solved from scratch, as in a build
        start = time.perf_counter()
        for p in params:
            try:
                cadgen.evaluate(p)
            except cadgen.MechanismError:
                pass
        evaluate_times.append(time.perf_counter() - start)
        build_mechanism.cache_clear()
        start = time.perf_counter()
        for x in designs:
            problem.certify(x)
        certify_times.append(time.perf_counter() - start)
    return {"evaluate": _rate(len(params), evaluate_times),
            "certify": _rate(len(designs), certify_times)}


def search_rates(folder: Path, evaluations: int, repeats: int) -> dict:
    from cadgen.optimize.run import optimize_study

    study = _load(_study_text('maximize = ["min_margin"]', evaluations, 1), folder)
    out = {}
    for workers in (1, 2):
        times = []
        for _ in range(repeats):
            result = optimize_study(study, workers=workers, max_certified=1)
            times.append(result.seconds["screen"])
        out[workers] = _rate(result.evaluations, times)
    out["algorithm"] = result.algorithm
    return out


def compare_methods(folder: Path, budgets=(1500, 6000), seeds=range(1, 6)) -> list:
    from cadgen.optimize.run import optimize_study
    from cadgen.optimize.study import load_study

    rows = []
    for name, objectives in COMPARED:
        for budget in budgets:
            best = {}
            for method in ("GA", "DE"):
                values = []
                for seed in seeds:
                    if objectives is None:
                        study = load_study(REPO / "params" / "studies" / "short-l2.toml")
                        study = study.with_budget(evaluations=budget, seed=seed)
                    else:
                        study = _load(_study_text(objectives, budget, seed), folder)
                    result = optimize_study(study, method=method, max_certified=1)
                    values.append(result.convergence[-1]["best"])
                best[method] = values
                print(f"  {name}, {budget}, {method}: {values}", file=sys.stderr)
            rows.append((name, budget, best))
    return rows


def _fmt(rate: tuple) -> tuple[str, str]:
    median, low, high = rate
    return f"{median:,.0f}", f"{low:,.0f}-{high:,.0f}"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", type=Path, default=None,
                        help="write the tables as Markdown (docs/optimize-benchmark.md)")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--population", type=int, default=2000)
    parser.add_argument("--exact", type=int, default=40, help="designs through the exact path")
    parser.add_argument("--evaluations", type=int, default=6000, help="the whole search's budget")
    parser.add_argument("--compare-methods", action="store_true")
    args = parser.parse_args(argv)

    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        study = _load(_study_text('maximize = ["min_margin"]', 1000, 1), folder)
        print("screen ...", file=sys.stderr)
        screen, problem, X = screen_rates(study, args.population, args.repeats)
        print("exact path ...", file=sys.stderr)
        exact = exact_rates(problem, X, args.exact, max(1, args.repeats // 2))
        print("whole search ...", file=sys.stderr)
        search = search_rates(folder, args.evaluations, max(1, args.repeats // 2))
        methods = compare_methods(folder) if args.compare_methods else []

    import os

    load = os.getloadavg()[0]
    lines = ["# Optimiser speed", "",
             "Generated by `python -m benchmarks.optimize` (do not edit by hand) on a "
             f"{len(os.sched_getaffinity(0))}-core machine (load average {load:.1f} when it "
             "ended: other work shares the cores, so the 2-worker figures are lower bounds). "
             "Designs drawn "
             "uniformly from the box of seven free parameters of the paper's design "
             f"({', '.join(f'{k} {lo:g}-{hi:g}' for k, (lo, hi) in FREE.items())}); "
             f"medians of {args.repeats} repeats (spread min-max).", "",
             "| path | designs/s (median) | spread | designs per call |",
             "|---|---:|---:|---:|"]
    for workers in (1, 2):
        median, spread = _fmt(screen[workers])
        lines.append(f"| screen (`PlantingProblem.evaluate`), {workers} worker"
                     f"{'s' if workers > 1 else ''} | {median} | {spread} | {args.population} |")
    for key, label in (("evaluate", "exact: `cadgen.evaluate` per design (validated)"),
                       ("certify", "exact: `certify` per design (validate the file + evaluate)")):
        median, spread = _fmt(exact[key])
        lines.append(f"| {label} | {median} | {spread} | 1 |")
    lines += ["", f"Screen speed-up on 2 workers: {screen[2][0] / screen[1][0]:.2f} x; screen "
              f"against `cadgen.evaluate`: {screen[1][0] / exact['evaluate'][0]:.0f} x "
              f"(1 worker). Designs the screen could evaluate: {screen['valid 1']} of "
              f"{args.population}.", "",
              f"## Whole search ({args.evaluations} evaluations, {search['algorithm']}, max "
              "min_margin over the seven, pymoo's own work included)",
              "", "| workers | evaluations/s (median) | spread |", "|---|---:|---:|"]
    for workers in (1, 2):
        median, spread = _fmt(search[workers])
        lines.append(f"| {workers} | {median} | {spread} |")
    if methods:
        lines += ["", "## GA against DE (one objective)", "",
                  "Best feasible screened objective after the budget, seeds 1-5 (median; "
                  "larger is better for min_margin, smaller for hole_width).", "",
                  "| study | evaluations | GA median | DE median | GA per seed | DE per seed |",
                  "|---|---:|---:|---:|---|---|"]
        for name, budget, best in methods:
            cells = [" ".join("-" if v is None else f"{v:.6g}" for v in best[m])
                     for m in ("GA", "DE")]
            medians = [statistics.median([v for v in best[m] if v is not None] or [float("nan")])
                       for m in ("GA", "DE")]
            lines.append(f"| {name} | {budget} | {medians[0]:.6g} | {medians[1]:.6g} | "
                         f"{cells[0]} | {cells[1]} |")
    text = "\n".join(lines) + "\n"
    print(text)
    if args.output:
        args.output.write_text(text, encoding="utf-8")


if __name__ == "__main__":
    main()
