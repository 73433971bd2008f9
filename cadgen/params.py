"""Parameter files: TOML format, schema and all-problems-at-once validation.

A parameter file names its mechanism kind and holds one table per part of the design:

* ``mechanism = "planting"`` (kind 1, :class:`PlantingParameters`): the differential
  planetary planting mechanism, tables ``[pitch_curve]``, ``[train]``, ``[planter]``,
  ``[field]`` and the optional ``[housing]``, ``[targets]``, ``[resolution]``;
* ``mechanism = "pricking"`` (kind 2, :class:`PrickingParameters`): the inclined
  hole-pricking mechanism, inverse-designed from its needle-tip loop, tables
  ``[trajectory]``, ``[linkage]``, ``[field]`` and the optional ``[gears]``,
  ``[resolution]``. Only the structure of the type-value points is checked here
  (at least 5 pairs of finite numbers); their geometry (repeated points,
  self-intersection, the sun centre inside the loop) is the kinematic model's to judge.

The schema is a set of frozen pydantic models, strict about types (a quoted ``"36"``
is not a number, ``true`` is not a number, an integer is accepted where a float is
asked), finite floats only, and no unknown keys. :func:`load_params` and
:func:`validate_text` never stop at the first problem: they raise one
:class:`ParameterError` that lists every problem found, each a
:class:`~kinematics.errors.Problem` with a dotted field path (``train.R``,
``field.plant_spacings.1``), a short code and a sentence naming the bad value.

Problem codes raised here:

==================  =====================================================================
code                meaning
==================  =====================================================================
file_not_found      the file does not exist
not_readable        the path is a directory or cannot be read
not_utf8            the file is not UTF-8 text
toml_syntax         the text is not valid TOML (message has line and column)
missing             a required key or table is absent
unknown_key         a key or table the schema does not know (with "did you mean")
wrong_type          e.g. a string or boolean where a number is asked
out_of_range        a number outside its allowed interval
not_finite          nan or inf
empty               an array that must not be empty
invalid_name        the design name cannot name an output folder
unknown_mechanism   ``mechanism`` names no known mechanism kind
unknown_kind        a ``kind`` (e.g. ``pitch_curve.kind``) names no known kind
inconsistent        a value contradicts a rule that needs no kinematics (``2*e2`` whole)
duplicate           a plant spacing or an inclination given twice (reported at the repeat)
not_allowed         a value outside a fixed set of choices: ``trajectory.degree`` not 3 or 5,
                    ``gears.split_exponent`` a string other than ``"equal-perimeter"``
==================  =====================================================================

Where array problems are reported: an array item at its index
(``field.inclinations_deg.1``); a type-value point that is not a pair of two finite
numbers once, at the point's index (``trajectory.points.3``: ``wrong_type`` for a
wrong shape or a non-number item, ``not_finite`` for nan or inf); too few points at
the array itself (``trajectory.points``, ``out_of_range``).

Once the file is structurally valid, :func:`cadgen.feasibility.design_problems`
adds the problems that need the kinematic model (their codes are its own).
Validation never writes anything.
"""

from __future__ import annotations

import difflib
import json
import math
import re
import tomllib
from collections.abc import Mapping
from datetime import date, datetime, time
from pathlib import Path
from typing import Annotated, Any, Literal, Union, get_args, get_origin

from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    TypeAdapter,
    ValidationError,
    ValidationInfo,
    field_validator,
)
from pydantic_core import PydanticCustomError

from kinematics.errors import DesignError, Problem

__all__ = [
    "ParameterError",
    "LimaconParameters",
    "PitchCurve",
    "TrainParameters",
    "PlanterParameters",
    "FieldParameters",
    "Gearbox1Envelope",
    "Gearbox2Envelope",
    "HousingParameters",
    "DesignTargets",
    "ResolutionParameters",
    "PlantingParameters",
    "TrajectoryParameters",
    "LinkageParameters",
    "GearParameters",
    "PrickingFieldParameters",
    "PrickingResolutionParameters",
    "PrickingParameters",
    "SplitExponent",
    "DesignParameters",
    "MECHANISM_KINDS",
    "NAME_PATTERN",
    "MIN_TEETH",
    "STEPS_PER_REVOLUTION_RANGE",
    "CLOSURE_RTOL_RANGE",
    "EQUAL_PERIMETER",
    "TRAJECTORY_DEGREES",
    "MIN_TYPE_VALUE_POINTS",
    "SPLIT_EXPONENT_RANGE",
    "INCLINATION_MAX_DEG",
    "INVERSE_GRID_RANGE",
    "load_params",
    "validate_text",
    "validate_data",
]

