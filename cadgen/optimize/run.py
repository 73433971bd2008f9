"""Run a study: pymoo searches with the screen, then the final designs are certified exactly.

**Screen.** pymoo minimises the problem's ``F`` under ``G <= 0`` (one inequality per target,
minus its normalised margin). Constraints are handled feasibility first, pymoo's default:
a feasible design beats an infeasible one, two infeasible ones are compared by their total
violation (the sum of their positive ``G``), and only two feasible ones by their objectives
(constraint domination in NSGA-II's tournaments and ranking for several objectives;
``comp_by_cv_and_fitness`` tournaments and ``FitnessSurvival``'s ranking, by violation,
then objective, in the GA for one). So a search from a
design that misses targets first drives the violation to zero, then improves the
objective.

- Several objectives: NSGA-II.
- One objective: a real-coded GA (SBX crossover, polynomial mutation, tournaments). See
  :data:`SINGLE_OBJECTIVE_METHOD` for the measurement that chose it over DE.

The initial population holds the base design (when it lies inside the bounds) and designs
drawn uniformly in the bounds from the study's seed; pymoo's own random state is seeded
from it too, so the same study and seed give the same designs, on any number of workers
(the evaluator puts every chunk back in order, and a design's screen does not depend on
its neighbours). The search stops at the evaluations budget exactly: the last generation
is shortened to what is left of it.

**Build checks.** A build also runs checks no target names (the duckbill cam, the
drivetrain's shafts, keys and bearings); the screen cannot see them. Each generation's
best design of each objective is checked exactly (:mod:`cadgen.optimize.checks`) and the
answers become one more constraint on every screened design (violated near a design that
failed them), so the search keeps off the regions a build would fail.

**Certify.** The final designs go through ``problem.certify``, the exact evaluator of
``cadgen build``, and the build checks: for one objective, the best screened-feasible
designs in order (at least :data:`CERTIFY_FIRST`, more if none of them passes, up to
``max_certified``); for several, the feasible Pareto front, spread along it (at most
``max_certified`` designs). The reported best is the best design that passes EXACTLY
(every target and every build check), never a screened number: for several objectives,
the certified front design nearest the ideal point (each objective scaled to the front's
range). No design passing: the least-violating certified design is reported as such, and
the run's exit code is 1.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from cadgen.optimize.checks import BuildKnowledge
from cadgen.optimize.finals import (FinalDesign, _natural, rounded, screened_rows,
                                    variable_steps)
from cadgen.optimize.problem import PopulationEvaluator, PymooProblem, make_problem

__all__ = ["optimize_study", "OptimizeResult", "FinalDesign", "OptimizeProgress", "base_point",
           "SINGLE_OBJECTIVE_METHOD", "CERTIFY_FIRST", "MAX_CERTIFIED", "population_size"]

#: Which pymoo method searches one objective, and why. Measured (``python -m
#: benchmarks.optimize --compare-methods``, docs/optimize-benchmark.md) against
#: DE/best/1/bin on three planting studies, seeds 1-5, the best feasible screened objective
#: (median), the run as it is (the incumbents' build checks included):
#:
#: - short-l2 (params/studies: from a design that misses two targets, max min_margin, the
#:   cam and drivetrain checks binding): GA 0.1629 against DE's 0.1620 at 6000
#:   evaluations, 0.1607 against 0.1594 at 1500;
#: - min hole_width@200 over seven free parameters of the paper's design, an optimum on
#:   the target's bound (0 mm): GA 8e-8 mm against DE's 2.4e-4 at 6000 (6e-4 against
#:   1.8e-3 at 1500);
#: - max min_margin over the same seven: DE ahead at 1500 (0.1953 against 0.1902), both
#:   0.196663 with every seed at 6000.
#:
#: So the GA: the better best at the full budget on two studies and equal on the third.
#: A likely reason (not measured apart): DE/best/1/bin breeds every child from the current
#: best, so when the build checks demote it its generation starts over from the next one,
#: where the GA's tournaments draw on the whole population; and near a bound DE's steps
#: shrink with the population's spread. Both keep feasibility first and both can shorten
#: their last generation to stop at the budget.
SINGLE_OBJECTIVE_METHOD = "GA"
#: Screened-feasible designs certified first (one objective); more follow if none passes.
CERTIFY_FIRST = 6
#: At most this many designs are certified (the exact path costs ~0.1-0.2 s each).
MAX_CERTIFIED = 24
#: Largest population; smaller budgets get smaller ones (see :func:`population_size`).
MAX_POPULATION = 100


@dataclass(frozen=True)
class OptimizeProgress:
    """One report of a running study (the ``progress`` callback of :func:`optimize`).

    ``stage`` is ``"screen"`` (after each generation) or ``"certify"`` (after each exact
    evaluation: ``done`` of ``total``). ``best`` is the best feasible screened value of
    the first objective in its own sense (None: none feasible yet; then ``violation`` is
    the smallest total constraint violation so far).
    """

    stage: str
    evaluations: int
    budget: int
    generation: int
    objective: str
    sense: str
    best: float | None
    violation: float
    feasible: int
    elapsed: float
    done: int = 0
    total: int = 0


@dataclass
class OptimizeResult:
    """Everything a study's run found (written by :mod:`cadgen.optimize.outputs`)."""

    study: Any
    variables: list
    lower: np.ndarray
    upper: np.ndarray
    objectives: list
    constraint_labels: list
    algorithm: str
    population: int
    evaluations: int
    generations: int
    where: str
    convergence: list            # per generation: evaluations, best, violation, feasible
    finals: list                 # FinalDesign, certified, best first
    best: FinalDesign | None     # the best exactly-passing design, else None
    least_violating: FinalDesign | None
    base: FinalDesign | None     # the base design, screened and exact
    front_size: int = 0          # feasible screened Pareto front (several objectives)
    chosen_tables: dict | None = None   # problem.tables_at(chosen.x): best.toml's values
    seconds: dict = field(default_factory=dict)

    @property
    def found(self) -> bool:
        return self.best is not None

    @property
    def exit_code(self) -> int:
        """0: a design meeting every target was found and certified; 1: none."""
        return 0 if self.found else 1

    @property
    def chosen(self) -> FinalDesign | None:
        """The design best.toml holds: the best, else the least violating."""
        return self.best or self.least_violating


