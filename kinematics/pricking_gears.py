"""The pricking mechanism's two non-circular gear stages, from the carrier motion.

Step 6 of the inverse design: the total ratio ``i = 1 - dphi2/dphi1`` split into
``i1 = K i^w`` and ``i2 = i / i1``, each a pair at centre distance a; every gear's pitch
curve along the curve parameter with its checks (closure, convexity, pressure-angle
deviation, the rack's undercut limit) and its contact functions for the tooth cutter.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .chebyshev import PiecewiseChebyshev
from .errors import DesignError
from .pitch_curves import parametric_curvature
from .pricking_motion import TWO_PI, CarrierMotion
from .scalar import brentq

__all__ = ["PitchCurveReport", "GearStage", "equal_perimeter_exponent", "EQUAL_PERIMETER",
           "STRETCH_MERGE_DEG"]

EQUAL_PERIMETER = "equal-perimeter"


@dataclass(frozen=True)
class PitchCurveReport:
    """One non-circular gear of the train, with its checks (lengths mm, angles deg).

    ``table`` holds the pitch curve on the uniform carrier grid: carrier angle,
    body polar angle (rad) and pitch radius, as manufactured.
    """

    name: str
    stage: int
    role: str
    perimeter: float
    radius_min: float
    radius_max: float
    curvature_min: float
    convex: bool
    concave_stretches: list
    pressure_angle_deviation_max_deg: float
    convex_radius_of_curvature_min: float
    undercut_limit: float
    undercut: bool
    table: dict = field(repr=False)
    profile_shift: float = 0.0   # x the undercut limit is for: m (ha* - x) / sin^2(alpha)


@dataclass(frozen=True)
class GearStage:
    """A non-circular pair at centre distance ``a`` with ratio ``i_k`` (drive over driven)."""

    index: int
    exponent: float
    constant: float
    ratio_min: float
    ratio_max: float
    closure_error: float
    drive: PitchCurveReport
    driven: PitchCurveReport

    @property
    def perimeter(self) -> float:
        return self.drive.perimeter


def _positive(i):
    """``i`` unchanged, or ``ratio_not_positive``: a power of a negative ratio would be NaN.

    The extreme search checks the ratio first; this guards a dip it could not see (a loop
    far from the sun centre), wherever the ratio is raised to a power.
    """
    if np.any(np.asarray(i) <= 0.0):
        raise DesignError.single(
            "trajectory.points", "ratio_not_positive",
            f"the planet's ratio to the carrier i = 1 - dphi2/dphi1 falls to "
            f"{float(np.min(i)):.4g}: the needle would have to turn back faster than the carrier; "
            "move the sun centre nearer the loop or spread the points of the pricking segment")
    return i


def _power_ratio(i, di, ddi, constant, exponent):
    """``g = C i^e`` and its first two derivatives along the curve parameter."""
    i = _positive(i)
    g = constant * i**exponent
    dg = constant * exponent * i ** (exponent - 1) * di
    ddg = constant * exponent * ((exponent - 1) * i ** (exponent - 2) * di**2
                                 + i ** (exponent - 1) * ddi)
    return g, dg, ddg


class _StageGeometry:
    """Everything along the curve parameter that the gear stages need."""

    def __init__(self, motion: CarrierMotion, samples_per_piece: int = 48):
        self.motion = motion
        self.a = motion.linkage.a
        # the rates are polynomials on the pieces of their own fits: the ratio is smooth
        # only between the union of those breaks, so it is fitted on that union
        breaks = np.union1d(motion.phi1_rate.breaks, motion.phi2_rate.breaks)
        self.ratio = PiecewiseChebyshev.interpolate(motion.ratio, breaks)
        self.ratio_rate = self.ratio.derivative()
        self.ratio_rate2 = self.ratio_rate.derivative()
        self.turn_rate = motion.phi1_rate            # dphi1/dv, sign = sense
        self.turn_rate2 = motion.phi1_rate.derivative()
        breaks = self.ratio.breaks
        local = (np.arange(samples_per_piece) + 0.5) / samples_per_piece
        self.samples = (breaks[:-1, None] + np.diff(breaks)[:, None] * local).ravel()
        self._memo = {}

    def _terms(self, v):
        """``(i, i', i'', phi1', phi1'')`` at ``v``, memoised: the perimeter and exponent
        searches fit on the ratio's own nodes again and again."""
        v = np.asarray(v, dtype=float)
        key = (v.shape, hash(v.tobytes()))
        terms = self._memo.get(key)
        if terms is None:
            terms = (self.ratio(v), self.ratio_rate(v), self.ratio_rate2(v),
                     self.turn_rate(v), self.turn_rate2(v))
            if len(self._memo) > 16:
                self._memo.clear()
            self._memo[key] = terms
        return terms

    def ratio_terms(self, v):
        return self._terms(v)[:3]

    def stage_ratio(self, v, constant, exponent):
        return _power_ratio(*self.ratio_terms(v), constant, exponent)

    def exponent_integral(self, exponent):
        """``integral i^w dphi1`` over one turn (magnitude)."""
        sense = self.motion.sense
        return PiecewiseChebyshev.interpolate(
            lambda v: _positive(self._terms(v)[0]) ** exponent * sense * self._terms(v)[3],
            self.ratio.breaks).integral()

    def gear_curve(self, v, constant, exponent, role, angle_factor):
        """Pitch radius and body-angle derivatives of one gear along ``v``.

        ``role``: "drive" (radius a g/(1+g)) or "driven" (a/(1+g)); the body
        angle turns at ``angle_factor(v) * dphi1/dv``.
        """
        g, dg, ddg = self.stage_ratio(v, constant, exponent)
        drive = self.a * g / (1 + g)
        d_drive = self.a * dg / (1 + g) ** 2
        dd_drive = self.a * (ddg / (1 + g) ** 2 - 2 * dg**2 / (1 + g) ** 3)
        if role == "drive":
            rho, d_rho, dd_rho = drive, d_drive, dd_drive
        else:
            rho, d_rho, dd_rho = self.a - drive, -d_drive, -dd_drive
        factor, d_factor = angle_factor(v)
        _, _, _, turn_rate, turn_rate2 = self._terms(v)
        psi_rate = factor * turn_rate
        psi_rate2 = d_factor * turn_rate + factor * turn_rate2
        return rho, d_rho, dd_rho, psi_rate, psi_rate2

    def perimeter(self, constant, exponent, role, angle_factor):
        def speed(v):
            rho, d_rho, _, psi_rate, _ = self.gear_curve(v, constant, exponent, role, angle_factor)
            return np.hypot(d_rho, rho * psi_rate)
        return PiecewiseChebyshev.interpolate(speed, self.ratio.breaks).integral()


