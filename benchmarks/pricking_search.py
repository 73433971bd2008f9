"""Can a pricking loop's type-value points, moved a few mm, give four convex pitch curves?

    python -m benchmarks.pricking_search [--file params/kernel-a.toml] [--box 3]
        [--evaluations 6000] [--seed 1] [--workers 2] [--algorithm cmaes|ga|de]
        [--objective min_margin|convexity] [--start x.json]

Runs pymoo directly on :class:`cadgen.optimize.pricking.PrickingProblem` (every design the
exact inverse design, ~60 ms), the population spread over a process pool, and certifies
the best design through the exact path (``cadgen.validate_data`` + ``cadgen.evaluate``).
Prints progress to stderr and a JSON summary on stdout: the best displacements, the four
curvature minima, the findings, the evaluations and the time.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

_PROBLEM = None


def _init(path, box, objective):
    global _PROBLEM
    import cadgen
    from cadgen.optimize.pricking import PrickingProblem

    _PROBLEM = PrickingProblem(cadgen.load_params(path), {"box": box}, [(objective, "max")])


def _evaluate(rows):
    result = _PROBLEM.evaluate(rows)
    return result["F"], result["G"], result["values"]["convexity"]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--file", default="params/kernel-a.toml")
    parser.add_argument("--box", type=float, default=3.0)
    parser.add_argument("--evaluations", type=int, default=6000)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--algorithm", choices=("cmaes", "ga", "de"), default="cmaes")
    parser.add_argument("--objective", choices=("min_margin", "convexity"), default="min_margin")
    parser.add_argument("--sigma", type=float, default=0.3, help="CMA-ES step, fraction of the box")
    parser.add_argument("--start", help="JSON list of displacements to start from")
    args = parser.parse_args(argv)

    import cadgen
    from cadgen.optimize.pricking import PrickingProblem
    from pymoo.core.problem import Problem
    from pymoo.optimize import minimize

    problem = PrickingProblem(cadgen.load_params(args.file), {"box": args.box},
                              [(args.objective, "max")])
    pool = ProcessPoolExecutor(args.workers, initializer=_init,
                               initargs=(args.file, args.box, args.objective))
    history = {"evaluations": 0, "best": -np.inf, "best_x": None, "start": time.time()}

    class Search(Problem):
        def __init__(self):
            super().__init__(n_var=len(problem.variables), n_obj=1,
                             # min_margin >= 0 is exactly every constraint holding: CMA-ES
                             # has no constraint handling of its own, so give it none
                             n_ieq_constr=0 if args.objective == "min_margin"
                             else len(problem.constraint_labels),
                             xl=problem.lower, xu=problem.upper)

        def _evaluate(self, X, out, *_, **__):
            X = np.clip(X, problem.lower, problem.upper)   # CMA-ES may step a hair outside
            chunks = np.array_split(X, min(len(X), 4 * args.workers))
            results = list(pool.map(_evaluate, chunks))
            F = np.vstack([r[0] for r in results])
            G = np.vstack([r[1] for r in results])
            convexity = np.concatenate([r[2] for r in results])
            history["evaluations"] += len(X)
            k = int(np.nanargmax(np.where(np.isnan(convexity), -np.inf, -F[:, 0])))
            if -F[k, 0] > history["best"]:
                history["best"], history["best_x"] = float(-F[k, 0]), X[k].copy()
            seconds = time.time() - history["start"]
            print(f"{history['evaluations']:6d} evaluations, {seconds:6.0f} s: "
                  f"best {args.objective} {history['best']:.4f} (this batch's convexity "
                  f"{np.nanmax(convexity):.4f})", file=sys.stderr, flush=True)
            out["F"] = F
            if self.n_ieq_constr:
                out["G"] = G

    x0 = np.asarray(json.loads(args.start), dtype=float) if args.start else np.zeros(
        len(problem.variables))
    if args.algorithm == "cmaes":
        from pymoo.algorithms.soo.nonconvex.cmaes import CMAES
        algorithm = CMAES(x0=x0, sigma=args.sigma, restarts=20, incpopsize=2, bipop=True,
                          tolfun=1e-9, tolx=1e-9, maxfevals=args.evaluations)
    elif args.algorithm == "ga":
        from pymoo.algorithms.soo.nonconvex.ga import GA
        algorithm = GA(pop_size=64)
    else:
        from pymoo.algorithms.soo.nonconvex.de import DE
        algorithm = DE(pop_size=64, variant="DE/rand/1/bin", CR=0.5)
    started = time.time()
    minimize(Search(), algorithm, ("n_evals", args.evaluations), seed=args.seed, verbose=False)
    elapsed = time.time() - started
    pool.shutdown()
    best = history["best_x"]
    certified = problem.certify(best)
    summary = {
        "file": args.file, "box_mm": args.box, "algorithm": args.algorithm,
        "objective": args.objective, "seed": args.seed, "workers": args.workers,
        "evaluations": history["evaluations"], "seconds": round(elapsed, 1),
        "best": {name: round(float(v), 6) for name, v in zip(problem.variables, best)},
        "best_list": [float(v) for v in best],
        "values": certified["values"], "passed": certified["passed"],
        "findings": [(f["code"], f["path"]) for f in certified["findings"]],
        "problems": certified["problems"],
    }
    print(json.dumps(summary, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
