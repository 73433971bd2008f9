"""Loading a parameter file: read, parse the TOML, validate, report every problem at once.

:func:`load_params` (a file), :func:`validate_text` (TOML text) and
:func:`validate_data` (a parsed mapping) never stop at the first problem: they raise
one :class:`ParameterError` that lists every problem found. The file is validated
against :data:`DesignParameters`, the union of the mechanism kinds told apart by
``mechanism``. Once the file is structurally valid,
:func:`cadgen.params.feasibility.design_problems` adds the problems that need the kinematic
model; it is imported inside the call, so parsing alone (and ``cadgen --help``) does
not pay for numpy and scipy. Validation never writes anything.

A problem that belongs to one build stage (``Problem.stage``, e.g. the duckbill
linkage to ``"cam"``) does not refuse the file on its own: the parameters come back
with it attached (:func:`stage_problems`), and :func:`cadgen.pipeline.build.build` makes it an
error when the scene runs that stage and a warning otherwise. A file with other
problems is refused with all of them, the staged ones among them.
"""

from __future__ import annotations

import re
import sys
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Any, Union, get_args

from pydantic import Field, TypeAdapter, ValidationError

from kinematics.errors import DesignError, Problem

from cadgen.params._problems import (
    _describe,
    _int_text,
    _label,
    _problems_from_error,
    _table_name,
    _union_members,
)
from cadgen.params.planting import PlantingParameters
from cadgen.params.pricking import PrickingParameters
from cadgen.params.side_files import wrong_kind_of_file

__all__ = [
    "ParameterError",
    "DesignParameters",
    "MECHANISM_KINDS",
    "load_params",
    "validate_text",
    "validate_data",
    "parse_toml",
    "stage_problems",
]


class ParameterError(DesignError):
    """A parameter file with problems; ``problems`` lists all of them.

    Also a :class:`ValueError` (through :class:`~kinematics.errors.DesignError`).
    """


def stage_problems(params) -> tuple:
    """The problems of build stages validation found in ``params`` (empty if none or not checked).

    Each has its ``stage``; a build running that stage refuses the design, any other
    build reports them as warnings (see :func:`validate_data`).
    """
    return tuple(getattr(params, "_stage_problems", None) or ())


DesignParameters = Annotated[
    Union[PlantingParameters, PrickingParameters], Field(discriminator="mechanism")
]
"""Every mechanism kind, told apart by ``mechanism``."""

_DESIGN_ADAPTER = TypeAdapter(DesignParameters)

_ROOT_NODE = ("union", "mechanism", _union_members(get_args(DesignParameters)[0], "mechanism"))
MECHANISM_KINDS = tuple(_ROOT_NODE[2])
"""Known mechanism kinds."""


# --------------------------------------------------------------------------- entry points


def _structural(data: Mapping[str, Any]) -> tuple[Any, list[Problem]]:
    try:
        return _DESIGN_ADAPTER.validate_python(data), []
    except ValidationError as exc:
        problems: list[Problem] = []
        for error in exc.errors(include_url=False):
            problems += _problems_from_error(error, _ROOT_NODE)
        return None, problems


def _too_long_integers(data: Mapping[str, Any]) -> list[Problem]:
    """An ``out_of_range`` problem for every integer too long to print.

    ``str()`` of an integer of more than ``sys.get_int_max_str_digits()`` (4300)
    digits raises ``ValueError``, and pydantic-core prints the inputs it reports (a
    discriminator tag, a literal choice): it swallows the error with an "Exception
    ignored" traceback on stderr, or the message formatting crashes. Only a
    hexadecimal, octal or binary TOML literal gives such an integer (the reader
    refuses a decimal one), so the file is judged on them alone, as for a decimal one.
    """
    limit = sys.get_int_max_str_digits()
    if not limit:
        return []
    bound = 10**limit
    found = []
    stack: list[tuple[list, Any]] = [([], data)]
    while stack:  # not recursive: the data may nest deeper than the stack allows
        parts, value = stack.pop()
        if isinstance(value, Mapping):
            stack += [(parts + [key], item) for key, item in reversed(value.items())]
        elif isinstance(value, (list, tuple)):
            stack += [(parts + [index], item) for index, item in reversed(list(enumerate(value)))]
        elif isinstance(value, int) and not isinstance(value, bool) and abs(value) >= bound:
            found.append(Problem(_table_name(parts), "out_of_range",
                                 f"{_label(parts)} = {_int_text(value)} has more than {limit} "
                                 "digits: far too large for any parameter"))
    return found


def _feasibility_problems(params: Any) -> list[Problem]:
    # Imported here: the kinematic checks pull in numpy/scipy, which a caller that
    # only parses (or prints --help) should not pay for.
    from cadgen.params.feasibility import design_problems

    try:
        return list(design_problems(params))
    except DesignError as exc:
        return list(exc.problems)


