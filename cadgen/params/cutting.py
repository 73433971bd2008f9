"""Gear cutting settings shared by every mechanism kind (the ``[gears]`` table).

``gears.profile_shift`` is a table from gear name to its profile-shift coefficient x (times
the module, positive away from the gear's centre), e.g. ``profile_shift = { intermediate =
0.3 }``. Its keys are the gears' names in the report with spaces and hyphens written ``_``
(:func:`kinematics.profile_shift.shift_key`):

* planting: ``central``, ``intermediate`` (the non-circular pair), ``gear_D``,
  ``planet_gear_E`` (gearbox 2's 1:1 pair), ``sun``, ``idler_1``, ``idler_2``,
  ``train_1_planet`` (train 1's set II), ``sun_I``, ``idler_1_I``, ``idler_2_I``, ``planet_I``
  (set I), ``input_gear_1``, ``central_shaft_gear``, ``input_gear_2``,
  ``transmission_driven_gear`` (the frame's drive);
* pricking: ``sun``, ``intermediate_1``, ``intermediate_2``, ``planet``.

Shifts are V-zero: within each pair in mesh the two shifts sum to zero, so the pitch curves
and the centre distances stay as they are (a non-circular pair's cannot move). A gear given
a shift gives each gear in mesh with it the opposite one, and so on along a chain of meshes
(train 1: sun x, idler 1 -x, idler 2 x, planet -x). Problems, all reported at once:
``wrong_type`` and ``not_finite``, ``unknown_key`` (with the gear names and a "did you mean"),
``out_of_range`` (a shift, or one it gives a mate, outside :data:`PROFILE_SHIFT_RANGE`) and
``profile_shift_changes_centre_distance`` (two shifts given in one chain that do not sum to
zero across a mesh, at the second one's path, naming the pair). Whether a shift makes teeth
pointed needs the gears' sizes: :mod:`cadgen.params.feasibility` checks it
(``profile_shift_pointed``).
"""

from __future__ import annotations

import math
from typing import Any, ClassVar, Literal

from pydantic import Field, model_validator

from cadgen.params._problems import _close_keys, _describe, _problems_error, _show
from cadgen.params._tables import _Table
from kinematics.profile_shift import PROFILE_SHIFT_RANGE

__all__ = ["CuttingParameters", "PlantingCuttingParameters", "ShiftTable", "PlantingShifts",
           "PrickingShifts", "PROFILE_SHIFT_RANGE", "PLANTING_MESHES", "PRICKING_MESHES"]

#: The planting mechanism's pairs in mesh, as ``gears.profile_shift`` keys (cadgen.gears.trains).
PLANTING_MESHES = (("central", "intermediate"), ("gear_D", "planet_gear_E"), ("sun", "idler_1"),
                   ("idler_1", "idler_2"), ("idler_2", "train_1_planet"), ("sun_I", "idler_1_I"),
                   ("idler_1_I", "idler_2_I"), ("idler_2_I", "planet_I"),
                   ("input_gear_1", "central_shaft_gear"),
                   ("input_gear_2", "transmission_driven_gear"))
#: The pricking mechanism's (the two intermediates share a shaft, not a mesh).
PRICKING_MESHES = (("sun", "intermediate_1"), ("intermediate_2", "planet"))

_LOW, _HIGH = PROFILE_SHIFT_RANGE


def _shift(gear: str):
    return Field(None, ge=_LOW, le=_HIGH,
                 description=f"profile shift coefficient x of the {gear} gear, dimensionless "
                             "(times the module; its mate takes -x)")


