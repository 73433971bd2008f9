"""The parameter schema for the studio's form, read from the pydantic models of each kind.

Every table of :class:`~cadgen.params.PlantingParameters` and
:class:`~cadgen.params.PrickingParameters` (nested tables such as ``cam.duckbill`` and
optional ones such as ``housing.gearbox1`` as tables of their own, with dotted names;
the top-level scalars ``mechanism`` and ``name`` in a table named ``""``), each field
with its type, unit, default, bounds and one-line description. The models are the only
source: a field added to a model appears in the form with nothing else to edit.

Where each entry comes from:

- ``type``: the annotation. ``float`` is ``number``, ``int`` ``integer``, a ``Literal``
  ``enum`` (its values in ``enum``), ``tuple[float, float]`` ``point``, ``tuple[X, ...]``
  and fixed tuples of three ``array`` (``items`` says of what: ``number``, ``point`` or
  ``enum``); ``X | None`` is X and not required.
- ``unit``: from the field name's suffix first (``_deg`` deg, ``_rad`` rad, ``_rpm`` r/min,
  ``_mpa`` MPa, ``_n`` N, ``_h`` h: the file's own naming rule), else from the
  description's unit suffix (the project writes ``"..., mm"`` or ``"..., mm (default:
  ...)"``, and bare ``"mm"``), else, for a field without a description, the table's
  docstring's (``"... radii ..., mm (each optional)"``). ``dimensionless`` and anything
  unrecognised give ``null``.
- bounds: the ``Field`` constraints (``gt``/``ge``/``lt``/``le``; on an array, its items'
  constraints, and ``min_items``/``max_items`` from its length constraints). A few rules
  live in validators, not in ``Field``: ``_validator_rules`` adds them, from the
  constants the validators use.
- ``description``: the field's description (first line), else the table docstring's
  first line; ``default``: the field's default (``null`` when none or when it is a table).
"""

from __future__ import annotations

import functools
import re
import types
import typing
from typing import Any, Literal, Union, get_args, get_origin

from annotated_types import Ge, Gt, Le, Lt, MaxLen, MinLen
from pydantic import BaseModel
from pydantic_core import PydanticUndefined

__all__ = ["UNITS", "NAME_SUFFIX_UNITS", "studio_schema", "kind_tables", "field_unit"]

#: Units the form shows, as the descriptions spell them (longest first, so "mm/s" wins
#: over "mm").
UNITS = ("kg/m^3", "mm/s", "r/min", "mm", "deg", "rad", "MPa", "N", "h")
#: Field-name suffixes that name the unit (the parameter files' convention).
NAME_SUFFIX_UNITS = {"_deg": "deg", "_rad": "rad", "_rpm": "r/min", "_mpa": "MPa",
                     "_n": "N", "_h": "h"}

#: A unit as a comma-separated (or parenthesised) item of a description: ``"b1, mm"``,
#: ``"points (x, y), mm, in the loop's order"``, ``"bore, mm (0: none)"``, ``"volume [x, y,
#: z], mm: every ..."``, ``"mm"``, ``"diameters given in the file (mm), by axis"``.
_UNIT_ITEM = re.compile(
    r"(?:^|[,(])\s*(?P<unit>" + "|".join(re.escape(u) for u in UNITS) + r")\s*(?=$|[,;:.()])")
#: Descriptions of the top-level scalars (their model is the whole file, whose docstring
#: describes the mechanism, not the field).
TOP_LEVEL_DESCRIPTIONS = {"mechanism": "mechanism kind: planting or pricking",
                          "name": "design name; also the name of its output folder"}


def _validator_rules() -> dict:
    """Rules that live in the models' validators, not in their ``Field`` constraints."""
    from cadgen.params.pricking import EQUAL_PERIMETER, SPLIT_EXPONENT_RANGE, TRAJECTORY_DEGREES
    from cadgen.params.solids import MIN_WALL

    low, high = SPLIT_EXPONENT_RANGE
    return {
        # the validator takes "equal-perimeter" or a number in the range
        "gears.split_exponent": {"type": "number", "enum": [EQUAL_PERIMETER],
                                 "minimum": low, "maximum": high},
        "trajectory.degree": {"type": "integer", "enum": list(TRAJECTORY_DEGREES)},
        "housing.wall": {"minimum": MIN_WALL},
    }


