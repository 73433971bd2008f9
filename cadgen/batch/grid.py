"""The designs of a batch: parameter files, grid files, names that must not collide.

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
"""

from __future__ import annotations

import copy
import itertools
import math
import os
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from kinematics.errors import DesignError, Problem

from cadgen.batch.summary import SUMMARY_CSV, SUMMARY_HTML
from cadgen.params.side_files import (assign_dotted as _assign, flatten_dotted, read_toml_file,
                                      wrong_kind_of_file)
from cadgen.params.side_files import is_number as _is_number, show as _show

__all__ = ["DesignJob", "GridError", "file_jobs", "expand_grid", "guard_names"]

_GRID_KEYS = ("base", "name", "grid")
_RANGE_KEYS = ("start", "stop", "num")
_NOT_SWEPT = ("name", "mechanism")
_MIN_INDEX_DIGITS = 3


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
    name = (read_toml_file(path, "")[0] or {}).get("name")
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
    grid, _, problems = read_toml_file(grid_path, "")
    if grid is None:
        raise GridError(problems, source)
    wrong = wrong_kind_of_file(grid, "grid")
    if wrong:   # one line naming the command that reads it, not an unknown key per table
        raise GridError(wrong, source)
    problems += [Problem(str(k), "unknown_key", f"unknown key '{k}' at the top level of the grid "
                         f"file; known keys: {', '.join(_GRID_KEYS)}")
                 for k in grid if k not in _GRID_KEYS]

    base, base_data = grid.get("base"), None
    if isinstance(base, str):
        base_data, _, found = read_toml_file(grid_path.parent / base, "base")
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
        for key, spec in flatten_dotted(table, _RANGE_KEYS):
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
