"""The pricking mechanism in the field: absolute needle motion and the inclined mechanism plane.

Absolute tip motion ``X = x_D + v t`` with ``t`` the time since the Rmax dead
centre at carrier speed ``omega`` (the tip goes round the loop in the points'
order; the carrier turns the way the accepted assembly mode says). The
mechanism plane is inclined by ``theta`` about the travel direction: vertical
components in the hole's vertical plane are ``y cos(theta)``, each applied once
(the paper's eq. 12 applies it twice). The vertical pricking depth is kept,
so in the mechanism plane the surface line sits at ``y_min + depth / cos(theta)``.

Angles are reported as *carrier progress* in degrees: the carrier's turn since
the Rmax dead centre, increasing with time whatever the carrier's sense.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from .scalar import brentq, minimize_scalar

from .errors import DesignError, Problem
from .pricking import PrickingDesign
from .planar import unit as _unit

__all__ = ["NeedleGeometry", "InclinationResult", "needle_geometry", "field_motion"]

TWO_PI = 2.0 * np.pi


@dataclass(frozen=True)
class NeedleGeometry:
    """The rocker (l1, fixed to the planet) and the needle (l2, perpendicular to it).

    ``side`` is +1 or -1: the needle turns +-90 degrees from the rocker, chosen so
    that it points down at the bottom of the loop.
    """

    rocker: float
    needle: float
    side: int

    def axis_angle(self, tip_angle):
        """Needle axis direction (root to tip) from the tip angle ``phi2`` of ``BD``."""
        beta = np.arctan2(self.needle, self.rocker)
        return np.asarray(tip_angle) + self.side * (0.5 * np.pi - beta)


def needle_geometry(design: PrickingDesign) -> NeedleGeometry:
    motion = design.motion
    v = np.linspace(0.0, motion.period, 4096, endpoint=False)
    lowest = v[np.argmin(motion.curve(motion.u(v))[:, 1])]
    phi2 = float(motion.phi2(lowest))
    options = [NeedleGeometry(design.linkage.rocker, design.linkage.needle, side)
               for side in (1, -1)]
    return min(options, key=lambda n: np.sin(n.axis_angle(phi2)))


@dataclass(frozen=True)
class InclinationResult:
    """Field figures at one inclination angle (mm, deg, carrier-progress deg)."""

    inclination_deg: float
    surface_level: float
    entry_progress_deg: float
    exit_progress_deg: float
    entry_angle_deg: float
    exit_angle_deg: float
    time_in_soil_deg: float
    hole_mouth: float
    mouth_range: tuple
    slow_windows_deg: list
    slow_window_total_deg: float
    projected_height: float
    width: float
    needle_root_in_soil: bool
    entry_parameter: float = 0.0
    exit_parameter: float = 0.0


class _FieldModel:
    """Positions, needle and timing along the curve parameter of an accepted design."""

    def __init__(self, design: PrickingDesign, carrier_speed_rpm: float, forward_speed: float):
        self.design = design
        self.motion = design.motion
        self.omega = TWO_PI * carrier_speed_rpm / 60.0
        self.speed = forward_speed
        self.needle = needle_geometry(design)
        self.start = self.motion.phi1_start

    def _wrap(self, v):
        v = np.asarray(v, dtype=float)
        turns = np.floor(v / self.motion.period)
        return v - turns * self.motion.period, turns

    def progress(self, v):
        """Carrier turn since the Rmax dead centre (rad, increasing with time; v any real)."""
        local, turns = self._wrap(v)
        return self.motion.sense * (self.motion.phi1(local) - self.start) + TWO_PI * turns

    def tip(self, v):
        return self.motion.curve(self.motion.u(self._wrap(v)[0]))

    def absolute_x(self, v):
        return self.tip(v)[..., 0] + self.speed * self.progress(v) / self.omega

    def axis(self, v):
        return self.needle.axis_angle(self.motion.phi2(self._wrap(v)[0]))

    def root(self, v):
        return self.tip(v) - self.needle.needle * _unit(self.axis(v))

    def horizontal_speed(self, v):
        """dX/dt (mm/s): the tip's relative x-speed along the loop plus the machine's."""
        local = self._wrap(v)[0]
        dx_dv = self.motion.curve(self.motion.u(local), 1)[..., 0]
        dv_dt = self.omega / np.abs(self.motion.phi1_rate(local))
        return dx_dv * dv_dt + self.speed


def _roots(function, grid, values):
    """Every sign change of ``values`` on ``grid``, polished by Brent's method."""
    change = np.flatnonzero(np.sign(values[:-1]) * np.sign(values[1:]) < 0)
    return np.array([brentq(function, grid[k], grid[k + 1], xtol=1e-12) for k in change])


