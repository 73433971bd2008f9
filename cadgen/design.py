"""From validated parameters to the kinematic models and their evaluation (both mechanisms)."""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from kinematics.evaluation import Targets, evaluate_planting
from kinematics.metrics import plant_events
from kinematics.pitch_curves import LimaconPitchCurve
from kinematics.planting import PlantingMechanism

from cadgen.solids.housings import housing_circles

__all__ = ["build_mechanism", "planting_events", "targets_of", "evaluate", "pricking_design",
           "pricking_field", "planting_circular_module"]


@lru_cache(maxsize=16)
def build_mechanism(params) -> PlantingMechanism:
    """The :class:`~kinematics.planting.PlantingMechanism` a validated parameter model describes.

    Cached (the parameters are frozen): validation's feasibility checks and the
    build share one mechanism, so its closure is solved once.
    """
    curve = params.pitch_curve
    train = params.train
    return PlantingMechanism(
        pitch_curve=LimaconPitchCurve(
            a1=curve.a1, b1=curve.b1, c1=curve.c1, d1=curve.d1, e1=curve.e1, e2=curve.e2,
            f1=curve.f1_rad, f2=curve.f2_rad, g1=curve.g1, g2=curve.g2),
        i12=train.i12, i13=train.i13, R=train.R, r=train.r,
        L1=params.planter.L1, L2=params.planter.L2,
        phi0=math.radians(train.phi0_deg), phic=math.radians(train.phic_deg), n=train.n,
        closure_rtol=params.resolution.closure_rtol)


@lru_cache(maxsize=16)
def planting_events(mechanism: PlantingMechanism, depth: float, steps: int):
    """The tip's plant events (lowest point, soil line, entry and exit) at ``depth`` mm,
    searched with ``steps`` samples a turn (:func:`kinematics.metrics.plant_events`; raises
    its ``NoSoilCrossingError``). Cached: validation's feasibility checks and the build's
    metrics share them."""
    return plant_events(mechanism.tip_path(), depth, steps=steps)


def targets_of(params) -> Targets:
    return Targets(**params.targets.model_dump())


def evaluate(params, mechanism: PlantingMechanism | None = None, steps: int | None = None):
    """Evaluate a validated design without writing anything.

    Planting: every design metric against its target, with events and accuracy
    (:class:`kinematics.evaluation.PlantingEvaluation`). Pricking: the inverse
    design with its linkage, gears, checks and findings
    (:class:`kinematics.pricking.PrickingDesign`; its field motion is
    :func:`pricking_field`).
    """
    if params.mechanism == "pricking":
        return pricking_design(params)
    mechanism = mechanism or build_mechanism(params)
    teeth = params.pitch_curve.teeth
    steps = steps or params.resolution.steps_per_revolution
    return evaluate_planting(
        mechanism, teeth=teeth, depth=params.field.depth, spacings=params.field.plant_spacings,
        carrier_speed_rpm=params.field.carrier_speed_rpm,
        housing_circles=housing_circles(params, mechanism),
        targets=targets_of(params), steps=steps,
        events=planting_events(mechanism, params.field.depth, steps))


@lru_cache(maxsize=16)
def pricking_design(params):
    """The inverse design of a validated pricking file (cached: validation and analysis share it)."""
    from kinematics.pricking import design_pricking

    from kinematics.profile_shift import shift_key

    trajectory, gears = params.trajectory, params.gears
    shifts, given = gears.profile_shift.resolved(), gears.profile_shift.given()
    names = ("sun", "intermediate 1", "intermediate 2", "planet")
    return design_pricking(
        np.asarray(trajectory.points, dtype=float), rocker=params.linkage.rocker,
        degree=trajectory.degree, centre=trajectory.sun_centre,
        a=params.linkage.centre_distance, l=params.linkage.tip_reach,
        exponent=gears.split_exponent, module=gears.module,
        pressure_angle=gears.pressure_angle_rad, addendum=gears.addendum,
        min_ratio=gears.min_ratio, grid=params.resolution.inverse_grid,
        max_scale_change=gears.max_scale_change,
        profile_shift={name: shifts[shift_key(name)] for name in names},
        shifts_given=[name for name in names if shift_key(name) in given])


def pricking_field(params, design=None):
    """Field figures of a pricking design at every inclination of the file."""
    from kinematics.pricking_field import field_motion

    design = design or pricking_design(params)
    field = params.field
    return field_motion(design, carrier_speed_rpm=field.carrier_speed_rpm,
                        forward_speed=field.forward_speed, depth=field.depth,
                        inclinations_deg=field.inclinations_deg)


def planting_circular_module(params, mechanism: PlantingMechanism | None = None) -> float:
    """The module (mm) the teeth stage cuts the planting trains' circular gears with: the
    file's ``gears.circular_module`` or the automatic choice (the validation's profile-shift
    check needs their tooth counts; the housings size them the same way)."""
    from cadgen.solids.housings import planting_modules   # cadgen.gears.circular's, as sized

    mechanism = mechanism or build_mechanism(params)
    return float(planting_modules(mechanism, params.pitch_curve.teeth,
                                  params.gears.circular_module)[1])