def _angle_factors(geometry: _StageGeometry, constant, exponent):
    """Body-angle rates (per dphi1) of the four gears, and their v-derivatives."""
    def sun(v):
        return np.ones_like(v), np.zeros_like(v)

    def stage1_ratio(v):
        g, dg, _ = geometry.stage_ratio(v, constant, exponent)
        return -g, -dg

    def planet(v):
        i, di, _ = geometry.ratio_terms(v)
        return i, di

    return sun, stage1_ratio, stage1_ratio, planet


def _stage_perimeters(geometry: _StageGeometry, exponent):
    constant = TWO_PI / geometry.exponent_integral(exponent)
    sun, int1, int2, planet = _angle_factors(geometry, constant, exponent)
    first = geometry.perimeter(constant, exponent, "drive", sun)
    second = geometry.perimeter(1.0 / constant, 1.0 - exponent, "drive", int2)
    return first, second, constant


def equal_perimeter_exponent(geometry: _StageGeometry) -> float:
    """The split exponent w that gives both stages the same pitch perimeter.

    At w = 0 stage 1 is a 1:1 circle pair and stage 2 carries all of i; at
    w = 1 the reverse; the perimeters cross in between.
    """
    def difference(w):
        first, second, _ = _stage_perimeters(geometry, w)
        return first - second

    low, high = 0.0, 1.0
    f_low, f_high = difference(low), difference(high)
    if f_low == 0.0:
        return low
    if np.sign(f_low) == np.sign(f_high):
        return 0.5  # no crossing (a ratio law too close to constant): an even split
    return float(brentq(difference, low, high, xtol=1e-12))