NAME_PATTERN = r"^[A-Za-z0-9][A-Za-z0-9._-]*$"
"""Design names: they become a folder name under the output root."""
NAME_MAX_LENGTH = 100
MIN_TEETH = 6
STEPS_PER_REVOLUTION_RANGE = (36, 1_000_000)
CLOSURE_RTOL_RANGE = (1e-15, 1e-6)
# 2*e2 must be a whole number; this absorbs the rounding of a decimal such as 1.5 in TOML.
E2_WHOLE_ABS_TOL = 1e-9

EQUAL_PERIMETER = "equal-perimeter"
"""``gears.split_exponent`` value asking for the two stages' pitch perimeters to be equal."""
TRAJECTORY_DEGREES = (3, 5)
"""Allowed degrees of the closed interpolating curve through the type-value points."""
MIN_TYPE_VALUE_POINTS = 5
SPLIT_EXPONENT_RANGE = (0.0, 4.0)
INCLINATION_MAX_DEG = 80.0
"""Inclinations theta of the mechanism plane must be in [0, this) degrees."""
INVERSE_GRID_RANGE = (36, 100_000)


class ParameterError(DesignError):
    """A parameter file with problems; ``problems`` lists all of them.

    Also a :class:`ValueError` (through :class:`~kinematics.errors.DesignError`).
    """


def _list_to_tuple(value: Any) -> Any:
    # TOML arrays arrive as lists; the frozen models store tuples (strict mode
    # would otherwise refuse a list for a tuple field).
    return tuple(value) if isinstance(value, list) else value


class _Table(BaseModel):
    """Base of every table: frozen, no unknown keys, strict types, finite floats."""

    model_config = ConfigDict(frozen=True, extra="forbid", strict=True, allow_inf_nan=False)


class LimaconParameters(_Table):
    """Pascal limacon variant, the pitch curve of the central non-circular gear.

    ``x(t) = a1 (e1 cos t)^2 + b1 cos(t + f1) + g1``,
    ``y(t) = c1 cos(e2 t) sin(e2 t) + d1 cos(t + f2) + g2``, ``r1 = |(x, y)|``.
    """

    kind: Literal["limacon"] = Field(description="pitch curve kind")
    a1: float = Field(description="a1, mm")
    b1: float = Field(description="b1, mm")
    c1: float = Field(description="c1, mm")
    d1: float = Field(description="d1, mm")
    e1: float = Field(description="e1, dimensionless")
    e2: float = Field(gt=0, description="e2, dimensionless; 2*e2 a whole number")
    f1_rad: float = Field(description="phase f1, rad")
    f2_rad: float = Field(description="phase f2, rad")
    g1: float = Field(description="g1, mm")
    g2: float = Field(description="g2, mm")
    teeth: int = Field(ge=MIN_TEETH, description="tooth count z of the non-circular gears")

    @field_validator("e2")
    @classmethod
    def _e2_closes(cls, e2: float) -> float:
        # cos(e2 t) sin(e2 t) = sin(2 e2 t)/2 has period pi/e2: one gear turn (2 pi)
        # holds a whole number of periods only if 2*e2 is whole.
        twice = 2.0 * e2
        if abs(twice - round(twice)) > E2_WHOLE_ABS_TOL:
            raise PydanticCustomError(
                "inconsistent",
                "e2 = {e2} makes 2*e2 = {twice} not a whole number, so the pitch curve "
                "does not close over one turn of the gear",
                {"e2": e2, "twice": twice},
            )
        return e2


PitchCurve = Annotated[Union[LimaconParameters], Field(discriminator="kind")]
"""Every pitch curve kind, told apart by ``kind``."""


class TrainParameters(_Table):
    """Planetary gear train: ratios, radii, catching-position directions, speed ratio."""

    i12: float = Field(gt=0, description="ratio i12 (sets A at R(1+i12))")
    i13: float = Field(gt=0, description="ratio i13")
    R: float = Field(gt=0, description="base radius R of carrier 1, mm")
    r: float = Field(gt=0, description="radius r of the circular gears in gearbox 2, mm")
    phi0_deg: float = Field(description="direction phi0 of O->C at catching, deg")
    phic_deg: float = Field(description="direction phic of C->E at catching, deg")
    n: float = Field(gt=1, description="central shaft speed / carrier-1 speed")

    @property
    def phi0_rad(self) -> float:
        """phi0 in radians."""
        return math.radians(self.phi0_deg)

    @property
    def phic_rad(self) -> float:
        """phic in radians."""
        return math.radians(self.phic_deg)


