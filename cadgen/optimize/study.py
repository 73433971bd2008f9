"""The study file of ``cadgen optimize``: read, validate (every problem at once), load.

A study names a base design, its free parameters and their bounds, the objectives and a
budget; the base file's targets are the constraints::

    base = "../xin2024-planter.toml"        # relative to the study file
    name = "planter-margins"                # output folder (default: the base's name)
    [free]                                  # dotted parameter paths and their bounds
    "planter.L2" = [150.0, 230.0]
    "pitch_curve.b1" = [24.0, 31.0]
    [objectives]                            # one or more
    maximize = ["min_margin"]               # the smallest normalised margin, or metric keys
    minimize = ["hole_width@185"]
    [budget]
    evaluations = 20000                     # designs screened (default 2000)
    seed = 1                                # same seed, same result (default 1)
    [precision]                             # optional: the step each free value is
    "planter.L2" = 0.5                      # rounded to before it is certified

The final designs are rounded to shop precision before they are certified, and the rounded
design is the one certified, written to best.toml and built: each free value to its
``[precision]`` step, else by its unit (:data:`DEFAULT_STEPS`: 0.01 mm for lengths, 0.01
deg, 1e-4 rad or 1e-4 for a ratio); the pricking points' displacements to
``[precision] "trajectory.points"`` (0.01 mm by default).

A pricking study moves the type-value points within a box:
``[free] "trajectory.points" = { box = 3.0 }`` (every point), or ``{ box = 3.0, points =
[3, 4, 5] }`` (those only, 1-based as Q1..Qm).

:func:`load_study` checks everything before any work and raises one :class:`StudyError`
listing every problem, each at its field (``free."planter.L2"``,
``objectives.maximize[0]``, ``budget.evaluations``, ``base``): unknown keys, a path the
base kind's schema does not have or that is not a real number (integers such as tooth
counts cannot be searched continuously), bounds that are not two finite numbers, reversed
or empty, or outside what the schema accepts at that path (each bound is validated in the
base file's place, as ``cadgen batch --grid`` validates its values), an unknown objective
(the problem class of the kind says which keys it knows), a budget that is not a positive
whole number, a base file that is missing or invalid. Nothing is written.
"""

from __future__ import annotations

import copy
import difflib
import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from kinematics.errors import Problem

from cadgen.params.loading import ParameterError
from cadgen.params.side_files import (assign_dotted as _assign, flatten_dotted, read_toml_file,
                                      wrong_kind_of_file)
from cadgen.params.side_files import is_number as _is_number, show as _show

__all__ = ["Study", "StudyError", "load_study", "STUDY_KEYS", "DEFAULT_EVALUATIONS",
           "DEFAULT_SEED", "MAX_EVALUATIONS", "DEFAULT_STEPS"]

STUDY_KEYS = ("base", "name", "free", "objectives", "budget", "precision")
#: The rounding step of a free value by its unit, when the study's [precision] gives none:
#: what a drawing or a workshop states (0.01 mm, 0.01 deg); a ratio or a radian to 1e-4.
DEFAULT_STEPS = {"mm": 0.01, "deg": 0.01, "rad": 1e-4, None: 1e-4}
_SENSES = {"maximize": "max", "minimize": "min"}
_BUDGET_KEYS = ("evaluations", "seed")
_BOX_KEYS = ("box", "points")
#: The only free path of a pricking study (the type-value points, moved within a box).
POINTS_PATH = "trajectory.points"
DEFAULT_EVALUATIONS = 2000
DEFAULT_SEED = 1
#: A budget beyond this is a typing slip, not a study: a billion screened designs take days.
MAX_EVALUATIONS = 10**9


class StudyError(ParameterError):
    """A study file with problems; ``problems`` lists all of them, each at its field."""


