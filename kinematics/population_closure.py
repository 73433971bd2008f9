"""The non-circular pair of N planting designs at once: pitch radii, closure, ratio law, module.

The population screen's counterpart of :mod:`kinematics.pitch_curves` (pure numpy, every
array ``(N, ...)``, one row a design). The same model and the same quadrature: the
closure ``mean(r1/(a - r1)) = 1`` on the ``K`` equally spaced nodes of the shared grid
(the periodic trapezoid rule, spectrally convergent), solved for ``a`` by Newton's method
from the left, where the convex decreasing residual makes every step land short of the
root. The exact path doubles its nodes until the root moves less than 1e-13 a; the
screen has one grid, so it compares the root on ``K`` nodes with the root on every other
node (``K/2``) and with the Fourier tail of the law, and a design whose law the grid does
not resolve is refused (``closure_unresolved``), never given a rough number.

The ratio law ``w = r1/(a - r1)`` is kept as its Fourier series (as
:class:`kinematics.pitch_curves.RatioLaw`), so the attitude ``Psi = -(F - phi)`` is the
series integrated term by term, on the grid by one inverse FFT; off the grid it is
interpolated from Psi and its exact derivatives there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["LIMACON_FIELDS", "PairLaw", "limacon_radius", "solve_pair", "pair_at"]

TWO_PI = 2.0 * np.pi

#: The ten limacon coefficients, in the order of the columns of ``coefficients`` (f1, f2 rad).
LIMACON_FIELDS = ("a1", "b1", "c1", "d1", "e1", "e2", "f1", "f2", "g1", "g2")

#: Newton iterations allowed for the closure root (it converges quadratically in about 5
#: from the Jensen start; a root close to max r1 takes a few more, each doubling the gap).
CLOSURE_ITERATIONS = 80
#: The closure root is converged once a Newton step is below this fraction of ``a``.
CLOSURE_STEP_RTOL = 1e-14
#: The root on K nodes and on K/2 nodes must agree to this fraction of ``a``, and the top
#: half of the law's spectrum must be below this fraction of its mean: else the grid does
#: not resolve the law and the design is refused (``closure_unresolved``).
RESOLVED_RTOL = 1e-10
#: A pitch radius below this fraction of the largest is a point (as solve_closure).
POINTED_RATIO = 1e-6
#: Newton iterations polishing a pitch radius extreme off the grid.
EXTREME_ITERATIONS = 4
#: Smallest pitch radius of either gear, in modules (as kinematics.tolerances).
MIN_PITCH_RADIUS_MODULES = 3.0


def limacon_radius(coefficients, t, *, derivatives: bool = False):
    """Pitch radius ``r1(t)`` of N limacons (and ``dr1/dt``, ``d2r1/dt2``).

    Parameters
    ----------
    coefficients : dict of (N,) float
        ``a1 .. g2`` (``f1``, ``f2`` in rad).
    t : (N, p) or (p,) float
        Gear angles (rad).
    """
    c = {k: np.asarray(coefficients[k], dtype=float)[:, None] for k in LIMACON_FIELDS}
    t = np.asarray(t, dtype=float)
    k1 = c["a1"] * c["e1"] ** 2
    cos_t, sin_t = np.cos(t), np.sin(t)
    cos_f1, sin_f1 = np.cos(c["f1"]), np.sin(c["f1"])
    cos_f2, sin_f2 = np.cos(c["f2"]), np.sin(c["f2"])
    cos1 = cos_t * cos_f1 - sin_t * sin_f1          # cos(t + f1)
    sin1 = sin_t * cos_f1 + cos_t * sin_f1
    cos2 = cos_t * cos_f2 - sin_t * sin_f2          # cos(t + f2)
    sin2 = sin_t * cos_f2 + cos_t * sin_f2
    twice = 2.0 * c["e2"] * t
    sin_e, cos_e = np.sin(twice), np.cos(twice)
    x = k1 * cos_t**2 + c["b1"] * cos1 + c["g1"]
    y = 0.5 * c["c1"] * sin_e + c["d1"] * cos2 + c["g2"]
    r = np.hypot(x, y)
    if not derivatives:
        return r
    dx = -2.0 * k1 * sin_t * cos_t - c["b1"] * sin1
    ddx = -2.0 * k1 * (cos_t**2 - sin_t**2) - c["b1"] * cos1
    dy = c["c1"] * c["e2"] * cos_e - c["d1"] * sin2
    ddy = -2.0 * c["c1"] * c["e2"] ** 2 * sin_e - c["d1"] * cos2
    with np.errstate(divide="ignore", invalid="ignore"):
        dr = (x * dx + y * dy) / r
        ddr = (dx**2 + dy**2 + x * ddx + y * ddy) / r - dr**2 / r
    return r, dr, ddr


def _polished_extreme(coefficients, t_grid, r_grid, sign):
    """Refine the grid's largest (``sign`` 1) or smallest (-1) pitch radius by Newton on r' = 0."""
    k = np.argmax(sign * r_grid, axis=1)
    h = TWO_PI / r_grid.shape[1]
    t0 = t_grid[k]
    t = t0.copy()
    for _ in range(EXTREME_ITERATIONS):
        _, dr, ddr = limacon_radius(coefficients, t[:, None], derivatives=True)
        with np.errstate(divide="ignore", invalid="ignore"):
            step = np.where(sign * ddr[:, 0] < 0.0, -dr[:, 0] / ddr[:, 0], 0.0)
        t = np.clip(t + np.nan_to_num(step), t0 - h, t0 + h)
    value = limacon_radius(coefficients, t[:, None])[:, 0]
    # never below the best sample: a step that went the wrong way is not taken
    best = r_grid[np.arange(len(k)), k]
    better = sign * value >= sign * best
    return np.where(better, t, t0), np.where(better, value, best)


def _closure_root(r):
    """Newton's root of ``mean(r/(a - r)) = 1`` per row, from the left. Returns (a, converged)."""
    r_top = r.max(axis=1)
    # Jensen: mean(r/(a-r)) >= m/(a-m), which is 1 at a = 2m, so 2m is left of the root
    a = np.maximum(2.0 * r.mean(axis=1), r_top * (1.0 + 1e-12))
    converged = np.zeros(len(r), dtype=bool)
    for _ in range(CLOSURE_ITERATIONS):
        gap = a[:, None] - r
        ratio = r / gap
        residual = ratio.mean(axis=1) - 1.0
        slope = -(ratio / gap).mean(axis=1)
        step = -residual / slope
        step = np.where(converged, 0.0, step)
        a = a + step
        converged |= np.abs(step) <= CLOSURE_STEP_RTOL * a
        if converged.all():
            break
    return a, converged & np.isfinite(a)