class PlanterParameters(_Table):
    """Planting arm lengths."""

    L1: float = Field(gt=0, description="L1: E to P1, mm")
    L2: float = Field(gt=0, description="L2: P1 to the duckbill tip N, mm")


class FieldParameters(_Table):
    """Operating case: planting depth, plant spacings, carrier speed."""

    depth: float = Field(gt=0, description="planting depth b, mm")
    plant_spacings: Annotated[
        tuple[Annotated[float, Field(gt=0)], ...], BeforeValidator(_list_to_tuple)
    ] = Field(min_length=1, description="plant spacings S, mm")
    carrier_speed_rpm: float = Field(30.0, gt=0, description="carrier-1 speed, r/min")

    @field_validator("plant_spacings")
    @classmethod
    def _no_duplicates(cls, spacings: tuple[float, ...]) -> tuple[float, ...]:
        return _no_repeats(spacings, "plant spacing")


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
        # The mapper below turns each repeat into its own problem at its index.
        raise PydanticCustomError(
            "duplicate", "{what}s repeat: {repeats}", {"repeats": repeats, "what": what}
        )
    return values


class _Envelope(_Table):
    """Explicit envelope radii of a gearbox about its gear axes, mm (each optional)."""

    def get(self, axis: str, default: float | None = None) -> float | None:
        """The radius given for ``axis`` (e.g. ``"C"``), or ``default`` when not given.

        Dict-like on purpose: callers merge explicit radii over derived ones with
        ``envelope.get(axis, derived_radius)``.
        """
        radius = getattr(self, axis, None) if axis in type(self).model_fields else None
        return default if radius is None else radius


class Gearbox1Envelope(_Envelope):
    """Explicit envelope radii of gearbox 1 about the axes O, A, B, C, mm (each optional)."""

    O: float | None = Field(None, gt=0)
    A: float | None = Field(None, gt=0)
    B: float | None = Field(None, gt=0)
    C: float | None = Field(None, gt=0)


class Gearbox2Envelope(_Envelope):
    """Explicit envelope radii of gearbox 2 about the axes C, D, E, mm (each optional)."""

    C: float | None = Field(None, gt=0)
    D: float | None = Field(None, gt=0)
    E: float | None = Field(None, gt=0)


class HousingParameters(_Table):
    """Kinematic envelope circles of the gearbox housings."""

    wall: float = Field(6.0, ge=0, description="largest gear tip to housing outside, mm")
    gearbox1: Gearbox1Envelope | None = None
    gearbox2: Gearbox2Envelope | None = None


class DesignTargets(_Table):
    """The agronomic targets the metrics are checked against (the spec's defaults)."""

    trajectory_height_min: float = Field(500.0, gt=0, description="mm")
    hole_width_max: float = Field(30.0, gt=0, description="mm")
    hole_verticality_max: float = Field(10.0, gt=0, description="mm")
    angle_difference_max_deg: float = Field(20.0, gt=0, le=180, description="deg")
    arm_distance_min: float = Field(10.0, ge=0, description="mm")
    ground_clearance_min: float = Field(20.0, ge=0, description="mm")
    module_min: float = Field(2.5, gt=0, description="mm")


class ResolutionParameters(_Table):
    """Numerical resolution knobs."""

    steps_per_revolution: int = Field(
        3600, ge=STEPS_PER_REVOLUTION_RANGE[0], le=STEPS_PER_REVOLUTION_RANGE[1]
    )
    closure_rtol: float = Field(1e-13, ge=CLOSURE_RTOL_RANGE[0], le=CLOSURE_RTOL_RANGE[1])


class PlantingParameters(_Table):
    """Mechanism kind 1: the differential planetary planting mechanism."""

    mechanism: Literal["planting"]
    name: str = Field(pattern=NAME_PATTERN, min_length=1, max_length=NAME_MAX_LENGTH)
    pitch_curve: PitchCurve
    train: TrainParameters
    planter: PlanterParameters
    field: FieldParameters
    housing: HousingParameters = HousingParameters()
    targets: DesignTargets = DesignTargets()
    resolution: ResolutionParameters = ResolutionParameters()


