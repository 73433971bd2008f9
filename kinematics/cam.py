"""The duckbill cam: timing at the mechanism's events, pitch curve, working profile, checks.

The cam is fixed to gearbox 2, coaxial with the planet gear at E; relative to
gearbox 2 the planter turns by ``-F(phi)``. The cam angle is ``theta = F(phi)``
(monotone: ``dF/dphi = r1 / (a - r1) > 0``), and the cam's frame is the planter's
frame at the catching position, so a planter-frame point ``q`` sits at
``Rot(-theta) q`` on the cam.

The follower is the lever of :class:`~kinematics.duckbill.DuckbillLinkage`; its
angle over the cam angle is a :class:`~kinematics.motion_laws.FollowerProgram`
whose phases are placed at the planting events (:func:`cam_timing`). The pitch
curve is the roller centre's path on the cam, with closed-form derivatives; the
working profile is the pitch curve moved one roller radius towards the cam.

Checks, each with where it fails (cam angle, carrier angle, phase):

* pressure angle: between the pitch curve's normal (the contact force) and the
  roller centre's velocity as a point of the lever (perpendicular to H-I);
* radius of curvature: where the pitch curve is convex its radius must exceed the
  roller's, else the working profile has a cusp and the roller undercuts it
  (``roller_undercut``); the working profile's smallest radius is reported.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from .scalar import brentq, minimize_scalar

from .duckbill import DuckbillLinkage
from .errors import DesignError, Problem
from .motion_laws import FollowerProgram
from .planar import cross, perp

__all__ = ["CamTiming", "cam_timing", "CamProfile", "CamCheck"]

TWO_PI = 2.0 * np.pi


@dataclass(frozen=True)
class CamTiming:
    """Carrier angles (rad, in one revolution from the catching point at 0) of the cam's phases.

    ``opening`` and ``closing`` are (start, end); ``events`` names the mechanism's
    events the phases were placed at (``lowest``, ``entry``, ``exit``,
    ``seedling_cleared``, ``catching`` = 2 pi, the next catch).
    """

    opening: tuple
    closing: tuple
    events: dict


def cam_timing(mechanism, events, *, seedling_height, opening_offset, opening_duration,
               closing_delay, closing_duration, closed_before_catch, path="cam"):
    """Place the cam's phases at the planting events (carrier angles in rad).

    * opening starts ``opening_offset`` after the lowest point (negative: before it)
      and lasts ``opening_duration``;
    * the duckbill stays open until the tip, having left the soil, is
      ``seedling_height`` above the soil line (it has passed the seedling), then
      ``closing_delay`` more; closing lasts ``closing_duration``;
    * closing must end ``closed_before_catch`` before the next catching point.

    Raises
    ------
    DesignError
        When the phases overlap, the tip never clears the seedling, or closing
        ends too late; each problem names its field.
    """
    lowest, exit_ = events.lowest, events.exit
    target = events.soil_level + seedling_height

    def height_above(phi):
        return mechanism.positions(np.array([phi]), points=("N",))["N"][0, 1] - target

    # the first carrier angle after the exit where the tip clears the seedling: scan, then Brent
    grid = np.linspace(exit_, TWO_PI, 721)
    heights = mechanism.positions(grid, points=("N",))["N"][:, 1] - target
    problems = []
    above = np.flatnonzero(heights >= 0.0)
    if len(above) == 0:
        raise DesignError.single(
            f"{path}.seedling_height", "seedling_not_cleared",
            f"after leaving the soil the tip never rises {seedling_height:g} mm above it "
            "before the next catch: lower the seedling height")
    k = int(above[0])
    cleared = float(grid[0]) if k == 0 else brentq(height_above, grid[k - 1], grid[k], xtol=1e-12)
    opening = (lowest + opening_offset, lowest + opening_offset + opening_duration)
    closing = (cleared + closing_delay, cleared + closing_delay + closing_duration)
    if opening[0] <= 0.0:
        problems.append(Problem(f"{path}.timing.opening_offset_deg", "phase_order",
                                f"opening would start {np.degrees(-opening[0]):.2f} deg before the "
                                "catching point"))
    if opening[1] > closing[0]:
        problems.append(Problem(
            f"{path}.timing.opening_duration_deg", "phase_order",
            f"opening ends at {np.degrees(opening[1]):.2f} deg, after closing must start "
            f"({np.degrees(closing[0]):.2f} deg, where the tip has cleared the seedling)"))
    latest = TWO_PI - closed_before_catch
    if closing[1] > latest:
        problems.append(Problem(
            f"{path}.timing.closing_duration_deg", "closes_too_late",
            f"closing ends at carrier angle {np.degrees(closing[1]):.2f} deg, later than "
            f"{np.degrees(latest):.2f} deg ({np.degrees(closed_before_catch):g} deg before the "
            "next catch): shorten the closing or the seedling height"))
    if problems:
        raise DesignError(problems)
    return CamTiming(opening=opening, closing=closing, events={
        "entry": float(events.entry), "lowest": float(lowest), "exit": float(exit_),
        "seedling_cleared": float(cleared), "catching": TWO_PI})


@dataclass(frozen=True)
class CamCheck:
    """Extremes of the cam's checks and where they occur (angles in rad)."""

    pressure_angle_max: float
    pressure_angle_at: float          # cam angle
    pitch_radius_convex_min: float    # smallest convex radius of curvature of the pitch curve
    pitch_radius_at: float
    profile_radius_min: float         # smallest radius of curvature of the working profile
    problems: list = field(default_factory=list)   # Problem records (checks that fail)