class ShiftTable(_Table):
    """Profile shift coefficients by gear (absent: 0, or the opposite of a mate's)."""

    MESHES: ClassVar[tuple] = ()

    @model_validator(mode="before")
    @classmethod
    def _check(cls, data: Any) -> Any:
        if not isinstance(data, dict):
            return data   # pydantic says it is not a table
        known = list(cls.model_fields)
        problems, numbers = [], {}
        for key, value in data.items():
            if key not in known:
                close = _close_keys(str(key), known)
                hint = ("; did you mean " + " or ".join(f"'{k}'" for k in close) + "?" if close
                        else "")
                problems.append(((key,), "unknown_key",
                                 f"unknown gear '{key}' in [gears.profile_shift]{hint} "
                                 f"(its gears: {', '.join(known)})"))
            elif isinstance(value, bool) or not isinstance(value, (int, float)):
                problems.append(((key,), "wrong_type",
                                 f"{key} must be a number, not {_describe(value)}"
                                 + (" (write numbers without quotes)"
                                    if isinstance(value, str) else "")))
            elif not math.isfinite(float(value)):
                problems.append(((key,), "not_finite", f"{key} = {_show(value)} is not a finite "
                                                       "number"))
            elif not _LOW <= value <= _HIGH:
                problems.append(((key,), "out_of_range",
                                 f"{key} = {_show(value)} is out of range: a profile shift "
                                 f"must be from {_LOW:g} to {_HIGH:g} (modules)"))
            else:
                numbers[key] = float(value)
        problems += _resolve(numbers, cls.MESHES, known)[1]
        if problems:
            raise _problems_error(problems)
        return data

    def given(self) -> dict:
        """The shifts the file gives, by key."""
        return {key: value for key, value in self if value is not None}

    def resolved(self) -> dict:
        """Every gear's shift by key: given, taken (opposite) from a mate, or 0."""
        return _resolve(self.given(), self.MESHES, list(type(self).model_fields))[0]

    def source(self, key: str) -> str:
        """The key whose given shift decides ``key``'s (``key`` itself when given; ``key``
        when nothing in its chain is given)."""
        return _resolve(self.given(), self.MESHES, list(type(self).model_fields))[2].get(key, key)


def _resolve(given: dict, meshes, gears) -> tuple:
    """``(every gear's shift, problems, sources)`` from the shifts ``given`` along the
    ``meshes``; ``sources`` maps each gear reached to the given key its shift comes from.

    Each chain of meshes takes its shifts from its first gear given (in ``gears`` order);
    a second gear given in the chain must agree with what reaches it, else
    ``profile_shift_changes_centre_distance`` at its path, naming the pair it reached
    through; a shift handed to a gear not given must stay in range (``out_of_range``, at the
    first gear's path).
    """
    values = {gear: 0.0 for gear in gears}
    problems, done, sources = [], set(), {}
    for seed in [g for g in gears if g in given]:
        if seed in done:
            continue
        values[seed] = given[seed]
        done.add(seed)
        sources[seed] = seed
        queue, via = [seed], {}
        while queue:
            current = queue.pop(0)
            for first, second in meshes:
                for here, there in ((first, second), (second, first)):
                    if here != current or there in done:
                        continue
                    done.add(there)
                    queue.append(there)
                    sources[there] = seed
                    values[there] = -values[here] if values[here] else 0.0
                    via[there] = here
                    if there in given and abs(given[there] - values[there]) > 1e-12:
                        problems.append(((there,), "profile_shift_changes_centre_distance",
                                         _conflict(seed, there, here, given, values, via)))
                        values[there] = given[there]
                    elif there not in given and not _LOW <= values[there] <= _HIGH:
                        problems.append(((seed,), "out_of_range", (
                            f"{seed} = {_show(given[seed])} gives {there} {values[there]:+g} "
                            f"(shifts in mesh are opposite: {_chain(there, via)}), outside "
                            f"{_LOW:g} to {_HIGH:g}: a shift here can be at most {-_LOW:g} in "
                            "size")))
    return values, problems, sources


def _chain(gear: str, via: dict) -> str:
    path = [gear]
    while path[-1] in via:
        path.append(via[path[-1]])
    return " - ".join(reversed(path))


def _conflict(seed, gear, mate, given, values, via) -> str:
    pair = (f"the pair {mate} - {gear} must have opposite shifts (V-zero), else its centre "
            "distance would have to change, and its pitch curves and axes fix it")
    if mate == seed:
        return (f"{gear} = {given[gear]:g} and {mate} = {given[mate]:g} do not sum to zero: "
                f"{pair}; give one of the two (the other takes the opposite) or make them "
                "opposite")
    return (f"{gear} = {given[gear]:g} does not agree with {seed} = {given[seed]:g}: through "
            f"the meshes {_chain(gear, via)}, {mate} takes {values[mate]:+g}, and {pair}; give "
            f"one shift per chain of meshes (the others alternate in sign: {gear} would take "
            f"{values[gear]:+g})")


