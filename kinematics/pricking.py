"""Mechanism kind 2: the inclined hole-pricking mechanism, inverse-designed from its tip loop.

The designer draws the needle tip's loop through type-value points; the linkage and
the carrier motion follow from the curve (:mod:`kinematics.pricking_motion`), the two
gear stages from the motion (:mod:`kinematics.pricking_gears`), and this module puts
them together: the scale that gives whole teeth, the forward check from the tabulated
pitch curves, and the findings a designer acts on.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .errors import DesignError, Problem
from .planar import unit as _unit
from .pricking_gears import (EQUAL_PERIMETER, STRETCH_MERGE_DEG, GearStage, PitchCurveReport,
                             _StageGeometry, _angle_factors, _gear_report, _integral_function,
                             _pitch_functions, _ratio_extreme, equal_perimeter_exponent)
from .pricking_motion import (TWO_PI, CarrierMotion, Linkage, carrier_motion, link_lengths,
                              travel_direction_problems)
from .profile_shift import (ModuleSetting, ShiftedGear, concave_advice, shift_key,
                            undercut_advice)
from .spline import ClosedCurve

__all__ = ["Linkage", "CarrierMotion", "GearStage", "PitchCurveReport", "PrickingDesign",
           "link_lengths", "carrier_motion", "design_pricking", "equal_perimeter_exponent",
           "travel_direction_problems", "EQUAL_PERIMETER", "FORWARD_TOLERANCE",
           "STRETCH_MERGE_DEG"]

#: The tip loop rebuilt from the tabulated pitch curves must stay this close to the curve (mm).
FORWARD_TOLERANCE = 1e-2


@dataclass(frozen=True)
class PrickingDesign:
    """The outcome of the inverse design (lengths mm, angles in the units named)."""

    curve: ClosedCurve
    linkage: Linkage
    motion: CarrierMotion
    modes: dict
    exponent: float
    stages: tuple
    scale: float
    teeth: tuple
    modules: tuple
    grid: dict
    forward_deviation: float
    grid_closure_error: float
    ratio_min: float
    ratio_max: float
    findings: list
    pitch_functions: dict = field(default_factory=dict, repr=False)

    @property
    def gears(self):
        return [gear for stage in self.stages for gear in (stage.drive, stage.driven)]

    @property
    def carrier_sense(self) -> str:
        return "counter-clockwise" if self.motion.sense > 0 else "clockwise"

    def cycle_functions(self):
        """Each gear's contact functions over the carrier cycle ``tau`` from the Rmax dead centre.

        ``tau = v - v_max`` (mod the period): the train, its sheet and the assembly start
        at the outer dead centre whichever type-value point the loop starts from. Each
        contact angle stays continuous across the loop's start (it gains its whole turn
        there). Returns ``({name: tau -> (rho, drho, psi, dpsi)}, breaks)``.
        """
        motion = self.motion
        shift, period = motion.v_max, motion.period

        def from_dead_centre(function):
            ends = np.array([0.0, period])
            turn = float(np.diff(function(ends)[2])[0])

            def shifted(tau):
                v = np.mod(np.asarray(tau, dtype=float), period) + shift
                wrapped = v >= period
                rho, d_rho, psi, d_psi = function(np.where(wrapped, v - period, v))
                return rho, d_rho, psi + np.where(wrapped, turn, 0.0), d_psi
            return shifted

        breaks = np.unique(np.concatenate([[0.0, period], motion.cycle(motion.breaks)]))
        functions = {name: from_dead_centre(f) for name, f in self.pitch_functions.items()}
        return functions, tuple(breaks[np.concatenate([[True], np.diff(breaks) > 0.0])])

    def cycle_curvatures(self) -> dict:
        """Each gear's signed pitch-curve curvature (1/mm, convex positive) at the contact over
        the carrier cycle ``tau`` of :meth:`cycle_functions`: ``{name: tau -> curvature}``."""
        shift, period = self.motion.v_max, self.motion.period

        def from_dead_centre(function):
            def shifted(tau):
                v = np.mod(np.asarray(tau, dtype=float), period) + shift
                return function(np.where(v >= period, v - period, v))
            return shifted

        return {name: from_dead_centre(f.curvature) for name, f in self.pitch_functions.items()}


def _forward_check(motion, grid_phi1, grid_v, radii):
    """Rebuild the tip loop from the tabulated pitch curves alone, as a shop would.

    Stage ratios are drive over driven radius on the uniform carrier grid; their
    product is interpolated by a periodic cubic spline and integrated, giving
    the needle angle and the tip. Returns the largest distance to the curve and
    the closure error of the integrated ratio (rad).
    """
    from scipy.interpolate import make_interp_spline

    sense = motion.sense
    count = len(grid_phi1)
    step = TWO_PI / count
    ratio = (radii["sun"] / radii["intermediate 1"]) * (radii["intermediate 2"] / radii["planet"])
    t = (np.arange(count) + 0.5) * step  # carrier progress from the Rmax dead centre
    spline = make_interp_spline(np.append(t, t[0] + TWO_PI), np.append(ratio, ratio[0]), k=3,
                                bc_type="periodic")
    # scipy does not extrapolate the antiderivative of a periodic spline: stay on [t0, t0 + 2 pi]
    integral = spline.antiderivative()
    turned = integral(t) - integral(t[0])
    closure = float(integral(t[0] + TWO_PI) - integral(t[0]) - TWO_PI)
    phi2 = float(motion.phi2(grid_v[0])) + sense * (t - t[0]) - sense * turned
    centre = np.asarray(motion.linkage.centre)
    tip = centre + 2 * motion.linkage.a * _unit(grid_phi1) + motion.linkage.l * _unit(phi2)
    target = motion.curve(motion.u(grid_v))
    return float(np.linalg.norm(tip - target, axis=1).max()), closure


def _stage_one_perimeter(points, *, degree, centre, rocker, a, l, exponent, min_ratio, sense,
                         **_):
    """Stage 1's pitch perimeter and the split exponent, without the gears' reports.

    All the first pass of :func:`design_pricking` needs to choose the scale: scaling
    about O keeps every angle, hence the ratio law and its split.
    """
    _, _, _, _, geometry, w, constant, _, _ = _motion_and_split(
        points, degree=degree, centre=centre, rocker=rocker, a=a, l=l, exponent=exponent,
        min_ratio=min_ratio, sense=sense)
    sun = _angle_factors(geometry, constant, w)[0]
    return geometry.perimeter(constant, w, "drive", sun), w


def _motion_and_split(points, *, degree, centre, rocker, a, l, exponent, min_ratio, sense):
    """Curve, linkage, carrier motion, the ratio's extremes and its split into two stages."""
    curve = ClosedCurve(points, degree)
    problems = travel_direction_problems(curve)
    if problems:
        raise DesignError(problems)
    linkage = link_lengths(curve, centre, rocker, a=a, l=l)
    motion, modes = carrier_motion(curve, linkage, sense=sense)
    geometry = _StageGeometry(motion)
    lowest_v, lowest_ratio = _ratio_extreme(geometry)
    if not lowest_ratio > min_ratio:
        raise DesignError.single(
            "trajectory.points", "ratio_not_positive",
            f"the planet's ratio to the carrier i = 1 - dphi2/dphi1 falls to {lowest_ratio:.4f} "
            f"(must stay above {min_ratio:g}) near {curve.describe(lowest_v)}: "
            "the needle would have to turn back faster than the carrier; spread the points of "
            "the pricking segment")
    highest_ratio = _ratio_extreme(geometry, -1.0)[1]
    w = equal_perimeter_exponent(geometry) if exponent == EQUAL_PERIMETER else float(exponent)
    constant = TWO_PI / geometry.exponent_integral(w)
    return curve, linkage, motion, modes, geometry, w, constant, lowest_ratio, highest_ratio