@dataclass(frozen=True)
class Study:
    """A validated study.

    Attributes
    ----------
    path : Path
        The study file.
    name : str
        The output folder's name (``<output-dir>/<name>/``).
    base_path : Path
        The base parameter file (resolved against the study file).
    base_params : PlantingParameters or PrickingParameters
        The validated base design.
    kind : str
        ``"planting"`` or ``"pricking"``.
    free : tuple or dict
        Planting: ``((path, low, high), ...)`` in file order. Pricking: the points' box
        spec ``{"box": float, "points": [1-based numbers]}`` (all points when the file
        names none).
    objectives : tuple of (str, str)
        ``((key, "max" | "min"), ...)``: maximised ones first, in file order.
    evaluations, seed : int
        The budget of screened designs and the random seed.
    text : str
        The study file's text (for the report).
    steps : dict
        ``{free path: rounding step}`` of every free path (``trajectory.points`` for a
        pricking study): the finals are rounded to these before they are certified.
    """

    path: Path
    name: str
    base_path: Path
    base_params: Any
    kind: str
    free: Any
    objectives: tuple
    evaluations: int
    seed: int
    text: str = ""
    steps: dict = field(default_factory=dict)

    def with_budget(self, *, evaluations: int | None = None, seed: int | None = None) -> "Study":
        """This study with the command line's ``--evaluations`` / ``--seed`` instead."""
        from dataclasses import replace

        problems = []
        if evaluations is not None and not _whole(evaluations, 1):
            problems.append(Problem("--evaluations", "out_of_range",
                                    f"--evaluations must be a whole number from 1 to "
                                    f"{MAX_EVALUATIONS}, not {evaluations!r}"))
        if seed is not None and not _whole(seed, 0):
            problems.append(Problem("--seed", "out_of_range",
                                    f"--seed must be a whole number >= 0, not {seed!r}"))
        if problems:
            raise StudyError(problems, str(self.path))
        return replace(self, evaluations=self.evaluations if evaluations is None else evaluations,
                       seed=self.seed if seed is None else seed)


# --------------------------------------------------------------------------- helpers


def _whole(value: Any, low: int) -> bool:
    return (isinstance(value, int) and not isinstance(value, bool)
            and low <= value <= MAX_EVALUATIONS)


def _free_field(path: str) -> str:
    return f'free."{path}"'


def _numeric_fields(kind: str) -> dict:
    """``{path: schema entry}`` of every field of the kind (the studio's schema)."""
    from cadgen.studio.schema import studio_schema

    tables = studio_schema()["kinds"][kind]["tables"]
    return {field["path"]: field for table in tables for field in table["fields"]}


def _related(problem_path: str, path: str) -> bool:
    return problem_path == path or problem_path.startswith(path + ".")


# --------------------------------------------------------------------------- the parts


def _check_bounds(path: str, spec: Any) -> tuple[tuple | None, list[Problem]]:
    """``(low, high)`` of one planting free path, or its problems (form only)."""
    where = _free_field(path)
    if not (isinstance(spec, list) and len(spec) == 2):
        return None, [Problem(where, "wrong_type", f"{path} needs its bounds as [low, high], "
                              f"two numbers, not {_show(spec)}")]
    bad = [k for k, v in enumerate(spec) if not (_is_number(v) and math.isfinite(v))]
    if bad:
        return None, [Problem(where, "wrong_type" if not _is_number(spec[bad[0]]) else
                              "not_finite", f"{path} bound {'low' if bad[0] == 0 else 'high'} "
                              f"must be a finite number, not {_show(spec[bad[0]])}")]
    low, high = float(spec[0]), float(spec[1])
    if low > high:
        return None, [Problem(where, "reversed", f"{path} bounds [{spec[0]!r}, {spec[1]!r}] are "
                              f"reversed: write [{spec[1]!r}, {spec[0]!r}]")]
    if low == high:
        return None, [Problem(where, "empty", f"{path} bounds [{spec[0]!r}, {spec[1]!r}] leave "
                              "nothing to search: fix the value in the base file instead")]
    return (low, high), []


