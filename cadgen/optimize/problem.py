"""The design problem an optimiser searches, and how a population is evaluated in parallel.

A mechanism kind becomes searchable by a class that follows :class:`DesignProblem`:
the planting screen (:class:`cadgen.optimize.planting.PlantingProblem`) and the
pricking points (:class:`cadgen.optimize.pricking.PrickingProblem`). :func:`make_problem`
builds the right one from a loaded study.

The optimiser (pymoo) sees the problem through :class:`PymooProblem`, whose vectorised
``_evaluate`` hands the whole population to a :class:`PopulationEvaluator`: in this
process, split in chunks over a pool of local processes (created once per run), or over
a Dask scheduler. Chunk results are put back in the population's order, so the result
never depends on the number of workers: every design is evaluated by the same code on
the same numbers wherever it runs.

Everything here pickles (problems, the evaluator's task), for process pools and Dask.
"""

from __future__ import annotations

import os
from typing import Any, Protocol, runtime_checkable

import numpy as np

from kinematics.errors import MechanismError

__all__ = ["SchedulerError", "DesignProblem", "make_problem", "problem_class", "INVALID_G",
           "certify_design",
           "PopulationEvaluator", "PymooProblem", "chunk_bounds"]

#: Seconds to reach a Dask scheduler before giving up.
CONNECT_TIMEOUT = 15


class SchedulerError(MechanismError):
    """The Dask scheduler cannot be reached (or dask.distributed is not installed)."""


#: G (and F) of a design that cannot be evaluated: pymoo needs finite numbers, and a
#: violation this large ranks the design behind every evaluable one.
INVALID_G = 1e6


@runtime_checkable
class DesignProblem(Protocol):
    """What the optimiser needs of a mechanism kind (planting, pricking).

    Attributes
    ----------
    kind : str
        ``"planting"`` or ``"pricking"``.
    variables : list of str
        Names of the free variables for tables and CSV (``"planter.L2"``, ``"Q3.x"``).
    lower, upper : (n,) float
        The search box.
    objectives : list of (str, str)
        ``[(key, "max" | "min")]``, keys of ``values``.
    constraint_labels : list of str
        One per target or check (``"hole_width@150"``), the columns of ``G``.
    """

    kind: str
    variables: list
    lower: np.ndarray
    upper: np.ndarray
    objectives: list
    constraint_labels: list

    def evaluate(self, X: np.ndarray) -> dict:
        """Screen a population: ``X`` (N, n) -> a dict of

        - ``"F"`` (N, k): the objectives to MINIMISE (maximised ones negated);
        - ``"G"`` (N, m): the constraints, ``<= 0`` feasible (minus the normalised margins);
        - ``"values"``: ``{key: (N,)}`` the metric values (for tables and CSV);
        - ``"valid"`` (N,) bool: False where the design cannot be evaluated (its G is
          :data:`INVALID_G`-like, its values NaN).
        """

    def certify(self, x: np.ndarray) -> dict:
        """The exact path (the evaluator ``cadgen build`` uses) on one design ``x`` (n,):
        ``{"values": {key: float}, "margins": {label: float}, "passed": bool,
        "objectives": {key: float}, "metrics": report.json's metric dicts (or the pricking
        report's sections), "problems": [validation problems, if any]}``."""

    def tables_at(self, x: np.ndarray) -> dict:
        """The base file's tables (a parameter mapping) with the design ``x`` applied."""


def problem_class(kind: str) -> type:
    """The DesignProblem class of a mechanism kind (imported on demand)."""
    if kind == "planting":
        from cadgen.optimize.planting import PlantingProblem

        return PlantingProblem
    if kind == "pricking":
        from cadgen.optimize.pricking import PrickingProblem

        return PrickingProblem
    raise ValueError(f"no design problem for mechanism kind {kind!r}")


def make_problem(study) -> DesignProblem:
    """The design problem of a loaded :class:`~cadgen.optimize.study.Study`.

    Planting gets ``free`` as ``[(path, low, high)]``; pricking gets the points' box
    spec ``{"box": 3.0, "points": [...]}`` (see the study's ``free``).
    """
    cls = problem_class(study.kind)
    return cls(study.base_params, study.free, list(study.objectives))


# --------------------------------------------------------------------------- parallel


def chunk_bounds(count: int, chunks: int) -> list[tuple[int, int]]:
    """``[(start, stop)]`` splitting ``count`` rows into ``chunks`` near-equal runs (in order)."""
    chunks = max(1, min(int(chunks), count))
    edges = np.linspace(0, count, chunks + 1).round().astype(int)
    return [(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:]) if b > a]


#: The problem a pool worker evaluates, set once by the pool's initializer (so each chunk
#: ships only its rows, never the problem again).
_WORKER_PROBLEM: Any = None


def _set_worker_problem(problem) -> None:
    global _WORKER_PROBLEM
    _WORKER_PROBLEM = problem


def _evaluate_in_worker(X: np.ndarray) -> dict:
    return _WORKER_PROBLEM.evaluate(X)