def _design_once(points, *, degree, centre, rocker, a, l, exponent, module, pressure_angle,
                 addendum, min_ratio, grid, sense, shifts=None):
    (curve, linkage, motion, modes, geometry, w, constant, lowest_ratio,
     highest_ratio) = _motion_and_split(points, degree=degree, centre=centre, rocker=rocker,
                                        a=a, l=l, exponent=exponent, min_ratio=min_ratio,
                                        sense=sense)
    sun, int1, int2, planet = _angle_factors(geometry, constant, w)

    sense = motion.sense
    phi1_start = motion.phi1_start
    grid_phi1 = phi1_start + sense * (np.arange(grid) + 0.5) * (TWO_PI / grid)
    grid_v = motion.invert(grid_phi1)
    common = dict(module=module, pressure_angle=pressure_angle, addendum=addendum)
    shifts = shifts or {}
    gears = {
        "sun": _gear_report("sun", 1, "drive", geometry, constant, w, sun, grid_v, **common,
                            shift=shifts.get("sun", 0.0)),
        "intermediate 1": _gear_report("intermediate 1", 1, "driven", geometry, constant, w,
                                       int1, grid_v, **common,
                                       shift=shifts.get("intermediate 1", 0.0)),
        "intermediate 2": _gear_report("intermediate 2", 2, "drive", geometry, 1.0 / constant,
                                       1.0 - w, int2, grid_v, **common,
                                       shift=shifts.get("intermediate 2", 0.0)),
        "planet": _gear_report("planet", 2, "driven", geometry, 1.0 / constant, 1.0 - w, planet,
                               grid_v, **common, shift=shifts.get("planet", 0.0)),
    }
    # body polar angles on the grid: sun phi1, intermediates pi - T1 and -T1, planet pi + T
    stage1_turn = _integral_function(geometry, lambda v: geometry.stage_ratio(v, constant, w)[0])
    total_turn = _integral_function(geometry, geometry.ratio)
    t1, tt = stage1_turn(grid_v), total_turn(grid_v)
    angles = {"sun": grid_phi1, "intermediate 1": np.pi - t1, "intermediate 2": -t1,
              "planet": np.pi + tt}
    for name, gear in gears.items():
        gear.table["body_angle"] = angles[name]
        gear.table["carrier_angle"] = grid_phi1
    pitch_functions = _pitch_functions(geometry, constant, w, (sun, int1, int2, planet),
                                       stage1_turn, total_turn)
    stage_closure = [abs((stage1_turn(curve.period) - stage1_turn(0.0)) * sense - TWO_PI),
                     abs((total_turn(curve.period) - total_turn(0.0)) * sense - TWO_PI)]
    stages = []
    for index, (drive, driven, c, e) in enumerate(
            ((gears["sun"], gears["intermediate 1"], constant, w),
             (gears["intermediate 2"], gears["planet"], 1.0 / constant, 1.0 - w)), start=1):
        g = geometry.stage_ratio(geometry.samples, c, e)[0]
        stages.append(GearStage(index, e, c, float(g.min()), float(g.max()),
                                float(stage_closure[index - 1]), drive, driven))
    radii = {name: gear.table["radius"] for name, gear in gears.items()}
    deviation, grid_closure = _forward_check(motion, grid_phi1, grid_v, radii)
    grid_tables = {"carrier_angle": grid_phi1, "curve_parameter": grid_v,
                   "tip": motion.curve(motion.u(grid_v)), "needle_angle": motion.phi2(grid_v),
                   "ratio": geometry.ratio(grid_v)}
    return (curve, linkage, motion, modes, w, tuple(stages), grid_tables, deviation,
            grid_closure, float(lowest_ratio), float(highest_ratio), pitch_functions)