# --------------------------------------------------------------------------- kind 2: pricking

_PROBLEMS = "problems"
"""Pydantic error type of a validator that wrote its own problems (see _problems_error)."""


def _problems_error(problems: list[tuple[tuple, str, str]]) -> PydanticCustomError:
    """An error carrying finished problems: ``(path suffix, code, message)`` each.

    The suffix is appended to the field's path (``(3,)`` makes ``trajectory.points.3``).
    """
    return PydanticCustomError(
        _PROBLEMS, "{count} problem(s)", {"count": len(problems), "problems": problems}
    )


def _show_array(values: list | tuple) -> str:
    return "[" + ", ".join(_show(v) for v in values) + "]"


def _pair_issue(value: Any, label: str) -> tuple[str, str] | None:
    """Why ``value`` is not a pair ``[x, y]`` of finite numbers, as ``(code, message)``."""
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        return "wrong_type", f"{label} must be a pair [x, y] of numbers, not {_describe(value)}"
    for index, item in enumerate(value):
        if isinstance(item, bool) or not isinstance(item, (int, float)):
            text = (f"{label} must be a pair [x, y] of numbers: its item {index} is "
                    f"{_describe(item)}")
            if isinstance(item, str):
                text += " (write numbers without quotes)"
            return "wrong_type", text
    for index, item in enumerate(value):
        if isinstance(item, int):
            try:
                float(item)
            except OverflowError:
                return "out_of_range", (f"{label}: its item {index} = {item} is too large to be "
                                        "represented as a float")
        elif not math.isfinite(item):
            return "not_finite", (f"{label} = {_show_array(value)} is not a pair of finite "
                                  f"numbers: its item {index} is {item!r}")
    return None


def _check_pair(value: Any, label: str) -> Any:
    issue = _pair_issue(value, label)
    if issue is not None:
        raise _problems_error([((), *issue)])
    return (float(value[0]), float(value[1]))


class TrajectoryParameters(_Table):
    """The wanted needle-tip loop relative to the machine, as type-value points.

    Frame: x = forward travel, y = up, mm. Only the structure is checked here; the
    kinematic model judges the geometry (repeats, self-intersection, O inside the loop).
    """

    points: tuple[tuple[float, float], ...] = Field(
        min_length=MIN_TYPE_VALUE_POINTS,
        description="type-value points Q1..Qm (x, y), mm, in the loop's order",
    )
    degree: int = Field(description="degree of the closed interpolating curve: 3 or 5")
    sun_centre: tuple[float, float] = Field((0.0, 0.0), description="sun-gear centre O, mm")

    @field_validator("points", mode="before")
    @classmethod
    def _points_are_pairs(cls, points: Any, info: ValidationInfo) -> Any:
        name = info.field_name
        if not isinstance(points, (list, tuple)):
            raise _problems_error([((), "wrong_type",
                                    f"{name} must be an array of [x, y] pairs, not "
                                    f"{_describe(points)}")])
        problems = []
        pairs = []
        for index, pair in enumerate(points):
            issue = _pair_issue(pair, f"{name}[{index}]")
            if issue is None:
                pairs.append((float(pair[0]), float(pair[1])))
            else:
                problems.append(((index,), *issue))
        if len(points) < MIN_TYPE_VALUE_POINTS:
            problems.insert(0, ((), "out_of_range",
                                f"{name} has {len(points)} item{'s' if len(points) != 1 else ''}: "
                                f"at least {MIN_TYPE_VALUE_POINTS} type-value points are needed"))
        if problems:
            raise _problems_error(problems)
        return tuple(pairs)

    @field_validator("sun_centre", mode="before")
    @classmethod
    def _sun_centre_is_a_pair(cls, centre: Any, info: ValidationInfo) -> Any:
        return _check_pair(centre, info.field_name)

    @field_validator("degree")
    @classmethod
    def _degree_allowed(cls, degree: int) -> int:
        if degree not in TRAJECTORY_DEGREES:
            allowed = " or ".join(str(d) for d in TRAJECTORY_DEGREES)
            raise PydanticCustomError(
                "not_allowed",
                "degree = {degree} is not allowed: it must be {allowed}",
                {"degree": degree, "allowed": allowed},
            )
        return degree