def certify_design(problem, x: np.ndarray) -> dict:
    """``problem.certify(x)`` and the checks a build runs beyond the targets.

    Adds ``"stage_problems"`` (what validation attaches to the parameters for a build
    stage to refuse: the duckbill linkage) when the problem's certify does not give them,
    and ``"build_failures"`` (:func:`cadgen.optimize.checks.build_checks`: the cam and
    drivetrain checks of ``cadgen build``). A design passes only with neither.
    """
    from cadgen.optimize.checks import build_checks

    result = dict(problem.certify(x))
    if result.get("problems"):
        result.setdefault("stage_problems", [])
        result["build_failures"] = []
        return result
    checks = build_checks(problem, x)
    result.setdefault("stage_problems", checks["stage_problems"])
    result["build_failures"] = checks["build_failures"] + [
        f"{p['path']}: {p['message']} [{p['code']}]" for p in checks["problems"]]
    return result


def _check_in_worker(x: np.ndarray) -> dict:
    from cadgen.optimize.checks import build_checks

    return build_checks(_WORKER_PROBLEM, x)


def _check_with(problem, x: np.ndarray) -> dict:
    from cadgen.optimize.checks import build_checks

    return build_checks(problem, x)


def _certify_in_worker(x: np.ndarray) -> dict:
    return certify_design(_WORKER_PROBLEM, x)


def _certify_with(problem, x: np.ndarray) -> dict:
    return certify_design(problem, x)


def _evaluate_with(problem, X: np.ndarray) -> dict:
    """A Dask task: ``problem`` arrives as a scattered future, resolved by the worker."""
    return problem.evaluate(X)


def _merge(parts: list[dict], count: int) -> dict:
    """Chunk results, in order, as one population's result."""
    if len(parts) == 1:
        return parts[0]
    merged = {"F": np.concatenate([p["F"] for p in parts]),
              "G": np.concatenate([p["G"] for p in parts]),
              "valid": np.concatenate([np.asarray(p["valid"], dtype=bool) for p in parts])}
    keys = list(dict.fromkeys(k for p in parts for k in p["values"]))
    merged["values"] = {k: np.concatenate([np.asarray(p["values"].get(k, np.full(len(p["F"]),
                                                                                 np.nan)),
                                                      dtype=float) for p in parts])
                        for k in keys}
    extra = [k for k in parts[0] if k not in merged]
    for key in extra:   # e.g. pricking's per-design error codes
        items = [p.get(key) for p in parts]
        if all(isinstance(i, list) for i in items):
            merged[key] = [v for i in items for v in i]
    assert len(merged["F"]) == count
    return merged


