"""Batch builds: many designs (parameter files or a parameter grid), local processes or Dask.

A batch is a list of :class:`DesignJob` records, made from parameter files
(:func:`file_jobs`) or from a grid file over one design's parameters
(:func:`expand_grid`). :func:`run_batch` runs :func:`run_design` once per design, in
local processes (:class:`concurrent.futures.ProcessPoolExecutor`) or on a Dask
cluster, and returns one small picklable summary dict per design, ordered by design
name. A failing design (a :class:`~cadgen.params.ParameterError`, a
:class:`~kinematics.errors.DesignError` or any other exception) is caught inside its
job and reported in its summary: it never stops the batch and never leaves outputs
behind (the build writes its folder atomically). :func:`write_summary` writes
``batch-summary.csv`` and ``batch-summary.html`` under the output root.

Grid file (TOML; ``base`` is relative to the grid file)::

    base = "params/xin2024-planter.toml"
    name = "r-sweep"                  # prefix of the generated names (default: the base's name)
    [grid]
    "train.R" = [34.0, 36.0, 38.0]                          # explicit values
    "planter.L2" = { start = 180.0, stop = 200.0, num = 3 }  # like numpy.linspace

The grid is the Cartesian product of its keys in file order, the last key varying
fastest; design ``k`` (from 1) is named ``<name>-<k>`` with ``k`` zero-padded to at
least three digits (``r-sweep-003``). Keys may also be written as TOML dotted keys
(``train.R = [...]``).

The command line (``cadgen batch``) is :func:`add_batch_arguments` plus :func:`main_batch`.

TODO(timeouts, worker deaths): no per-design ``--timeout`` yet. ``signal.alarm`` in
the worker would do for local processes (the task runs in its main thread, and the
staged output folder is removed on the way out), but Dask runs tasks in threads that
cannot be interrupted: a timed-out design could still write its folder after being
reported failed. The fix for both: each design in a child process the job can kill.
A worker that dies (segfault, out of memory) is reported as ``worker_error``; with
local processes it breaks the pool, so every unfinished design is reported so too.
"""

from __future__ import annotations

import argparse
import copy
import csv
import html
import importlib
import io
import itertools
import json
import math
import numbers
import os
import re
import sys
import time
import tomllib
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, TextIO

from kinematics.errors import DesignError, MechanismError, Problem

__all__ = [
    "DEFAULT_BUILD", "SUMMARY_CSV", "SUMMARY_HTML", "EXIT_OK", "EXIT_FAILED", "EXIT_PROBLEMS",
    "DesignJob", "GridError", "file_jobs", "expand_grid", "guard_names", "run_design",
    "run_batch", "summary_csv", "summary_html", "write_summary", "batch_exit_code", "Progress",
    "add_batch_arguments", "main_batch",
]

DEFAULT_BUILD = "cadgen.build:build"
"""The build each design runs unless told otherwise: ``"module:function"``, called as
``build(params, output_root=Path, **build_kwargs)``; it returns an object with
``report`` (dict) and ``output_dir`` (and optionally ``files``), or the report dict."""

SUMMARY_CSV = "batch-summary.csv"
SUMMARY_HTML = "batch-summary.html"

# The same codes as cadgen.cli (not imported from it: the CLI imports this module).
EXIT_OK = 0
EXIT_FAILED = 1
EXIT_PROBLEMS = 2

_GRID_KEYS = ("base", "name", "grid")
_RANGE_KEYS = ("start", "stop", "num")
_NOT_SWEPT = ("name", "mechanism")
_MIN_INDEX_DIGITS = 3
_TRACEBACK_LINES = 30

Build = Callable[..., Any] | str


# --------------------------------------------------------------------------- jobs


@dataclass(frozen=True)
class DesignJob:
    """One design of a batch, small and picklable.

    Attributes
    ----------
    name : str
        Design name (its output folder, its place in the summary); for a file that
        cannot be read or names no design, the file's stem.
    source : str
        The parameter file or grid file, as the user gave it.
    path, data : str or None, dict or None
        The parameter file's absolute path, or the parsed parameters of a grid design.
    values : dict
        The grid values set in this design (dotted key -> value); empty for a file.
    blocked_by : str or None
        Why the design must not be built even if valid (see :func:`guard_names`).
    """

    name: str
    source: str
    path: str | None = None
    data: dict | None = None
    values: dict = field(default_factory=dict)
    blocked_by: str | None = None


class GridError(DesignError):
    """A grid file with problems; ``problems`` lists all of them (paths ``grid.<key>``,
    ``base``, ``name``). A DesignError and a ValueError (not a ParameterError, whose
    module pulls in pydantic when imported)."""


def _peek_name(path: Path) -> str:
    """The ``name`` a parameter file gives, without validating it; else the file's stem."""
    name = (_read_toml(path, "")[0] or {}).get("name")
    return name if isinstance(name, str) and name else path.stem


