"""What a designer can do about a gear finding, in parameters of the file, with computed values.

The checks (:mod:`cadgen.gears.pairs`, :mod:`cadgen.gears.spur`) measure the cut teeth and say
what is wrong; which parameter would put it right depends on the gear's mates (a profile
shift is V-zero: every gear in mesh with it takes the opposite shift) and on the mechanism
(the planting mechanism's non-circular module follows from ``pitch_curve.teeth``, the
pricking mechanism's is ``gears.module``, the trains' circular gears' ``gears.circular_module``).
:func:`advise_train` completes each finding of a cut train with that advice:

* undercut: the least profile shift that ends it, ``x = ha* - rho_min sin^2(alpha) / m``
  (:func:`kinematics.profile_shift.shift_verdict`), as ``set gears.profile_shift.<gear> = x``
  when the gear and every gear whose shift follows from it stay within the allowed range,
  free of undercut and unpointed there; else why no shift avoids it. Then the tooth count or
  module at which a rack cuts the gear without undercut, when it is a practical one;
* pointed teeth: the module (more teeth) and the shift that give the tip 0.25 modules;
* a concave stretch no pinion cutter fits: the module from which a 10-tooth cutter fits, or,
  below a practical module, that the curve must be reshaped there.

The checks' values are the cut gears'; the advice uses the closed forms of
:mod:`kinematics.profile_shift`, with each gear's smallest convex radius of curvature.
"""

from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass

from kinematics.errors import DesignError, Problem
from kinematics.profile_shift import (MIN_PRACTICAL_MODULE, MIN_SHAPER_TEETH, MIN_TIP_THICKNESS,
                                      SHAPER_CLEARANCE, ModuleSetting, ShiftedGear,
                                      largest_unpointed_module, largest_unpointed_shift,
                                      shift_setting, undercut_advice)

__all__ = ["TrainHints", "advise_train", "planting_hints", "pricking_hints",
           "linked_gears"]


@dataclass(frozen=True)
class TrainHints:
    """A mechanism's settings the advice names.

    Attributes
    ----------
    modules : dict
        Gear name -> :class:`ModuleSetting`.
    reshape : str
        What changes the non-circular pitch curves, for a sentence ("the type-value points there").
    pressure_angle : float
        rad.
    addendum : float
        ha*.
    given : frozenset
        The ``gears.profile_shift`` keys the file gives (advice changes those, not their mates).
    """

    modules: dict
    reshape: str
    pressure_angle: float
    addendum: float
    given: frozenset = frozenset()


def planting_hints(mechanism, teeth: int, cutting) -> TrainHints:
    """The planting mechanism's: the non-circular gears' module from ``pitch_curve.teeth``,
    the circular gears' ``gears.circular_module``."""
    from cadgen.gears.circular import planting_modules

    perimeter = float(mechanism.module(teeth)) * math.pi * teeth
    module_nc, module_c = planting_modules(mechanism, teeth, cutting.circular_module)
    modules = {name: ModuleSetting("pitch_curve.teeth", module_nc, perimeter)
               for name in ("central", "intermediate")}
    modules.update({name: ModuleSetting("gears.circular_module", module_c)
                    for name in ("gear D", "planet gear E", "sun", "idler 1", "idler 2",
                                 "train-1 planet")})
    try:
        from cadgen.gears.circular import holding_set_module

        module_i = holding_set_module(mechanism, cutting.circular_module,
                                      cutting.pressure_angle_rad)
        modules.update({name: ModuleSetting("gears.circular_module", module_i)
                        for name in ("sun I", "idler 1-I", "idler 2-I", "planet I")})
    except DesignError:   # the teeth stage says why set I cannot be cut
        pass
    return TrainHints(modules, "the pitch_curve coefficients", cutting.pressure_angle_rad,
                      cutting.addendum, _given(cutting))


def _given(cutting) -> frozenset:
    table = getattr(cutting, "profile_shift", None)
    return frozenset(table.given()) if table is not None else frozenset()


def pricking_hints(design, cutting) -> TrainHints:
    """The pricking mechanism's: every gear's module is ``gears.module`` (the design scales
    slightly to whole teeth)."""
    modules = {}
    for index, names in enumerate((("sun", "intermediate 1"), ("intermediate 2", "planet"))):
        for name in names:
            modules[name] = ModuleSetting("gears.module", float(design.modules[index]))
    reshape = ("the type-value points there (trajectory.points)"
               + (", or trajectory.degree = 5" if design.curve.degree == 3 else ""))
    return TrainHints(modules, reshape, cutting.pressure_angle_rad, cutting.addendum,
                      _given(cutting))


def linked_gears(name: str, meshes, gears: dict) -> list:
    """The gears whose profile shift follows from ``name``'s, as :class:`ShiftedGear` with
    their sign (-1 for a mate, +1 for a mate's mate, ...), nearest first.

    ``meshes``: pairs of gear names in mesh; ``gears``: name -> :class:`ShiftedGear`."""
    signs, queue = {name: 1}, [name]
    while queue:
        current = queue.pop(0)
        for first, second in meshes:
            for here, there in ((first, second), (second, first)):
                if here == current and there not in signs:
                    signs[there] = -signs[current]
                    queue.append(there)
    return [dataclasses.replace(gears[other], sign=sign) for other, sign in signs.items()
            if other != name and other in gears]