def _stretch_text(stretch) -> str:
    low, high = stretch["carrier_deg"]
    span = (f"{low:.1f} deg" if f"{low:.1f}" == f"{high:.1f}" else f"{low:.1f} to {high:.1f} deg")
    return f"carrier progress {span} (tip near {stretch['near']})"


def _findings(stages, curve, *, pressure_angle, addendum, module, given=()):
    """The pitch curves' findings, each with what cuts it or avoids it in the file's terms:
    the pinion cutter the teeth stage takes on a concave stretch (or the module from which one
    fits), the profile shift (V-zero with the gear's mate) or module that ends an undercut."""
    setting = ModuleSetting("gears.module", module)
    smoother = ("use the degree-5 curve (trajectory.degree = 5) or move the type-value points "
                "there (trajectory.points) onto a smoother loop" if curve.degree == 3 else
                "move the type-value points there (trajectory.points) onto a smoother loop")
    notes = []
    for stage in stages:
        for gear, mate in ((stage.drive, stage.driven), (stage.driven, stage.drive)):
            path = f"gears.{gear.name.replace(' ', '_')}"
            if not gear.convex:
                where = "; ".join(_stretch_text(s) for s in gear.concave_stretches)
                cutter, fits = concave_advice(1 / -gear.curvature_min, module, setting=setting)
                notes.append(Problem(
                    path, "concave_pitch_curve",
                    f"the {gear.name} gear's pitch curve is concave (curvature down to "
                    f"{gear.curvature_min:.4f} 1/mm) at {where}: a rack cannot cut it there"
                    + cutter + {"cutter": f"; to cut it with the rack instead, {smoother}",
                                "module": f"; or {smoother}"}.get(fits, f"; so {smoother}")))
            if gear.undercut:
                # a prediction for rack cutting, so a warning: the cut teeth's measured root
                # thickness (the gear checks of stage teeth) decides whether it fails
                shifted = ShiftedGear(gear.name, gear.convex_radius_of_curvature_min, module,
                                      gear.profile_shift, shaped=not gear.convex)
                linked = [ShiftedGear(mate.name, mate.convex_radius_of_curvature_min, module,
                                      mate.profile_shift, sign=-1, shaped=not mate.convex)]
                notes.append(Problem(
                    path, "undercut",
                    f"the {gear.name} gear's pitch curve bends to a radius of curvature of "
                    f"{gear.convex_radius_of_curvature_min:.2f} mm, below the rack undercut limit "
                    f"{gear.undercut_limit:.2f} mm (m (ha* - x) / sin^2 alpha, x = "
                    f"{gear.profile_shift:g}): rack-cut teeth are predicted to be undercut there "
                    "(a warning; the cut teeth's root thickness, checked in stage teeth, decides)"
                    + undercut_advice(shifted, linked, pressure_angle=pressure_angle,
                                      addendum=addendum, setting=setting,
                                      given={shift_key(name) for name in given}),
                    stage="teeth"))
    return notes