def file_jobs(files: Iterable[str | os.PathLike]) -> list[DesignJob]:
    """One job per parameter file, named by the file's ``name`` (read, not validated).

    Parameters
    ----------
    files : iterable of str or path-like

    Returns
    -------
    list of DesignJob
        In the given order. Files that cannot be read still make a job: its build
        reports the problem (``file_not_found``, ``toml_syntax``...).
    """
    jobs = []
    for file in files:
        path = Path(file)
        jobs.append(DesignJob(_peek_name(path), str(file), path=str(path.resolve())))
    return jobs


def guard_names(jobs: Sequence[DesignJob]) -> list[DesignJob]:
    """Block every design whose name an earlier one took, or a summary file's name.

    Two designs of one name would write the same output folder. A blocked design is
    still validated (its own problems come first) but not built.

    Parameters
    ----------
    jobs : sequence of DesignJob
        In priority order (the first of a name is built).

    Returns
    -------
    list of DesignJob
    """
    first: dict[str, DesignJob] = {}
    guarded = []
    for job in jobs:
        if job.name in (SUMMARY_CSV, SUMMARY_HTML):
            job = replace(job, blocked_by=f"design name {job.name!r} is the batch summary's "
                                          "file name; rename the design")
        elif job.name in first and first[job.name].source == job.source:
            job = replace(job, blocked_by=f"{job.source} is given twice; it is built once")
        elif job.name in first:
            job = replace(job, blocked_by=f"design name {job.name!r} is also the name of "
                                          f"{first[job.name].source}, built instead; its outputs "
                                          "would overwrite them: rename one")
        else:
            first[job.name] = job
        guarded.append(job)
    return guarded


# --------------------------------------------------------------------------- grid files


def _read_toml(path: Path, where: str) -> tuple[dict | None, list[Problem]]:
    """Parse a TOML file; problems at ``where`` if it cannot be read or parsed."""
    try:
        text = path.read_bytes().decode("utf-8-sig")
    except FileNotFoundError:
        return None, [Problem(where, "file_not_found", f"no such file: {path}")]
    except UnicodeDecodeError:
        return None, [Problem(where, "not_utf8", f"{path} is not UTF-8 text")]
    except OSError as exc:
        return None, [Problem(where, "not_readable", f"cannot read {path}: {exc.strerror}")]
    try:
        return tomllib.loads(text), []
    except tomllib.TOMLDecodeError as exc:
        return None, [Problem(where, "toml_syntax", f"TOML syntax error in {path}: {exc}")]


def _show(value: Any) -> str:
    return json.dumps(value) if isinstance(value, str) else repr(value)


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _flatten(table: Mapping, prefix: str = "") -> Iterable[tuple[str, Any]]:
    """``(dotted key, spec)`` of a ``[grid]`` table; TOML dotted keys make nested tables."""
    for key, value in table.items():
        dotted = f"{prefix}.{key}" if prefix else str(key)
        if isinstance(value, dict) and not any(k in value for k in _RANGE_KEYS):
            yield from _flatten(value, dotted)
        else:
            yield dotted, value


def _linspace(start: float, stop: float, num: int) -> list:
    """``num`` evenly spaced values from ``start`` to ``stop`` inclusive, endpoints exact.

    Whole numbers stay integers when ``start`` and ``stop`` are integers and the step is
    whole (a sweep of tooth counts).
    """
    if num == 1:
        return [start]
    if isinstance(start, int) and isinstance(stop, int) and (stop - start) % (num - 1) == 0:
        step = (stop - start) // (num - 1)
        return [start + i * step for i in range(num)]
    step = (stop - start) / (num - 1)
    return [float(start) + i * step for i in range(num - 1)] + [float(stop)]


def _axis_values(key: str, spec: Any) -> tuple[list | None, list[Problem]]:
    """The values of one grid key, or its problems."""
    where = f"grid.{key}"
    if isinstance(spec, list):
        if not spec:
            return None, [Problem(where, "empty", f"{key} has no values: give at least one")]
        return spec, []
    if not isinstance(spec, dict):
        return None, [Problem(where, "wrong_type",
                              f"{key} must be an array of values or a table "
                              f"{{ start, stop, num }}, not {_show(spec)}")]
    problems = [Problem(f"{where}.{k}", "unknown_key",
                        f"unknown key '{k}' in the range of {key}; known keys: start, stop, num")
                for k in spec if k not in _RANGE_KEYS]
    problems += [Problem(f"{where}.{k}", "missing", f"the range of {key} needs '{k}'")
                 for k in _RANGE_KEYS if k not in spec]
    problems += [Problem(f"{where}.{k}", "wrong_type",
                         f"{key} {k} must be a finite number, not {_show(spec[k])}")
                 for k in ("start", "stop")
                 if k in spec and not (_is_number(spec[k]) and math.isfinite(spec[k]))]
    num = spec.get("num")
    if "num" in spec and not (_is_number(num) and isinstance(num, int) and num >= 1):
        problems.append(Problem(f"{where}.num", "out_of_range" if _is_number(num) else "wrong_type",
                                f"{key} num must be a whole number, at least 1, not {_show(num)}"))
    if problems:
        return None, problems
    return _linspace(spec["start"], spec["stop"], num), []


