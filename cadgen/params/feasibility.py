"""Design feasibility checks that need the kinematic model.

Run after the parameter file is structurally valid; each returns problems with
the field path a designer should change, never raises for a bad design.
"""

from __future__ import annotations

import dataclasses
import math

from kinematics.errors import ConvergenceError, DesignError, Problem
from kinematics.pitch_curves import pair_problems

__all__ = ["design_problems", "CAM_STAGE"]

#: The build stage the duckbill linkage and cam timing checks belong to: a scene that
#: runs no cam (metrics only) keeps them as warnings (see :func:`cadgen.pipeline.build.build`).
CAM_STAGE = "cam"


def _in_stage(problems, stage: str) -> list:
    return [dataclasses.replace(p, stage=stage) for p in problems]


def design_problems(params) -> list:
    """Every reason a structurally valid design cannot be built, as :class:`Problem` records.

    Checks: the pitch curve closes (and is not pointed); both non-circular
    gears' smallest radii clear the cutting limit for the module; no profile
    shift (``gears.profile_shift``) points a circular gear's teeth; the planting
    depth leaves the tip a way out of the soil; the duckbill linkage can open
    the mouth the pot needs; the cam's phases fit the revolution.

    The last two belong to the cam stage (``Problem.stage == "cam"``): the
    kinematics and the metrics do not need them. The pitch curve's cutting limit
    stays a problem of every build: the spec rejects such a curve, and the module
    metric assumes gears that can be cut.
    """
    if params.mechanism == "pricking":
        return _pricking_problems(params)
    from cadgen.design import build_mechanism

    try:
        mechanism = build_mechanism(params)
        closure = mechanism.closure
        module = mechanism.module(params.pitch_curve.teeth)
    except DesignError as error:
        return list(error.problems)
    except ConvergenceError as error:
        return [Problem("pitch_curve", "closure_not_converged", str(error))]
    problems = pair_problems(closure, module)
    if problems:
        return problems
    problems = _module_problems(params, module)
    problems += shift_problems(params, planting_circular_sizes(params, mechanism))
    if problems:
        return problems
    from cadgen.design import planting_events

    try:
        # the metrics' own events (cached): a depth the tip path never leaves is refused
        # here, with the tip path's height
        events = planting_events(mechanism, params.field.depth,
                                 params.resolution.steps_per_revolution)
    except DesignError as error:   # no events: no cam timing to check
        return list(error.problems) + _cam_problems(params, mechanism, None)
    return _cam_problems(params, mechanism, events)


#: A module below this fraction of ``targets.module_min`` fails the target so plainly that
#: cutting the gears is pointless: a build that cuts them refuses the design, before it cuts.
FAR_BELOW_MODULE_TARGET = 0.5


def _module_problems(params, module: float) -> list:
    """``module_far_below_target`` (stage teeth) when the non-circular module is less than
    half its target: the metrics report the failed target either way, and a build that cuts
    the teeth would spend its time (a thousand teeth of a tenth of a millimetre, say) on
    gears that cannot be used. Names the tooth count that meets the target."""
    import math

    target = params.targets.module_min
    if target is None or not module < FAR_BELOW_MODULE_TARGET * target:
        return []
    teeth = params.pitch_curve.teeth
    perimeter = module * math.pi * teeth
    fits = math.floor(perimeter / (math.pi * target) + 1e-9)
    advice = (f"pitch_curve.teeth = {fits} or fewer gives a module of "
              f"{perimeter / (math.pi * fits):.3f} mm" if fits >= 6 else
              "no tooth count of at least 6 reaches it on this pitch curve")
    return [Problem("pitch_curve.teeth", "module_far_below_target",
                    f"{teeth} teeth on the {perimeter:.1f} mm pitch curve are a module of "
                    f"{module:.4g} mm, less than half the {target:g} mm target "
                    f"(targets.module_min): gears this fine fail it however they are cut, so "
                    f"a build that cuts them refuses the design before cutting; {advice}, or "
                    "lower targets.module_min",
                    stage="teeth")]