def _module_problem(perimeter, module, teeth, scale, min_teeth, max_scale_change) -> Problem:
    """``module_does_not_fit``, with the modules that give whole teeth at the drawn size."""
    exact = perimeter / (np.pi * module)
    counts = [n for n in range(max(min_teeth, int(exact) - 1), max(min_teeth, int(exact) - 1) + 4)]
    fits = ", ".join(f"{perimeter / (np.pi * n):.4g} mm ({n} teeth)" for n in counts)
    return Problem(
        "gears.module", "module_does_not_fit",
        f"at module {module:g} mm stage 1's pitch perimeter ({perimeter:.2f} mm at the drawn size) "
        f"holds {exact:.2f} teeth; {teeth} whole teeth would scale the whole design, drawn loop "
        f"included, by {scale:.4g}, beyond the {max_scale_change:.0%} allowed "
        f"(gears.max_scale_change): modules that fit the drawn size: {fits}")


def design_pricking(points, *, rocker: float, degree: int = 3, centre=(0.0, 0.0),
                    a: float | None = None, l: float | None = None,
                    exponent=EQUAL_PERIMETER, module: float = 2.0,
                    pressure_angle: float = np.radians(20.0), addendum: float = 1.0,
                    min_ratio: float = 0.05, grid: int = 720, min_teeth: int = 8,
                    sense: int | None = None,
                    max_scale_change: float = 0.05, profile_shift=None,
                    shifts_given=None) -> PrickingDesign:
    """Inverse design of the pricking mechanism from the type-value points of its tip loop.

    The design is scaled about the sun centre so that stage 1 holds a whole
    number of teeth at ``module``; stage 2 then takes the nearest whole number
    and its own module (equal to ``module`` with the equal-perimeter split).
    The scale may differ from 1 by at most ``max_scale_change`` (the drawn loop
    is the designer's; rounding to whole teeth is meant to move it slightly):
    beyond that, ``module_does_not_fit`` names the modules that would.
    ``profile_shift`` maps gear names (``"sun"``, ``"intermediate 1"``, ...) to their profile
    shift coefficients (default 0): each gear's rack undercut limit is
    ``m (ha* - x) / sin^2(alpha)`` (:mod:`kinematics.profile_shift`); ``shifts_given`` names
    the gears whose shift the file states (the others' follow from a mate's), so that the
    advice changes those (default: every gear with a non-zero shift).

    Raises
    ------
    DesignError
        With a specific code: ``coincident_points``, ``self_intersecting_curve``,
        ``origin_inside_loop``, ``rocker_too_long``, ``unreachable_points``,
        ``no_assembly_mode``, ``ratio_not_positive``, ``loop_runs_forward``,
        ``module_does_not_fit``, ``fit_not_converged``.
    """
    points = np.asarray(points, dtype=float)
    centre = np.asarray(centre, dtype=float)
    options = dict(degree=degree, centre=centre, rocker=rocker, a=a, l=l, exponent=exponent,
                   module=module, pressure_angle=pressure_angle, addendum=addendum,
                   min_ratio=min_ratio, grid=grid, sense=sense)
    perimeter, split = _checked_design(points, options, _stage_one_perimeter)
    # scaling about O leaves every angle, hence the ratio law and its split, unchanged
    options["exponent"] = split
    teeth_1 = max(min_teeth, int(round(perimeter / (np.pi * module))))
    scale = teeth_1 * np.pi * module / perimeter
    if abs(scale - 1.0) > max_scale_change:
        raise DesignError([_module_problem(perimeter, module, teeth_1, scale, min_teeth,
                                           max_scale_change)])
    if a is not None:
        options["a"] = a * scale
    if l is not None:
        options["l"] = l * scale
    options["rocker"] = rocker * scale
    options["shifts"] = dict(profile_shift or {})
    result = _checked_design(centre + scale * (points - centre), options)
    (curve, linkage, motion, modes, w, stages, grid_tables, deviation, closure, i_min, i_max,
     functions) = result
    teeth_2 = max(min_teeth, int(round(stages[1].perimeter / (np.pi * module))))
    modules = (stages[0].perimeter / (np.pi * teeth_1), stages[1].perimeter / (np.pi * teeth_2))
    given = (shifts_given if shifts_given is not None
             else [name for name, x in (profile_shift or {}).items() if x])
    findings = (_findings(stages, curve, pressure_angle=pressure_angle, addendum=addendum,
                          module=module, given=given) + _forward_findings(deviation, grid))
    return PrickingDesign(curve, linkage, motion, modes, w, stages, float(scale),
                          (teeth_1, teeth_2), modules, grid_tables, deviation, abs(closure),
                          i_min, i_max, findings, functions)


