"""Follower motion laws, and the periodic dwell-rise-dwell-return program of a cam.

A motion law maps the normalised phase ``x`` in [0, 1] to the normalised lift
``s`` in [0, 1] with zero velocity at both ends; each law here returns ``s`` and
its first two derivatives in closed form, so the cam's pitch curve, pressure
angle and radius of curvature need no finite differences.

* ``"cycloidal"`` (the default): ``s = x - sin(2 pi x) / (2 pi)``; zero velocity and
  zero acceleration at both ends (no jump in acceleration, finite jerk);
* ``"polynomial-345"``: ``s = 10 x^3 - 15 x^4 + 6 x^5``; the same end conditions
  with a lower peak acceleration (5.77 against 6.28).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import DesignError, Problem

__all__ = ["MOTION_LAWS", "cycloidal", "polynomial_345", "FollowerProgram"]

TWO_PI = 2.0 * np.pi


def cycloidal(x):
    """Cycloidal law: ``(s, ds/dx, d2s/dx2)`` at normalised phases ``x`` in [0, 1]."""
    x = np.asarray(x, dtype=float)
    angle = TWO_PI * x
    return x - np.sin(angle) / TWO_PI, 1.0 - np.cos(angle), TWO_PI * np.sin(angle)


def polynomial_345(x):
    """3-4-5 polynomial law: ``(s, ds/dx, d2s/dx2)`` at normalised phases ``x`` in [0, 1]."""
    x = np.asarray(x, dtype=float)
    return (x**3 * (10.0 - 15.0 * x + 6.0 * x**2), 30.0 * x**2 * (1.0 - x) ** 2,
            60.0 * x * (1.0 - x) * (1.0 - 2.0 * x))


MOTION_LAWS = {"cycloidal": cycloidal, "polynomial-345": polynomial_345}
"""The motion laws by the names the parameter files use."""


@dataclass(frozen=True)
class FollowerProgram:
    """Periodic follower displacement over the cam angle: low dwell, rise, high dwell, return.

    Attributes
    ----------
    lift : float
        Follower displacement of the rise (the unit of the follower: rad for a lever).
    rise : (float, float)
        Cam angles (rad) where the rise starts and ends; the end is after the start.
    fall : (float, float)
        Cam angles (rad) where the return starts and ends, after the rise and
        ending at most one turn after the rise starts.
    rise_law, fall_law : str
        Keys of :data:`MOTION_LAWS`.
    """

    lift: float
    rise: tuple
    fall: tuple
    rise_law: str = "cycloidal"
    fall_law: str = "cycloidal"

    def __post_init__(self):
        problems = []
        (r0, r1), (f0, f1) = self.rise, self.fall
        for name, law in (("rise_law", self.rise_law), ("fall_law", self.fall_law)):
            if law not in MOTION_LAWS:
                problems.append(Problem(name, "unknown_law", f"motion law {law!r} is not one of "
                                        f"{', '.join(MOTION_LAWS)}"))
        if not (r0 < r1 <= f0 < f1 <= r0 + TWO_PI):
            problems.append(Problem(
                "", "phase_order",
                f"cam phases out of order: rise {np.degrees(r0):.3f}..{np.degrees(r1):.3f} deg, "
                f"return {np.degrees(f0):.3f}..{np.degrees(f1):.3f} deg must follow each other "
                "within one turn"))
        if problems:
            raise DesignError(problems)

    def __call__(self, theta):
        """Displacement and its first two derivatives over the cam angle ``theta`` (rad, any turn)."""
        (r0, r1), (f0, f1) = self.rise, self.fall
        # phase measured from the start of the rise, in [0, 2 pi): the program is periodic
        phase = np.mod(np.asarray(theta, dtype=float) - r0, TWO_PI)
        rise_span, fall_start, fall_span = r1 - r0, f0 - r0, f1 - f0
        s = np.zeros_like(phase)
        ds = np.zeros_like(phase)
        dds = np.zeros_like(phase)
        rising = phase < rise_span
        s[(phase >= rise_span) & (phase < fall_start)] = self.lift
        falling = (phase >= fall_start) & (phase < fall_start + fall_span)
        if rising.any():
            x = phase[rising] / rise_span
            v, dv, ddv = MOTION_LAWS[self.rise_law](x)
            s[rising] = self.lift * v
            ds[rising] = self.lift * dv / rise_span
            dds[rising] = self.lift * ddv / rise_span**2
        if falling.any():
            x = (phase[falling] - fall_start) / fall_span
            v, dv, ddv = MOTION_LAWS[self.fall_law](x)
            s[falling] = self.lift * (1.0 - v)
            ds[falling] = -self.lift * dv / fall_span
            dds[falling] = -self.lift * ddv / fall_span**2
        return s, ds, dds

    def phase_of(self, theta):
        """Name of the phase at each cam angle: ``"closed"``, ``"opening"``, ``"open"``, ``"closing"``."""
        (r0, r1), (f0, f1) = self.rise, self.fall
        phase = np.mod(np.asarray(theta, dtype=float) - r0, TWO_PI)
        names = np.full(phase.shape, "closed", dtype=object)
        names[phase < r1 - r0] = "opening"
        names[(phase >= r1 - r0) & (phase < f0 - r0)] = "open"
        names[(phase >= f0 - r0) & (phase < f1 - r0)] = "closing"
        return names
