"""From pydantic's validation errors to the project's problems, with sentences a user reads.

Each pydantic error becomes one :class:`~kinematics.errors.Problem` (sometimes none,
sometimes several) with a dotted field path as it is written in the file
(``train.R``, ``field.plant_spacings.1``: union tags dropped), a short code (the
table in :mod:`cadgen.params`) and a sentence naming the bad value the way a TOML
reader would (``the string "36"``), with a "did you mean" for a misspelt key.

Validators speak to the mapper through pydantic errors of the project's own types:
``duplicate`` (see :func:`cadgen.params._tables._no_repeats`), ``inconsistent`` and
``not_allowed`` (message used as is), and ``problems`` (:func:`_problems_error`: a
validator that wrote its problems itself).
"""

from __future__ import annotations

import difflib
import json
import math
import re
from collections.abc import Mapping
from datetime import date, datetime, time
from typing import Any, Union, get_args, get_origin

from pydantic import BaseModel
from pydantic_core import PydanticCustomError

from kinematics.errors import Problem

from cadgen.params._tables import NAME_MAX_LENGTH

__all__ = [
    "_problems_error",
    "_union_members",
    "_problems_from_error",
    "_describe",
    "_show",
    "_close_keys",
]

_PROBLEMS = "problems"
"""Pydantic error type of a validator that wrote its own problems (see _problems_error)."""


def _problems_error(problems: list[tuple[tuple, str, str]]) -> PydanticCustomError:
    """An error carrying finished problems: ``(path suffix, code, message)`` each.

    The suffix is appended to the field's path (``(3,)`` makes ``trajectory.points.3``).
    """
    return PydanticCustomError(
        _PROBLEMS, "{count} problem(s)", {"count": len(problems), "problems": problems}
    )


# --------------------------------------------------------------------------- schema walk


def _union_members(annotation: Any, discriminator: str) -> dict[str, type[BaseModel]]:
    """Map each tag value of a discriminated union to its model."""
    members = get_args(annotation) if get_origin(annotation) is Union else (annotation,)
    table = {}
    for member in members:
        for tag in get_args(member.model_fields[discriminator].annotation):
            table[tag] = member
    return table


def _model_of(annotation: Any) -> type[BaseModel] | None:
    """The model class inside ``Model`` or ``Model | None``, else None."""
    candidates = get_args(annotation) if get_args(annotation) else (annotation,)
    for candidate in candidates:
        if isinstance(candidate, type) and issubclass(candidate, BaseModel):
            return candidate
    return None


def _node_of(annotation: Any, field_info: Any = None) -> Any:
    if field_info is not None and field_info.discriminator:
        discriminator = field_info.discriminator
        return ("union", discriminator, _union_members(annotation, discriminator))
    return _model_of(annotation)


def _walk(loc: tuple, root: Any) -> tuple[list, Any, Any]:
    """Turn a pydantic error location into a file path, from the schema node ``root``.

    Returns ``(parts, parent, node)``: the path parts with union tags dropped, the
    schema node holding the last part, and the node the last part leads to (a model
    class, a ``("union", discriminator, members)`` triple, or None).
    """
    parts: list = []
    parent = None
    node: Any = root
    for item in loc:
        if isinstance(node, tuple) and item in node[2]:
            node = node[2][item]  # union tag in pydantic's location, not in the file
            continue
        parent = node
        parts.append(item)
        if isinstance(node, type) and issubclass(node, BaseModel) and item in node.model_fields:
            info = node.model_fields[item]
            node = _node_of(info.annotation, info)
        else:
            node = None
    return parts, parent, node


def _known_keys(node: Any) -> list[str]:
    if isinstance(node, tuple):
        keys: list[str] = []
        for model in node[2].values():
            keys += [k for k in model.model_fields if k not in keys]
        return keys
    if isinstance(node, type) and issubclass(node, BaseModel):
        return list(node.model_fields)
    return []


# --------------------------------------------------------------------------- messages


_INT_SHOWN_DIGITS = 30
"""Integers longer than this are shortened in messages (see :func:`_int_text`)."""