class PopulationEvaluator:
    """Evaluates populations of one problem: here, over local processes, or over Dask.

    Parameters
    ----------
    problem : DesignProblem
    workers : int
        Local processes (1: in this process, no pool). Ignored with ``scheduler``.
    scheduler : str, optional
        A Dask scheduler address (``tcp://host:8786``); the population is split in
        chunks over its workers (``distributed.Client``).
    min_chunk : int
        Fewest designs per chunk: smaller chunks cost more in messages than they save.

    A pool is created on first use and kept until :meth:`close` (use it as a context
    manager): one pool per run, fork where the platform has it (the workers start with
    the problem and numpy already loaded).
    """

    def __init__(self, problem, *, workers: int = 1, scheduler: str | None = None,
                 min_chunk: int = 16):
        if int(workers) < 1:
            raise ValueError(f"workers must be at least 1, not {workers!r}")
        self.problem = problem
        self.workers = int(workers)
        self.scheduler = scheduler
        self.min_chunk = int(min_chunk)
        self._pool = None
        self._client = None
        self._remote_problem = None

    # -- lifetime ------------------------------------------------------------------------

    def __enter__(self):
        return self

    def __exit__(self, exc_type, *exc_info):
        self.close(abandon=exc_type is not None)
        return False

    def close(self, abandon: bool = False) -> None:
        """End the pool (and the Dask client); ``abandon``: kill its workers at once rather
        than wait for the chunks they are evaluating (the run was interrupted, or failed)."""
        if self._pool is not None:
            if abandon:
                from cadgen.processes import stop_pool

                stop_pool(self._pool)
            else:
                self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None
        if self._client is not None:
            self._client.close()
            self._client = None

    @property
    def parallelism(self) -> int:
        """How many chunks a population is split into."""
        if self.scheduler:
            client = self._dask()
            return max(1, sum(client.nthreads().values()))
        return self.workers

    def describe(self) -> str:
        if self.scheduler:
            return f"Dask scheduler {self.scheduler}"
        return "this process" if self.workers == 1 else f"{self.workers} local processes"

    def _local_pool(self):
        if self._pool is None:
            import multiprocessing

            from cadgen.processes import process_pool

            # its workers die with this thread, whatever ends it (cadgen.processes.lifeline)
            method = "fork" if "fork" in multiprocessing.get_all_start_methods() else None
            self._pool = process_pool(self.workers, multiprocessing.get_context(method),
                                      initializer=_set_worker_problem,
                                      initargs=(self.problem,))
        return self._pool

    def _pool_map(self, function, items) -> list:
        """``function`` of each item over the local pool, in order. The tasks are queued
        (and the workers started) whole, interrupts held back: see
        :func:`cadgen.processes.process_pool`."""
        from cadgen.processes import sigint_deferred

        with sigint_deferred():
            results = self._local_pool().map(function, items)
        return list(results)

    def _dask(self):
        if self._client is None:
            try:
                from distributed import Client
            except ImportError:
                raise SchedulerError("a Dask scheduler needs dask.distributed: "
                                     "pip install -e '.[dask]'") from None
            try:
                self._client = Client(self.scheduler, set_as_default=False,
                                      timeout=CONNECT_TIMEOUT)
            except (OSError, TimeoutError, ValueError) as error:
                raise SchedulerError(f"cannot reach the Dask scheduler {self.scheduler}: "
                                     f"{' '.join(str(error).split())[:200]}") from None
            [self._remote_problem] = self._client.scatter([self.problem], broadcast=True)
        return self._client

    # -- evaluation ----------------------------------------------------------------------

    def __call__(self, X) -> dict:
        """The problem's ``evaluate`` of the population ``X`` (N, n), rows in order."""
        X = np.ascontiguousarray(X, dtype=float)
        count = len(X)
        chunks = min(self.parallelism, max(1, count // max(1, self.min_chunk)))
        if chunks <= 1:
            return self.problem.evaluate(X)
        bounds = chunk_bounds(count, chunks)
        if self.scheduler:
            client = self._dask()
            futures = [client.submit(_evaluate_with, self._remote_problem, X[a:b], pure=False)
                       for a, b in bounds]
            parts = client.gather(futures)   # in the order submitted
        else:
            parts = self._pool_map(_evaluate_in_worker, [X[a:b] for a, b in bounds])
        return _merge(parts, count)

    def check(self, designs) -> list[dict]:
        """:func:`cadgen.optimize.checks.build_checks` of each design, in order."""
        return self._map(_check_in_worker, _check_with, designs)

    def _map(self, in_worker, with_problem, designs) -> list[dict]:
        designs = [np.asarray(x, dtype=float) for x in designs]
        if len(designs) <= 1 or (self.workers == 1 and not self.scheduler):
            return [with_problem(self.problem, x) for x in designs]
        if self.scheduler:
            client = self._dask()
            return client.gather([client.submit(with_problem, self._remote_problem, x,
                                                pure=False) for x in designs])
        return self._pool_map(in_worker, designs)

    def certify(self, designs) -> list[dict]:
        """:func:`certify_design` of each design (n,), in order, where populations are evaluated."""
        return self._map(_certify_in_worker, _certify_with, designs)


def _pymoo_problem_class():
    """pymoo's Problem subclass, defined on first use (pymoo loads only for a search)."""
    from pymoo.core.problem import Problem

    class _PymooProblem(Problem):
        """A DesignProblem as pymoo sees it: vectorised, every constraint ``G <= 0``.

        ``last`` keeps the latest population's full result (values, valid), which the
        runner's callback records for the convergence plot and the final tables.
        """

        def __init__(self, problem, evaluator):
            # one more constraint than the problem's: the build checks, 0 when screened (the
            # screen cannot see them), set violated on a design the exact checks fail
            # (cadgen.optimize.checks; the run demotes its incumbents that way)
            super().__init__(n_var=len(problem.variables), n_obj=len(problem.objectives),
                             n_ieq_constr=len(problem.constraint_labels) + 1,
                             xl=np.asarray(problem.lower, dtype=float),
                             xu=np.asarray(problem.upper, dtype=float),
                             vtype=float)
            self.design_problem = problem
            self.evaluator = evaluator
            self.history: list[dict] = []
            self.knowledge = None   # a checks.BuildKnowledge, set by the run

        def _evaluate(self, X, out, *args, **kwargs):
            result = self.evaluator(X)
            F = np.asarray(result["F"], dtype=float)
            G = np.asarray(result["G"], dtype=float)
            # pymoo compares numbers: a NaN would poison the ranking, so an unusable
            # value counts as an invalid design
            bad = ~np.isfinite(F).all(axis=1) | ~np.isfinite(G).all(axis=1)
            F = np.where(bad[:, None], INVALID_G, F)
            G = np.where(bad[:, None], INVALID_G, G)
            flags = (np.zeros(len(G)) if self.knowledge is None
                     else self.knowledge.flags(X))
            G = np.hstack([G, flags[:, None]])
            out["F"] = F
            out["G"] = G
            self.history.append({"X": np.array(X, dtype=float), "F": F, "G": G,
                                 "values": result.get("values", {}),
                                 "valid": np.asarray(result.get("valid", ~bad), dtype=bool)
                                 & ~bad})

    return _PymooProblem


def PymooProblem(problem, evaluator) -> Any:
    """A pymoo ``Problem`` over ``problem`` whose populations go through ``evaluator``.

    Every evaluated population is appended to its ``history`` (X, F, G, values, valid).
    """
    return _pymoo_problem_class()(problem, evaluator)


def cpu_count() -> int:
    """Cores this process may use (the affinity mask where the platform has one)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:   # not on Linux
        return os.cpu_count() or 1