def _pointed_advice(gear: ShiftedGear, linked, hints: TrainHints) -> str:
    """The shift and the module (more teeth) that give the tip ``MIN_TIP_THICKNESS`` modules,
    by the closed form of the spur gear of its tightest convex radius of curvature (exact on
    a circle; on a non-circular curve the cut teeth come out a little thicker)."""
    alpha, addendum = hints.pressure_angle, hints.addendum
    parts = []
    if gear.shift > 0:
        largest = largest_unpointed_shift(gear.radius, gear.module, alpha, addendum,
                                          backlash=gear.backlash)
        if -addendum < largest < gear.shift:
            value = max(math.floor(largest * 100) / 100, 0.0)
            key, setting = shift_setting(gear, linked, value, hints.given)
            bound = "or less" if setting == value else "or more"   # a mate's: the opposite
            parts.append(f"gears.profile_shift.{key} = {setting:.2f} {bound} keeps the tip "
                         f"{MIN_TIP_THICKNESS:g} m thick")
    setting = hints.modules.get(gear.name)
    if setting is not None:
        largest = largest_unpointed_module(gear.radius, alpha, addendum, gear.shift,
                                           gear.module)
        if largest < gear.module:
            parts.append(setting.text(largest, f"gives the tip {MIN_TIP_THICKNESS:g} m"))
    return "".join(f"; {part}" for part in parts)


def _concave_advice(radius: float, name: str, hints: TrainHints) -> str:
    """For ``concave_too_tight``: the module from which a pinion cutter fits a concave
    stretch of ``radius`` mm (or that no practical one does), and the curve's reshaping."""
    setting = hints.modules.get(name)
    if setting is None or not radius > 0:
        return ""
    largest = 2 * SHAPER_CLEARANCE * radius / MIN_SHAPER_TEETH
    advice = setting.text(largest, f"fits a {MIN_SHAPER_TEETH}-tooth pinion cutter")
    if largest >= MIN_PRACTICAL_MODULE:
        return f"; {advice}; or reshape {hints.reshape} to open the concave stretch"
    return f"; {advice}: reshape {hints.reshape} to open the concave stretch"


def _pinion_cut(check, teeth: int) -> list:
    """The teeth a pinion cutter cut: every one (``gears.cutter = "shaper"``), those round the
    concave stretches (``"auto"``, when one fits), or none."""
    if check.cutter == "shaper":
        return list(range(teeth))
    return list(check.concave_teeth) if "shaper" in check.cutter else []


def _gear_table(train) -> dict:
    gears = {}
    for profile, check, stage, index in train.gears:
        systems = stage.generated.systems or (stage.generated.system,) * 2
        gears[profile.name] = ShiftedGear(profile.name, float(check.convex_radius_min),
                                          float(profile.module), float(check.profile_shift),
                                          1, float(systems[index].backlash),
                                          shaped="shaper" in check.cutter)
    return gears


def advise_train(train, hints: TrainHints):
    """``train`` with every finding of its gears, and every failure, completed by the advice
    (see the module docstring); the measured values are untouched."""
    gears = _gear_table(train)
    meshes = [tuple(stage.generated.pair.names) for stage in train.stages]
    advised = {}
    for name, gear in gears.items():
        profile, check = next((p, c) for p, c, _, _ in train.gears if p.name == name)
        problems = []
        for code, message in check.problems:
            if code in ("undercut", "undercut_root_too_thin"):
                shaped = set(_pinion_cut(check, profile.teeth))
                message += undercut_advice(gear, linked_gears(name, meshes, gears),
                                           pressure_angle=hints.pressure_angle,
                                           addendum=hints.addendum,
                                           setting=hints.modules.get(name),
                                           pinion_teeth=[k for k in check.undercut_teeth
                                                         if k in shaped],
                                           given=hints.given)
            elif code in ("pointed_teeth", "profile_shift_pointed"):
                message += _pointed_advice(gear, linked_gears(name, meshes, gears), hints)
            elif code == "concave_too_tight" and check.curvature_min < 0:
                message += _concave_advice(-1.0 / check.curvature_min, name, hints)
            problems.append((code, message))
        if problems != list(check.problems):
            advised[name] = dataclasses.replace(check, problems=problems)
    failures = tuple((stage, _advised_failure(problem, hints)) for stage, problem in train.failures)
    if not advised and failures == train.failures:
        return train
    stages = []
    for stage in train.stages:
        generated = stage.generated
        checks = tuple(advised.get(profile.name, check)
                       for profile, check in zip(generated.profiles, generated.checks))
        stages.append(dataclasses.replace(stage, generated=dataclasses.replace(
            generated, checks=checks)))
    return dataclasses.replace(train, stages=tuple(stages), failures=failures)


#: The gear and the concave radius a ``gear_not_cuttable`` failure names (pairs._check_problems).
_NOT_CUT = re.compile(r"the (.+?) gear cannot be cut: .*concave down to a radius of ([0-9.]+) mm")


def _advised_failure(problem: Problem, hints: TrainHints) -> Problem:
    """A gear that could not be cut for a concave stretch: the module advice."""
    found = _NOT_CUT.match(problem.message)
    if problem.code != "gear_not_cuttable" or found is None:
        return problem
    extra = _concave_advice(float(found.group(2)), found.group(1), hints)
    return dataclasses.replace(problem, message=problem.message + extra) if extra else problem