def field_motion(design: PrickingDesign, *, carrier_speed_rpm: float, forward_speed: float,
                 depth: float, inclinations_deg, samples: int = 8192) -> list:
    """Entry and exit angles, hole mouth, time in soil, slow window, size: per inclination.

    Raises
    ------
    DesignError
        ``no_soil_crossing`` (path ``field.depth``) when the tip cannot climb
        out of the soil at some inclination.
    """
    model = _FieldModel(design, carrier_speed_rpm, forward_speed)
    period = model.motion.period
    grid = np.linspace(0.0, period, samples + 1)
    tip = model.tip(grid)
    y_low_index = int(np.argmin(tip[:-1, 1]))
    low = minimize_scalar(lambda s: float(model.tip(np.array([s]))[0, 1]),
                          bounds=(grid[max(y_low_index - 1, 0)], grid[y_low_index + 1]),
                          method="bounded", options={"xatol": 1e-12 * period})
    v_low, y_min = float(low.x), float(low.fun)
    y_max = float(tip[:, 1].max())
    width = float(np.ptp(tip[:, 0]))
    # horizontal-speed sign changes do not depend on the inclination
    slow = _slow_windows(model, grid)
    # one plant, seen from the lowest point: half a loop either side of it
    around = grid - 0.5 * period + v_low
    results = []
    for theta_deg in inclinations_deg:
        theta = np.radians(theta_deg)
        surface = y_min + depth / np.cos(theta)
        if surface >= y_max:
            raise DesignError([Problem(
                "field.depth", "no_soil_crossing",
                f"at inclination {theta_deg:g} deg the surface line in the mechanism plane "
                f"({depth:g} / cos(theta) = {depth / np.cos(theta):.2f} mm above the lowest point) "
                f"is above the whole loop (height {y_max - y_min:.2f} mm)")])

        def gap(v):
            return model.tip(np.atleast_1d(v))[..., 1] - surface

        crossings = _roots(lambda s: float(gap(s)[0]), around, gap(around))
        entry = crossings[crossings < v_low].max()
        leave = crossings[crossings > v_low].min()
        axis = model.axis(np.array([entry, leave]))
        angles = np.degrees(np.arctan(np.abs(np.sin(axis)) * np.cos(theta) / np.abs(np.cos(axis))))
        # hole mouth: where the needle shaft crosses the surface while the tip is below it
        window = np.linspace(entry, leave, 2001)
        tips, roots = model.tip(window), model.root(window)
        above = roots[:, 1] > surface
        share = (surface - tips[:, 1]) / np.where(above, roots[:, 1] - tips[:, 1], 1.0)
        crossing_x = tips[:, 0] + share * (roots[:, 0] - tips[:, 0])
        crossing_x = crossing_x + model.speed * model.progress(window) / model.omega
        crossing_x = crossing_x[above]
        mouth = (float(crossing_x.min()), float(crossing_x.max())) if crossing_x.size else (0.0, 0.0)
        results.append(InclinationResult(
            inclination_deg=float(theta_deg), surface_level=float(surface),
            entry_progress_deg=float(np.degrees(model.progress(entry))),
            exit_progress_deg=float(np.degrees(model.progress(leave))),
            entry_angle_deg=float(angles[0]), exit_angle_deg=float(angles[1]),
            time_in_soil_deg=float(np.degrees(model.progress(leave) - model.progress(entry))),
            hole_mouth=mouth[1] - mouth[0], mouth_range=mouth,
            slow_windows_deg=slow, slow_window_total_deg=float(sum(b - a for a, b in slow)),
            projected_height=float((y_max - y_min) * np.cos(theta)), width=width,
            needle_root_in_soil=bool((~above).any()),
            entry_parameter=float(entry), exit_parameter=float(leave)))
    return results


def _slow_windows(model: _FieldModel, grid):
    """Carrier-progress windows (deg) where the tip's absolute horizontal speed is below 10 % of v."""
    threshold = 0.1 * model.speed

    def excess(v):
        return float(np.abs(model.horizontal_speed(np.array([v])))[0] - threshold)

    values = np.abs(model.horizontal_speed(grid)) - threshold
    edges = list(_roots(excess, grid, values))
    if values[0] < 0.0:  # slow across the start of the loop: the window wraps round
        edges = edges[1:] + [edges[0] + grid[-1]] if edges else []
    windows = []
    for start, stop in zip(edges[::2], edges[1::2]):
        windows.append([float(np.degrees(model.progress(start))),
                        float(np.degrees(model.progress(stop)))])
    return windows