@dataclass(frozen=True)
class CamProfile:
    """A plate cam driving the duckbill lever through a roller.

    Attributes
    ----------
    linkage : DuckbillLinkage
    program : FollowerProgram
        Lever angle (rad) over the cam angle.
    roller_radius : float
        mm.
    carrier_of_cam : callable
        Cam angle -> carrier angle (the inverse of ``F``), for reporting where.
    """

    linkage: DuckbillLinkage
    program: FollowerProgram
    roller_radius: float
    carrier_of_cam: object = None

    # ------------------------------------------------------------ geometry
    def pitch_point(self, theta):
        """Roller centre on the cam and its first two cam-angle derivatives: (n, 2) each.

        ``P = Rot(-theta) q(theta)`` with ``q`` the roller centre in the planter
        frame: ``P' = Rot(-theta)(q' - J q)``, ``P'' = Rot(-theta)(q'' - 2 J q' - q)``.
        """
        theta = np.atleast_1d(np.asarray(theta, dtype=float))
        lam, dlam, ddlam = self.program(theta)
        q, q_lam, q_lamlam = self.linkage.roller_centre(lam)
        dq = q_lam * dlam[:, None]
        ddq = q_lamlam * dlam[:, None] ** 2 + q_lam * ddlam[:, None]
        return (_rotate(q, -theta), _rotate(dq - perp(q), -theta),
                _rotate(ddq - 2.0 * perp(dq) - q, -theta))

    def _orientation(self) -> float:
        # +1 when the pitch curve runs counter-clockwise with the cam angle (it runs
        # clockwise: the planter turns by -theta), for the outward normal's sign
        theta = np.linspace(0.0, TWO_PI, 256, endpoint=False)
        p = self.pitch_point(theta)[0]
        area = 0.5 * np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1])
        return 1.0 if area > 0 else -1.0

    def outward_normal(self, theta):
        """Unit normal of the pitch curve pointing away from the cam: (n, 2)."""
        _, d1, _ = self.pitch_point(theta)
        # the right-hand normal of a counter-clockwise curve points outwards
        normal = self._orientation() * np.stack([d1[:, 1], -d1[:, 0]], axis=-1)
        return normal / np.linalg.norm(normal, axis=1, keepdims=True)

    def pitch_curvature(self, theta):
        """Signed curvature of the pitch curve (1/mm): positive where it is convex (bulges out)."""
        _, d1, d2 = self.pitch_point(theta)
        return self._orientation() * cross(d1, d2) / np.linalg.norm(d1, axis=1) ** 3

    def pressure_angle(self, theta):
        """Pressure angle (rad, 0..pi/2) between the contact normal and the roller's lever velocity."""
        theta = np.atleast_1d(np.asarray(theta, dtype=float))
        lam = self.program(theta)[0]
        _, q_lam, _ = self.linkage.roller_centre(lam)
        direction = _rotate(q_lam, -theta)
        normal = self.outward_normal(theta)
        # atan2 of |sin| and |cos| keeps full precision near 0 where arccos would not
        return np.arctan2(np.abs(cross(normal, direction)), np.abs(np.sum(normal * direction, axis=1)))

    def pitch_curve(self, points: int):
        """The pitch curve at ``points`` equal cam-angle steps, counter-clockwise: (points, 2)."""
        theta = np.linspace(0.0, TWO_PI, points, endpoint=False)
        curve = self.pitch_point(theta)[0]
        return curve if self._orientation() > 0 else curve[::-1]

    def working_profile(self, points: int):
        """The cam's contour: the pitch curve moved one roller radius inwards, counter-clockwise."""
        theta = np.linspace(0.0, TWO_PI, points, endpoint=False)
        contour = self.pitch_point(theta)[0] - self.roller_radius * self.outward_normal(theta)
        return contour if self._orientation() > 0 else contour[::-1]

    def follower_at_carrier(self, phi, cam_angle):
        """Lever angle (rad), roller lift (mm) and blade opening (rad) at carrier angles ``phi``.

        ``cam_angle`` is the function ``F``; the lift is the roller centre's
        distance from E less the base radius.
        """
        lam = self.program(cam_angle(phi))[0]
        centre = self.linkage.roller_centre(lam)[0]
        lift = np.linalg.norm(centre, axis=1) - self.linkage.base_radius
        return lam, lift, self.linkage.opening_of_lever(lam)

    # -------------------------------------------------------------- checks
    def check(self, *, max_pressure_angle: float, samples: int = 7200, path: str = "cam") -> CamCheck:
        """Pressure angle and radius of curvature against their limits, refined by Brent."""
        theta = np.linspace(0.0, TWO_PI, samples, endpoint=False)
        step = TWO_PI / samples
        angle_max, angle_at = _refined_extreme(lambda t: -self.pressure_angle(t)[0],
                                               -self.pressure_angle(theta), theta, step)
        angle_max = -angle_max
        curvature = self.pitch_curvature(theta)
        convex = curvature > 0
        # the smallest convex radius is the largest positive curvature
        kappa_max, kappa_at = _refined_extreme(lambda t: -self.pitch_curvature(t)[0],
                                               -curvature, theta, step)
        kappa_max = -kappa_max
        radius_convex_min = 1.0 / kappa_max if kappa_max > 0 else np.inf
        with np.errstate(divide="ignore"):
            radius = 1.0 / curvature
        # the working profile's radius: rho - r_roller where convex (negative: a cusp),
        # |rho| + r_roller where concave
        profile_min = min(radius_convex_min - self.roller_radius,
                          float(np.min(np.abs(radius[~convex]), initial=np.inf)) + self.roller_radius)
        problems = []
        where = self._where(angle_at)
        if angle_max > max_pressure_angle:
            problems.append(Problem(
                f"{path}.max_pressure_angle_deg", "pressure_angle_too_large",
                f"pressure angle reaches {np.degrees(angle_max):.2f} deg (limit "
                f"{np.degrees(max_pressure_angle):g}) {where}: lengthen the phase or enlarge the "
                "base radius"))
        if radius_convex_min <= self.roller_radius:
            undercut = theta[convex & (radius <= self.roller_radius)]
            span = (f"over {np.degrees(undercut.min()):.1f}..{np.degrees(undercut.max()):.1f} deg of "
                    "cam angle" if len(undercut) else "")
            problems.append(Problem(
                f"{path}.roller_radius", "roller_undercut",
                f"the {self.roller_radius:g}-mm roller is larger than the pitch curve's smallest "
                f"convex radius of curvature, {radius_convex_min:.3f} mm {self._where(kappa_at)} "
                f"{span}: the working profile would have a cusp and the roller would not follow "
                f"the law there; use a roller under {radius_convex_min:.2f} mm, a longer phase or "
                "a larger base radius"))
        return CamCheck(float(angle_max), float(angle_at), float(radius_convex_min),
                        float(kappa_at), profile_min, problems)

    def _where(self, theta) -> str:
        phase = self.program.phase_of(np.array([theta]))[0]
        text = f"at cam angle {np.degrees(theta):.2f} deg"
        if self.carrier_of_cam is not None:
            text += f" (carrier angle {np.degrees(self.carrier_of_cam(theta)):.2f} deg)"
        return f"{text}, {phase}"


def _refined_extreme(function, values, grid, step):
    """Minimum of ``function`` (sampled as ``values`` on ``grid``), polished by bounded Brent."""
    k = int(np.argmin(values))
    best = minimize_scalar(function, bounds=(grid[k] - step, grid[k] + step), method="bounded",
                           options={"xatol": 1e-12})
    if best.fun < values[k]:
        return float(best.fun), float(np.mod(best.x, TWO_PI))
    return float(values[k]), float(grid[k])


def _rotate(v, angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.stack([c * v[:, 0] - s * v[:, 1], s * v[:, 0] + c * v[:, 1]], axis=-1)