class LinkageParameters(_Table):
    """Rocker arm, and optional expert overrides of the lengths the curve normally sets."""

    rocker: float = Field(gt=0, description="l1, rocker arm length, mm")
    centre_distance: float | None = Field(
        None, gt=0, description="a, centre distance of every gear pair, mm (normally derived)"
    )
    tip_reach: float | None = Field(
        None, gt=0, description="l, planet centre B to the needle tip D, mm (normally derived)"
    )


SplitExponent = Union[Literal["equal-perimeter"], float]
"""``gears.split_exponent``: ``"equal-perimeter"`` or a number w in [0, 4]."""


class GearParameters(_Table):
    """How the total relative ratio is split into two stages, and the gear cutting data."""

    split_exponent: SplitExponent = Field(
        EQUAL_PERIMETER,
        description='w in i1 = K i^w: "equal-perimeter" or a number in [0, 4]',
    )
    module: float = Field(2.0, gt=0, description="target module m, mm")
    pressure_angle_deg: float = Field(20.0, gt=0, lt=45, description="pressure angle, deg")
    addendum: float = Field(1.0, gt=0, description="addendum coefficient ha*, dimensionless")
    min_ratio: float = Field(
        0.05, gt=0, description="lower bound of the total relative ratio i, dimensionless"
    )

    @field_validator("split_exponent", mode="before")
    @classmethod
    def _split_exponent(cls, value: Any, info: ValidationInfo) -> Any:
        name = info.field_name
        low, high = SPLIT_EXPONENT_RANGE
        choices = f'{_show(EQUAL_PERIMETER)} or a number from {low:g} to {high:g}'
        if isinstance(value, str):
            if value == EQUAL_PERIMETER:
                return value
            try:
                float(value)
            except ValueError:
                text = f"{name} = {_show(value)} is not allowed: it must be {choices}"
                if _close_keys(value, [EQUAL_PERIMETER], cutoff=0.4):
                    text += f"; did you mean {_show(EQUAL_PERIMETER)}?"
                raise _problems_error([((), "not_allowed", text)]) from None
            raise _problems_error([((), "wrong_type",
                                    f"{name} must be {choices}, not {_describe(value)} "
                                    "(write numbers without quotes)")])
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise _problems_error([((), "wrong_type",
                                    f"{name} must be {choices}, not {_describe(value)}")])
        try:
            number = float(value)
        except OverflowError:
            raise _problems_error([((), "out_of_range",
                                    f"{name} = {value} is too large to be represented as a "
                                    "float")]) from None
        if not math.isfinite(number):
            raise _problems_error([((), "not_finite",
                                    f"{name} = {_show(value)} is not a finite number")])
        if not low <= number <= high:
            raise _problems_error([((), "out_of_range",
                                    f"{name} = {_show(value)} is out of range: it must be "
                                    f"from {low:g} to {high:g}")])
        return number

    @property
    def pressure_angle_rad(self) -> float:
        """The pressure angle in radians."""
        return math.radians(self.pressure_angle_deg)


class PrickingFieldParameters(_Table):
    """Operating case: speeds, vertical pricking depth, inclinations of the mechanism plane."""

    carrier_speed_rpm: float = Field(75.0, gt=0, description="carrier speed omega, r/min")
    forward_speed: float = Field(gt=0, description="machine speed v, mm/s")
    depth: float = Field(gt=0, description="vertical pricking depth, mm")
    inclinations_deg: Annotated[
        tuple[Annotated[float, Field(ge=0, lt=INCLINATION_MAX_DEG)], ...],
        BeforeValidator(_list_to_tuple),
    ] = Field(min_length=1, description="inclinations theta of the mechanism plane, deg")

    @field_validator("inclinations_deg")
    @classmethod
    def _no_duplicates(cls, inclinations: tuple[float, ...]) -> tuple[float, ...]:
        return _no_repeats(inclinations, "inclination")

    @property
    def inclinations_rad(self) -> tuple[float, ...]:
        """The inclinations theta in radians."""
        return tuple(math.radians(theta) for theta in self.inclinations_deg)


class PrickingResolutionParameters(_Table):
    """Numerical resolution knobs of the inverse design."""

    inverse_grid: int = Field(
        720, ge=INVERSE_GRID_RANGE[0], le=INVERSE_GRID_RANGE[1],
        description="uniform carrier-angle samples per turn of the inverse solve",
    )