def _checked_design(points, options, stage=None):
    """:func:`_design_once` (or another pass), an unconverged fit turned into a design error."""
    from .chebyshev import UnconvergedFit

    try:
        return (stage or _design_once)(points, **options)
    except UnconvergedFit as error:
        curve = ClosedCurve(points, options["degree"])
        where = sorted({curve.describe(0.5 * (low + high)) for low, high in error.intervals})
        raise DesignError.single(
            "trajectory.points", "fit_not_converged",
            f"the carrier and needle motion could not be resolved to its tolerance near "
            f"{', '.join(where[:4])} ({error}): the loop has a kink or a near-cusp there that "
            "the linkage cannot follow smoothly; move the type-value points there onto a "
            "smoother loop") from None


def _forward_findings(deviation: float, grid: int) -> list:
    """The tabulated pitch curves must reproduce the loop; if not, the grid that would."""
    if deviation <= FORWARD_TOLERANCE:
        return []
    # the periodic cubic spline through the tables errs as (step)^4: aim at half the tolerance
    needed = grid * (deviation / (0.5 * FORWARD_TOLERANCE)) ** 0.25
    suggestion = int(np.ceil(needed / 360.0) * 360)
    return [Problem(
        "resolution.inverse_grid", "forward_check_deviation",
        f"the tip loop rebuilt from the pitch curves tabulated at {grid} carrier steps strays "
        f"{deviation:.3g} mm from the designed loop (tolerance {FORWARD_TOLERANCE:g} mm): the "
        f"ratio changes too fast for that grid; set resolution.inverse_grid to about "
        f"{suggestion}")]