def _assign(data: dict, key: str, value: Any) -> str | None:
    """Set the dotted ``key`` in ``data`` (making missing tables); a reason if it cannot."""
    parts = key.split(".")
    node = data
    for depth, part in enumerate(parts[:-1]):
        child = node.setdefault(part, {})
        if not isinstance(child, dict):
            table = ".".join(parts[: depth + 1])
            return f"{table} is not a table in the base file, so {key} cannot be set"
        node = child
    node[parts[-1]] = value
    return None


def _related(path: str, key: str) -> bool:
    """Is a problem at ``path`` about the grid ``key`` (the key, inside it, or a parent)?"""
    return path == key or path.startswith(key + ".") or key.startswith(path + ".")


def expand_grid(grid_file: str | os.PathLike) -> list[DesignJob]:
    """Expand a grid file into one job per point of its Cartesian product.

    Parameters
    ----------
    grid_file : str or path-like
        The grid TOML file (format in the module docstring).

    Returns
    -------
    list of DesignJob
        In product order (the last key varies fastest), named ``<name>-001`` onwards,
        each holding the base file's data with the grid values set.

    Raises
    ------
    GridError
        Listing every problem before anything runs: the grid file or its base cannot
        be read; an unknown top-level key; a missing ``base`` or ``[grid]``; a key
        with no values, a bad range, or a value the parameter schema refuses at that
        key (an unknown key, a wrong type, out of range: each named ``grid.<key>``);
        a base file that is invalid where the grid does not override it. Problems
        that only a combination of values shows (and the kinematic feasibility
        checks) are each design's own, reported when it is built.
    """
    from cadgen.params import NAME_PATTERN, ParameterError, validate_data
    from cadgen.params._tables import NAME_MAX_LENGTH

    grid_path = Path(grid_file)
    source = str(grid_file)
    grid, problems = _read_toml(grid_path, "")
    if grid is None:
        raise GridError(problems, source)
    problems += [Problem(str(k), "unknown_key", f"unknown key '{k}' at the top level of the grid "
                         f"file; known keys: {', '.join(_GRID_KEYS)}")
                 for k in grid if k not in _GRID_KEYS]

    base, base_data = grid.get("base"), None
    if isinstance(base, str):
        base_data, found = _read_toml(grid_path.parent / base, "base")
        problems += found
    else:
        problems.append(Problem("base", "missing", "required key 'base' (the parameter file the "
                                "grid varies, relative to the grid file) is missing")
                        if base is None else
                        Problem("base", "wrong_type", f"base must be a string, not {_show(base)}"))

    table = grid.get("grid")
    axes: list[tuple[str, list]] = []
    if table is None:
        problems.append(Problem("grid", "missing", "required table [grid] is missing"))
    elif not isinstance(table, dict):
        problems.append(Problem("grid", "wrong_type", f"grid must be a table, not {_show(table)}"))
    else:
        seen = set()
        for key, spec in _flatten(table):
            if key in seen:
                problems.append(Problem(f"grid.{key}", "duplicate", f"{key} is given twice"))
                continue
            seen.add(key)
            if not all(key.split(".")):
                problems.append(Problem(f"grid.{key}", "unknown_key",
                                        f"{key!r} is not a dotted key like 'train.R'"))
                continue
            if key in _NOT_SWEPT:
                problems.append(Problem(f"grid.{key}", "not_allowed",
                                        f"{key} cannot be swept (the grid sets it)"))
                continue
            values, axis_problems = _axis_values(key, spec)
            problems += axis_problems
            if values is not None:
                axes.append((key, values))
        if not seen:
            problems.append(Problem("grid", "empty", "[grid] names no key to vary"))

    count = math.prod(len(values) for _, values in axes) if axes else 0
    prefix = grid.get("name")
    if prefix is None and isinstance(base_data, dict):
        prefix = base_data.get("name")
    width = max(_MIN_INDEX_DIGITS, len(str(count)))
    if not isinstance(prefix, str) and (prefix is not None or isinstance(base_data, dict)):
        # (no name and no readable base: the base's problem says it all)
        problems.append(Problem("name", "wrong_type" if "name" in grid else "missing",
                                "name (the prefix of the design names) must be a string"))
    elif isinstance(prefix, str) and (not re.match(NAME_PATTERN, prefix)
                                      or len(prefix) + 1 + width > NAME_MAX_LENGTH):
        problems.append(Problem("name", "invalid_name",
                                f"name {_show(prefix)} cannot prefix design names: it must start "
                                "with a letter or digit, contain only letters, digits, '.', '_' "
                                f"and '-', and leave room for '-{'0' * width}' within "
                                f"{NAME_MAX_LENGTH} characters"))
    if not isinstance(base_data, dict):
        if base_data is not None:
            problems.append(Problem("base", "wrong_type", f"{base} is not a parameter table"))
        raise GridError(problems, source)

    # Each value of each key is checked against the schema with every other key at its
    # first value, so a bad value is reported at its own key, once.
    firsts = {key: values[0] for key, values in axes}
    reported = set()
    for key, values in axes:
        for index, value in enumerate(values):
            data = copy.deepcopy(base_data)
            data["name"] = "grid-check"  # the real names are checked above
            reasons = [_assign(data, k, value if k == key else firsts[k]) for k in firsts]
            reason = next((r for r in reasons if r), None)
            if reason:
                found = [Problem(key, "wrong_type", reason)]
            else:
                try:
                    validate_data(data, source, check_feasibility=False)
                    continue
                except ParameterError as exc:
                    found = exc.problems
            for problem in found:
                owner = next((k for k in firsts if _related(problem.path, k)), None)
                if owner is None:
                    entry = (problem.path or "base", problem.code,
                             f"in the base file {base}: {problem.message}")
                elif owner == key:
                    where = "" if problem.path == key else f"{problem.path}: "
                    entry = (f"grid.{key}", problem.code,
                             f"{where}{problem.message}" if len(values) == 1 else
                             f"value {index + 1} of {len(values)}: {where}{problem.message}")
                else:
                    continue  # another key's first value: reported under that key
                if entry not in reported:
                    reported.add(entry)
                    problems.append(Problem(*entry))
    if problems:
        raise GridError(problems, source)

    jobs = []
    keys = [key for key, _ in axes]
    for number, combination in enumerate(itertools.product(*(v for _, v in axes)), start=1):
        data = copy.deepcopy(base_data)
        name = f"{prefix}-{number:0{width}d}"
        data["name"] = name
        for key, value in zip(keys, combination):
            _assign(data, key, value)
        jobs.append(DesignJob(name, source, data=data, values=dict(zip(keys, combination))))
    return jobs


