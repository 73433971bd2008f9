"""Mechanism kind 2, ``mechanism = "pricking"``: the inclined hole-pricking mechanism.

It is inverse-designed from its needle-tip loop: tables ``[trajectory]``,
``[linkage]``, ``[field]`` and the optional ``[gears]``, ``[resolution]``;
:class:`PrickingParameters` holds them all. Only the structure of the type-value
points is checked here (at least 5 pairs of finite numbers); their geometry (repeated
points, self-intersection, the sun centre inside the loop) is the kinematic model's
to judge.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal, Union

from pydantic import BeforeValidator, Field, ValidationInfo, field_validator
from pydantic_core import PydanticCustomError

from cadgen.params._problems import _close_keys, _describe, _problems_error, _show
from cadgen.params.cutting import CuttingParameters, PrickingShifts
from cadgen.params.dynamics import DynamicsParameters
from cadgen.params.scene import SceneParameters
from cadgen.params.solids import GroundParameters, ShellParameters, SolidsParameters
from cadgen.params.machine import ManufacturingParameters, PrickingMachineParameters
from cadgen.params._tables import NAME_MAX_LENGTH, NAME_PATTERN, _list_to_tuple, _no_repeats, _Table

__all__ = [
    "TrajectoryParameters",
    "LinkageParameters",
    "GearParameters",
    "PrickingFieldParameters",
    "PrickingResolutionParameters",
    "PrickingParameters",
    "SplitExponent",
    "EQUAL_PERIMETER",
    "TRAJECTORY_DEGREES",
    "MIN_TYPE_VALUE_POINTS",
    "SPLIT_EXPONENT_RANGE",
    "INCLINATION_MAX_DEG",
    "INVERSE_GRID_RANGE",
]

EQUAL_PERIMETER = "equal-perimeter"
"""``gears.split_exponent`` value asking for the two stages' pitch perimeters to be equal."""
TRAJECTORY_DEGREES = (3, 5)
"""Allowed degrees of the closed interpolating curve through the type-value points."""
MIN_TYPE_VALUE_POINTS = 5
SPLIT_EXPONENT_RANGE = (0.0, 4.0)
INCLINATION_MAX_DEG = 80.0
"""Inclinations theta of the mechanism plane must be in [0, this) degrees."""
INVERSE_GRID_RANGE = (36, 100_000)


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
                return "out_of_range", (f"{label}: its item {index} = {_show(item)} is too "
                                        "large to be represented as a float")
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
    rocker_width: float = Field(16.0, gt=0, description="width of the rocker bar (solids), mm")
    rocker_thickness: float = Field(8.0, gt=0, description="thickness of the rocker bar (solids), mm")
    needle_diameter: float = Field(8.0, gt=0, description="diameter of the needle (solids), mm")


SplitExponent = Union[Literal["equal-perimeter"], float]
"""``gears.split_exponent``: ``"equal-perimeter"`` or a number w in [0, 4]."""


class GearParameters(CuttingParameters):
    """How the total relative ratio is split into two stages, and the gear cutting data."""

    split_exponent: SplitExponent = Field(
        EQUAL_PERIMETER,
        description='w in i1 = K i^w: "equal-perimeter" or a number in [0, 4]',
    )
    module: float = Field(2.0, ge=0.1, description="target module m, mm")
    min_ratio: float = Field(
        0.05, gt=0, description="lower bound of the total relative ratio i, dimensionless"
    )
    max_scale_change: float = Field(
        0.05, gt=0, le=0.5,
        description="largest change of scale, as a fraction, the design may take so that "
                    "stage 1 holds whole teeth at the module (0.05 = 5 %)")
    profile_shift: PrickingShifts = Field(
        PrickingShifts(), description="profile shift coefficient by gear (V-zero: a mate takes "
                                      "the opposite)")

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
                                    f"{name} = {_show(value)} is too large to be represented "
                                    "as a float")]) from None
        if not math.isfinite(number):
            raise _problems_error([((), "not_finite",
                                    f"{name} = {_show(value)} is not a finite number")])
        if not low <= number <= high:
            raise _problems_error([((), "out_of_range",
                                    f"{name} = {_show(value)} is out of range: it must be "
                                    f"from {low:g} to {high:g}")])
        return number


class PrickingFieldParameters(_Table):
    """Operating case: speeds, vertical pricking depth, inclinations of the mechanism plane."""

    carrier_speed_rpm: float = Field(75.0, ge=0.01, description="carrier speed omega, r/min")
    forward_speed: float = Field(gt=0, description="machine speed v, mm/s")
    depth: float = Field(ge=0.1, description="vertical pricking depth, mm")
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
    sweep_atol: float = Field(1e-6, ge=1e-12, le=1.0,
                              description="the FCL sweeps' certified minima within this, mm")


class PrickingParameters(_Table):
    """Mechanism kind 2: the inclined hole-pricking mechanism, designed from its tip loop."""

    mechanism: Literal["pricking"]
    name: str = Field(pattern=NAME_PATTERN, min_length=1, max_length=NAME_MAX_LENGTH)
    trajectory: TrajectoryParameters
    linkage: LinkageParameters
    gears: GearParameters = GearParameters()
    field: PrickingFieldParameters
    resolution: PrickingResolutionParameters = PrickingResolutionParameters()
    housing: ShellParameters = ShellParameters()
    ground: GroundParameters = GroundParameters()
    solids: SolidsParameters = SolidsParameters()
    machine: PrickingMachineParameters = PrickingMachineParameters()
    manufacturing: ManufacturingParameters = ManufacturingParameters()
    dynamics: DynamicsParameters = DynamicsParameters()
    scene: SceneParameters = SceneParameters()