def field_unit(name: str, description: str | None, table_doc: str | None = None) -> str | None:
    """The unit of a field (see the module docstring for the order of the sources)."""
    for suffix, unit in NAME_SUFFIX_UNITS.items():
        if name.endswith(suffix):
            return unit
    for text in (description, None if description else table_doc):
        match = _UNIT_ITEM.search(text.strip()) if text else None
        if match:
            return match.group("unit")
    return None


def _strip_annotated(annotation):
    metadata = []
    while get_origin(annotation) is typing.Annotated:
        args = get_args(annotation)
        annotation, extra = args[0], args[1:]
        for item in extra:
            metadata += list(getattr(item, "metadata", None) or [item])
    return annotation, metadata


def _optional(annotation):
    """``(inner, optional)`` for ``X | None``."""
    if get_origin(annotation) in (Union, types.UnionType):
        args = [a for a in get_args(annotation) if a is not type(None)]
        if len(args) < len(get_args(annotation)):
            return (args[0] if len(args) == 1 else Union[tuple(args)]), True
    return annotation, False


def _is_model(annotation) -> bool:
    return isinstance(annotation, type) and issubclass(annotation, BaseModel)


def _bounds(metadata) -> dict:
    out = {"minimum": None, "maximum": None, "exclusive_minimum": False,
           "exclusive_maximum": False}
    for item in metadata:
        if isinstance(item, Gt):
            out.update(minimum=item.gt, exclusive_minimum=True)
        elif isinstance(item, Ge):
            out.update(minimum=item.ge, exclusive_minimum=False)
        elif isinstance(item, Lt):
            out.update(maximum=item.lt, exclusive_maximum=True)
        elif isinstance(item, Le):
            out.update(maximum=item.le, exclusive_maximum=False)
    return out


def _scalar_type(annotation) -> tuple[str, list | None]:
    if get_origin(annotation) is Literal:
        return "enum", list(get_args(annotation))
    if annotation is bool:
        return "boolean", None
    if annotation is int:
        return "integer", None
    if annotation is float:
        return "number", None
    if annotation is str:
        return "string", None
    if get_origin(annotation) in (Union, types.UnionType):
        # a union of a literal and a number (gears.split_exponent): a number with choices
        kinds = [_scalar_type(_strip_annotated(a)[0]) for a in get_args(annotation)]
        enum = [v for kind, values in kinds if kind == "enum" for v in values]
        numeric = [kind for kind, _ in kinds if kind in ("number", "integer")]
        return (numeric[0] if numeric else "enum"), enum or None
    raise TypeError(f"no form type for the annotation {annotation!r}")


def _describe_type(annotation) -> dict:
    """``type``, ``items``, ``enum``, bounds (of the field, or of an array's items)."""
    annotation, metadata = _strip_annotated(annotation)
    annotation, optional = _optional(annotation)
    annotation, more = _strip_annotated(annotation)
    metadata += more
    out = {"items": None, "min_items": None, "max_items": None}
    if get_origin(annotation) is tuple:
        args = get_args(annotation)
        variadic = len(args) == 2 and args[1] is Ellipsis
        item, item_metadata = _strip_annotated(args[0])
        if not variadic and len(args) == 2 and _scalar_type(item)[0] == "number":
            out.update(type="point", enum=None, **_bounds(item_metadata))
        else:
            inner = _describe_type(args[0])
            out.update(type="array", items=inner["type"], enum=inner["enum"],
                       **{k: inner[k] for k in ("minimum", "maximum", "exclusive_minimum",
                                                 "exclusive_maximum")})
            if not variadic:
                out.update(min_items=len(args), max_items=len(args))
        for item in metadata:
            if isinstance(item, MinLen):
                out["min_items"] = item.min_length
            elif isinstance(item, MaxLen):
                out["max_items"] = item.max_length
    else:
        kind, enum = _scalar_type(annotation)
        out.update(type=kind, enum=enum, **_bounds(metadata))
    out["optional"] = optional
    return out