# --------------------------------------------------------------------------- one design


def _resolve_build(build: Build | None) -> Callable[..., Any]:
    build = DEFAULT_BUILD if build is None else build
    if callable(build):
        return build
    module, _, name = str(build).partition(":")
    if not module or not name:
        raise ValueError(f"build must be a callable or 'module:function', not {build!r}")
    return getattr(importlib.import_module(module), name)


def _snake(name: str) -> str:
    return re.sub(r"(?<!^)(?=[A-Z])", "_", name).lower()


def _number(value: Any) -> float | int | None:
    """A plain Python number (numpy scalars would print as ``np.float64(...)``)."""
    if value is None:
        return None
    return int(value) if isinstance(value, numbers.Integral) else float(value)


def _flag(value: Any) -> bool | None:
    return None if value is None else bool(value)


def _report_metrics(report: Mapping) -> dict:
    """``{metric id: {value, unit, target, passed}}`` of a report, in report order.

    Planting: the report's metrics, ``key@<spacing>mm`` for per-spacing ones. Pricking
    (no targets, so ``passed`` is None): the forward-check deviation, the number of
    findings, and per inclination the hole mouth, time in soil and projected height.
    """
    metrics = {}
    for m in report.get("metrics", ()):
        spacing = m.get("spacing_mm")
        key = m["key"] if spacing is None else f"{m['key']}@{float(spacing):g}mm"
        metrics[key] = {"value": _number(m.get("value")), "unit": m.get("unit", ""),
                        "target": m.get("target"), "passed": _flag(m.get("passed"))}
    if report.get("mechanism") == "pricking":
        def add(key, value, unit):
            metrics[key] = {"value": _number(value), "unit": unit, "target": None, "passed": None}

        add("forward_deviation", report.get("verification", {}).get("forward_deviation_mm"), "mm")
        add("findings", len(report.get("findings", ())), "")
        for row in report.get("field", {}).get("per_inclination", ()):
            at = f"@{float(row['inclination_deg']):g}deg"
            add("hole_mouth" + at, row.get("hole_mouth_mm"), "mm")
            add("time_in_soil" + at, row.get("time_in_soil_deg"), "deg")
            add("projected_height" + at, row.get("projected_height_mm"), "mm")
    return metrics


def _summary(job: DesignJob, start: float, **fields) -> dict:
    summary = {"name": job.name, "source": job.source, "values": dict(job.values), "ok": False,
               "passed": None, "metrics": {}, "notes": [], "failure": None, "files": [],
               "output_dir": None}
    summary.update(fields)
    summary["seconds"] = round(time.perf_counter() - start, 3)
    return summary


def _problem_failure(exc: DesignError) -> dict:
    problems = [{"path": p.path, "code": p.code, "message": p.message} for p in exc.problems]
    return {"code": problems[0]["code"] if problems else _snake(type(exc).__name__),
            "message": "; ".join(str(p) for p in exc.problems) or str(exc),
            "exception": type(exc).__name__, "problems": problems}


def _exception_failure(exc: BaseException, code: str | None = None) -> dict:
    import traceback

    text = "".join(traceback.format_exception(exc)).splitlines()[-_TRACEBACK_LINES:]
    return {"code": code or _snake(type(exc).__name__),
            "message": f"{type(exc).__name__}: {exc}", "exception": type(exc).__name__,
            "problems": [], "traceback": "\n".join(text)}


