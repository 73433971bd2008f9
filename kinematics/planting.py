"""Mechanism kind 1: the high-catching low-planting differential planetary planting mechanism.

Model and conventions exactly as ``shared/spec/planting-mechanism.md``: frame
x = forward travel, y = up, angles counter-clockwise, ``u(t) = (cos t, sin t)``;
``phi`` is the carrier-1 angle (carrier 1 turns clockwise), ``phi = 0`` at the
catching position. All positions come with closed-form first and second
derivatives with respect to ``phi`` (``dF/dphi = r1/(a - r1)`` is known in closed
form), so velocities and accelerations are never finite-differenced.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from . import tolerances as tol
from .pitch_curves import Closure, LimaconPitchCurve, polar_perimeter, solve_closure
from .planar import unit as _unit, perp as _perp

__all__ = ["PlantingMechanism", "PointMotion", "ARM_POINTS", "CENTRE_LINE", "rotating_offset"]

#: Named points of one arm, from the carrier to the duckbill tip.
ARM_POINTS = ("A", "B", "C", "D", "E", "P1", "N")
#: The arm's centre line used for the kinematic arm-distance check.
CENTRE_LINE = ("C", "E", "P1", "N")


@dataclass(frozen=True)
class PointMotion:
    """Position and its first two derivatives with respect to the carrier angle.

    Attributes
    ----------
    position, velocity, acceleration : (n, 2) float
        mm, mm/rad, mm/rad^2. Multiply by ``omega`` and ``omega**2`` for time.
    """

    position: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray


@dataclass(frozen=True)
class PlantingMechanism:
    """Geometry of the planting mechanism (lengths mm, angles rad).

    Parameters
    ----------
    pitch_curve : LimaconPitchCurve
        Central non-circular gear, ``r1(t)``.
    i12, i13 : float
        Ratios of the first planetary train, placing A, B and C on carrier 1.
    R : float
        Sun radius of the first train (mm).
    r : float
        Radius of the 1:1 circular pair at D and E (mm).
    L1, L2 : float
        Planter offsets: P1 is L1 behind E, the tip N is L2 below P1 (mm).
    phi0 : float
        Direction of O->C at the catching position (rad).
    phic : float
        Direction of C->E (gearbox 2) at the catching position (rad).
    n : float
        Central-shaft speed over carrier-1 speed (> 1).
    closure_rtol : float
        Relative tolerance of the closure quadrature.
    """

    pitch_curve: LimaconPitchCurve
    i12: float
    i13: float
    R: float
    r: float
    L1: float
    L2: float
    phi0: float = np.pi / 2
    phic: float = np.pi / 2
    n: float = 3.0
    closure_rtol: float = tol.CLOSURE_RTOL

    # ----------------------------------------------------------------- train
    @cached_property
    def closure(self) -> Closure:
        """The 1:1 closure of the non-circular pair (centre distance a)."""
        return solve_closure(self.pitch_curve, rtol=self.closure_rtol)

    @cached_property
    def pitch_perimeter(self) -> float:
        """Perimeter of the central gear's pitch curve ``rho = r1(t)`` (mm)."""
        return polar_perimeter(self.pitch_curve)

    def module(self, teeth: int) -> float:
        """Module of the non-circular pair with ``teeth`` teeth: perimeter / (pi z) (spec)."""
        return self.pitch_perimeter / (np.pi * teeth)

    @property
    def centre_distance(self) -> float:
        return self.closure.centre_distance

    @property
    def carrier_radii(self) -> dict:
        """Distances of A, B and C from O (mm)."""
        R, i12, i13 = self.R, self.i12, self.i13
        return {"A": R * (1 + i12), "B": R * (1 + 2 * i12 + i13), "C": 2 * R * (1 + i12 + i13)}

    @property
    def converted_ratios(self) -> tuple[float, float]:
        """Converted-train ratios (sun to planet) of the two parallel sets of train 1.

        The gearbox-2 set must counter-rotate (planet at -1 x carrier) and the
        other set must not rotate, given the sun at ``n`` x carrier: ratios
        ``-2/(n - 1)`` and ``-1/(n - 1)`` (-1 and -1/2 for n = 3).
        """
        return -2.0 / (self.n - 1.0), -1.0 / (self.n - 1.0)

    def attitude(self, phi):
        """Planter attitude ``Psi = phi - F(phi)`` (rad), exactly periodic, 0 = upright."""
        return -self.closure.law.periodic_part(phi)

    def intermediate_rotation(self, phi):
        """Intermediate-gear rotation ``F(phi)`` relative to gearbox 2 (rad)."""
        return self.closure.law.integral(phi)

    def attitude_derivatives(self, phi):
        """``(Psi, dPsi/dphi, d2Psi/dphi2)``, each the shape of ``phi``."""
        phi = np.asarray(phi, dtype=float)
        ratio, ratio_rate = self.closure.law.ratio(phi)
        return self.attitude(phi), 1.0 - ratio, -ratio_rate

    # --------------------------------------------------------------- points
    def motion(self, phi, point: str = "N", arm: int = 0) -> PointMotion:
        """Position, velocity and acceleration of one named point of one arm.

        Parameters
        ----------
        phi : (n,) float
            Carrier-1 angles (rad), any number of revolutions.
        point : {"A", "B", "C", "D", "E", "P1", "N"}
        arm : {0, 1}
            Arm 1 is arm 0 shifted by 180 degrees of carrier angle.
        """
        if point not in ARM_POINTS:
            raise ValueError(f"point must be one of {ARM_POINTS}, not {point!r}")
        if arm not in (0, 1):
            raise ValueError(f"arm must be 0 or 1, not {arm!r}")
        phi = np.atleast_1d(np.asarray(phi, dtype=float)) + np.pi * arm
        if point in ("A", "B", "C"):
            return self._carrier_point(phi, self.carrier_radii[point])
        centre = self._carrier_point(phi, self.carrier_radii["C"])
        if point in ("D", "E"):
            reach = self.centre_distance + (2 * self.r if point == "E" else 0.0)
            return rotating_offset(centre, self.phic + phi, 1.0, 0.0, reach * np.array([1.0, 0.0]))
        hub = rotating_offset(centre, self.phic + phi, 1.0, 0.0,
                               (self.centre_distance + 2 * self.r) * np.array([1.0, 0.0]))
        psi, dpsi, ddpsi = self.attitude_derivatives(phi)
        offset = np.array([-self.L1, 0.0 if point == "P1" else -self.L2])
        return rotating_offset(hub, psi, dpsi, ddpsi, offset)

    def absolute_motion(self, phi, spacing: float, point: str = "N", arm: int = 0) -> PointMotion:
        """Motion over the ground at plant spacing ``spacing`` (mm).

        The machine advances ``2 S`` per carrier revolution, so ``X = x + (S / pi) phi``:
        the velocity gains ``S / pi`` along x, the acceleration is unchanged
        (constant forward speed). Per radian; times ``omega`` (``omega**2``) for seconds.
        """
        relative = self.motion(phi, point, arm)
        phi = np.atleast_1d(np.asarray(phi, dtype=float))
        drift = spacing / np.pi
        position = relative.position + np.stack([drift * phi, np.zeros_like(phi)], axis=-1)
        velocity = relative.velocity + np.array([drift, 0.0])
        return PointMotion(position, velocity, relative.acceleration)

    def positions(self, phi, arm: int = 0, points=ARM_POINTS) -> dict:
        """Positions of several named points: ``{name: (n, 2) array}`` (mm).

        Shares the carrier, gearbox-2 and attitude terms between the points, so
        asking for four points costs little more than asking for one.
        """
        unknown = set(points) - set(ARM_POINTS)
        if unknown:
            raise ValueError(f"points must be among {ARM_POINTS}, not {sorted(unknown)}")
        phi = np.atleast_1d(np.asarray(phi, dtype=float)) + np.pi * arm
        carrier = _unit(self.phi0 - phi)
        radii = self.carrier_radii
        out = {name: radii[name] * carrier for name in ("A", "B", "C") if name in points}
        centre = radii["C"] * carrier
        box = _unit(self.phic + phi)
        a = self.centre_distance
        if "D" in points:
            out["D"] = centre + a * box
        hub = centre + (a + 2 * self.r) * box
        if "E" in points:
            out["E"] = hub
        if "P1" in points or "N" in points:
            psi = self.attitude(phi)
            back = -self.L1 * _unit(psi)
            if "P1" in points:
                out["P1"] = hub + back
            if "N" in points:
                out["N"] = hub + back - self.L2 * _perp(_unit(psi))
        return {name: out[name] for name in points}

    def _carrier_point(self, phi, radius) -> PointMotion:
        # carrier 1 turns clockwise: the direction of O->point is phi0 - phi
        direction = _unit(self.phi0 - phi)
        return PointMotion(radius * direction, -radius * _perp(direction), -radius * direction)

    # ------------------------------------------------------------- bounds
    def speed_bound(self, point: str = "N") -> float:
        # a hair above the exact bound so round-off in the motion never exceeds it
        return self._speed_bound(point) * (1.0 + 1e-12)

    def acceleration_bound(self, point: str = "N") -> float:
        return self._acceleration_bound(point) * (1.0 + 1e-12)

    def _speed_bound(self, point: str) -> float:
        """An upper bound (mm/rad) on the speed of ``point`` over all carrier angles.

        From the triangle inequality on the closed-form velocity: carrier terms
        move at their radius, gearbox-2 terms at (radius + reach), planter terms
        at most ``max|dPsi/dphi|`` times their offset. Used to certify minima
        between samples.
        """
        closure = self.closure
        rc = self.carrier_radii["C"]
        if point in ("A", "B", "C"):
            return self.carrier_radii[point]
        reach = closure.centre_distance + 2 * self.r
        if point == "D":
            return rc + closure.centre_distance
        if point == "E":
            return rc + reach
        spin = max(abs(1.0 - closure.ratio_min), abs(1.0 - closure.ratio_max))
        offset = self.L1 if point == "P1" else float(np.hypot(self.L1, self.L2))
        return rc + reach + spin * offset

    def _acceleration_bound(self, point: str) -> float:
        """An upper bound (mm/rad^2) on the acceleration of ``point`` over all carrier angles."""
        closure = self.closure
        a = closure.centre_distance
        rc = self.carrier_radii["C"]
        if point in ("A", "B", "C"):
            return self.carrier_radii[point]
        if point == "D":
            return rc + a
        hub = rc + a + 2 * self.r
        if point == "E":
            return hub
        spin = max(abs(1.0 - closure.ratio_min), abs(1.0 - closure.ratio_max))
        gap = a - closure.radius_max[1]
        spin_rate = a * self.pitch_curve.radius_rate_bound() / gap**2
        offset = self.L1 if point == "P1" else float(np.hypot(self.L1, self.L2))
        return hub + (spin_rate + spin**2) * offset

    def tip_path(self, arm: int = 0):
        """The duckbill tip N as a :class:`kinematics.metrics.TipPath`."""
        from .metrics import TipPath

        return TipPath(motion=lambda phi: self.motion(phi, "N", arm),
                       attitude=self.attitude if arm == 0 else (lambda phi: self.attitude(phi + np.pi)),
                       speed_bound=self.speed_bound("N"),
                       acceleration_bound=self.acceleration_bound("N"))

    def path_height_of_E(self) -> float:
        """Closed form height of the path of E: ``2 (Rc + a + 2 r)`` (mm)."""
        return 2.0 * (self.carrier_radii["C"] + self.centre_distance + 2 * self.r)


def rotating_offset(base: PointMotion, angle, rate, rate_rate, offset) -> PointMotion:
    """Motion of ``base + Rot(angle) @ offset`` where ``angle`` has the given derivatives.

    ``Q' = B' + angle' J Rot q``, ``Q'' = B'' + angle'' J Rot q - angle'^2 Rot q``.
    """
    angle = np.asarray(angle, dtype=float)
    cos, sin = np.cos(angle), np.sin(angle)
    arm = np.stack([cos * offset[0] - sin * offset[1], sin * offset[0] + cos * offset[1]], axis=-1)
    turned = _perp(arm)
    rate = np.asarray(rate, dtype=float)[..., None] if np.ndim(rate) else rate
    rate_rate = np.asarray(rate_rate, dtype=float)[..., None] if np.ndim(rate_rate) else rate_rate
    return PointMotion(
        base.position + arm,
        base.velocity + rate * turned,
        base.acceleration + rate_rate * turned - rate**2 * arm,
    )