class PlantingShifts(ShiftTable):
    """Profile shifts of the planting mechanism's gears (``gears.profile_shift``)."""

    MESHES: ClassVar[tuple] = PLANTING_MESHES

    central: float | None = _shift("central non-circular")
    intermediate: float | None = _shift("intermediate non-circular")
    gear_D: float | None = _shift("circular D (1:1 pair)")
    planet_gear_E: float | None = _shift("circular planet E (1:1 pair)")
    sun: float | None = _shift("train-1 sun")
    idler_1: float | None = _shift("train-1 first idler")
    idler_2: float | None = _shift("train-1 second idler")
    train_1_planet: float | None = _shift("train-1 planet")
    sun_I: float | None = _shift("train-1 set-I sun")
    idler_1_I: float | None = _shift("train-1 set-I first idler")
    idler_2_I: float | None = _shift("train-1 set-I second idler")
    planet_I: float | None = _shift("train-1 set-I planet")
    input_gear_1: float | None = _shift("drive input gear 1")
    central_shaft_gear: float | None = _shift("drive central shaft gear")
    input_gear_2: float | None = _shift("drive input gear 2")
    transmission_driven_gear: float | None = _shift("drive transmission driven gear")


class PrickingShifts(ShiftTable):
    """Profile shifts of the pricking mechanism's gears (``gears.profile_shift``)."""

    MESHES: ClassVar[tuple] = PRICKING_MESHES

    sun: float | None = _shift("sun")
    intermediate_1: float | None = _shift("first intermediate")
    intermediate_2: float | None = _shift("second intermediate")
    planet: float | None = _shift("planet")


class CuttingParameters(_Table):
    """How the gears' teeth are cut, checked and drawn (standard defaults)."""

    cutter: Literal["auto", "shaper"] = Field(
        "auto", description='"auto": rack on convex stretches, pinion cutter on concave ones; '
                            '"shaper": a pinion cutter everywhere')
    pressure_angle_deg: float = Field(20.0, ge=5, lt=45, description="pressure angle, deg")
    addendum: float = Field(1.0, ge=0.1, le=2,
                            description="addendum coefficient ha*, dimensionless")
    dedendum: float = Field(1.25, gt=0, le=2.5, description="dedendum coefficient hf*, dimensionless")
    tip_radius: float = Field(0.38, ge=0, le=0.6,
                              description="cutter tip radius (root fillet), coefficient of the module")
    backlash: float | None = Field(
        None, ge=0, le=2, description="circumferential backlash taken off each gear's teeth, mm "
                                      "(default: the [manufacturing] process's allowance)")
    flank_points: int = Field(96, ge=8, le=4000, description="points per generated flank")
    chord_tolerance: float = Field(0.005, gt=0, le=1,
                                   description="largest deviation of the DXF polyline from the profile, mm")
    bore_diameter: float = Field(0.0, ge=0, description="shaft bore of every gear, mm (0: none)")
    # at most 4000: each pose costs about 6 ms of the teeth stage on the paper's 22-tooth
    # pair (16000 poses took 100 s against 1.8 s at the default; benchmarks/knob_costs.py)
    meshing_poses: int | None = Field(
        None, ge=16, le=4000,
        description="poses of the meshing check over one cycle (default 8 per tooth, at least 96)")
    circular_module: float | None = Field(
        None, gt=0, description="module of the trains' circular gears, mm (default: the largest "
                                "0.05-mm step that gives every one a whole tooth count)")

    face_width: float | None = Field(
        None, gt=0, description="face width of every gear, mm (default: 6 modules of each gear, "
                                "to 0.5 mm)")

    def face_width_for(self, module: float) -> float:
        """The face width given, or 6 modules rounded to 0.5 mm (mm)."""
        return self.face_width if self.face_width is not None else max(0.5, round(12.0 * module) / 2)

    @property
    def pressure_angle_rad(self) -> float:
        return math.radians(self.pressure_angle_deg)


class PlantingCuttingParameters(CuttingParameters):
    """How the planting mechanism's gears are cut: the shared settings and the gears' shifts."""

    profile_shift: PlantingShifts = Field(
        PlantingShifts(), description="profile shift coefficient by gear (V-zero: a mate takes "
                                      "the opposite)")