def run_design(job: DesignJob, output_root: str | os.PathLike, build: Build | None = None,
               build_kwargs: Mapping | None = None) -> dict:
    """Validate and build one design; never raises for a bad design.

    Parameters
    ----------
    job : DesignJob
    output_root : str or path-like
        The build writes ``<output_root>/<name>/``.
    build : callable or str, optional
        ``build(params, output_root=Path, **build_kwargs)``, or ``"module:function"``;
        :data:`DEFAULT_BUILD` when omitted.
    build_kwargs : mapping, optional
        Extra keyword arguments of the build (``plots=False``...).

    Returns
    -------
    dict
        ``name``, ``source``, ``values`` (grid values), ``ok`` (built), ``passed``
        (targets met: bool, or None without targets or a build), ``metrics``
        (``{id: {value, unit, target, passed}}``), ``notes`` (the report's
        ``failures`` sentences, when it has them: why a built design did not pass),
        ``failure`` (None, or ``code``, ``message``, ``exception``, ``problems`` as
        ``{path, code, message}`` dicts, and ``traceback`` for an unexpected
        exception), ``files`` (written, relative to ``output_dir``), ``seconds`` and
        ``output_dir`` (str or None).
    """
    start = time.perf_counter()
    try:
        from cadgen.params import load_params, validate_data

        if job.path is not None:
            params = load_params(job.path)
        else:
            params = validate_data(job.data, job.source)
        if job.blocked_by:
            return _summary(job, start, failure={
                "code": "duplicate_name", "message": job.blocked_by,
                "exception": None, "problems": []})
        result = _resolve_build(build)(params, output_root=Path(output_root),
                                       **dict(build_kwargs or {}))
    except DesignError as exc:  # ParameterError too
        return _summary(job, start, failure=_problem_failure(exc))
    except MechanismError as exc:  # e.g. ConvergenceError: a verdict on the design
        return _summary(job, start, failure=_exception_failure(exc))
    except Exception as exc:  # a bug or an engine error: still only this design fails
        return _summary(job, start, failure=_exception_failure(exc, "exception"))
    report = result if isinstance(result, Mapping) else getattr(result, "report", {}) or {}
    output_dir = None if isinstance(result, Mapping) else getattr(result, "output_dir", None)
    files = [] if isinstance(result, Mapping) else list(getattr(result, "files", None) or [])
    notes = [str(note) for note in report.get("failures", ()) or ()]
    return _summary(job, start, ok=True, passed=_flag(report.get("passed")),
                    metrics=_report_metrics(report), notes=notes, files=[str(f) for f in files],
                    output_dir=None if output_dir is None else str(output_dir))


# --------------------------------------------------------------------------- executors


def _order(summary: Mapping) -> tuple:
    """Summary order: by name, then source; a file given twice: the built one first."""
    failure = summary["failure"] or {}
    return summary["name"], summary["source"], not summary["ok"], failure.get("code", "")


def _collect(futures: Mapping, finished: Iterable, on_result) -> list[dict]:
    """Summaries of ``futures`` (future -> job) in the order ``finished`` yields them."""
    summaries = []
    for future in finished:
        try:
            summary = future.result()
        except Exception as exc:  # the job did not return: BrokenProcessPool, KilledWorker
            summary = _summary(futures[future], time.perf_counter(),
                               failure=_exception_failure(exc, "worker_error"))
        if hasattr(future, "release"):
            future.release()  # Dask: let the cluster forget the result
        summaries.append(summary)
        if on_result is not None:
            on_result(summary)
    return summaries


def _run_local(jobs, output_root, build, build_kwargs, workers, on_result):
    import multiprocessing
    import pickle
    from concurrent.futures import ProcessPoolExecutor, as_completed

    try:
        pickle.dumps(build)
    except Exception as exc:
        raise TypeError(f"the build {build!r} cannot be sent to worker processes ({exc}); "
                        "give a module-level function or 'module:function'") from None
    # spawn: one start method on every platform, safe when the parent holds threads (a
    # Dask client); each worker pays its imports once (fork saves ~0.2 s per worker).
    context = multiprocessing.get_context("spawn")
    pool = ProcessPoolExecutor(max_workers=max(1, min(workers, len(jobs))), mp_context=context)
    try:
        futures = {pool.submit(run_design, job, output_root, build, build_kwargs): job
                   for job in jobs}
        summaries = _collect(futures, as_completed(futures), on_result)
    except BaseException:
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown()
    return summaries


def _run_dask(jobs, output_root, build, build_kwargs, scheduler, on_result):
    import uuid

    try:
        from dask.distributed import Client, as_completed as dask_completed
    except ImportError:
        raise ImportError("a Dask scheduler needs dask.distributed: "
                          "pip install 'cadgen[dask]'") from None
    batch = uuid.uuid4().hex[:8]  # keys unique across batches sharing a cluster
    with Client(scheduler) as client:
        futures = {client.submit(run_design, job, output_root, build, build_kwargs,
                                 key=f"cadgen-{job.name}-{batch}-{number}", pure=False): job
                   for number, job in enumerate(jobs)}
        try:
            return _collect(futures, dask_completed(list(futures)), on_result)
        except BaseException:
            client.cancel(list(futures))
            raise