@dataclass(frozen=True)
class PairLaw:
    """The closed non-circular pair of each design.

    Attributes (each (N,) unless said)
    ----------
    centre_distance : a (mm)
    radius_min, radius_max : refined extremes of r1 (mm)
    perimeter : of ``rho = r1(t)`` (mm)
    attitude_grid : (N, K) float
        ``Psi = phi - F`` on the grid ``2 pi j / K`` (the law's Fourier series, integrated
        term by term, by one inverse FFT).
    ratio_grid, ratio_rate_grid : (N, K) float
        ``w = r1/(a - r1)`` and ``dw/dphi`` on the grid (closed form).
    reason : (N,) object
        "" for a closed, resolved pair, else the reason code.
    """

    coefficients: dict
    centre_distance: np.ndarray
    radius_min: np.ndarray
    radius_max: np.ndarray
    perimeter: np.ndarray
    attitude_grid: np.ndarray
    ratio_grid: np.ndarray
    ratio_rate_grid: np.ndarray
    reason: np.ndarray

    def attitude(self, phi):
        """``Psi(phi) = phi - F(phi)`` off the grid: ``phi`` (N, p) -> (N, p).

        Quintic Hermite interpolation between the two grid angles round ``phi`` of Psi
        and its exact first and second derivatives ``1 - w`` and ``-dw/dphi``: an error
        of order ``h^6`` (``h = 2 pi / K``), far below the screen's tolerances at every
        grid of docs/accuracy.md, at a few dozen operations a point instead of a sum
        over K/2 modes.
        """
        phi = np.asarray(phi, dtype=float)
        samples = self.attitude_grid.shape[1]
        h = TWO_PI / samples
        position = np.mod(phi, TWO_PI) / h
        left = np.minimum(np.floor(position).astype(np.intp), samples - 1)
        t = position - left
        right = np.where(left + 1 == samples, 0, left + 1)

        def at(grid, index):
            return np.take_along_axis(grid, index, axis=1)

        psi0, psi1 = at(self.attitude_grid, left), at(self.attitude_grid, right)
        rate0 = h * (1.0 - at(self.ratio_grid, left))
        rate1 = h * (1.0 - at(self.ratio_grid, right))
        curve0 = -h * h * at(self.ratio_rate_grid, left)
        curve1 = -h * h * at(self.ratio_rate_grid, right)
        t2 = t * t
        t3 = t2 * t
        t4, t5 = t3 * t, t3 * t2
        return (psi0 * (1.0 - 10.0 * t3 + 15.0 * t4 - 6.0 * t5)
                + rate0 * (t - 6.0 * t3 + 8.0 * t4 - 3.0 * t5)
                + curve0 * (0.5 * t2 - 1.5 * t3 + 1.5 * t4 - 0.5 * t5)
                + psi1 * (10.0 * t3 - 15.0 * t4 + 6.0 * t5)
                + rate1 * (-4.0 * t3 + 7.0 * t4 - 3.0 * t5)
                + curve1 * (0.5 * t3 - t4 + 0.5 * t5))

    def ratio(self, phi):
        """``(w, dw/dphi)`` at ``phi`` (N, p), in closed form from r1."""
        r, dr, _ = limacon_radius(self.coefficients, phi, derivatives=True)
        gap = self.centre_distance[:, None] - r
        return r / gap, self.centre_distance[:, None] * dr / gap**2


