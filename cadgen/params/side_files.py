"""Files that sit beside the parameter files and name a base design: grid and study files.

``cadgen batch --grid`` reads a grid (a base design and ``[grid]``), ``cadgen optimize`` a
study (a base design and ``[free]``). Both read a TOML file into problems at a field,
walk a table of dotted parameter paths, show a bad value in a message, and set a dotted
path in the base design's tables: the pieces here, one definition each.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from kinematics.errors import Problem

__all__ = ["read_toml_file", "show", "is_number", "flatten_dotted", "assign_dotted",
           "FILE_KINDS", "kind_of_file", "wrong_kind_of_file"]

#: The three kinds of file, how each is told (a top-level key or table) and the command that
#: reads it: a parameter file has ``mechanism``; a grid and a study name a ``base`` design
#: and hold ``[grid]`` or ``[free]``.
FILE_KINDS = {"parameter": ("mechanism", "parameter file", "cadgen build FILE"),
              "grid": ("grid", "grid file", "cadgen batch --grid FILE"),
              "study": ("free", "study file", "cadgen optimize FILE")}


def kind_of_file(data: Mapping[str, Any]) -> str | None:
    """``"parameter"``, ``"grid"`` or ``"study"``: what ``data`` (a parsed TOML file) is by its
    tables, or None when it is none of them plainly."""
    if "mechanism" in data and "base" not in data:
        return "parameter"
    if "base" in data and "mechanism" not in data:
        for kind in ("grid", "study"):
            if isinstance(data.get(FILE_KINDS[kind][0]), Mapping):
                return kind
    return None


def wrong_kind_of_file(data: Mapping[str, Any], expected: str) -> list[Problem]:
    """One problem naming the command that reads ``data``, when it is plainly another kind of
    file than ``expected`` (a parameter file given to ``cadgen batch --grid``, a study given
    to ``cadgen build``); else none. A user would otherwise read one ``unknown key`` per
    table, which is true and no help."""
    kind = kind_of_file(data)
    if kind is None or kind == expected:
        return []
    key, what, command = FILE_KINDS[kind]
    wanted = FILE_KINDS[expected][1]
    how = f"mechanism = {show(data['mechanism'])}" if kind == "parameter" else \
        f"a base design and [{key}]"
    return [Problem("", "not_a_" + FILE_KINDS[expected][1].replace(" ", "_"),
                    f"this is a {what} ({how}), not a {wanted}: run `{command}`")]


def read_toml_file(path: Path, where: str) -> tuple[dict | None, str, list[Problem]]:
    """Parse a TOML file: ``(data, text, problems at where)`` (data None when it cannot)."""
    try:
        text = path.read_bytes().decode("utf-8-sig")
    except FileNotFoundError:
        return None, "", [Problem(where, "file_not_found", f"no such file: {path}")]
    except IsADirectoryError:
        return None, "", [Problem(where, "not_readable", f"{path} is a directory")]
    except UnicodeDecodeError:
        return None, "", [Problem(where, "not_utf8", f"{path} is not UTF-8 text")]
    except OSError as exc:
        return None, "", [Problem(where, "not_readable", f"cannot read {path}: {exc.strerror}")]
    from cadgen.params.loading import ParameterError, parse_toml

    try:
        return parse_toml(text), text, []
    except ParameterError as error:   # syntax, nesting too deep, an integer too long
        return None, text, [Problem(where, p.code, f"{path}: {p.message}")
                            for p in error.problems]


def show(value: Any) -> str:
    """A value as a message quotes it: strings in double quotes, the rest as Python shows it."""
    return json.dumps(value) if isinstance(value, str) else repr(value)


def is_number(value: Any) -> bool:
    """An int or float, not a bool (TOML's true is not a number)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def flatten_dotted(table: Mapping, leaf_keys: Iterable[str],
                   prefix: str = "") -> Iterable[tuple[str, Any]]:
    """``(dotted path, spec)`` of a table of parameter paths.

    TOML dotted keys (``planter.L2 = ...``) make nested tables; an inline table holding one
    of ``leaf_keys`` (``{ start, stop, num }``, ``{ box = 3.0 }``) is a spec, not a level.
    """
    leaf_keys = tuple(leaf_keys)
    for key, value in table.items():
        dotted = f"{prefix}.{key}" if prefix else str(key)
        if isinstance(value, dict) and not any(k in value for k in leaf_keys):
            yield from flatten_dotted(value, leaf_keys, dotted)
        else:
            yield dotted, value


def assign_dotted(data: dict, path: str, value: Any) -> str | None:
    """Set the dotted ``path`` in ``data`` (making missing tables); a reason if it cannot."""
    parts = path.split(".")
    node = data
    for depth, part in enumerate(parts[:-1]):
        child = node.setdefault(part, {})
        if not isinstance(child, dict):
            table = ".".join(parts[: depth + 1])
            return f"{table} is not a table in the base file, so {path} cannot be set"
        node = child
    node[parts[-1]] = value
    return None