def run_batch(jobs: Sequence[DesignJob], output_root: str | os.PathLike = "outputs", *,
              workers: int | None = None, scheduler: str | None = None,
              build: Build | None = None, build_kwargs: Mapping | None = None,
              on_result: Callable[[dict], None] | None = None) -> list[dict]:
    """Build every design, in local processes or on a Dask cluster.

    Parameters
    ----------
    jobs : sequence of DesignJob
        Pass them through :func:`guard_names` first if names may repeat.
    output_root : str or path-like, default "outputs"
        Made absolute here, so workers with another working directory write the same
        folders. On a Dask cluster of several machines it must be a shared filesystem
        (and so must the parameter files).
    workers : int, optional
        Local worker processes (default ``os.cpu_count()``); ignored with a scheduler.
    scheduler : str, optional
        A Dask scheduler address (``tcp://host:8786``): one ``client.submit`` per design.
        Needs ``dask[distributed]`` here and ``cadgen`` installed on the workers.
    build : callable or str, optional
        See :func:`run_design`. A callable must pickle by reference (a module-level
        function) for local processes; Dask's cloudpickle also takes closures.
    build_kwargs : mapping, optional
        Extra keyword arguments of the build.
    on_result : callable, optional
        Called with each summary as its design finishes (in finishing order).

    Returns
    -------
    list of dict
        One summary per job (see :func:`run_design`), ordered by name, then source.

    Notes
    -----
    Local workers are spawned, not forked (safe beside a Dask client's threads), so a
    script calling this needs ``if __name__ == "__main__":``. No timeout yet (TODO above).
    """
    if not jobs:
        return []
    root = str(Path(output_root).resolve())
    kwargs = dict(build_kwargs or {})
    build = DEFAULT_BUILD if build is None else build
    if scheduler:
        summaries = _run_dask(jobs, root, build, kwargs, scheduler, on_result)
    else:
        summaries = _run_local(jobs, root, build, kwargs, workers or os.cpu_count() or 1,
                               on_result)
    return sorted(summaries, key=_order)


# --------------------------------------------------------------------------- summary


def _status(summary: Mapping) -> str:
    return "ok" if summary["ok"] else "failed"


def _yes_no(value: bool | None) -> str:
    return "" if value is None else ("yes" if value else "no")


def _cell(value: Any) -> str:
    """A CSV cell: floats round-trip exactly (repr), tables and arrays as JSON."""
    if value is None or isinstance(value, (str, int, float)):
        return "" if value is None else repr(value) if isinstance(value, float) else str(value)
    return json.dumps(value)


def _columns(summaries: Sequence[Mapping]) -> tuple[list[str], list[str]]:
    """Grid keys and metric ids of all designs, in first-seen order."""
    grid_keys: dict[str, None] = {}
    metric_ids: dict[str, None] = {}
    for summary in summaries:
        grid_keys.update(dict.fromkeys(summary.get("values", {})))
        metric_ids.update(dict.fromkeys(summary["metrics"]))
    return list(grid_keys), list(metric_ids)


def _failure_codes(summary: Mapping) -> str:
    failure = summary["failure"]
    if not failure:
        return ""
    codes = [p["code"] for p in failure.get("problems") or ()] or [failure["code"]]
    return ";".join(dict.fromkeys(codes))


def _missed(summary: Mapping) -> str:
    return ";".join(k for k, m in summary["metrics"].items() if m["passed"] is False)


def _why_not(summary: Mapping) -> str:
    """Why a built design did not pass: its missed targets, else its report's first note."""
    missed, notes = _missed(summary), summary.get("notes") or ()
    if missed or not notes:
        return "missed " + (missed.replace(";", ", ") or "its targets")
    return notes[0] + (f" (+{len(notes) - 1} more)" if len(notes) > 1 else "")


def summary_csv(summaries: Sequence[Mapping]) -> str:
    """The batch summary as CSV text: one row per design, ordered by name.

    Columns: ``design``, ``status`` (ok/failed), ``passed`` (yes/no, empty without
    targets), ``missed_targets``, one ``grid:<key>`` column per grid key, one column per
    metric id (its value), ``notes`` (why a built design did not pass, when its report
    says), ``failure_code``, ``failure`` (every problem), ``source``, ``output`` (the
    folder under the output root). No timings or absolute paths: the same batch gives
    the same file.
    """
    ordered = sorted(summaries, key=_order)
    grid_keys, metric_ids = _columns(ordered)
    stream = io.StringIO()
    writer = csv.writer(stream, lineterminator="\n")
    writer.writerow(["design", "status", "passed", "missed_targets",
                     *(f"grid:{k}" for k in grid_keys), *metric_ids,
                     "notes", "failure_code", "failure", "source", "output"])
    for s in ordered:
        metrics = s["metrics"]
        writer.writerow([
            s["name"], _status(s), _yes_no(s["passed"]), _missed(s),
            *(_cell(s.get("values", {}).get(k)) for k in grid_keys),
            *(_cell(metrics[k]["value"]) if k in metrics else "" for k in metric_ids),
            "; ".join(s.get("notes", ())), _failure_codes(s),
            s["failure"]["message"] if s["failure"] else "", s["source"],
            Path(s["output_dir"]).name if s["output_dir"] else "",
        ])
    return stream.getvalue()


_HTML_STYLE = """
body { font-family: system-ui, sans-serif; margin: 1.5em; color: #222; }
table { border-collapse: collapse; font-size: 0.9em; } th { background: #f3f3f3; }
th, td { border: 1px solid #ccc; padding: 0.3em 0.6em; vertical-align: top; }
td.num { text-align: right; font-variant-numeric: tabular-nums; } .ok { color: #176117; }
.failed, .miss { color: #a40000; font-weight: bold; } td.reason { white-space: pre-wrap; }
"""