def solve_pair(coefficients, teeth, samples: int) -> PairLaw:
    """Close the non-circular pair of every design on a grid of ``samples`` nodes.

    Reasons a design is refused (its numbers are then NaN): ``pointed_pitch_curve`` (r1
    touches zero, or falls below 3 modules: :func:`kinematics.pitch_curves.pair_problems`),
    ``tiny_intermediate_radius`` (``a - max r1`` below 3 modules), ``closure_not_converged``,
    ``closure_unresolved`` (the grid does not resolve the law).
    """
    if samples % 4 or samples < 16:
        raise ValueError(f"samples must be a multiple of 4, at least 16, not {samples}")
    t = np.arange(samples) * (TWO_PI / samples)
    r, dr, _ = limacon_radius(coefficients, t, derivatives=True)
    count = r.shape[0]
    reason = np.full(count, "", dtype=object)
    _, r_min = _polished_extreme(coefficients, t, r, -1.0)
    _, r_max = _polished_extreme(coefficients, t, r, 1.0)
    pointed = ~(r_min > POINTED_RATIO * r_max)
    reason[pointed] = "pointed_pitch_curve"
    # a pointed row gets a harmless stand-in radius so the arithmetic below stays finite
    safe_r = np.where(pointed[:, None], 1.0, r)
    a, converged = _closure_root(safe_r)
    half, half_converged = _closure_root(safe_r[:, ::2])
    ok = ~pointed
    reason[ok & ~(converged & half_converged)] = "closure_not_converged"
    w = safe_r / (a[:, None] - safe_r)
    spectrum = np.fft.rfft(w, axis=1) / samples
    mean = spectrum[:, 0].real
    tail = np.abs(spectrum[:, samples // 4:]).max(axis=1)
    # a root at or below the true max r1: the nodes miss the law's peak (the exact path then
    # doubles its nodes; here a finer grid takes the design)
    unresolved = ~((np.abs(a - half) <= RESOLVED_RTOL * a) & (tail <= RESOLVED_RTOL * mean)
                   & (a > r_max) & (half > r_max))
    perimeter = TWO_PI * np.hypot(r, dr).mean(axis=1)
    module = perimeter / (np.pi * np.asarray(teeth, dtype=float))
    limit = MIN_PITCH_RADIUS_MODULES * module
    # a central gear too pointed to cut is refused whatever the grid resolves (r1 alone says
    # so); the intermediate gear's smallest radius a - max r1 needs a resolved root
    reason[(reason == "") & (r_min < limit)] = "pointed_pitch_curve"
    reason[(reason == "") & unresolved] = "closure_unresolved"
    reason[(reason == "") & (a - r_max < limit)] = "tiny_intermediate_radius"
    # the law's series, modes 1 .. K/2 - 1 (the Nyquist term of an even grid is dropped:
    # the tail check above has made it negligible)
    modes = np.arange(1, samples // 2)
    weights = spectrum[:, 1:samples // 2] / (1j * modes)
    padded = np.zeros((count, samples // 2 + 1), dtype=complex)
    padded[:, 1:samples // 2] = weights * samples
    periodic = np.fft.irfft(padded, n=samples, axis=1)
    periodic -= periodic[:, :1]
    w_rate = a[:, None] * dr / (a[:, None] - safe_r) ** 2
    return PairLaw(coefficients=coefficients, centre_distance=a, radius_min=r_min,
                   radius_max=r_max, perimeter=perimeter, attitude_grid=-periodic,
                   ratio_grid=w, ratio_rate_grid=w_rate, reason=reason)


def pair_at(law: PairLaw, rows) -> PairLaw:
    """The pair law of the designs ``rows`` (an index array or a mask)."""
    return PairLaw(coefficients={k: np.asarray(v)[rows] for k, v in law.coefficients.items()},
                   centre_distance=law.centre_distance[rows], radius_min=law.radius_min[rows],
                   radius_max=law.radius_max[rows], perimeter=law.perimeter[rows],
                   attitude_grid=law.attitude_grid[rows], ratio_grid=law.ratio_grid[rows],
                   ratio_rate_grid=law.ratio_rate_grid[rows], reason=law.reason[rows])