#: Concave runs closer than this in carrier progress are one stretch for the designer (deg).
STRETCH_MERGE_DEG = 1.0


def _stretches(v, mask, geometry, curve, motion):
    """Runs of ``mask`` over the samples, in carrier progress (deg) from the Rmax dead centre.

    Runs less than :data:`STRETCH_MERGE_DEG` apart are merged, so a curvature that
    grazes zero reads as one stretch, not a hundred one-sample ones.
    """
    if not mask.any():
        return []
    progress = np.degrees(motion.progress(v))
    order = np.argsort(progress)
    progress, mask, v = progress[order], mask[order], v[order]
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(int), [0]])))
    merged = []
    for start, stop in zip(edges[::2], edges[1::2]):
        if merged and progress[start] - progress[merged[-1][1] - 1] < STRETCH_MERGE_DEG:
            merged[-1][1] = stop
        else:
            merged.append([start, stop])
    runs = []
    for start, stop in merged:
        first, last = curve.describe(motion.u(v[start])), curve.describe(motion.u(v[stop - 1]))
        runs.append({"carrier_deg": [float(progress[start]), float(progress[stop - 1])],
                     "near": first if first == last else f"{first} to {last}",
                     "samples": int(mask[start:stop].sum())})
    return runs


def _gear_report(name, stage, role, geometry, constant, exponent, factor, grid_v, module,
                 pressure_angle, addendum, shift=0.0):
    v = geometry.samples
    rho, d_rho, dd_rho, psi_rate, psi_rate2 = geometry.gear_curve(v, constant, exponent, role,
                                                                  factor)
    # curve rho(v) u(psi(v)): signed curvature, made positive where convex whatever the sense
    tangential = rho * psi_rate
    curvature = parametric_curvature(rho, d_rho, dd_rho, psi_rate, psi_rate2)
    deviation = np.degrees(np.arctan2(np.abs(d_rho), np.abs(tangential)))
    concave = curvature < 0.0
    limit = module * (addendum - shift) / np.sin(pressure_angle) ** 2   # rack, profile shift x
    convex_radius_min = float(1.0 / curvature[~concave].max()) if (~concave).any() else np.inf
    tight = (~concave) & (curvature > 1.0 / limit)
    table_rho, _, _, _, _ = geometry.gear_curve(grid_v, constant, exponent, role, factor)
    return PitchCurveReport(
        name=name, stage=stage, role=role,
        perimeter=geometry.perimeter(constant, exponent, role, factor),
        radius_min=float(rho.min()), radius_max=float(rho.max()),
        curvature_min=float(curvature.min()), convex=not concave.any(),
        concave_stretches=_stretches(v, concave, geometry, geometry.motion.curve, geometry.motion),
        pressure_angle_deviation_max_deg=float(deviation.max()),
        convex_radius_of_curvature_min=convex_radius_min, undercut_limit=float(limit),
        undercut=bool(tight.any()),
        table={"radius": table_rho}, profile_shift=float(shift))


def _integral_function(geometry, rate):
    """Antiderivative along v of ``rate(v) * dphi1/dv`` (signed like phi1), zero at the Rmax dead centre.

    The gears' body frames are fixed by where this is zero: at the Rmax dead centre,
    whichever type-value point the loop starts from.
    """
    integral = PiecewiseChebyshev.interpolate(lambda v: rate(v) * geometry.turn_rate(v),
                                              geometry.ratio.breaks).antiderivative()
    coefficients = integral.coefficients.copy()
    coefficients[:, 0] -= float(integral(geometry.motion.v_max))
    return PiecewiseChebyshev(integral.breaks, coefficients)