def validate_data(
    data: Mapping[str, Any], source: str | None = None, *, check_feasibility: bool = True
) -> PlantingParameters | PrickingParameters:
    """Validate an already-parsed parameter mapping.

    Parameters
    ----------
    data : mapping
        The parsed file (what :func:`tomllib.loads` returns).
    source : str, optional
        Where the data came from, for the error message.
    check_feasibility : bool, default True
        Also run :func:`cadgen.params.feasibility.design_problems` once the structure is
        valid (it needs the kinematic model).

    Returns
    -------
    PlantingParameters or PrickingParameters
        The validated, frozen parameters (the member of :data:`DesignParameters`
        that ``mechanism`` names), with the problems of build stages found, if any,
        attached: :func:`stage_problems` (a metrics-only evaluation may go on).

    Raises
    ------
    ParameterError
        Listing every problem found, when one belongs to no stage (the staged ones
        are listed too).
    """
    if not isinstance(data, Mapping):
        problem = Problem("", "wrong_type", f"expected a table, not {_describe(data)}")
        raise ParameterError([problem], source)
    problems = _too_long_integers(data) or wrong_kind_of_file(data, "parameter")
    if problems:
        raise ParameterError(problems, source)
    params, problems = _structural(data)
    staged = []
    if not problems and check_feasibility:
        problems = _feasibility_problems(params)
        staged = [p for p in problems if p.stage]
    if len(problems) > len(staged):
        raise ParameterError(problems, source)
    if staged:
        params._stage_problems = tuple(staged)
    return params


_TOML_POSITION = re.compile(r"\s*\(at line (\d+), column (\d+)\)\s*$")


def _syntax_problem(exc: tomllib.TOMLDecodeError) -> Problem:
    text = str(exc)
    match = _TOML_POSITION.search(text)
    line = getattr(exc, "lineno", None) or (int(match.group(1)) if match else None)
    column = getattr(exc, "colno", None) or (int(match.group(2)) if match else None)
    reason = getattr(exc, "msg", None) or (_TOML_POSITION.sub("", text) if match else text)
    where = f" at line {line}, column {column}" if line is not None else ""
    return Problem("", "toml_syntax", f"TOML syntax error{where}: {reason}")


def _too_deep_problem() -> Problem:
    return Problem("", "too_deep",
                   "arrays or inline tables are nested too deeply to read (hundreds of levels); "
                   "no parameter nests deeper than an array of [x, y] pairs")


def _long_integer_problem(text: str, exc: ValueError) -> Problem:
    if "digits" not in str(exc):
        # Not the digit limit: keep the parser's words rather than lose the problem.
        return Problem("", "toml_syntax", f"TOML syntax error: {exc}")
    # Where the long run of digits starts, for the message (the parser does not say).
    limit = sys.get_int_max_str_digits() or 4300
    match = re.search(r"[0-9][0-9_]{%d,}" % limit, text)
    where = ""
    if match:
        line = text.count("\n", 0, match.start()) + 1
        column = match.start() - (text.rfind("\n", 0, match.start()) + 1) + 1
        where = f" at line {line}, column {column}"
    return Problem("", "out_of_range",
                   f"an integer{where} has more than {limit} digits: far too large for any "
                   "parameter")


def validate_text(
    text: str, source: str | None = None, *, check_feasibility: bool = True
) -> PlantingParameters | PrickingParameters:
    """Parse and validate the text of a parameter file.

    Parameters
    ----------
    text : str
        TOML text.
    source : str, optional
        Where the text came from (a file name), for the error message.
    check_feasibility : bool, default True
        See :func:`validate_data`.

    Returns
    -------
    PlantingParameters or PrickingParameters
        The validated, frozen parameters.

    Raises
    ------
    ParameterError
        Listing every problem; a TOML syntax error is a single ``toml_syntax``
        problem with its line and column.
    """
    return validate_data(parse_toml(text, source), source, check_feasibility=check_feasibility)


def parse_toml(text: str, source: str | None = None) -> dict:
    """TOML text as a dictionary, or a :class:`ParameterError` with one problem (never a crash).

    Used for parameter files and batch grid files alike.
    """
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError([_syntax_problem(exc)], source) from None
    except RecursionError:
        # tomllib parses arrays and inline tables recursively: a few hundred levels of
        # nesting (valid TOML) exhaust the interpreter's stack. No parameter nests deeper
        # than an array of pairs, so this is a bad file, not a crash.
        raise ParameterError([_too_deep_problem()], source) from None
    except ValueError as exc:
        # tomllib lets int()'s digit limit (sys.get_int_max_str_digits(), 4300 by
        # default) through as a bare ValueError for a decimal integer that long.
        raise ParameterError([_long_integer_problem(text, exc)], source) from None


def load_params(
    path: str | Path, *, check_feasibility: bool = True
) -> PlantingParameters | PrickingParameters:
    """Read, parse and validate a parameter file.

    Parameters
    ----------
    path : str or Path
        A UTF-8 TOML file (a leading byte-order mark is tolerated).
    check_feasibility : bool, default True
        See :func:`validate_data`.

    Returns
    -------
    PlantingParameters or PrickingParameters
        The validated, frozen parameters.

    Raises
    ------
    ParameterError
        Listing every problem, including a missing, unreadable or non-UTF-8 file.
    """
    path = Path(path)
    source = str(path)
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        problem = Problem("", "file_not_found", f"no such file: {source}")
        raise ParameterError([problem], source) from None
    except IsADirectoryError:
        raise ParameterError([Problem("", "not_readable", f"{source} is a directory, not a file")],
                             source) from None
    except OSError as exc:
        raise ParameterError([Problem("", "not_readable", f"cannot read {source}: {exc.strerror}")],
                             source) from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise ParameterError(
            [Problem("", "not_utf8",
                     f"the file is not UTF-8 text: byte 0x{raw[exc.start]:02x} at offset "
                     f"{exc.start} (line {line}); save it as UTF-8")],
            source,
        ) from None
    return validate_text(text.removeprefix("\ufeff"), source, check_feasibility=check_feasibility)
