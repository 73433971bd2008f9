"""Mechanism kind 2: the inclined hole-pricking mechanism, inverse-designed from its tip loop.

Planetary train of non-circular gears on one carrier, all centre distances a:
sun (fixed, O) -> first intermediate (A) = second intermediate (same shaft) ->
planet (B). ``A = O + a u(phi1)``, ``B = O + 2a u(phi1)``, ``D = B + l u(phi2)``.

Inverse design (spec, step by step): closed curve through the type-value
points; ``l = (Rmax + Rmin)/2`` and ``a = (Rmax - Rmin)/4`` from the refined
radial extremes on the curve; ``phi1 = alpha + s arccos(c)``, the branch sign
``s`` switching exactly at the two dead centres; the assembly mode accepted
only if ``phi1`` is strictly monotone over the loop (one full carrier turn).

Along the curve parameter the carrier and needle angles are analytic on every
spline span split at the dead centres, so they are held as piecewise Chebyshev
interpolants (:mod:`kinematics.chebyshev`): the ratio ``i = 1 - dphi2/dphi1``
and every integral (closure, perimeters) come without finite differences.

``phi2`` is computed as ``alpha + sigma + delta`` with ``sigma = s arccos(c)``
and ``delta`` the angle at B between OB produced and BD: at the Rmin dead centre
``sigma`` and ``delta`` jump by opposite 2 pi, so ``phi2`` is continuous without
unwrapping.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from .scalar import brentq

from .chebyshev import PiecewiseChebyshev
from .errors import ConvergenceError, DesignError, Problem
from .spline import ClosedCurve
from .planar import unit as _unit, cross as _cross

__all__ = ["Linkage", "CarrierMotion", "GearStage", "PitchCurveReport", "PrickingDesign",
           "link_lengths", "carrier_motion", "design_pricking", "EQUAL_PERIMETER"]

TWO_PI = 2.0 * np.pi
EQUAL_PERIMETER = "equal-perimeter"
#: |c| may exceed 1 by this much from round-off on the curve before the point is unreachable.
REACH_TOL = 1e-9
#: The tip loop rebuilt from the tabulated pitch curves must stay this close to the curve (mm).
FORWARD_TOLERANCE = 1e-2


def travel_direction_problems(curve: ClosedCurve, path: str = "trajectory.points") -> list:
    """The tip must move backwards (-x) relative to the machine at the bottom of its loop.

    The points' order is the tip's order in time, and x is forward travel: at the
    bottom the tip must run against the travel, so that over the ground it is
    nearly still while it pricks. The same points in the reverse order give the
    same gears with the carrier turning the other way and the needle dragged
    forward through the soil (a mouth of hundreds of mm): rejected, not renumbered.
    """
    u = curve.polyline_parameters()
    lowest = float(u[np.argmin(curve(u)[:, 1])])
    velocity = curve(lowest, 1)
    if velocity[0] < 0.0:
        return []
    return [Problem(path, "loop_runs_forward",
                    f"in the points' order the tip moves forward (+x, the direction of travel) "
                    f"at the bottom of the loop (near {curve.describe(lowest)}), so it would be "
                    "dragged through the soil instead of standing nearly still over it: list the "
                    "points in the reverse order (the points' order is the tip's order in time, "
                    "and x is forward travel)")]


@dataclass(frozen=True)
class Linkage:
    """Lengths (mm): centre distance ``a``, tip reach ``l = |BD|``, rocker ``l1``, needle ``l2``."""

    centre: tuple
    a: float
    l: float
    rocker: float
    needle: float
    u_max: float
    u_min: float
    radius_max: float
    radius_min: float
    derived: bool = True


def link_lengths(curve: ClosedCurve, centre, rocker: float, *, a: float | None = None,
                 l: float | None = None) -> Linkage:
    """``a`` and ``l`` from the curve's refined radial extremes (or the given overrides).

    The tip must touch both circles ``R = l +- 2a`` round O, hence
    ``l = (Rmax + Rmin)/2`` and ``a = (Rmax - Rmin)/4``.
    """
    centre = np.asarray(centre, dtype=float)
    problems = curve.centre_problems(centre)
    if problems:
        raise DesignError(problems)
    (u_min, r_min), (u_max, r_max) = curve.radius_extrema(centre)
    derived = a is None and l is None
    a = (r_max - r_min) / 4.0 if a is None else float(a)
    l = (r_max + r_min) / 2.0 if l is None else float(l)
    if not rocker < l:
        raise DesignError.single(
            "linkage.rocker", "rocker_too_long",
            f"the rocker l1 = {rocker:g} mm must be shorter than the tip reach l = {l:.3f} mm "
            "(the needle l2 = sqrt(l^2 - l1^2) would not exist)")
    return Linkage(tuple(centre), a, l, float(rocker), float(np.sqrt(l * l - rocker * rocker)),
                   u_max, u_min, r_max, r_min, derived)


@dataclass(frozen=True)
class CarrierMotion:
    """Carrier and needle angles along the loop for one assembly mode.

    ``v`` is the curve's own parameter (``v`` in ``[0, period)``, 0 at Q1); the
    Rmax and Rmin dead centres are at ``v_max`` and ``v_min``. They are not
    break points: the angles are analytic across them, and only the knots
    (the type-value points) break the fits. ``sense`` is +1 when the carrier
    turns counter-clockwise as the tip goes round the loop in the points' order.
    Carrier *progress* is measured from the Rmax dead centre (:meth:`progress`).
    """

    curve: ClosedCurve
    linkage: Linkage
    sense: int
    v_min: float
    v_max: float
    breaks: np.ndarray
    phi1: PiecewiseChebyshev = field(repr=False)
    phi2: PiecewiseChebyshev = field(repr=False)
    phi1_rate: PiecewiseChebyshev = field(repr=False)
    phi2_rate: PiecewiseChebyshev = field(repr=False)

    @property
    def period(self) -> float:
        return self.curve.period

    def u(self, v):
        """Curve parameter at motion parameter ``v``."""
        return np.mod(np.asarray(v, dtype=float), self.period)

    def v(self, u):
        """Motion parameter at curve parameter ``u`` (the inverse of :meth:`u`)."""
        return np.mod(np.asarray(u, dtype=float), self.period)

    def cycle(self, v):
        """Cycle parameter ``tau`` from the Rmax dead centre, in ``[0, period)``, at ``v``."""
        return np.mod(np.asarray(v, dtype=float) - self.v_max, self.period)

    @property
    def phi1_start(self) -> float:
        """Carrier angle at the Rmax dead centre, where carrier progress starts."""
        return float(self.phi1(self.v_max))

    def progress(self, v):
        """Carrier turn since the Rmax dead centre (rad, in ``[0, 2 pi)``), at ``v`` in ``[0, period]``."""
        return np.mod(self.sense * (self.phi1(v) - self.phi1_start), TWO_PI)

    def ratio(self, v):
        """Total relative ratio of the planet to the carrier, ``i = 1 - dphi2/dphi1``."""
        return 1.0 - self.phi2_rate(v) / self.phi1_rate(v)

    def tip(self, v):
        """Tip position from the linkage (forward kinematics of the angles), (n, 2)."""
        centre = np.asarray(self.linkage.centre)
        return (centre + 2 * self.linkage.a * _unit(self.phi1(v))
                + self.linkage.l * _unit(self.phi2(v)))

    def invert(self, phi1_values, iterations: int = 60):
        """Curve parameters ``v`` where the carrier angle takes ``phi1_values`` (any turn)."""
        start = float(self.phi1(0.0))
        # the same carrier position within the turn that v in [0, period] covers
        target = start + self.sense * np.mod(
            self.sense * (np.asarray(phi1_values, dtype=float) - start), TWO_PI)
        low = np.zeros_like(target)
        high = np.full_like(target, self.period)
        for _ in range(iterations):  # vectorized bisection on the monotone phi1
            middle = 0.5 * (low + high)
            above = self.sense * (self.phi1(middle) - target) > 0
            high = np.where(above, middle, high)
            low = np.where(above, low, middle)
        v = 0.5 * (low + high)
        for _ in range(2):  # polish with Newton's method
            v = np.clip(v - (self.phi1(v) - target) / self.phi1_rate(v), 0.0, self.period)
        return v


class _RadialGaps:
    """``l + 2a - R`` and ``R - (l - 2a)`` along the curve, without cancellation at the dead centres.

    Near a dead centre ``R`` is within round-off of ``l +- 2a`` and the plain
    difference loses every digit that ``arccos`` needs (it depends on the square
    root of the gap). Instead ``d = p(u) - p(u*)`` is summed exactly from the
    spline's polynomial pieces, chained knot to knot from the dead centre ``u*``
    (a type-value point a hundredth of a millimetre from it puts a knot there),
    and ``R^2 - R*^2 = d.(2 p* + d)`` keeps full relative precision. When a and
    l are derived from the curve, ``R* = l +- 2a`` exactly: the one rounding of
    ``l - 2a`` would otherwise make the gap negative over a micrometre, clamp the
    arccos and put a kink in the carrier angle.
    """

    def __init__(self, curve: ClosedCurve, linkage: Linkage):
        self.curve = curve
        self.centre = np.asarray(linkage.centre, dtype=float)
        self.a, self.l = linkage.a, linkage.l
        knots = curve.knots
        middles = 0.5 * (knots[:-1] + knots[1:])
        factorials = np.cumprod(np.concatenate([[1.0], np.arange(1.0, curve.degree + 1)]))
        # power coefficients of every span's polynomial about its middle: (spans, degree + 1, 2)
        self._middle_coefficients = np.stack(
            [curve(middles, k) / factorials[k] for k in range(curve.degree + 1)], axis=1)
        self._middles = middles
        outer, inner = self.l + 2 * self.a, self.l - 2 * self.a
        self.expansions = []
        for u_star, circle in ((linkage.u_max, outer), (linkage.u_min, inner)):
            rel_star = curve(u_star) - self.centre
            r_star = float(np.linalg.norm(rel_star))
            offset = 0.0 if linkage.derived else (circle - r_star if circle == outer
                                                   else r_star - circle)
            self.expansions.append((rel_star, r_star, offset, *self._anchored(u_star)))

    def _span(self, u):
        knots = self.curve.knots
        return np.clip(np.searchsorted(knots, np.mod(u, self.curve.period), side="right") - 1,
                       0, len(knots) - 2)

    def _shifted(self, spans, anchors) -> np.ndarray:
        """Power coefficients of each span's polynomial about its anchor: (k, degree + 1, 2)."""
        from math import comb

        degree = self.curve.degree
        h = np.asarray(anchors, dtype=float) - self._middles[spans]
        q, r = np.meshgrid(np.arange(degree + 1), np.arange(degree + 1))
        binomial = np.array([[comb(int(a), int(b)) if a >= b else 0 for a in range(degree + 1)]
                             for b in range(degree + 1)], dtype=float)   # [r, q] = C(q, r)
        powers = np.where(q >= r, h[:, None, None] ** np.maximum(q - r, 0), 0.0)
        return np.einsum("krq,kqd->krd", binomial * powers, self._middle_coefficients[spans])

    @staticmethod
    def _increment(coefficients, step):
        """``P(anchor + step) - P(anchor)`` from power coefficients, constant left out."""
        step = np.asarray(step, dtype=float)[..., None]
        total = np.zeros(step.shape[:-1] + (2,)) + coefficients[..., -1, :]
        for q in range(coefficients.shape[-2] - 2, 0, -1):
            total = total * step + coefficients[..., q, :]
        return total * step

    def _anchored(self, u_star: float):
        """Per span: an anchor parameter, ``p(anchor) - p(u*)`` and coefficients about the anchor.

        The anchor is ``u*`` in its own span, else the span's end nearer ``u*``
        along the chain; half the loop is chained forwards and the rest backwards,
        so every chain is short, and each chain is a cumulative sum of whole-span
        increments (each exact to its own rounding).
        """
        knots = self.curve.knots
        count = len(knots) - 1
        widths = np.diff(knots)
        own = int(self._span(np.array([u_star]))[0])
        forward = (own + 1 + np.arange(count // 2)) % count
        backward = (own - 1 - np.arange(count - count // 2 - 1)) % count
        anchors = np.empty(count)
        anchors[own], anchors[forward], anchors[backward] = u_star, knots[forward], knots[backward + 1]
        coefficients = self._shifted(np.arange(count), anchors)
        offsets = np.zeros((count, 2))
        if forward.size:
            steps = np.concatenate([
                self._increment(coefficients[own], knots[own + 1] - u_star)[None],
                self._increment(coefficients[forward[:-1]], widths[forward[:-1]])])
            offsets[forward] = np.cumsum(steps, axis=0)
        if backward.size:
            steps = np.concatenate([
                self._increment(coefficients[own], knots[own] - u_star)[None],
                self._increment(coefficients[backward[:-1]], -widths[backward[:-1]])])
            offsets[backward] = np.cumsum(steps, axis=0)
        return anchors, offsets, coefficients

    def __call__(self, u):
        """``(R, l + 2a - R, R - (l - 2a))`` at curve parameters ``u``."""
        u = np.mod(np.asarray(u, dtype=float), self.curve.period)
        radius = np.linalg.norm(self.curve(u) - self.centre, axis=-1)
        spans = self._span(u)
        gaps = []
        for index, (rel_star, r_star, offset, anchors, offsets, coefficients) in enumerate(
                self.expansions):
            delta = offsets[spans] + self._increment(coefficients[spans], u - anchors[spans])
            change = np.einsum("...j,...j->...", delta, 2 * rel_star + delta)  # R^2 - R*^2
            # outer: gap = (outer - R*) + (R*^2 - R^2)/(R* + R); inner: (R* - inner) + (R^2 - R*^2)/(R + R*)
            sign = -1.0 if index == 0 else 1.0
            gaps.append(offset + sign * change / (r_star + radius))
        return radius, gaps[0], gaps[1]


def _mode_functions(curve: ClosedCurve, linkage: Linkage, sense: int):
    """phi1(v) and phi2(v) for one branch assignment: +sense from the Rmax dead centre to Rmin.

    ``w`` is the parameter measured from the Rmax dead centre; the arccos branch is
    ``+sense`` on ``[0, w_min)`` and ``-sense`` after. ``v`` runs from Q1, so the
    stretch before the Rmax dead centre belongs to the previous turn (``-2 pi sense``).
    """
    centre = np.asarray(linkage.centre)
    a, l = linkage.a, linkage.l
    period = curve.period
    w_min = float(np.mod(linkage.u_min - linkage.u_max, period))
    reference = np.mean(curve.polyline(), axis=0) - centre
    ref_angle = float(np.arctan2(reference[1], reference[0]))
    ref_dir = _unit(ref_angle)
    gaps = _RadialGaps(curve, linkage)

    def angles(v):
        v = np.asarray(v, dtype=float)
        u = v
        w = np.mod(v - linkage.u_max, period)
        earlier = v < linkage.u_max
        rel = curve(u) - centre
        radius, outer_gap, inner_gap = gaps(u)
        alpha = ref_angle + np.arctan2(_cross(ref_dir, rel), rel @ ref_dir)
        # 1 - c and 1 + c from the gaps: c = cos(theta) = (R^2 + 4a^2 - l^2) / (4 a R)
        one_minus = outer_gap * (radius + l - 2 * a) / (4 * a * radius)
        one_plus = inner_gap * (radius + l + 2 * a) / (4 * a * radius)
        theta = 2.0 * np.arctan2(np.sqrt(np.maximum(one_minus, 0.0)),
                                 np.sqrt(np.maximum(one_plus, 0.0)))
        sign = np.where(w < w_min, sense, -sense)
        sigma = sign * theta
        delta = np.arctan2(-radius * np.sin(sigma), radius * np.cos(sigma) - 2 * a)
        phi1 = (alpha + sigma + np.where(w < w_min, 0.0, TWO_PI * sense)
                - np.where(earlier, TWO_PI * sense, 0.0))
        cosine = np.where(one_minus < 0.0, 1.0 - one_minus, np.where(one_plus < 0.0,
                                                                     one_plus - 1.0, 0.0))
        return phi1, alpha + sigma + delta, cosine

    return angles, float(linkage.u_min)


def _cosine_of(curve, linkage, v):
    """``c = (R^2 + 4a^2 - l^2) / (4 a R)`` at curve parameters ``v``: +-1 at the dead centres."""
    radius = np.linalg.norm(curve(v) - np.asarray(linkage.centre), axis=-1)
    a, l = linkage.a, linkage.l
    return (radius**2 + 4 * a * a - l * l) / (4 * a * radius)


def _reach_problems(curve, linkage, angles, path):
    # as dense as ever for a drawn loop (20 x 64 a span); a digitised one has short spans
    count = max(20 * 13 * 64, 16 * len(curve.knots) * curve.samples_per_span)
    v = np.linspace(0.0, curve.period, count, endpoint=False)
    cosine = angles(v)[2]
    bad = np.abs(cosine) > 1.0 + REACH_TOL
    if not bad.any():
        return []
    where = sorted({curve.describe(s) for s in v[bad]})
    kind = "centre distance a and reach l" if not linkage.derived else "linkage"
    return [Problem(path, "unreachable_points",
                    f"the loop leaves the annulus l - 2a <= R <= l + 2a that the tip can reach "
                    f"(a = {linkage.a:.4f} mm, l = {linkage.l:.4f} mm; curve R from "
                    f"{linkage.radius_min:.4f} to {linkage.radius_max:.4f} mm) near "
                    f"{', '.join(where)}: the {kind} must follow from the curve "
                    f"(a = {(linkage.radius_max - linkage.radius_min) / 4:.4f}, "
                    f"l = {(linkage.radius_max + linkage.radius_min) / 2:.4f} mm)")]


def _piece_samples(breaks, per_piece: int) -> np.ndarray:
    """``per_piece`` evenly spaced samples on every piece, both ends included."""
    local = np.linspace(0.0, 1.0, per_piece + 1)[:-1]
    inner = (breaks[:-1, None] + np.diff(breaks)[:, None] * local).ravel()
    return np.append(inner, breaks[-1])


def carrier_motion(curve: ClosedCurve, linkage: Linkage, *, path: str = "trajectory.points",
                   sense: int | None = None):
    """Try both assembly modes; return the accepted :class:`CarrierMotion` and the mode report.

    A mode is accepted only if ``phi1`` is strictly monotone along the loop,
    gains one full turn, and ``phi2`` returns to its start. When both modes
    qualify, the one whose planet ratio keeps more margin is taken, unless
    ``sense`` (+1 counter-clockwise, -1 clockwise carrier) asks for one.

    Raises
    ------
    DesignError
        ``unreachable_points`` when the loop leaves the reachable annulus (a or l
        set by hand), ``no_assembly_mode`` when neither mode turns the carrier
        monotonically (a dent in the loop, say), with where it reverses.
    """
    reports = {}
    accepted = []
    for mode in (1, -1):
        angles, v_min = _mode_functions(curve, linkage, mode)
        problems = _reach_problems(curve, linkage, angles, path) if mode == 1 else []
        if problems:   # the annulus does not depend on the mode: checked once
            raise DesignError(problems)
        # the branch switch is continuous only where the tip really reaches l +- 2a
        tiny = 1e-9 * curve.period
        jump = max(abs(float(angles(np.array([dead - tiny]))[0][0]
                             - angles(np.array([dead + tiny]))[0][0]))
                   for dead in (v_min, linkage.u_max))
        if jump > 1e-5:
            raise DesignError.single(
                path if linkage.derived else "linkage", "dead_centre_mismatch",
                f"the carrier angle jumps by {np.degrees(jump):.3f} deg at a dead centre: the tip "
                f"never reaches R = l +- 2a (a = {linkage.a:.4f}, l = {linkage.l:.4f} mm; the curve "
                f"spans R = {linkage.radius_min:.4f} to {linkage.radius_max:.4f} mm), so the "
                "linkage would have to snap between its assembly modes; derive a and l from "
                f"the curve (a = {(linkage.radius_max - linkage.radius_min) / 4:.4f}, "
                f"l = {(linkage.radius_max + linkage.radius_min) / 2:.4f} mm)")
        # The angles are analytic across both dead centres (the branch switch turns the
        # arccos's |dv| into dv), so only the knots break them. A break at a dead centre
        # would leave a sliver between it and a nearby type-value point, on which the third
        # derivative the gears' curvature needs is ill-conditioned (error ~ 1/width^3).
        breaks = np.asarray(curve.knots, dtype=float)
        try:
            phi1 = PiecewiseChebyshev.interpolate(lambda v: angles(v)[0], breaks)
            phi2 = PiecewiseChebyshev.interpolate(lambda v: angles(v)[1], breaks)
        except ConvergenceError:
            # only a near-cusp of the angles does this: the tip nearly touches l +- 2a twice
            probe = np.linspace(0.0, curve.period, 20000, endpoint=False)
            cosine = np.abs(_cosine_of(curve, linkage, probe))
            away = np.ones(probe.shape, dtype=bool)
            for dead in (v_min, linkage.u_max):
                away &= np.abs(np.mod(probe - dead + 0.5 * curve.period, curve.period)
                               - 0.5 * curve.period) > 0.02 * curve.period
            near = np.flatnonzero((cosine > 1 - 1e-3) & away)
            where = sorted({curve.describe(s) for s in probe[near]}) or ["?"]
            raise DesignError.single(
                path, "near_dead_centre",
                f"the loop comes back almost to a dead-centre radius (l +- 2a) near "
                f"{', '.join(where)}: the carrier would have to turn almost instantly there; "
                "round off the loop there") from None
        rate1, rate2 = phi1.derivative(), phi2.derivative()
        probe = _piece_samples(rate1.breaks, max(64, -(-8320 // (len(rate1.breaks) - 1))))
        slope = mode * rate1(probe)
        turn = float(phi1(curve.period) - phi1(0.0))
        needle_turn = float(phi2(curve.period) - phi2(0.0))
        monotone = bool(slope.min() > 0.0)
        full = abs(turn - TWO_PI * mode) < 1e-6
        closed = abs(needle_turn) < 1e-6
        reversals = sorted({curve.describe(s) for s in probe[slope <= 0.0]})
        reports[mode] = {"monotone": monotone, "carrier_turn_deg": float(np.degrees(turn)),
                         "needle_turn_deg": float(np.degrees(needle_turn)),
                         "reverses_near": reversals[:6]}
        if monotone and full and closed:
            accepted.append(CarrierMotion(curve, linkage, mode, v_min, float(linkage.u_max),
                                          breaks, phi1, phi2, rate1, rate2))
    if not accepted:
        where = "; ".join(f"mode {'+' if s > 0 else '-'}: carrier reverses near "
                          f"{', '.join(r['reverses_near']) or 'nowhere'}"
                          for s, r in reports.items())
        raise DesignError.single(
            path, "no_assembly_mode",
            f"neither assembly mode turns the carrier monotonically through one turn ({where}): "
            "the loop has a dent or bulge the linkage cannot follow; smooth the points there")
    if sense is not None:
        chosen = [m for m in accepted if m.sense == sense]
        if not chosen:
            raise DesignError.single(
                path, "no_assembly_mode",
                f"the {'counter-clockwise' if sense > 0 else 'clockwise'} carrier mode does not "
                f"turn monotonically (reverses near {', '.join(reports[sense]['reverses_near'])})")
        return chosen[0], reports
    if len(accepted) == 2:  # both work: keep the one whose planet ratio has more margin
        probe = np.linspace(0.0, curve.period, 4096)
        accepted.sort(key=lambda m: -float(m.ratio(probe).min()))
    return accepted[0], reports


# ----------------------------------------------------------------- gear stages
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
                 pressure_angle, addendum):
    v = geometry.samples
    rho, d_rho, dd_rho, psi_rate, psi_rate2 = geometry.gear_curve(v, constant, exponent, role,
                                                                  factor)
    # curve rho(v) u(psi(v)): signed curvature, made positive where convex whatever the sense
    tangential = rho * psi_rate
    speed = np.hypot(d_rho, tangential)
    bend = (d_rho * (2 * d_rho * psi_rate + rho * psi_rate2)
            - tangential * (dd_rho - rho * psi_rate**2))
    curvature = np.sign(psi_rate) * bend / speed**3
    deviation = np.degrees(np.arctan2(np.abs(d_rho), np.abs(tangential)))
    concave = curvature < 0.0
    limit = module * addendum / np.sin(pressure_angle) ** 2
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
        table={"radius": table_rho})


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
                 addendum, min_ratio, grid, sense):
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
    gears = {
        "sun": _gear_report("sun", 1, "drive", geometry, constant, w, sun, grid_v, **common),
        "intermediate 1": _gear_report("intermediate 1", 1, "driven", geometry, constant, w,
                                       int1, grid_v, **common),
        "intermediate 2": _gear_report("intermediate 2", 2, "drive", geometry, 1.0 / constant,
                                       1.0 - w, int2, grid_v, **common),
        "planet": _gear_report("planet", 2, "driven", geometry, 1.0 / constant, 1.0 - w, planet,
                               grid_v, **common),
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

    def make(c, e, role, factor, angle):
        def functions(v):
            v = np.asarray(v, dtype=float)
            v = np.where((v < 0.0) | (v > period), np.mod(v, period), v)
            rho, d_rho, _, psi_rate, _ = geometry.gear_curve(v, c, e, role, factor)
            return rho, d_rho, angle(v), psi_rate
        return functions

    return {name: make(*spec) for name, spec in specs.items()}


def _stretch_text(stretch) -> str:
    low, high = stretch["carrier_deg"]
    span = (f"{low:.1f} deg" if f"{low:.1f}" == f"{high:.1f}" else f"{low:.1f} to {high:.1f} deg")
    return f"carrier progress {span} (tip near {stretch['near']})"


def _findings(stages, curve):
    notes = []
    for stage in stages:
        for gear in (stage.drive, stage.driven):
            if not gear.convex:
                where = "; ".join(_stretch_text(s) for s in gear.concave_stretches)
                advice = ("use the degree-5 curve, or move the type-value points there onto a "
                          "smoother loop" if curve.degree == 3 else
                          "move the type-value points there onto a smoother loop")
                notes.append(Problem(
                    f"gears.{gear.name.replace(' ', '_')}", "concave_pitch_curve",
                    f"the {gear.name} gear's pitch curve is concave (curvature down to "
                    f"{gear.curvature_min:.4f} 1/mm) at {where}: a rack cannot cut it there, it "
                    f"needs a shaper cutter of pitch radius below {1 / -gear.curvature_min:.1f} mm; "
                    f"or {advice}"))
            if gear.undercut:
                notes.append(Problem(
                    f"gears.{gear.name.replace(' ', '_')}", "undercut",
                    f"the {gear.name} gear's pitch curve bends to a radius of curvature of "
                    f"{gear.convex_radius_of_curvature_min:.2f} mm, below the rack undercut limit "
                    f"{gear.undercut_limit:.2f} mm (m ha*/sin^2 alpha): rack-cut teeth would be "
                    "undercut; use a smaller module, a profile shift or a shaper cutter"))
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
                    max_scale_change: float = 0.05) -> PrickingDesign:
    """Inverse design of the pricking mechanism from the type-value points of its tip loop.

    The design is scaled about the sun centre so that stage 1 holds a whole
    number of teeth at ``module``; stage 2 then takes the nearest whole number
    and its own module (equal to ``module`` with the equal-perimeter split).
    The scale may differ from 1 by at most ``max_scale_change`` (the drawn loop
    is the designer's; rounding to whole teeth is meant to move it slightly):
    beyond that, ``module_does_not_fit`` names the modules that would.

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
    result = _checked_design(centre + scale * (points - centre), options)
    (curve, linkage, motion, modes, w, stages, grid_tables, deviation, closure, i_min, i_max,
     functions) = result
    teeth_2 = max(min_teeth, int(round(stages[1].perimeter / (np.pi * module))))
    modules = (stages[0].perimeter / (np.pi * teeth_1), stages[1].perimeter / (np.pi * teeth_2))
    findings = _findings(stages, curve) + _forward_findings(deviation, grid)
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