def _one_line(text: str | None) -> str:
    return " ".join((text or "").strip().split("\n\n")[0].split())


def _default(field) -> Any:
    default = field.get_default(call_default_factory=True)
    if default is PydanticUndefined or isinstance(default, BaseModel):
        return None
    if isinstance(default, tuple):
        return [list(v) if isinstance(v, tuple) else v for v in default]
    return default


def _table_title(name: str) -> str:
    return name.split(".")[-1].replace("_", " ").capitalize() if name else "Design"


def _walk(model: type[BaseModel], name: str, tables: list, rules: dict) -> None:
    doc = _one_line(model.__doc__)
    # a field without a description takes its unit from its table's docstrings (the
    # class's and its bases': the shaft diameters' unit is said once, on the base)
    docs = [_one_line(c.__doc__) for c in model.__mro__
            if c.__doc__ and issubclass(c, BaseModel) and c is not BaseModel]
    unit_doc = next((d for d in docs if field_unit("", d)), doc)
    fields = []
    for key, field in model.model_fields.items():
        path = f"{name}.{key}" if name else key
        annotation, _ = _strip_annotated(field.annotation)
        inner, _ = _optional(annotation)
        inner, _ = _strip_annotated(inner)
        members = [m for m in (get_args(inner) if get_origin(inner) in (Union, types.UnionType)
                               else (inner,)) if _is_model(m)]
        if members:   # a table of its own (a discriminated union of one member: that member)
            for member in members:
                _walk(member, path, tables, rules)
            continue
        described = _describe_type(field.annotation)
        described.update(_bounds(field.metadata) if described["type"] != "array"
                         and any(isinstance(m, (Gt, Ge, Lt, Le)) for m in field.metadata)
                         else {})
        for item in field.metadata:
            if isinstance(item, MinLen) and described["type"] == "array":
                described["min_items"] = item.min_length
            elif isinstance(item, MaxLen) and described["type"] == "array":
                described["max_items"] = item.max_length
        description = _one_line(field.description)
        if not name and key in TOP_LEVEL_DESCRIPTIONS:
            description = TOP_LEVEL_DESCRIPTIONS[key]
        elif description in UNITS:   # the targets say only their unit: the key says the rest
            description = f"{key.replace('_', ' ')}, {description}"
        entry = {"path": path, "key": key, "type": described["type"],
                 "items": described["items"],
                 "unit": field_unit(key, field.description, unit_doc),
                 "default": _default(field), "required": field.is_required(),
                 "minimum": described["minimum"], "maximum": described["maximum"],
                 "exclusive_minimum": described["exclusive_minimum"],
                 "exclusive_maximum": described["exclusive_maximum"],
                 "min_items": described["min_items"], "max_items": described["max_items"],
                 "enum": described["enum"], "nullable": described["optional"],
                 "description": description or f"{key}: {unit_doc[:1].lower() + unit_doc[1:]}"}
        entry.update(rules.get(path, {}))
        fields.append(entry)
    if fields:
        # the table itself comes before its nested tables, as in the file
        position = next((i for i, t in enumerate(tables) if t["name"].startswith(name + ".")),
                        len(tables)) if name else 0
        tables.insert(position, {"name": name, "title": _table_title(name),
                                 "description": doc, "fields": fields})


def kind_tables(model: type[BaseModel]) -> list:
    """Every table of a mechanism kind's model (see the module docstring)."""
    tables: list = []
    _walk(model, "", tables, _validator_rules())
    return tables


@functools.cache
def studio_schema() -> dict:
    """``{"kinds": {"planting": {"tables": [...]}, "pricking": {...}}}`` (computed once)."""
    from cadgen.params import PlantingParameters, PrickingParameters

    return {"kinds": {"planting": {"tables": kind_tables(PlantingParameters)},
                      "pricking": {"tables": kind_tables(PrickingParameters)}}}