def _cam_problems(params, mechanism, events) -> list:
    """The duckbill linkage and (given the plant ``events``) the cam's timing, in the cam
    stage (checks of the contour itself are reported, not refused: a designer wants to see
    the cam that fails)."""
    from cadgen.cam.design import linkage_of, timing_of

    problems = []
    try:
        linkage_of(params)
    except DesignError as error:
        problems += _in_stage(error.problems, CAM_STAGE)
    if events is None:
        return problems
    try:
        timing_of(params, mechanism, events)
    except DesignError as error:
        problems += _in_stage(error.problems, CAM_STAGE)
    return problems


def _pricking_problems(params) -> list:
    """Run the inverse design and the field check; their specific errors are the problems."""
    from cadgen.design import pricking_design, pricking_field

    try:
        design = pricking_design(params)
        pricking_field(params, design)
    except DesignError as error:
        return list(error.problems)
    except ConvergenceError as error:
        return [Problem("trajectory.points", "not_converged", str(error))]
    return []


# ------------------------------------------------------------------------------ profile shift


def planting_circular_sizes(params, mechanism) -> dict:
    """``{gears.profile_shift key: (pitch radius, module)}`` (mm) of the planting trains'
    circular gears, cut with the module the teeth stage takes."""
    from cadgen.design import planting_circular_module

    module = planting_circular_module(params, mechanism)
    R, train = params.train.R, params.train
    return {key: (float(radius), module) for key, radius in (
        ("gear_D", train.r), ("planet_gear_E", train.r), ("sun", R), ("idler_1", R * train.i12),
        ("idler_2", R * train.i13), ("train_1_planet", R))}


def shift_problems(params, sizes: dict) -> list:
    """``profile_shift_pointed`` for every circular gear whose profile shift (given, or the
    opposite of a mate's) leaves its teeth pointed: the shifted spur gear's tip (closed form,
    exact for a circular gear) thinner than ``MIN_TIP_THICKNESS`` modules. ``sizes``: key ->
    (pitch radius, module). Reported at the path of the shift the file gives.

    A non-circular gear's tip is thickest-to-thinnest along its curve; the closed form at its
    tightest convex radius is only an estimate (measured on the paper's intermediate gear it
    under-states the tip by 0.1 to 0.25 mm), so its teeth are judged where they are cut: the
    teeth stage fails a shifted gear whose cut teeth are pointed (``profile_shift_pointed``).
    """
    from kinematics.profile_shift import (MIN_TIP_THICKNESS, largest_unpointed_shift,
                                          tip_thickness)

    gears = params.gears
    table = gears.profile_shift
    alpha = gears.pressure_angle_rad
    problems = []
    for key, shift in table.resolved().items():
        if shift <= 0 or key not in sizes:
            continue   # a negative shift thickens the tip
        radius, module = sizes[key]
        tip = tip_thickness(radius, module, alpha, gears.addendum, shift)
        if tip >= MIN_TIP_THICKNESS * module:
            continue
        source = table.source(key)
        largest = largest_unpointed_shift(radius, module, alpha, gears.addendum)
        given = "" if source == key else f" (the opposite of its mate's, from {source})"
        limit = (f"the largest shift that keeps {MIN_TIP_THICKNESS:g} m is "
                 f"{math.floor(largest * 100) / 100:.2f}" if largest > 0
                 else "it is pointed at any shift above 0")
        state = f"a tip {tip:.3f} mm thick" if tip > 0 else "flanks that cross below the tip"
        teeth = 2 * radius / module
        problems.append(Problem(
            f"gears.profile_shift.{source}", "profile_shift_pointed",
            f"a profile shift of {shift:+g} on the {key.replace('_', ' ')} gear{given} makes its "
            f"teeth pointed: {teeth:.4g} teeth of module {module:g} mm get {state}, below "
            f"{MIN_TIP_THICKNESS:g} m ({MIN_TIP_THICKNESS * module:.3f} mm); {limit}"))
    return problems