def _check_path(path: str, fields: dict, kind: str) -> list[Problem]:
    """Is ``path`` a real-number field of the kind's schema?"""
    where = _free_field(path)
    field = fields.get(path)
    if field is None:
        close = difflib.get_close_matches(path, list(fields), n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        return [Problem(where, "unknown_key",
                        f"{path} is not a parameter of a {kind} design{hint}")]
    if field["type"] == "integer":
        return [Problem(where, "not_allowed", f"{path} is a whole number; the search moves "
                        "real numbers only: fix it in the base file or sweep it with "
                        "cadgen batch --grid")]
    if field["type"] != "number":
        return [Problem(where, "wrong_type", f"{path} is not a number ({field['type']}): "
                        "only real-number parameters can be free")]
    return []


def _check_in_schema(path: str, bounds: tuple, base_data: dict, source: str) -> list[Problem]:
    """Each bound validated in the base file's place (the schema's ranges and rules)."""
    from cadgen.params import validate_data

    problems = []
    for side, value in zip(("low", "high"), bounds):
        data = copy.deepcopy(base_data)
        _assign(data, path, value)
        try:
            validate_data(data, source, check_feasibility=False)
        except ParameterError as error:
            for problem in error.problems:
                if _related(problem.path, path):
                    problems.append(Problem(_free_field(path), problem.code,
                                            f"bound {side} {value:g} is outside what "
                                            f"{path} accepts: {problem.message}"))
    return problems


def _check_points(spec: Any, base_params) -> tuple[dict | None, list[Problem]]:
    """The pricking box spec ``{box, points}``, or its problems."""
    where = _free_field(POINTS_PATH)
    if not isinstance(spec, dict):
        return None, [Problem(where, "wrong_type", f"{POINTS_PATH} needs {{ box = 3.0 }} or "
                              f"{{ box = 3.0, points = [3, 4] }}, not {_show(spec)}")]
    problems = [Problem(f"{where}.{k}", "unknown_key", f"unknown key '{k}'; known keys: box, "
                        "points") for k in spec if k not in _BOX_KEYS]
    box = spec.get("box")
    if box is None:
        problems.append(Problem(f"{where}.box", "missing", "the half-side of the square each "
                                "point moves within (mm) is missing: box = 3.0"))
    elif not (_is_number(box) and math.isfinite(box) and box > 0):
        problems.append(Problem(f"{where}.box", "out_of_range" if _is_number(box) else
                                "wrong_type", f"box must be a positive number of mm, not "
                                f"{_show(box)}"))
    count = len(base_params.trajectory.points) if base_params is not None else None
    numbers = spec.get("points")
    if numbers is not None:
        if not isinstance(numbers, list) or not numbers:
            problems.append(Problem(f"{where}.points", "wrong_type", "points must be a list of "
                                    f"point numbers (1-based, Q1..Qm), not {_show(numbers)}"))
        else:
            for k, n in enumerate(numbers):
                if not (isinstance(n, int) and not isinstance(n, bool)
                        and (count is None or 1 <= n <= count)):
                    problems.append(Problem(f"{where}.points[{k}]", "out_of_range",
                                            f"{_show(n)} is not a point number from 1 to "
                                            f"{count} (Q1..Q{count})"))
                elif n in numbers[:k]:
                    problems.append(Problem(f"{where}.points[{k}]", "duplicate",
                                            f"point {n} is given twice"))
    if problems:
        return None, problems
    return {"box": float(box), "points": list(numbers or range(1, (count or 0) + 1))}, []


def _check_objectives(table: Any, known: list | None) -> tuple[list, list[Problem]]:
    """``[(key, sense)]`` of ``[objectives]``, or its problems."""
    if table is None:
        return [], [Problem("objectives", "missing", "required table [objectives] is missing: "
                            'maximize = ["min_margin"], say')]
    if not isinstance(table, dict):
        return [], [Problem("objectives", "wrong_type",
                            f"objectives must be a table, not {_show(table)}")]
    problems = [Problem(f"objectives.{k}", "unknown_key", f"unknown key '{k}' in [objectives]; "
                        "known keys: maximize, minimize") for k in table if k not in _SENSES]
    objectives, seen = [], {}
    for word, sense in _SENSES.items():
        keys = table.get(word, [])
        if isinstance(keys, str):
            keys = [keys]
        if not isinstance(keys, list):
            problems.append(Problem(f"objectives.{word}", "wrong_type", f"{word} must be a list "
                                    f"of objective names, not {_show(keys)}"))
            continue
        for index, key in enumerate(keys):
            where = f"objectives.{word}[{index}]"
            if not isinstance(key, str):
                problems.append(Problem(where, "wrong_type", f"an objective is a name, not "
                                        f"{_show(key)}"))
            elif known is not None and key not in known:
                close = difflib.get_close_matches(key, known, n=1)
                hint = f" (did you mean {close[0]!r}?)" if close else ""
                problems.append(Problem(where, "unknown_objective", f"unknown objective "
                                        f"{_show(key)}{hint}; known: {', '.join(known)}"))
            elif key in seen:
                problems.append(Problem(where, "duplicate", f"{key} is already an objective "
                                        f"({seen[key]})"))
            else:
                seen[key] = where
                objectives.append((key, sense))
    if not problems and not objectives:
        problems.append(Problem("objectives", "empty", "name at least one objective: "
                                'maximize = ["min_margin"], say'))
    return objectives, problems


def _check_precision(table: Any, free: Any, kind: str | None) -> tuple[dict, list[Problem]]:
    """``{free path: rounding step}`` of every free path (``[precision]`` or by its unit), or
    the table's problems: a key that is not a free path, a step that is not a positive
    number smaller than the path's range."""
    if free is None or kind is None:
        return {}, []
    if kind == "pricking":
        spans = {POINTS_PATH: 2 * free["box"]}
        defaults = {POINTS_PATH: DEFAULT_STEPS["mm"]}
    else:
        units = _numeric_fields(kind)
        spans = {path: high - low for path, low, high in free}
        defaults = {path: DEFAULT_STEPS.get(units[path]["unit"], DEFAULT_STEPS[None])
                    for path in spans}
    if table is None:
        return defaults, []
    if not isinstance(table, dict):
        return {}, [Problem("precision", "wrong_type",
                            f"precision must be a table, not {_show(table)}")]
    steps, problems = dict(defaults), []
    for key, step in flatten_dotted(table, ()):
        where = f'precision."{key}"'
        if key not in spans:
            close = difflib.get_close_matches(key, list(spans), n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            problems.append(Problem(where, "unknown_key", f"{key} is not a free path of this "
                                    f"study{hint}; free: {', '.join(spans)}"))
        elif not (_is_number(step) and math.isfinite(step) and 0 < step < spans[key]):
            problems.append(Problem(where, "out_of_range" if _is_number(step) else "wrong_type",
                                    f"the rounding step of {key} must be a positive number "
                                    f"below its range ({spans[key]:g}), not {_show(step)}"))
        else:
            steps[key] = float(step)
    return steps, problems


def _check_budget(table: Any) -> tuple[int, int, list[Problem]]:
    if table is None:
        return DEFAULT_EVALUATIONS, DEFAULT_SEED, []
    if not isinstance(table, dict):
        return 0, 0, [Problem("budget", "wrong_type",
                              f"budget must be a table, not {_show(table)}")]
    problems = [Problem(f"budget.{k}", "unknown_key", f"unknown key '{k}' in [budget]; known "
                        "keys: evaluations, seed") for k in table if k not in _BUDGET_KEYS]
    evaluations = table.get("evaluations", DEFAULT_EVALUATIONS)
    seed = table.get("seed", DEFAULT_SEED)
    if not _whole(evaluations, 1):
        problems.append(Problem("budget.evaluations", "out_of_range" if _is_number(evaluations)
                                else "wrong_type", f"evaluations must be a whole number from 1 "
                                f"to {MAX_EVALUATIONS}, not {_show(evaluations)}"))
    if not _whole(seed, 0):
        problems.append(Problem("budget.seed", "out_of_range" if _is_number(seed) else
                                "wrong_type",
                                f"seed must be a whole number >= 0, not {_show(seed)}"))
    return evaluations, seed, problems


# --------------------------------------------------------------------------- loading


def load_study(path: str | os.PathLike) -> Study:
    """Read and validate a study file (format in the module docstring).

    Raises
    ------
    StudyError
        With every problem found, each at its field; nothing is written.
    """
    from cadgen.params import NAME_PATTERN, load_params
    from cadgen.params._tables import NAME_MAX_LENGTH
    from cadgen.optimize.problem import problem_class

    study_path = Path(path)
    source = str(path)
    data, text, problems = read_toml_file(study_path, "")
    if data is None:
        raise StudyError(problems, source)
    wrong = wrong_kind_of_file(data, "study")
    if wrong:   # one line naming the command that reads it, not an unknown key per table
        raise StudyError(wrong, source)
    problems += [Problem(str(k), "unknown_key", f"unknown key '{k}' at the top level of the "
                         f"study; known keys: {', '.join(STUDY_KEYS)}")
                 for k in data if k not in STUDY_KEYS]

    # the base design: read as data (to validate each bound in its place) and loaded
    base, base_data, base_params, base_path = data.get("base"), None, None, None
    if isinstance(base, str) and base:
        base_path = (study_path.parent / base).resolve()
        base_data, _, found = read_toml_file(base_path, "base")
        problems += found
        if base_data is not None:
            try:
                base_params = load_params(base_path)
            except ParameterError as error:
                problems += [Problem("base", p.code, f"{base}: {p.path or '<file>'}: {p.message}")
                             for p in error.problems]
    else:
        problems.append(Problem("base", "missing", "required key 'base' (the parameter file to "
                                "start from, relative to the study file) is missing")
                        if base is None else
                        Problem("base", "wrong_type",
                                f"base must be a file name, not {_show(base)}"))
    kind = getattr(base_params, "mechanism", None)
    if kind is None and isinstance(base_data, dict) and base_data.get("mechanism") in (
            "planting", "pricking"):
        kind = base_data["mechanism"]

    name = data.get("name", getattr(base_params, "name", None))
    if "name" in data and not (isinstance(name, str) and re.match(NAME_PATTERN, name)
                               and len(name) <= NAME_MAX_LENGTH):
        problems.append(Problem("name", "invalid_name", f"name {_show(name)} cannot name an "
                                "output folder: letters, digits, '.', '_' and '-', starting "
                                f"with a letter or digit, at most {NAME_MAX_LENGTH} characters"))

    free: Any = None
    table = data.get("free")
    if table is None:
        problems.append(Problem("free", "missing", "required table [free] is missing: "
                                '"planter.L2" = [150.0, 230.0], say'))
    elif not isinstance(table, dict):
        problems.append(Problem("free", "wrong_type", f"free must be a table, not {_show(table)}"))
    elif not table:
        problems.append(Problem("free", "empty", "[free] names no parameter to search"))
    elif kind == "pricking":
        for key, spec in flatten_dotted(table, _BOX_KEYS):
            if key != POINTS_PATH:
                problems.append(Problem(_free_field(key), "not_allowed", f"a pricking study "
                                        f"moves {POINTS_PATH} only, not {key}"))
            else:
                free, found = _check_points(spec, base_params)
                problems += found
    elif kind == "planting":
        fields, free = _numeric_fields(kind), []
        supported = getattr(problem_class(kind), "supported_paths", None)
        supported = None if supported is None else list(supported(base_params))
        for key, spec in flatten_dotted(table, _BOX_KEYS):
            found = _check_path(key, fields, kind)
            if not found and supported is not None and key not in supported:
                found = [Problem(_free_field(key), "not_supported", f"{key} cannot be searched: "
                                 "the planting screen does not model it; free paths: "
                                 f"{', '.join(supported)}")]
            bounds, bound_problems = _check_bounds(key, spec)
            found += bound_problems
            if not found and base_data is not None:
                found = _check_in_schema(key, bounds, base_data, str(base_path))
            problems += found
            if not found:
                free.append((key, *bounds))
        free = tuple(free)

    known = None
    if base_params is not None:
        known = list(problem_class(kind).objective_keys(base_params))
    objectives, found = _check_objectives(data.get("objectives"), known)
    problems += found
    evaluations, seed, found = _check_budget(data.get("budget"))
    problems += found
    steps, found = _check_precision(data.get("precision"), free, kind)
    problems += found
    if problems or base_params is None:
        raise StudyError(problems, source)
    return Study(path=study_path, name=name, base_path=base_path, base_params=base_params,
                 kind=kind, free=free, objectives=tuple(objectives), evaluations=evaluations,
                 seed=seed, text=text, steps=steps)
