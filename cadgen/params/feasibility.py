"""Design feasibility checks that need the kinematic model.

Run after the parameter file is structurally valid; each returns problems with
the field path a designer should change, never raises for a bad design.
"""

from __future__ import annotations

import dataclasses

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
    gears' smallest radii clear the cutting limit for the module; the planting
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
    from cadgen.design import planting_events

    try:
        # the metrics' own events (cached): a depth the tip path never leaves is refused
        # here, with the tip path's height
        events = planting_events(mechanism, params.field.depth,
                                 params.resolution.steps_per_revolution)
    except DesignError as error:   # no events: no cam timing to check
        return list(error.problems) + _cam_problems(params, mechanism, None)
    return _cam_problems(params, mechanism, events)


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