def summary_html(summaries: Sequence[Mapping], title: str = "Batch summary") -> str:
    """The batch summary as one self-contained HTML page (a table, inline style).

    Same rows and order as :func:`summary_csv`; metric headers carry their units, a
    missed target is marked, and a failed design shows every problem.
    """
    esc = html.escape
    ordered = sorted(summaries, key=_order)
    grid_keys, metric_ids = _columns(ordered)
    units = {k: m.get("unit") or "" for s in reversed(ordered) for k, m in s["metrics"].items()}
    built = sum(s["ok"] for s in ordered)
    not_passed = sum(s["ok"] and s["passed"] is False for s in ordered)
    head = ["design", "status", "passed", *grid_keys,
            *(f"{k} ({units[k]})" if units[k] else k for k in metric_ids), "failure or notes",
            "source"]
    rows = []
    for s in ordered:
        cells = [f"<td>{esc(s['name'])}</td>",
                 f"<td class=\"{_status(s)}\">{_status(s)}</td>",
                 f"<td class=\"{'miss' if s['passed'] is False else ''}\">"
                 f"{_yes_no(s['passed'])}</td>"]
        cells += [f"<td class=\"num\">{esc(_cell(s.get('values', {}).get(k)))}</td>"
                  for k in grid_keys]
        for k in metric_ids:
            m = s["metrics"].get(k) or {"value": None}
            target = f" title=\"target {esc(str(m['target']))}\"" if m.get("target") else ""
            mark = " miss" if m.get("passed") is False else ""
            value = "" if m["value"] is None else f"{m['value']:.6g}"
            cells.append(f"<td class=\"num{mark}\"{target}>{value}</td>")
        failure = s["failure"]
        reason = ("\n".join(s.get("notes", ())) if not failure else
                  "\n".join(str(Problem(**p)) for p in failure["problems"]) if failure["problems"]
                  else f"{failure['message']} [{failure['code']}]")
        cells += [f"<td class=\"reason\">{esc(reason)}</td>", f"<td>{esc(s['source'])}</td>"]
        rows.append("<tr>" + "".join(cells) + "</tr>")
    return (
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
        f"<title>{esc(title)}</title>\n<style>{_HTML_STYLE}</style>\n</head>\n<body>\n"
        f"<h1>{esc(title)}</h1>\n<p>{len(ordered)} designs: {built} built, "
        f"{len(ordered) - built} failed, {not_passed} built but did not pass.</p>\n"
        "<table>\n<thead><tr>" + "".join(f"<th>{esc(h)}</th>" for h in head) + "</tr></thead>\n"
        "<tbody>\n" + "\n".join(rows) + "\n</tbody>\n</table>\n</body>\n</html>\n"
    )


def write_summary(summaries: Sequence[dict], output_root: str | os.PathLike) -> tuple[Path, Path]:
    """Write ``batch-summary.csv`` and ``.html`` atomically under ``output_root``; their paths."""
    from .atomic import write_text_atomic

    root = Path(output_root)
    root.mkdir(parents=True, exist_ok=True)
    return (write_text_atomic(root / SUMMARY_CSV, summary_csv(summaries)),
            write_text_atomic(root / SUMMARY_HTML, summary_html(summaries)))


def batch_exit_code(summaries: Iterable[Mapping], strict: bool = False) -> int:
    """:data:`EXIT_OK` if every design built (and, when ``strict``, none missed a target:
    a design without targets passes), else :data:`EXIT_FAILED`."""
    for s in summaries:
        if not s["ok"] or (strict and s["passed"] is False):
            return EXIT_FAILED
    return EXIT_OK


# --------------------------------------------------------------------------- progress


def _clock(seconds: float) -> str:
    seconds = int(round(seconds))
    hours, rest = divmod(seconds, 3600)
    return (f"{hours}:" if hours else "") + f"{rest // 60:02d}:{rest % 60:02d}"


def _reason(summary: Mapping) -> str:
    failure = summary["failure"]
    if not failure:
        return ""
    problems = failure.get("problems") or ()
    more = f" (+{len(problems) - 1} more)" if len(problems) > 1 else ""
    first = str(Problem(**problems[0])) if problems else f"{failure['message']} [{failure['code']}]"
    return first + more


