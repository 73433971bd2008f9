"""The pricking mechanism's linkage and carrier motion along its drawn tip loop.

Planetary train of non-circular gears on one carrier, all centre distances a:
sun (fixed, O) -> first intermediate (A) = second intermediate (same shaft) ->
planet (B). ``A = O + a u(phi1)``, ``B = O + 2a u(phi1)``, ``D = B + l u(phi2)``.

Steps 2 to 4 of the inverse design: ``l = (Rmax + Rmin)/2`` and ``a = (Rmax - Rmin)/4``
from the refined radial extremes on the curve; ``phi1 = alpha + s arccos(c)``, the
branch sign ``s`` switching exactly at the two dead centres; the assembly mode
accepted only if ``phi1`` is strictly monotone over the loop (one full carrier turn).

The carrier and needle angles are analytic along the curve parameter across both
dead centres (the branch switch turns the arccos's ``|dv|`` into ``dv``), so they are
held as piecewise Chebyshev interpolants (:mod:`kinematics.chebyshev`) broken only at
the type-value points: the ratio ``i = 1 - dphi2/dphi1`` and every integral come
without finite differences. ``phi2`` is ``alpha + sigma + delta`` with ``sigma = s
arccos(c)`` and ``delta`` the angle at B between OB produced and BD: at the Rmin dead
centre ``sigma`` and ``delta`` jump by opposite 2 pi, so ``phi2`` is continuous
without unwrapping.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .chebyshev import PiecewiseChebyshev
from .errors import ConvergenceError, DesignError, Problem
from .spline import ClosedCurve
from .planar import unit as _unit, cross as _cross

__all__ = ["Linkage", "CarrierMotion", "link_lengths", "carrier_motion",
           "travel_direction_problems", "REACH_TOL"]

TWO_PI = 2.0 * np.pi
#: |c| may exceed 1 by this much from round-off on the curve before the point is unreachable.
REACH_TOL = 1e-9


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