def _int_text(value: int) -> str:
    """An integer for a sentence, its leading digits only when it is very long.

    ``str()`` of an integer of more than ``sys.get_int_max_str_digits()`` (4300)
    digits raises ``ValueError``, and a TOML hexadecimal integer can be that long;
    a few hundred digits would swamp the message anyway.
    """
    magnitude = abs(value)
    if magnitude < 10**_INT_SHOWN_DIGITS:
        return str(value)
    digits = int(math.log10(magnitude)) + 1
    if magnitude < 10 ** (digits - 1):  # log10 rounded up across a power of ten
        digits -= 1
    elif magnitude >= 10**digits:
        digits += 1
    head = str(magnitude // 10 ** max(digits - 12, 0))  # integer division: no str limit
    return f"{'-' if value < 0 else ''}{head}... ({digits} digits)"


def _describe(value: Any) -> str:
    """A TOML reader's name for a value: ``the string "36"``, ``the boolean true``."""
    if isinstance(value, bool):
        return f"the boolean {str(value).lower()}"
    if isinstance(value, int):
        return f"the integer {_int_text(value)}"
    if isinstance(value, float):
        return f"the float {value!r}"
    if isinstance(value, str):
        return f"the string {json.dumps(value)}"
    if isinstance(value, (list, tuple)):
        return f"an array of {len(value)} item{'s' if len(value) != 1 else ''}"
    if isinstance(value, Mapping):
        return "a table"
    if isinstance(value, (datetime, date, time)):
        return f"the date/time {value.isoformat()}"
    return f"a {type(value).__name__}"


def _show(value: Any) -> str:
    if isinstance(value, int) and not isinstance(value, bool):
        return _int_text(value)  # repr() of a huge integer raises ValueError
    return json.dumps(value) if isinstance(value, str) else repr(value)


_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")


def _key_text(key: Any) -> str:
    """A key as TOML writes it: bare when it can be, else a quoted string.

    A quoted key may hold anything (a newline, a dot, a control character); written
    raw it would break the one-line ``path: message [code]`` report or make the
    dotted path ambiguous.
    """
    text = str(key)
    if isinstance(key, int) or _BARE_KEY.fullmatch(text):
        return text
    return '"' + "".join(_KEY_ESCAPES.get(char) or _escape(char) for char in text) + '"'


_KEY_ESCAPES = {'"': '\\"', "\\": "\\\\", "\n": "\\n", "\t": "\\t", "\r": "\\r"}


def _escape(char: str) -> str:
    # TOML's escapes: printable characters stay, the others become \uXXXX / \UXXXXXXXX
    # (json.dumps would write a surrogate pair for U+10000 and above, which TOML refuses).
    if char.isprintable():
        return char
    code = ord(char)
    return f"\\u{code:04X}" if code <= 0xFFFF else f"\\U{code:08X}"


def _label(parts: list) -> str:
    """``plant_spacings[1]`` style name of the last path element, for sentences."""
    if not parts:
        return "the file"
    if isinstance(parts[-1], int):
        return f"{_label(parts[:-1])}[{parts[-1]}]"
    return _key_text(parts[-1])


def _close_keys(key: str, known: list[str], cutoff: float = 0.6) -> list[str]:
    """Known keys closest to a misspelt one (case ignored first; ties all returned)."""

    def score(candidate: str) -> tuple[float, float]:
        folded = difflib.SequenceMatcher(None, key.lower(), candidate.lower()).ratio()
        exact = difflib.SequenceMatcher(None, key, candidate).ratio()
        return folded, exact

    scored = {candidate: score(candidate) for candidate in known}
    if not scored:
        return []
    best = max(scored.values())
    if best[0] < cutoff:
        return []
    return [candidate for candidate, value in scored.items() if value == best]


def _table_name(parts: list) -> str:
    return ".".join(_key_text(p) for p in parts) if parts else ""


_EXPECTED = {
    "float_type": "a number",
    "int_type": "an integer",
    "string_type": "a string",
    "bool_type": "true or false",
    "tuple_type": "an array",
    "list_type": "an array",
    "model_type": "a table",
    "model_attributes_type": "a table",
    "dict_type": "a table",
}

_RELATIONS = {
    "greater_than": ("gt", "greater than"),
    "greater_than_equal": ("ge", "at least"),
    "less_than": ("lt", "less than"),
    "less_than_equal": ("le", "at most"),
}

_CUSTOM_CODES = {"inconsistent", "not_allowed", "wall_too_thin"}


def _problems_from_error(error: Mapping[str, Any], root: Any) -> list[Problem]:
    """Turn one pydantic error into the project's problems (usually one).

    ``root`` is the schema node the error's location starts from (see :func:`_walk`).
    """
    kind = error["type"]
    value = error.get("input")
    ctx = error.get("ctx") or {}
    parts, parent, node = _walk(tuple(error["loc"]), root)
    path = _table_name(parts)
    name = _label(parts)

    if kind == "missing":
        if isinstance(node, type) or isinstance(node, tuple):
            return [Problem(path, "missing", f"required table [{path}] is missing")]
        where = f" from [{_table_name(parts[:-1])}]" if len(parts) > 1 else ""
        return [Problem(path, "missing", f"required key '{name}' is missing{where}")]

    if kind == "extra_forbidden":
        what = "table" if isinstance(value, Mapping) else "key"
        table = _table_name(parts[:-1])
        where = f" in [{table}]" if table else " at the top level"
        shown = name if name.startswith('"') else f"'{name}'"  # a quoted key shows its quotes
        text = f"unknown {what} {shown}{where}"
        known = _known_keys(parent)
        close = _close_keys(str(parts[-1]), known)  # the key itself, not its quoted form
        if close:
            text += "; did you mean " + " or ".join(f"'{k}'" for k in close) + "?"
        elif known:
            text += "; known keys: " + ", ".join(known)
        return [Problem(path, "unknown_key", text)]

    if kind in ("union_tag_invalid", "union_tag_not_found"):
        discriminator = node[1] if isinstance(node, tuple) else "kind"
        known = ", ".join(f"'{tag}'" for tag in (node[2] if isinstance(node, tuple) else ()))
        tag_path = _table_name(parts + [discriminator])
        subject = "mechanism" if not parts else f"{_label(parts).replace('_', ' ')}"
        tag = value.get(discriminator) if isinstance(value, Mapping) else None
        if kind == "union_tag_not_found":
            return [Problem(tag_path, "missing",
                            f"required key '{discriminator}' is missing; it names the "
                            f"{subject} kind, one of {known}")]
        if not isinstance(tag, str):
            return [Problem(tag_path, "wrong_type",
                            f"{discriminator} must be a string naming the {subject} kind "
                            f"(one of {known}), not {_describe(tag)}")]
        code = "unknown_mechanism" if not parts else "unknown_kind"
        text = f"unknown {subject} kind {_show(tag)}; known kinds: {known}"
        return [Problem(tag_path, code, text)]

    if kind == "finite_number":
        return [Problem(path, "not_finite", f"{name} = {_show(value)} is not a finite number")]

    if kind in _RELATIONS:
        key, relation = _RELATIONS[kind]
        return [Problem(path, "out_of_range",
                        f"{name} = {_show(value)} is out of range: it must be {relation} "
                        f"{_show(ctx.get(key))}")]

    if kind == "float_type" and isinstance(value, int) and not isinstance(value, bool):
        return [Problem(path, "out_of_range",
                        f"{name} = {_int_text(value)} is too large to be represented as a "
                        "float")]

    if kind in _EXPECTED:
        text = f"{name} must be {_EXPECTED[kind]}, not {_describe(value)}"
        if isinstance(value, str) and kind in ("float_type", "int_type"):
            text += " (write numbers without quotes)"
        elif kind == "int_type" and isinstance(value, float) and value.is_integer():
            text += " (write it without a decimal point)"
        return [Problem(path, "wrong_type", text)]

    if parts == ["name"] and kind.startswith("string_"):
        return [Problem(path, "invalid_name",
                        f"name {_show(value)} cannot name an output folder: it must be 1 to "
                        f"{NAME_MAX_LENGTH} characters, start with a letter or digit and "
                        "contain only letters, digits, '.', '_' and '-'")]

    if (kind == "too_short" and isinstance(value, (list, tuple))
            and len(value) >= ctx.get("min_length", 0)):
        # pydantic counts the items that passed: the array was long enough, and each
        # item that failed is already reported at its own index.
        return []

    if kind == "too_short" and ctx.get("min_length") == 1:
        return [Problem(path, "empty", f"{name} must not be empty")]

    if kind in ("too_short", "too_long"):
        return [Problem(path, "out_of_range",
                        f"{name} has {ctx.get('actual_length')} items: {error['msg'].lower()}")]

    if kind == "duplicate":
        return [
            Problem(f"{path}.{index}", "duplicate",
                    f"{name}[{index}] = {_show(spacing)} repeats {name}[{first}]; "
                    f"give each {ctx.get('what', 'value')} once")
            for index, first, spacing in ctx["repeats"]
        ]

    if kind in _CUSTOM_CODES:
        return [Problem(path, kind, error["msg"])]

    if kind == _PROBLEMS:
        # A validator that wrote its problems itself (see _problems_error).
        return [
            Problem(_table_name(parts + list(suffix)), code, message)
            for suffix, code, message in ctx["problems"]
        ]

    if kind == "literal_error":
        expected = ctx.get("expected")
        text = f"{name} = {_show(value)} is not allowed: it must be {expected}"
        choices = re.findall(r"'([^']*)'", str(expected))
        close = _close_keys(str(value), choices) if isinstance(value, str) else []
        if close:
            text += "; did you mean " + " or ".join(f"'{k}'" for k in close) + "?"
        return [Problem(path, "unknown_kind", text)]

    # Not expected from a TOML file; keep pydantic's own words rather than lose the problem.
    return [Problem(path, kind, f"{name}: {error['msg']} (got {_describe(value)})")]

