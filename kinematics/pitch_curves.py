"""Closed pitch curves of non-circular gears and the closure of a gear pair.

The central gear's pitch curve is the polar curve ``rho = r1(t)``, ``t`` the
gear's rotation angle. It meshes at a fixed centre distance ``a`` with a gear
whose radius at the contact is ``a - r1(t)``; the pair closes 1:1 when

    integral_0^2pi r1(t) / (a - r1(t)) dt = 2 pi.

Method (and its error): the integrand is periodic and analytic, so the
trapezoid rule on ``N`` equally spaced nodes converges geometrically (the
Euler-Maclaurin error terms all vanish). For each ``N`` the discrete closure
``mean(r/(a - r)) = 1`` is solved for ``a`` by Brent's method; ``N`` is doubled
until two successive roots agree to ``rtol`` and the Fourier tail of the ratio
law is negligible. The last change of ``a`` is reported as the error estimate.
A coarse 1-degree rectangle rule with both end points counted (the paper's
MATLAB habit) double-counts the node at 2 pi and gives 59.997 mm instead of
59.944 mm for the paper's design.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from .scalar import brentq, minimize_scalar

from .errors import ConvergenceError, DesignError, Problem
from . import tolerances as tol

__all__ = [
    "LimaconPitchCurve",
    "CirclePitchCurve",
    "FocalEllipsePitchCurve",
    "Closure",
    "RatioLaw",
    "solve_closure",
    "polar_perimeter",
    "polar_curvature",
    "parametric_curvature",
    "refined_radius_extrema",
    "pair_problems",
    "centre_distance_at_nodes",
]

TWO_PI = 2.0 * np.pi


@dataclass(frozen=True)
class LimaconPitchCurve:
    """Pascal-limacon variant with ten coefficients (spec: planting mechanism).

    ``x(t) = a1 (e1 cos t)^2 + b1 cos(t + f1) + g1``,
    ``y(t) = c1 cos(e2 t) sin(e2 t) + d1 cos(t + f2) + g2``,
    ``r1(t) = hypot(x, y)``. Lengths in mm, ``f1``, ``f2`` in radians.
    ``2 e2`` must be a whole number, else ``r1`` is not 2 pi periodic.
    """

    a1: float
    b1: float
    c1: float
    d1: float
    e1: float
    e2: float
    f1: float
    f2: float
    g1: float
    g2: float

    def __post_init__(self):
        twice = 2.0 * self.e2
        if not np.isclose(twice, round(twice), rtol=0, atol=1e-12) or round(twice) == 0:
            raise DesignError.single(
                "pitch_curve.e2", "open_pitch_curve",
                f"2*e2 = {twice:g} is not a whole non-zero number, so r1(t) is not "
                "periodic over one turn and the gear pair cannot close")

    def _xy(self, t):
        t = np.asarray(t, dtype=float)
        x = self.a1 * self.e1**2 * np.cos(t) ** 2 + self.b1 * np.cos(t + self.f1) + self.g1
        y = 0.5 * self.c1 * np.sin(2 * self.e2 * t) + self.d1 * np.cos(t + self.f2) + self.g2
        return t, x, y

    def radius(self, t):
        """Pitch radius ``r1(t)``; ``t`` any shape (rad), result same shape (mm)."""
        _, x, y = self._xy(t)
        return np.hypot(x, y)

    def radius_rate_bound(self) -> float:
        """Upper bound on ``|dr1/dt|`` from the coefficients (``|r'| <= |(x', y')|``)."""
        dx = abs(self.a1 * self.e1**2) + abs(self.b1)
        dy = abs(self.c1 * self.e2) + abs(self.d1)
        return float(np.hypot(dx, dy))

    def radius_derivatives(self, t):
        """``(r1, dr1/dt, d2r1/dt2)`` in closed form, each the shape of ``t``."""
        t, x, y = self._xy(t)
        k1 = self.a1 * self.e1**2
        dx = -k1 * np.sin(2 * t) - self.b1 * np.sin(t + self.f1)
        ddx = -2 * k1 * np.cos(2 * t) - self.b1 * np.cos(t + self.f1)
        dy = self.c1 * self.e2 * np.cos(2 * self.e2 * t) - self.d1 * np.sin(t + self.f2)
        ddy = -2 * self.c1 * self.e2**2 * np.sin(2 * self.e2 * t) - self.d1 * np.cos(t + self.f2)
        r = np.hypot(x, y)
        with np.errstate(divide="ignore", invalid="ignore"):
            dr = (x * dx + y * dy) / r
            ddr = (dx**2 + dy**2 + x * ddx + y * ddy) / r - dr**2 / r
        return r, dr, ddr


@dataclass(frozen=True)
class CirclePitchCurve:
    """A circle of radius ``radius`` (mm): the trivial pitch curve, for checks."""

    radius_value: float

    def radius(self, t):
        return np.full(np.shape(t), float(self.radius_value))

    def radius_rate_bound(self) -> float:
        return 0.0

    def radius_derivatives(self, t):
        shape = np.shape(t)
        return np.full(shape, float(self.radius_value)), np.zeros(shape), np.zeros(shape)


@dataclass(frozen=True)
class FocalEllipsePitchCurve:
    """An ellipse turning about a focus: ``rho = p / (1 + e cos t)``, ``p = A (1 - e^2)``.

    Two equal ones mesh at ``a = 2 A`` with ``F(phi) = 2 atan(((1-e)/(1+e)) tan(phi/2))``:
    closed forms for closure tests, with a ratio swing ``((1+e)/(1-e))^2`` as large as wanted.
    """

    semi_major: float
    eccentricity: float

    def __post_init__(self):
        if not 0.0 <= self.eccentricity < 1.0:
            raise ValueError(f"eccentricity must be in [0, 1), not {self.eccentricity}")

    def radius(self, t):
        return self.radius_derivatives(t)[0]

    def radius_rate_bound(self) -> float:
        e = self.eccentricity
        return self.semi_major * (1 - e * e) * e / (1 - e) ** 2

    def radius_derivatives(self, t):
        t = np.asarray(t, dtype=float)
        e = self.eccentricity
        p = self.semi_major * (1 - e * e)
        c, s = np.cos(t), np.sin(t)
        q = 1 + e * c
        return p / q, p * e * s / q**2, p * e * (c * q + 2 * e * s * s) / q**3


def _nodes(count: int) -> np.ndarray:
    return np.arange(count) * (TWO_PI / count)


def refined_radius_extrema(curve, samples: int = 2048, xatol: float = tol.REFINE_XATOL):
    """Minimum and maximum of ``curve.radius`` over a turn, refined off the grid.

    Every sampled local extremum within reach of the sampled global one is
    polished by bounded Brent minimisation, so an extremum between samples is
    found, not rounded to the nearest sample.

    Returns
    -------
    (t_min, r_min), (t_max, r_max) : tuple of (float, float)
    """
    t = _nodes(samples)
    r = curve.radius(t)
    h = TWO_PI / samples
    results = []
    for sign in (1.0, -1.0):
        values = sign * r
        # local minima of the sampled (periodic) sequence
        local = np.flatnonzero((values <= np.roll(values, 1)) & (values <= np.roll(values, -1)))
        # keep the ones that could beat the best sample after refinement
        spread = np.ptp(values) * 1e-3 + 1e-12
        local = local[values[local] <= values.min() + spread]
        best_t, best_v = t[values.argmin()], values.min()
        for k in local:
            res = minimize_scalar(lambda s: sign * float(curve.radius(s)),
                                  bounds=(t[k] - h, t[k] + h), method="bounded",
                                  options={"xatol": xatol})
            if res.fun < best_v:
                best_t, best_v = float(res.x), float(res.fun)
        results.append((float(np.mod(best_t, TWO_PI)), sign * best_v))
    return results[0], results[1]


@dataclass(frozen=True)
class RatioLaw:
    """The transmission law ``w(t) = r1 / (a - r1)`` and its integral ``F``.

    ``F(phi) = integral_0^phi w dt`` is evaluated from the Fourier series of
    ``w`` (exact integration term by term), with the mean forced to 1: the
    closure residual is reported by :class:`Closure`, and forcing it keeps
    ``phi - F(phi)`` exactly periodic over any number of revolutions.
    """

    curve: object
    centre_distance: float
    coefficients: np.ndarray = field(repr=False)  # complex, modes 1..K

    def ratio(self, t):
        """``w(t) = r1/(a - r1)`` and ``dw/dt``, each the shape of ``t``."""
        r, dr, _ = self.curve.radius_derivatives(t)
        gap = self.centre_distance - r
        return r / gap, self.centre_distance * dr / gap**2

    def periodic_part(self, phi):
        """``F(phi) - phi`` (rad); 2 pi periodic, zero at 0. ``phi`` any shape.

        Sum of ``2 Re(c_k (z^k - 1) / (i k))`` with ``z = exp(i phi)``, by Horner's
        scheme: one pass over the modes, no (points x modes) matrix.
        """
        phi = np.asarray(phi, dtype=float)
        modes = np.arange(1, len(self.coefficients) + 1)
        weights = self.coefficients / (1j * modes)
        if phi.size <= 64:
            # few points (a refinement step): one small matrix beats a loop over modes
            phase = np.exp(1j * np.multiply.outer(np.mod(phi, TWO_PI), modes)) - 1.0
            return 2.0 * np.real(phase @ weights)
        z = np.exp(1j * np.mod(phi, TWO_PI))
        total = np.zeros_like(z)
        for weight in weights[::-1]:
            total = (total + weight) * z
        return 2.0 * np.real(total - weights.sum())

    def integral(self, phi):
        """``F(phi)`` (rad), exact turns plus the periodic part (no drift)."""
        phi = np.asarray(phi, dtype=float)
        return phi + self.periodic_part(phi)


@dataclass(frozen=True)
class Closure:
    """Result of closing a non-circular pair 1:1.

    Attributes
    ----------
    centre_distance : float
        ``a`` (mm).
    error_estimate : float
        ``|a_N - a_{N/2}|`` of the last doubling (mm).
    nodes : int
        Quadrature nodes used.
    residual : float
        ``mean(w) - 1`` at the solution on the final nodes (closure error of F(2 pi)/2 pi).
    ratio_min, ratio_max : float
        Extremes of ``w = r1/(a - r1)`` (refined).
    law : RatioLaw
    """

    centre_distance: float
    error_estimate: float
    nodes: int
    residual: float
    ratio_min: float
    ratio_max: float
    radius_min: tuple
    radius_max: tuple
    law: RatioLaw = field(repr=False)

    @property
    def ratio_swing(self) -> float:
        """``max w / min w``: how far the law departs from 1:1."""
        return self.ratio_max / self.ratio_min


def _discrete_root(r: np.ndarray, r_max_true: float) -> float | None:
    """Solve ``mean(r/(a - r)) = 1`` for ``a`` above every node radius."""
    r_top = max(float(r.max()), r_max_true)
    def residual(a):
        return np.mean(r / (a - r)) - 1.0
    lo = r_top * (1.0 + 8 * np.finfo(float).eps) + 1e-300
    hi = 2.0 * r_top  # every term <= 1 there, so the residual is <= 0
    if residual(hi) >= 0.0:
        return hi  # a circle: a = 2 r exactly
    if residual(lo) <= 0.0:
        return None  # the nodes miss the peak of the law: not resolved yet
    return brentq(residual, lo, hi, xtol=1e-15 * r_top, rtol=4 * np.finfo(float).eps, maxiter=500)


def centre_distance_at_nodes(curve, nodes: int) -> float:
    """The closure root of the trapezoid rule on exactly ``nodes`` nodes (no doubling).

    For accuracy studies: :func:`solve_closure` is the method to use. Raises
    :class:`ConvergenceError` when so few nodes miss the peak of the law.
    """
    (_, _), (_, r_max) = refined_radius_extrema(curve)
    a = _discrete_root(curve.radius(_nodes(nodes)), r_max)
    if a is None:
        raise ConvergenceError(f"{nodes} nodes do not resolve the ratio law")
    return a


def solve_closure(curve, *, rtol: float = tol.CLOSURE_RTOL,
                  min_nodes: int = tol.CLOSURE_MIN_NODES,
                  max_nodes: int = tol.CLOSURE_MAX_NODES,
                  tail_rtol: float = tol.FOURIER_TAIL_RTOL) -> Closure:
    """Centre distance ``a`` that closes the pair 1:1, with its error estimate.

    Raises
    ------
    DesignError
        If the pitch radius touches zero (pointed pitch curve).
    ConvergenceError
        If ``max_nodes`` does not resolve the ratio law to ``rtol`` (a law so
        peaked that it cannot be trusted); never returns NaN.
    """
    (t_min, r_min), (t_max, r_max) = refined_radius_extrema(curve)
    # a polar curve through (or within round-off of) its centre has a point there
    if not np.isfinite(r_min) or r_min <= 1e-6 * r_max:
        raise DesignError.single(
            "pitch_curve", "pointed_pitch_curve",
            f"the pitch radius r1 falls to {r_min:.3g} mm at t = {np.degrees(t_min):.2f} deg: "
            "the pitch curve passes through its centre and has a point there")
    count = min_nodes
    previous = None
    while True:
        t = _nodes(count)
        r = curve.radius(t)
        a = _discrete_root(r, r_max)
        if previous is not None and a is not None:
            change = abs(a - previous)
            w = r / (a - r)
            spectrum = np.fft.rfft(w) / count
            mean = spectrum[0].real
            tail = np.abs(spectrum[len(spectrum) // 2:]).max()
            if change <= rtol * a and tail <= tail_rtol * mean and a > r_max:
                break
        if count >= max_nodes:
            raise ConvergenceError(
                f"closure quadrature did not converge with {count} nodes: the ratio "
                f"law r1/(a - r1) is too peaked to resolve (max r1 = {r_max:.9g} mm, "
                f"last a = {a!s} mm)")
        previous = a
        count *= 2
    # keep modes until the spectrum reaches round-off
    significant = np.flatnonzero(np.abs(spectrum[1:]) > 1e-16 * mean)
    keep = (significant.max() + 1) if significant.size else 0
    law = RatioLaw(curve, a, spectrum[1:1 + keep].copy())
    w_min = r_min / (a - r_min)
    w_max = r_max / (a - r_max)
    return Closure(centre_distance=a, error_estimate=change, nodes=count,
                   residual=float(mean - 1.0), ratio_min=w_min, ratio_max=w_max,
                   radius_min=(t_min, r_min), radius_max=(t_max, r_max), law=law)


def polar_perimeter(curve, *, rtol: float = 1e-13, min_nodes: int = 256,
                    max_nodes: int = 2**20) -> float:
    """Arc length (mm) of the polar curve ``rho = r(t)``, periodic trapezoid rule doubled to ``rtol``."""
    count, previous = min_nodes, None
    while True:
        r, dr, _ = curve.radius_derivatives(_nodes(count))
        length = float(np.mean(np.hypot(r, dr)) * TWO_PI)
        if previous is not None and abs(length - previous) <= rtol * length:
            return length
        if count >= max_nodes:
            raise ConvergenceError(f"perimeter did not converge with {count} nodes")
        previous, count = length, count * 2


def polar_curvature(curve, t):
    """Signed curvature (1/mm) of ``rho = r(t)``; negative on concave stretches."""
    r, dr, ddr = curve.radius_derivatives(t)
    return (r**2 + 2 * dr**2 - r * ddr) / (r**2 + dr**2) ** 1.5


def parametric_curvature(rho, d_rho, dd_rho, psi_rate, psi_rate2):
    """Signed curvature (1/mm) of the pitch curve ``rho(v) u(psi(v))`` from its derivatives.

    ``rho``, ``psi`` and their first and second derivatives along any parameter ``v`` (arrays
    of one shape): the curve's ``x' y'' - y' x''`` over ``|p'|^3``, signed with ``psi'`` so
    that a convex stretch is positive whichever way the parameter runs round the gear (a
    driven gear's contact turns backwards). With ``psi = v`` it is :func:`polar_curvature`.
    """
    tangential = rho * psi_rate
    speed = np.hypot(d_rho, tangential)
    bend = (d_rho * (2 * d_rho * psi_rate + rho * psi_rate2)
            - tangential * (dd_rho - rho * psi_rate**2))
    return np.sign(psi_rate) * bend / speed**3


def _finer_module(largest: float, path: str) -> str:
    """What cuts a stretch that needs a module of at most ``largest`` mm, as advice."""
    from kinematics.profile_shift import MIN_PRACTICAL_MODULE

    if largest >= MIN_PRACTICAL_MODULE:
        return f"a module of at most {largest:.3f} mm cuts it (more teeth: {path}.teeth)"
    return (f"no practical module cuts it (it would take one below {max(largest, 0.0):.3g} mm, "
            f"under {MIN_PRACTICAL_MODULE:g} mm)")


def pair_problems(closure: Closure, module: float, *, path: str = "pitch_curve",
                  min_radius_modules: float = tol.MIN_PITCH_RADIUS_MODULES) -> list:
    """Why a closed non-circular pair cannot be cut with ``module`` (empty when it can).

    Both gears' smallest pitch radii, ``min r1`` and ``a - max r1``, must be at
    least ``min_radius_modules`` modules: below it the stretch is pointed and
    the dedendum leaves no rim round the shaft.
    """
    limit = min_radius_modules * module
    (t_min, r_min), (t_max, r_max) = closure.radius_min, closure.radius_max
    gap = closure.centre_distance - r_max
    problems = []
    if r_min < limit:
        problems.append(Problem(
            path, "pointed_pitch_curve",
            f"the central gear's pitch radius falls to {r_min:.3f} mm at t = "
            f"{np.degrees(t_min):.2f} deg, below {min_radius_modules:g} modules ({limit:.3f} mm "
            f"at module {module:.3f} mm): that stretch is pointed and cannot be cut with this "
            f"module; {_finer_module(r_min / min_radius_modules, path)}, or a rounder pitch "
            "curve"))
    if gap < limit:
        problems.append(Problem(
            path, "tiny_intermediate_radius",
            f"the intermediate gear's radius a - r1 falls to {gap:.3f} mm at t = "
            f"{np.degrees(t_max):.2f} deg (a = {closure.centre_distance:.4f} mm, ratio swing "
            f"1:{closure.ratio_swing:.1f}), below {min_radius_modules:g} modules ({limit:.3f} mm): "
            f"it cannot be cut with module {module:.3f} mm; "
            f"{_finer_module(gap / min_radius_modules, path)}, or a pitch curve of a smaller "
            "ratio swing"))
    return problems
