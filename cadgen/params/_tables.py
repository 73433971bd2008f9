"""Shared pieces of the parameter tables: the base model, the name rule, common validators.

Every table of every mechanism kind derives from :class:`_Table`: a frozen pydantic
model, strict about types (a quoted ``"36"`` is not a number, ``true`` is not a number,
an integer is accepted where a float is asked), finite floats only, and no unknown keys.

Validators here raise pydantic errors of the project's own types (``duplicate``);
:mod:`cadgen.params._problems` turns them into :class:`~kinematics.errors.Problem`
records.
"""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, ConfigDict
from pydantic_core import PydanticCustomError

__all__ = [
    "NAME_PATTERN",
    "NAME_MAX_LENGTH",
    "_Table",
    "_list_to_tuple",
    "_no_repeats",
]

NAME_PATTERN = r"^[A-Za-z0-9][A-Za-z0-9._-]*$"
"""Design names: they become a folder name under the output root."""
NAME_MAX_LENGTH = 100


def _list_to_tuple(value: Any) -> Any:
    # TOML arrays arrive as lists; the frozen models store tuples (strict mode
    # would otherwise refuse a list for a tuple field).
    return tuple(value) if isinstance(value, list) else value


class _Table(BaseModel):
    """Base of every table: frozen, no unknown keys, strict types, finite floats."""

    model_config = ConfigDict(frozen=True, extra="forbid", strict=True, allow_inf_nan=False)


def _no_repeats(values: tuple[float, ...], what: str) -> tuple[float, ...]:
    """``values`` unchanged, or a ``duplicate`` error listing every repeat (``what`` names one)."""
    first_index: dict[float, int] = {}
    repeats = []
    for index, value in enumerate(values):
        if value in first_index:
            repeats.append((index, first_index[value], value))
        else:
            first_index[value] = index
    if repeats:
        # The error mapper (_problems) turns each repeat into its own problem at its index.
        raise PydanticCustomError(
            "duplicate", "{what}s repeat: {repeats}", {"repeats": repeats, "what": what}
        )
    return values