class PrickingParameters(_Table):
    """Mechanism kind 2: the inclined hole-pricking mechanism, designed from its tip loop."""

    mechanism: Literal["pricking"]
    name: str = Field(pattern=NAME_PATTERN, min_length=1, max_length=NAME_MAX_LENGTH)
    trajectory: TrajectoryParameters
    linkage: LinkageParameters
    gears: GearParameters = GearParameters()
    field: PrickingFieldParameters
    resolution: PrickingResolutionParameters = PrickingResolutionParameters()


DesignParameters = Annotated[
    Union[PlantingParameters, PrickingParameters], Field(discriminator="mechanism")
]
"""Every mechanism kind, told apart by ``mechanism``."""

_DESIGN_ADAPTER = TypeAdapter(DesignParameters)


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


_ROOT_NODE = ("union", "mechanism", _union_members(get_args(DesignParameters)[0], "mechanism"))
MECHANISM_KINDS = tuple(_ROOT_NODE[2])
"""Known mechanism kinds."""


def _walk(loc: tuple) -> tuple[list, Any, Any]:
    """Turn a pydantic error location into a file path.

    Returns ``(parts, parent, node)``: the path parts with union tags dropped, the
    schema node holding the last part, and the node the last part leads to (a model
    class, a ``("union", discriminator, members)`` triple, or None).
    """
    parts: list = []
    parent = None
    node: Any = _ROOT_NODE
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


def _describe(value: Any) -> str:
    """A TOML reader's name for a value: ``the string "36"``, ``the boolean true``."""
    if isinstance(value, bool):
        return f"the boolean {str(value).lower()}"
    if isinstance(value, int):
        return f"the integer {value}"
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
    return json.dumps(value) if isinstance(value, str) else repr(value)


def _label(parts: list) -> str:
    """``plant_spacings[1]`` style name of the last path element, for sentences."""
    if not parts:
        return "the file"
    if isinstance(parts[-1], int):
        return f"{_label(parts[:-1])}[{parts[-1]}]"
    return str(parts[-1])


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
    return ".".join(str(p) for p in parts) if parts else ""


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

_CUSTOM_CODES = {"inconsistent", "not_allowed"}


def _problems_from_error(error: Mapping[str, Any]) -> list[Problem]:
    """Turn one pydantic error into the project's problems (usually one)."""
    kind = error["type"]
    value = error.get("input")
    ctx = error.get("ctx") or {}
    parts, parent, node = _walk(tuple(error["loc"]))
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
        text = f"unknown {what} '{name}'{where}"
        known = _known_keys(parent)
        close = _close_keys(str(name), known)
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
                        f"{name} = {value} is too large to be represented as a float")]

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
        return [Problem(path, "unknown_kind",
                        f"{name} = {_show(value)} is not allowed: it must be {expected}")]

    # Not expected from a TOML file; keep pydantic's own words rather than lose the problem.
    return [Problem(path, kind, f"{name}: {error['msg']} (got {_describe(value)})")]


# --------------------------------------------------------------------------- entry points


def _structural(data: Mapping[str, Any]) -> tuple[Any, list[Problem]]:
    try:
        return _DESIGN_ADAPTER.validate_python(data), []
    except ValidationError as exc:
        problems: list[Problem] = []
        for error in exc.errors(include_url=False):
            problems += _problems_from_error(error)
        return None, problems


def _feasibility_problems(params: Any) -> list[Problem]:
    # Imported here: the kinematic checks pull in numpy/scipy, which a caller that
    # only parses (or prints --help) should not pay for.
    from cadgen.feasibility import design_problems

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
        Also run :func:`cadgen.feasibility.design_problems` once the structure is
        valid (it needs the kinematic model).

    Returns
    -------
    PlantingParameters or PrickingParameters
        The validated, frozen parameters (the member of :data:`DesignParameters`
        that ``mechanism`` names).

    Raises
    ------
    ParameterError
        Listing every problem found.
    """
    if not isinstance(data, Mapping):
        problem = Problem("", "wrong_type", f"expected a table, not {_describe(data)}")
        raise ParameterError([problem], source)
    params, problems = _structural(data)
    if not problems and check_feasibility:
        problems = _feasibility_problems(params)
    if problems:
        raise ParameterError(problems, source)
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
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError([_syntax_problem(exc)], source) from None
    return validate_data(data, source, check_feasibility=check_feasibility)


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
