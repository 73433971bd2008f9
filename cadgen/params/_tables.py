"""Shared pieces of the parameter tables: the base model, the name rule, common validators.

Every table of every mechanism kind derives from :class:`_Table`: a frozen pydantic
model, strict about types (a quoted ``"36"`` is not a number, ``true`` is not a number,
an integer is accepted where a float is asked), finite floats no larger than
:data:`MAX_MAGNITUDE` in magnitude, and no unknown keys.

Validators here raise pydantic errors of the project's own types (``duplicate``);
:mod:`cadgen.params._problems` turns them into :class:`~kinematics.errors.Problem`
records.
"""

from __future__ import annotations

from typing import Annotated, Any, get_args, get_origin

from pydantic import BaseModel, ConfigDict, PrivateAttr, ValidationInfo, field_validator
from pydantic_core import PydanticCustomError

__all__ = [
    "NAME_PATTERN",
    "NAME_MAX_LENGTH",
    "MAX_MAGNITUDE",
    "_Table",
    "_list_to_tuple",
    "_no_repeats",
]

NAME_PATTERN = r"^[A-Za-z0-9][A-Za-z0-9._-]*$"
"""Design names: they become a folder name under the output root."""
NAME_MAX_LENGTH = 100
MAX_MAGNITUDE = 1e6
"""No number in a parameter file is larger in magnitude (lengths in mm: 1 km; angles in
degrees; speeds in r/min or mm/s; a density in kg/m^3). Finite floats up to 1.8e308
otherwise reach the kinematic model, whose squares and sums overflow to inf and NaN
(an OverflowError, a RuntimeWarning, a root finder handed inf) instead of a problem
naming the field."""


def _list_to_tuple(value: Any) -> Any:
    # TOML arrays arrive as lists; the frozen models store tuples (strict mode
    # would otherwise refuse a list for a tuple field).
    return tuple(value) if isinstance(value, list) else value


class _Table(BaseModel):
    """Base of every table: frozen, no unknown keys, strict types, finite floats up to 1e6."""

    model_config = ConfigDict(frozen=True, extra="forbid", strict=True, allow_inf_nan=False)

    # On a whole design: the problems of build stages validation found (not a field, so
    # not in the file, the hash or model_dump); see cadgen.params.loading.stage_problems.
    _stage_problems: tuple = PrivateAttr(default=())

    @field_validator("*")
    @classmethod
    def _not_huge(cls, value: Any, info: ValidationInfo) -> Any:
        # Every float of every table. In an array, at the item (a plant spacing, a
        # type-value point); a point (a fixed-length tuple: sun_centre) as a whole, where
        # its other problems are reported too.
        name = info.field_name
        if isinstance(value, tuple) and not _is_point(cls.model_fields[name].annotation):
            items = [((index,), f"{name}[{index}]", item) for index, item in enumerate(value)]
        else:
            items = [((), name, value)]
        problems = []
        for suffix, label, item in items:
            numbers = item if isinstance(item, tuple) else (item,)
            if any(isinstance(n, float) and abs(n) > MAX_MAGNITUDE for n in numbers):
                shown = repr(list(item)) if isinstance(item, tuple) else repr(item)
                problems.append((suffix, "out_of_range",
                                 f"{label} = {shown} is out of range: no parameter is larger "
                                 f"than {MAX_MAGNITUDE:g} in magnitude"))
        if problems:
            from cadgen.params._problems import _problems_error  # _problems imports this module

            raise _problems_error(problems)
        return value


def _is_point(annotation: Any) -> bool:
    """A fixed-length tuple annotation (``tuple[float, float]``), not ``tuple[float, ...]``."""
    while get_origin(annotation) is Annotated:
        annotation = get_args(annotation)[0]
    return get_origin(annotation) is tuple and Ellipsis not in get_args(annotation)


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
