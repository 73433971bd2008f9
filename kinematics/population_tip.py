"""The duckbill tip of N planting designs: on the shared grid and off it, with closed-form derivatives.

The same model as :class:`kinematics.planting.PlantingMechanism` (spec frame: x forward, y
up; carrier 1 clockwise), written for arrays ``(N, p)`` of carrier angles, one row a design:

    C = Rc u(phi0 - phi),  E = C + (a + 2 r) u(phic + phi),
    N = E - L1 u(Psi) - L2 u(Psi + 90 deg),  Psi = phi - F(phi),

``dPsi/dphi = 1 - w`` and ``d2Psi/dphi2 = -dw/dphi`` with the ratio law ``w`` in closed form,
so the refinements below step on exact slopes, never on differences of samples.
"""

from __future__ import annotations

import numpy as np

from .population_closure import PairLaw

__all__ = ["TrainArrays", "tip_on_grid", "tip_at", "arm_points_on_grid", "arm_points_at",
           "refine_extreme", "refine_crossing"]

TWO_PI = 2.0 * np.pi

#: Newton steps polishing an extreme of the tip height off the grid (quadratic convergence
#: from within half a grid step: three leave round-off).
EXTREME_STEPS = 3
#: Safeguarded Newton steps locating a soil crossing inside its grid bracket.
CROSSING_STEPS = 8
#: A crossing is located once a Newton step is below this (rad).
ROOT_ATOL = 1e-14


class TrainArrays:
    """The train and planter of N designs, each attribute (N, 1) so it broadcasts over angles.

    ``Rc = 2 R (1 + i12 + i13)``, ``reach = a + 2 r`` (C to E), ``L1``, ``L2``, ``phi0``, ``phic``.
    """

    def __init__(self, designs: dict, law: PairLaw):
        def column(name):
            return np.asarray(designs[name], dtype=float)[:, None]

        self.Rc = 2.0 * column("R") * (1.0 + column("i12") + column("i13"))
        self.reach = law.centre_distance[:, None] + 2.0 * column("r")
        self.L1, self.L2 = column("L1"), column("L2")
        self.phi0, self.phic = column("phi0"), column("phic")
        self.law = law


def _tip(train: TrainArrays, phi, psi, psi_rate=None, psi_rate_rate=None):
    """Tip position (and velocity, acceleration when the attitude's rates are given)."""
    carrier = train.phi0 - phi
    box = train.phic + phi
    cos_c, sin_c = np.cos(carrier), np.sin(carrier)
    cos_b, sin_b = np.cos(box), np.sin(box)
    cos_p, sin_p = np.cos(psi), np.sin(psi)
    L1, L2, Rc, reach = train.L1, train.L2, train.Rc, train.reach
    # the planter's offset -L1 u(Psi) - L2 u(Psi + 90deg) and its turn by +90 deg
    off_x, off_y = -L1 * cos_p + L2 * sin_p, -L1 * sin_p - L2 * cos_p
    out = {"x": Rc * cos_c + reach * cos_b + off_x, "y": Rc * sin_c + reach * sin_b + off_y,
           "psi": psi}
    if psi_rate is None:
        return out
    out["dx"] = Rc * sin_c - reach * sin_b - psi_rate * off_y
    out["dy"] = -Rc * cos_c + reach * cos_b + psi_rate * off_x
    out["ddx"] = -Rc * cos_c - reach * cos_b - psi_rate_rate * off_y - psi_rate**2 * off_x
    out["ddy"] = -Rc * sin_c - reach * sin_b + psi_rate_rate * off_x - psi_rate**2 * off_y
    return out


def tip_on_grid(train: TrainArrays, samples: int) -> dict:
    """Tip positions of arm 0 on the grid ``phi_j = 2 pi j / K``: ``{"x", "y", "psi"}`` each (N, K)."""
    phi = np.arange(samples) * (TWO_PI / samples)
    return _tip(train, phi, train.law.attitude_grid)


def tip_at(train: TrainArrays, phi, arm: int = 0) -> dict:
    """Tip position, velocity and acceleration (per rad) at carrier angles ``phi`` (N, p)."""
    phi = np.asarray(phi, dtype=float) + np.pi * arm
    w, w_rate = train.law.ratio(phi)
    return _tip(train, phi, train.law.attitude(phi), 1.0 - w, -w_rate)