class Progress:
    """A one-line progress bar: ``[12/40] 30% ok 11, failed 1, eta 00:42``.

    On a terminal the line is redrawn in place (failures printed above it); elsewhere (a
    log, CI) it prints one line per finished design.

    Parameters
    ----------
    total : int
        Number of designs.
    stream : text stream, default sys.stderr
    tty : bool, optional
        Force the terminal mode on or off (default: ``stream.isatty()``).
    """

    def __init__(self, total: int, stream: TextIO | None = None, tty: bool | None = None):
        self.total = total
        self.stream = sys.stderr if stream is None else stream
        self.tty = bool(tty if tty is not None else getattr(self.stream, "isatty", bool)())
        self.done = self.ok = self.failed = 0
        self.start = time.perf_counter()
        if self.tty:  # show the bar at once: the first design may take a while
            self.stream.write(self.line())
            self.stream.flush()

    def line(self) -> str:
        """The current progress line (no line break)."""
        percent = 100 * self.done // self.total if self.total else 100
        text = f"[{self.done}/{self.total}] {percent}% ok {self.ok}, failed {self.failed}"
        if 0 < self.done < self.total:
            elapsed = time.perf_counter() - self.start
            text += f", eta {_clock(elapsed / self.done * (self.total - self.done))}"
        return text

    def update(self, summary: Mapping) -> None:
        """Count one finished design and show it."""
        self.done += 1
        self.ok += bool(summary["ok"])
        self.failed += not summary["ok"]
        if self.tty:
            if not summary["ok"]:
                self.stream.write(f"\r\x1b[Kfailed {summary['name']}: {_reason(summary)}\n")
            self.stream.write("\r\x1b[K" + self.line())
        else:
            verdict = "ok" if summary["ok"] else f"failed: {_reason(summary)}"
            self.stream.write(f"[{self.done}/{self.total}] {summary['name']} {verdict} "
                              f"({summary['seconds']:.1f} s)\n")
        self.stream.flush()

    def close(self) -> None:
        """End the bar's line (terminal mode)."""
        if self.tty and self.done:
            self.stream.write("\n")
            self.stream.flush()


# --------------------------------------------------------------------------- command line


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {value}")
    return value


def add_batch_arguments(parser: argparse.ArgumentParser) -> argparse.ArgumentParser:
    """Add the ``cadgen batch`` arguments to ``parser`` (a subcommand's parser) and return it.

    ``FILE ...``, ``--grid GRID`` (repeatable), ``--output-dir DIR``, ``--workers N``,
    ``--scheduler ADDRESS``, ``--strict``; also sets the default ``handler=main_batch``.
    """
    parser.add_argument("files", nargs="*", metavar="FILE", help="TOML parameter file")
    parser.add_argument("--grid", action="append", default=[], metavar="GRID",
                        help="TOML grid file: a base parameter file and values to vary "
                             "(the Cartesian product is built); may be repeated")
    parser.add_argument("--output-dir", metavar="DIR", default="outputs",
                        help="root of the output folders and of batch-summary.csv/.html "
                             "(default: %(default)s)")
    parser.add_argument("--workers", metavar="N", type=_positive_int, default=None,
                        help=f"local worker processes (default: the number of CPUs, "
                             f"{os.cpu_count()} here); ignored with --scheduler")
    parser.add_argument("--scheduler", metavar="ADDRESS", default=None,
                        help="run on the Dask cluster of this scheduler (tcp://host:8786) "
                             "instead of local processes; needs the 'dask' extra")
    parser.add_argument("--strict", action="store_true",
                        help="also exit 1 if a design misses one of its targets")
    parser.set_defaults(handler=main_batch)
    return parser


def main_batch(args: argparse.Namespace) -> int:
    """Run ``cadgen batch`` (``args`` from :func:`add_batch_arguments`): build every design,
    write the summary, print where it is.

    Returns
    -------
    int
        :data:`EXIT_OK` (0) every design built (with ``--strict``: and met its targets);
        :data:`EXIT_FAILED` (1) otherwise; :data:`EXIT_PROBLEMS` (2) if nothing ran (a
        bad grid file, no designs, no Dask). Progress goes to stderr; the closing
        counts and the summary paths to stdout.
    """
    jobs = file_jobs(args.files)
    for grid in args.grid:
        try:
            jobs += expand_grid(grid)
        except GridError as exc:
            for problem in exc.problems:
                print(f"{grid}: {problem}", file=sys.stderr)
            return EXIT_PROBLEMS
    if not jobs:
        print("cadgen batch: no designs: give parameter files or --grid GRID", file=sys.stderr)
        return EXIT_PROBLEMS
    jobs = guard_names(jobs)

    progress = Progress(len(jobs))
    start = time.perf_counter()
    try:
        summaries = run_batch(jobs, args.output_dir, workers=args.workers,
                              scheduler=args.scheduler, on_result=progress.update)
    except (ImportError, OSError) as exc:  # no dask, or the scheduler cannot be reached
        print(f"cadgen batch: {exc}", file=sys.stderr)
        return EXIT_PROBLEMS
    finally:
        progress.close()
    csv_path, html_path = write_summary(summaries, args.output_dir)

    built = sum(s["ok"] for s in summaries)
    not_passed = sum(s["ok"] and s["passed"] is False for s in summaries)
    took, plural = _clock(time.perf_counter() - start), "s" * (len(summaries) != 1)
    print(f"{len(summaries)} design{plural} in {took}: {built} built, "
          f"{len(summaries) - built} failed, {not_passed} built but did not pass")
    for s in summaries:
        if not s["ok"]:
            print(f"  failed {s['name']} ({s['source']}): {_reason(s)}")
        elif s["passed"] is False:
            print(f"  did not pass {s['name']}: {_why_not(s)}")
    print(f"summary: {csv_path}\n         {html_path}")
    return batch_exit_code(summaries, args.strict)