def _ratio_extreme(geometry: _StageGeometry, sign: float = 1.0, per_piece: int = 64):
    """Smallest (``sign`` = 1) or largest (-1) ratio along the loop, with where.

    Dense samples on every interpolation piece, then Brent round the four most
    extreme local extrema: a narrow peak between samples is not missed.
    """
    from .scalar import minimize_scalar

    breaks = geometry.ratio.breaks
    local = (np.arange(per_piece) + 0.5) / per_piece
    v = (breaks[:-1, None] + np.diff(breaks)[:, None] * local).ravel()
    values = sign * geometry.ratio(v)
    extrema = np.flatnonzero((values <= np.roll(values, 1)) & (values <= np.roll(values, -1)))
    best_v, best = float(v[values.argmin()]), float(values.min())
    for k in extrema[np.argsort(values[extrema])][:4]:
        low, high = v[max(k - 1, 0)], v[min(k + 1, len(v) - 1)]
        result = minimize_scalar(lambda s: sign * float(geometry.ratio(np.array([s]))[0]),
                                 bounds=(low, high), method="bounded", options={"xatol": 1e-10})
        if result.fun < best:
            best_v, best = float(result.x), float(result.fun)
    return best_v, sign * best


def _pitch_functions(geometry, constant, exponent, factors, stage1_turn, total_turn):
    """Each gear's contact functions along the curve parameter: ``v -> (rho, drho, psi, dpsi)``.

    ``psi`` is the polar angle of the contact point in the gear's own frame:
    the sun ``phi1``, the first intermediate ``pi - T1``, the second ``-T1``,
    the planet ``pi + T`` (T1, T the integrated stage-1 and total ratios).
    """
    sun, int1, int2, planet = factors
    phi1 = geometry.motion.phi1
    specs = {
        "sun": (constant, exponent, "drive", sun, lambda v: phi1(v)),
        "intermediate 1": (constant, exponent, "driven", int1, lambda v: np.pi - stage1_turn(v)),
        "intermediate 2": (1.0 / constant, 1.0 - exponent, "drive", int2,
                           lambda v: -stage1_turn(v)),
        "planet": (1.0 / constant, 1.0 - exponent, "driven", planet,
                   lambda v: np.pi + total_turn(v)),
    }

    period = geometry.motion.period
    return {name: _ContactFunctions(geometry, period, *spec) for name, spec in specs.items()}


class _ContactFunctions:
    """One gear's contact functions ``v -> (rho, drho, psi, dpsi)`` (called), and the signed
    curvature of its pitch curve at the contact (:meth:`curvature`, from the closed-form second
    derivatives: the tooth strength takes each gear as the spur gear of that curvature)."""

    def __init__(self, geometry, period, constant, exponent, role, factor, angle):
        self._geometry, self._period = geometry, period
        self._spec = (constant, exponent, role, factor)
        self._angle = angle

    def _wrapped(self, v):
        v = np.asarray(v, dtype=float)
        return np.where((v < 0.0) | (v > self._period), np.mod(v, self._period), v)

    def __call__(self, v):
        v = self._wrapped(v)
        rho, d_rho, _, psi_rate, _ = self._geometry.gear_curve(v, *self._spec)
        return rho, d_rho, self._angle(v), psi_rate

    def derivatives(self, v):
        """``(rho, drho, ddrho, dpsi, ddpsi)`` along ``v`` (mm and rad per unit of ``v``), from
        the ratio law's closed-form derivatives: what the dynamics' accelerations need."""
        return self._geometry.gear_curve(self._wrapped(v), *self._spec)

    def curvature(self, v):
        """Signed curvature (1/mm) of the pitch curve at the contact, convex positive."""
        return parametric_curvature(*self._geometry.gear_curve(self._wrapped(v), *self._spec))