def _arm_points(train, phi, psi):
    """C, E, P1, N of one arm as (x, y) pairs of arrays the shape of ``phi``."""
    cos_c, sin_c = np.cos(train.phi0 - phi), np.sin(train.phi0 - phi)
    cos_b, sin_b = np.cos(train.phic + phi), np.sin(train.phic + phi)
    cos_p, sin_p = np.cos(psi), np.sin(psi)
    c = (train.Rc * cos_c, train.Rc * sin_c)
    e = (c[0] + train.reach * cos_b, c[1] + train.reach * sin_b)
    p1 = (e[0] - train.L1 * cos_p, e[1] - train.L1 * sin_p)
    n = (p1[0] + train.L2 * sin_p, p1[1] - train.L2 * cos_p)
    return c, e, p1, n


def arm_points_on_grid(train: TrainArrays, samples: int, stride: int = 1):
    """Centre lines C-E-P1-N of both arms on every ``stride``-th grid angle of half a revolution.

    Arm 1 is arm 0 half a revolution later: on an even grid its attitude is the grid's,
    shifted by ``K/2``. Returns ``(phi (m,), arm0, arm1)``, each arm four (x, y) pairs (N, m).
    """
    index = np.arange(0, samples // 2, stride)
    phi = index * (TWO_PI / samples)
    psi = train.law.attitude_grid
    arm0 = _arm_points(train, phi, psi[:, index])
    arm1 = _arm_points(train, phi + np.pi, psi[:, index + samples // 2])
    return phi, arm0, arm1


def arm_points_at(train: TrainArrays, phi):
    """Centre lines of both arms at carrier angles ``phi`` (N, p), off the grid (the series)."""
    phi = np.asarray(phi, dtype=float)
    arm0 = _arm_points(train, phi, train.law.attitude(phi))
    arm1 = _arm_points(train, phi + np.pi, train.law.attitude(phi + np.pi))
    return arm0, arm1


def refine_extreme(train: TrainArrays, phi_grid_best, value_grid_best, sign: float, h: float):
    """Polish the lowest (``sign`` 1) or highest (-1) tip height next to its best grid sample.

    Newton on ``dy/dphi = 0`` with the closed-form ``d2y/dphi2``, kept within one grid step;
    never worse than the sample. Returns ``(phi, y)``, each (N,).
    """
    start = np.asarray(phi_grid_best, dtype=float)
    phi = start.copy()
    for _ in range(EXTREME_STEPS):
        tip = tip_at(train, phi[:, None])
        dy, ddy = tip["dy"][:, 0], tip["ddy"][:, 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            step = np.where(sign * ddy > 0.0, -dy / ddy, 0.0)
        phi = np.clip(phi + np.nan_to_num(step), start - h, start + h)
    y = tip_at(train, phi[:, None])["y"][:, 0]
    better = sign * y <= sign * value_grid_best
    return np.where(better, phi, start), np.where(better, y, value_grid_best)


def refine_crossing(train: TrainArrays, low, high, g_low, g_high, level):
    """Where the tip height crosses ``level`` in ``[low, high]`` (N, p), by safeguarded Newton.

    ``g_low``, ``g_high`` are ``y - level`` at the bracket's ends, of opposite signs: a Newton
    step that leaves the shrinking bracket is replaced by bisection, so every step keeps
    the root bracketed.
    """
    low, high = np.array(low, dtype=float), np.array(high, dtype=float)
    g_low = np.asarray(g_low, dtype=float)
    level = np.asarray(level, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        phi = low - g_low * (high - low) / (np.asarray(g_high, dtype=float) - g_low)
    phi = np.where(np.isfinite(phi), phi, 0.5 * (low + high))
    done = np.zeros(phi.shape, dtype=bool)
    for _ in range(CROSSING_STEPS):
        tip = tip_at(train, phi)
        gap, slope = tip["y"] - level, tip["dy"]
        same = np.sign(gap) == np.sign(g_low)
        low, high = np.where(same, phi, low), np.where(same, high, phi)
        g_low = np.where(same, gap, g_low)
        with np.errstate(divide="ignore", invalid="ignore"):
            newton = phi - gap / slope
        inside = np.isfinite(newton) & (newton >= low) & (newton <= high)
        step = np.where(inside, newton, 0.5 * (low + high))
        # a row stops where its step vanishes (its root to round-off): frozen, it does not
        # wander off on round-off while other rows go on
        done |= (gap == 0.0) | (np.abs(step - phi) <= ROOT_ATOL)
        phi = np.where(done, phi, step)
    return phi