def population_size(budget: int) -> int:
    """Designs per generation: a tenth of the budget, within [8, 100] (never above it)."""
    return int(min(budget, max(8, min(MAX_POPULATION, budget // 10))))


def base_point(study, problem) -> np.ndarray:
    """The base design as a point of the search space.

    Planting: the base file's value at each free path. Pricking: no displacement.
    """
    if study.kind == "pricking":
        return np.zeros(len(problem.variables))
    values = []
    for path in problem.variables:
        node = study.base_params
        for part in path.split("."):
            node = getattr(node, part)
        values.append(float(node))
    return np.asarray(values, dtype=float)


def _initial_population(base: np.ndarray, lower, upper, size: int, seed: int) -> np.ndarray:
    """``size`` designs: the base (if inside the bounds) and uniform draws from ``seed``."""
    rng = np.random.default_rng(seed)
    X = lower + rng.random((size, len(lower))) * (upper - lower)
    if np.all((base >= lower) & (base <= upper)):
        X[0] = base
    return X


def _algorithm(n_obj: int, size: int, X0: np.ndarray, method: str | None = None):
    """``(pymoo algorithm, its name)``: NSGA-II for several objectives, else ``method``."""
    if n_obj > 1:
        from pymoo.algorithms.moo.nsga2 import NSGA2

        return NSGA2(pop_size=size, sampling=X0), "NSGA-II"
    method = method or SINGLE_OBJECTIVE_METHOD
    if method == "DE":
        from pymoo.algorithms.soo.nonconvex.de import DE

        return DE(pop_size=size, sampling=X0, variant="DE/best/1/bin"), "DE/best/1/bin"
    if method != "GA":   # DE: kept for the comparison that chose the GA (benchmarks/optimize.py)
        raise ValueError(f"unknown single-objective method {method!r}: GA or DE")
    from pymoo.algorithms.soo.nonconvex.ga import GA

    return GA(pop_size=size, sampling=X0), "GA (SBX, polynomial mutation)"


# --------------------------------------------------------------------------- the archive


class _Archive:
    """Every screened design, in evaluation order, and the running best."""

    def __init__(self, problem):
        self.problem = problem
        self.X, self.F, self.G, self.valid, self.values = [], [], [], [], []
        self.best_index: int | None = None
        self.min_violation = float("inf")
        self.feasible_count = 0
        self.refused: set = set()      # X.tobytes() of designs the build checks fail
        self.knowledge = None          # the run's checks.BuildKnowledge

    def add(self, entry: dict) -> None:
        offset = sum(len(x) for x in self.X)
        self.X.append(entry["X"])
        self.F.append(entry["F"])
        self.G.append(entry["G"])
        self.valid.append(entry["valid"])
        self.values.append(entry["values"])
        violation = np.maximum(entry["G"], 0.0).sum(axis=1)
        feasible = entry["valid"] & (violation <= 0.0)
        self.feasible_count += int(feasible.sum())
        self.min_violation = min(self.min_violation, float(violation.min(initial=np.inf)))
        if feasible.any():
            k = int(np.flatnonzero(feasible)[np.argmin(entry["F"][feasible, 0])])
            if self.best_index is None or entry["F"][k, 0] < self.first_f(self.best_index):
                self.best_index = offset + k

    def usable(self) -> np.ndarray:
        """(N,) bool: screened feasible and not refused by the build checks."""
        a = self.arrays()
        usable = a["valid"] & np.all(a["G"] <= 0.0, axis=1)
        if self.knowledge is not None:   # what the build checks said since
            usable &= self.knowledge.flags(a["X"]) == 0.0
        if self.refused:
            keys = np.array([row.tobytes() for row in a["X"]], dtype=object)
            usable &= ~np.isin(keys, list(self.refused))
        return usable

    def refuse(self, x: np.ndarray) -> None:
        """The build checks fail ``x``: no best, no candidate any more."""
        self.refused.add(np.asarray(x, dtype=float).tobytes())
        usable = np.flatnonzero(self.usable())
        self.best_index = (None if not usable.size else
                           int(usable[np.argmin(self.arrays()["F"][usable, 0])]))

    def first_f(self, index: int) -> float:
        return float(self.arrays()["F"][index, 0])

    def arrays(self) -> dict:
        if getattr(self, "_cache", (None, -1))[1] != len(self.X):
            keys = list(dict.fromkeys(k for v in self.values for k in v))
            values = {k: np.concatenate([np.asarray(v.get(k, np.full(len(x), np.nan)),
                                                    dtype=float)
                                         for v, x in zip(self.values, self.X)]) for k in keys}
            self._cache = ({"X": np.concatenate(self.X), "F": np.concatenate(self.F),
                            "G": np.concatenate(self.G), "valid": np.concatenate(self.valid),
                            "values": values}, len(self.X))
        return self._cache[0]

    def screened(self, index: int) -> dict:
        """The screen's figures of one archived design."""
        a = self.arrays()
        G = a["G"][index]
        objectives = {key: float(-f if sense == "max" else f)
                      for (key, sense), f in zip(self.problem.objectives, a["F"][index])}
        return {"values": {k: float(v[index]) for k, v in a["values"].items()},
                "margins": dict(zip(self.problem.constraint_labels, (-G).tolist())),
                "objectives": objectives,
                "feasible": bool(a["valid"][index] and np.all(G <= 0.0)),
                "violation": float(np.maximum(G, 0.0).sum())}


def _unique_rows(X: np.ndarray, order: np.ndarray) -> np.ndarray:
    """``order`` with repeated designs (the same X) dropped, first kept."""
    _, first = np.unique(X[order], axis=0, return_index=True)
    return order[np.sort(first)]


def _single_candidates(archive: _Archive) -> list[int]:
    """Archive rows to certify, best first: screened-feasible by objective, else least violating."""
    a = archive.arrays()
    violation = np.maximum(a["G"], 0.0).sum(axis=1)
    feasible = np.flatnonzero(archive.usable())
    if feasible.size:
        order = feasible[np.argsort(a["F"][feasible, 0], kind="stable")]
    else:
        order = np.argsort(violation, kind="stable")
    return _unique_rows(a["X"], order).tolist()


def _front_candidates(archive: _Archive, cap: int) -> tuple[list[int], int]:
    """The feasible Pareto front of every screened design, at most ``cap`` spread along it.

    Returns ``(rows, front size)``; with no feasible design, the least violating rows.
    """
    from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

    a = archive.arrays()
    violation = np.maximum(a["G"], 0.0).sum(axis=1)
    feasible = np.flatnonzero(archive.usable())
    if not feasible.size:
        return _unique_rows(a["X"], np.argsort(violation, kind="stable"))[:cap].tolist(), 0
    unique = _unique_rows(a["X"], feasible)
    _, first = np.unique(a["F"][unique], axis=0, return_index=True)   # equal F: one design
    unique = unique[np.sort(first)]
    front = unique[NonDominatedSorting().do(a["F"][unique], only_non_dominated_front=True)]
    front = front[np.lexsort(a["F"][front].T[::-1])]   # along the first objective
    if len(front) > cap:   # evenly along the front, both ends kept
        front = front[np.unique(np.linspace(0, len(front) - 1, cap).round().astype(int))]
    return front.tolist(), len(front)


def _compromise(designs: list, objectives: list) -> FinalDesign:
    """The design nearest the ideal point, each exact objective scaled to the designs' range."""
    F = np.array([[_natural(d.exact["objectives"][key], sense) for key, sense in objectives]
                  for d in designs], dtype=float)
    span = F.max(axis=0) - F.min(axis=0)
    scaled = (F - F.min(axis=0)) / np.where(span > 0, span, 1.0)
    return designs[int(np.argmin(np.linalg.norm(scaled, axis=1)))]


def _exact_key(design: FinalDesign, objectives: list) -> float:
    key, sense = objectives[0]
    return _natural(float(design.exact["objectives"][key]), sense)


# --------------------------------------------------------------------------- build checks


def _check_incumbents(algorithm, evaluator, archive: _Archive, knowledge, checked: dict) -> None:
    """Check the population's best screened-feasible design of each objective; learn from it.

    The screen cannot see the checks a build runs beyond the targets (the cam, the
    drivetrain's key pressure...). Each incumbent not checked before is checked exactly
    (:func:`cadgen.optimize.checks.build_checks`) unless it sits close by a design that
    passed (``knowledge.settled``: the certification checks the finals anyway), the
    answer kept in ``knowledge``, and
    the population's ``build:checks`` constraint recomputed from it in place (pymoo
    recomputes the violations), so the next tournaments and survival rank the designs
    taken to fail behind every feasible one. The checks do not depend on where they run:
    the search stays the same on any number of workers.
    """
    pop = algorithm.pop
    X, F, G = pop.get("X", "F", "G")
    feasible = np.flatnonzero(np.all(G <= 0.0, axis=1))
    picks = []
    for j in range(F.shape[1] if feasible.size else 0):   # the best of each objective
        k = int(feasible[np.argmin(F[feasible, j])])
        if X[k].tobytes() not in checked and k not in picks and not knowledge.settled(X[k]):
            picks.append(k)
    if not picks:
        return
    for k, result in zip(picks, evaluator.check([X[k] for k in picks])):
        passes = not (result["build_failures"] or result["stage_problems"] or result["problems"])
        checked[X[k].tobytes()] = passes
        knowledge.add(X[k], passes)
        if not passes:
            archive.refuse(X[k])
    flags = knowledge.flags(X)
    for k in np.flatnonzero(flags != G[:, -1]):
        updated = np.array(G[k], dtype=float)
        updated[-1] = flags[k]
        pop[k].G = updated
        pop[k].CV = None      # recomputed from G when next read
    if F.shape[1] == 1:
        from pymoo.algorithms.soo.nonconvex.ga import FitnessSurvival

        # DE and the GA read the ranks this sets; NSGA-II ranks afresh each generation
        FitnessSurvival().do(algorithm.problem, pop, return_indices=True)
        algorithm._set_optimum()


# --------------------------------------------------------------------------- the run


def optimize_study(study, *, workers: int = 1, scheduler: str | None = None,
                   progress: Callable[[OptimizeProgress], None] | None = None,
                   problem=None, max_certified: int = MAX_CERTIFIED,
                   method: str | None = None, check_incumbents: bool = True) -> OptimizeResult:
    """Search a study's free parameters, then certify the final designs exactly.

    Parameters
    ----------
    study : Study
        From :func:`cadgen.optimize.study.load_study` (its budget and seed are used).
    workers : int
        Local processes screening each population (1: this process).
    scheduler : str, optional
        A Dask scheduler address: screen on its workers instead.
    progress : callable, optional
        Receives an :class:`OptimizeProgress` after each generation and each exact
        evaluation. The library never prints.
    problem : DesignProblem, optional
        Instead of :func:`make_problem` ``(study)`` (tests, benchmarks).
    max_certified : int
        At most this many designs are certified.
    method : str, optional
        One objective: ``"GA"`` (default, :data:`SINGLE_OBJECTIVE_METHOD`) or ``"DE"``
        (for the comparison in benchmarks/optimize.py).
    check_incumbents : bool
        Run the build checks (:mod:`cadgen.optimize.checks`) on each generation's best
        screened-feasible design(s) and demote those that fail (see
        :func:`_check_incumbents`); False: the screen alone steers the search.

    Returns
    -------
    OptimizeResult
    """
    started = time.perf_counter()
    problem = problem if problem is not None else make_problem(study)
    lower = np.asarray(problem.lower, dtype=float)
    upper = np.asarray(problem.upper, dtype=float)
    objectives = list(problem.objectives)
    first_key, first_sense = objectives[0]
    budget = int(study.evaluations)
    size = population_size(budget)
    base = base_point(study, problem)
    X0 = _initial_population(base, lower, upper, size, study.seed)
    algorithm, name = _algorithm(len(objectives), size, X0, method)
    archive = _Archive(problem)
    convergence = []
    checked: dict = {}   # X.tobytes() -> the incumbent passed the build checks

    def report(stage, generation, done=0, total=0):
        if progress is None:
            return
        best = (None if archive.best_index is None
                else _natural(archive.first_f(archive.best_index), first_sense))
        progress(OptimizeProgress(stage, evaluated, budget, generation, first_key, first_sense,
                                  best, archive.min_violation, archive.feasible_count,
                                  time.perf_counter() - started, done, total))

    with PopulationEvaluator(problem, workers=workers, scheduler=scheduler) as evaluator:
        pymoo_problem = PymooProblem(problem, evaluator)
        knowledge = pymoo_problem.knowledge = archive.knowledge = BuildKnowledge(lower, upper)
        algorithm.setup(pymoo_problem, termination=("n_eval", budget), seed=int(study.seed),
                        verbose=False)
        generation = evaluated = 0
        while algorithm.has_next():
            if algorithm.is_initialized:   # the last generation: what the budget leaves
                algorithm.n_offsprings = min(size, budget - algorithm.evaluator.n_eval)
            algorithm.next()
            for entry in pymoo_problem.history[len(archive.X):]:
                archive.add(entry)
            if check_incumbents:
                _check_incumbents(algorithm, evaluator, archive, knowledge, checked)
            generation += 1
            evaluated = int(algorithm.evaluator.n_eval)
            best = archive.best_index
            convergence.append({
                "evaluations": evaluated, "generation": generation,
                "best": None if best is None else _natural(archive.first_f(best), first_sense),
                "violation": archive.min_violation, "feasible": archive.feasible_count})
            report("screen", generation)
        screen_seconds = time.perf_counter() - started

        # ---- certify
        front_size = 0
        if len(objectives) > 1:
            rows, front_size = _front_candidates(archive, max_certified)
        else:
            rows = _single_candidates(archive)
        certify_started = time.perf_counter()
        finals: list[FinalDesign] = []
        # the designs certified are the ones a workshop is given: rounded to the study's
        # steps (0.01 mm...), screened again and certified as rounded
        candidates = rounded(archive.arrays()["X"][rows], variable_steps(study, problem),
                              lower, upper) if rows else np.zeros((0, len(lower)))
        batch = list(range(min(len(candidates), max_certified if len(objectives) > 1
                               else min(CERTIFY_FIRST, max_certified))))
        total = len(batch)
        while batch:
            exact = evaluator.certify([candidates[k] for k in batch])
            screened = screened_rows(problem, candidates[batch])
            for k, shown, result in zip(batch, screened, exact):
                finals.append(FinalDesign(np.array(candidates[k]), shown, result))
                report("certify", generation, len(finals), total)
            if len(objectives) > 1 or any(f.passed for f in finals):
                break
            batch = list(range(len(finals), min(len(candidates), max_certified,
                                                 2 * len(finals))))
            total += len(batch)

        base_design = None
        if np.all(np.isfinite(base)):
            [base_exact] = evaluator.certify([base])
            base_design = FinalDesign(base, screened_rows(problem, base[None, :])[0], base_exact,
                                      role="base")
        certify_seconds = time.perf_counter() - certify_started
        where = evaluator.describe()

    passing = [f for f in finals if f.passed]
    if not passing:
        best = None
    elif len(objectives) > 1:
        best = _compromise(passing, objectives)
    else:
        best = min(passing, key=lambda f: _exact_key(f, objectives))
    least = None if best or not finals else min(
        finals, key=lambda f: (len(f.exact.get("stage_problems") or ()), f.exact_violation))
    chosen = best or least
    for final in finals:
        final.role = ("best" if final is best else "least violating" if final is least else
                      "front" if len(objectives) > 1 else "candidate")
    if chosen is not None:   # best first, then the rest in their order
        finals.remove(chosen)
        finals.insert(0, chosen)
    return OptimizeResult(
        study=study, variables=list(problem.variables), lower=lower, upper=upper,
        objectives=objectives, constraint_labels=list(problem.constraint_labels),
        algorithm=name, population=size, evaluations=evaluated, generations=generation,
        where=where, convergence=convergence, finals=finals, best=best, least_violating=least,
        base=base_design, front_size=front_size,
        chosen_tables=None if chosen is None else problem.tables_at(chosen.x),
        seconds={"screen": screen_seconds, "certify": certify_seconds,
                 "total": time.perf_counter() - started})
