"""Kinematic clearances: distance between the two arms' centre lines, and housing-to-ground gap.

These are the kinematic forms of two design metrics (spec): the arm distance
between the centre-line polylines C-E-P1-N of the two arms, and the ground
clearance of housing envelope circles. The solid-based FCL versions take over
when a scene has solids; both return a :class:`~kinematics.sweep.CertifiedMinimum`
so a report can show either.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import tolerances as tol
from .planting import CENTRE_LINE, PlantingMechanism
from .sweep import CertifiedMinimum, certified_minimum
from .planar import cross as _cross

__all__ = [
    "segment_distances",
    "polyline_distance",
    "arm_distance",
    "HousingCircle",
    "ground_clearance",
    "KinematicClearance",
]


def _point_segment(points, starts, ends):
    """Distance from points to segments, all (..., 2) broadcast together."""
    direction = ends - starts
    length2 = np.einsum("...i,...i->...", direction, direction)
    offset = points - starts
    with np.errstate(invalid="ignore", divide="ignore"):
        along = np.einsum("...i,...i->...", offset, direction) / length2
    along = np.where(length2 > 0.0, np.clip(along, 0.0, 1.0), 0.0)
    nearest = starts + along[..., None] * direction
    return np.linalg.norm(points - nearest, axis=-1)


def segment_distances(p0, p1, q0, q1):
    """Distance between 2-D segments ``p0-p1`` and ``q0-q1``; arrays (..., 2), result (...).

    Zero when the segments cross; otherwise the least of the four end-point to
    segment distances (exact for segments in the plane).
    """
    p0, p1, q0, q1 = (np.asarray(v, dtype=float) for v in (p0, p1, q0, q1))
    d1 = _cross(p1 - p0, q0 - p0)
    d2 = _cross(p1 - p0, q1 - p0)
    d3 = _cross(q1 - q0, p0 - q0)
    d4 = _cross(q1 - q0, p1 - q0)
    crossing = (d1 * d2 < 0.0) & (d3 * d4 < 0.0)
    ends = np.minimum.reduce([
        _point_segment(p0, q0, q1), _point_segment(p1, q0, q1),
        _point_segment(q0, p0, p1), _point_segment(q1, p0, p1)])
    return np.where(crossing, 0.0, ends)


def polyline_distance(first, second):
    """Least distance between two open polylines per sample.

    Parameters
    ----------
    first, second : (n, k, 2) float
        ``n`` samples of polylines with ``k`` vertices.

    Returns
    -------
    (n,) float
    """
    first = np.asarray(first, dtype=float)
    second = np.asarray(second, dtype=float)
    a0, a1 = first[:, :-1, None, :], first[:, 1:, None, :]
    b0, b1 = second[:, None, :-1, :], second[:, None, 1:, :]
    return segment_distances(a0, a1, b0, b1).reshape(len(first), -1).min(axis=1)


def _centre_line(mechanism: PlantingMechanism, phi, arm):
    points = mechanism.positions(phi, arm=arm, points=CENTRE_LINE)
    return np.stack([points[name] for name in CENTRE_LINE], axis=1)


def arm_distance(mechanism: PlantingMechanism, *, steps: int = tol.STEPS_PER_REVOLUTION,
                 atol: float = tol.ARM_DISTANCE_ATOL,
                 max_evaluations: int = tol.ARM_DISTANCE_EVALUATIONS) -> CertifiedMinimum:
    """Certified least distance between the two arms' centre lines C-E-P1-N.

    The pair's distance repeats every half revolution (the arms swap), so half a
    revolution is searched with ``steps // 2`` samples. Where the centre lines
    cross the distance is 0 over a whole range of carrier angles: it is never
    negative (``floor = 0``), so a crossing found is the certified minimum.

    Bounds (``V``, ``A``: relative speed and acceleration of any two points of the
    arms; a point along a segment moves no faster than its faster end, so each is
    twice the largest bound of the centre-line points):

    - first order, ``|d'| <= V``;
    - second order, ``d'' <= A + V^2 / d`` where ``d > 0``: unbounded where the
      arms touch, where the distance has a kink;
    - second order on the squared distance, which stays valid there: for each pair
      of points ``w(t)``, ``(|w|^2)'' = 2 |w'|^2 + 2 w.w'' <= 2 V^2 + 2 |w| A``, so on an
      interval of width ``h`` with end values at least ``m``,
      ``d^2 >= m^2 - (V^2 + A (m + V h)) h^2 / 4``.

    Parameters
    ----------
    atol : float
        The search closes when the bound is within this of the value (mm).
    max_evaluations : int
        Budget of distance evaluations; a search that spends it reports
        ``certified = False`` with the gap ``[bound, value]`` it reached.
    """
    speed = 2.0 * max(mechanism.speed_bound(p) for p in CENTRE_LINE)
    accel = 2.0 * max(mechanism.acceleration_bound(p) for p in CENTRE_LINE)

    def distance(phi):
        return polyline_distance(_centre_line(mechanism, phi, 0), _centre_line(mechanism, phi, 1))

    def curvature(first_order_bounds):
        with np.errstate(divide="ignore"):
            return np.where(first_order_bounds > 0.0,
                            accel + speed**2 / first_order_bounds, np.inf)

    def squared_bound(f_left, f_right, width):
        nearest = np.minimum(f_left, f_right)
        squared = nearest**2 - (speed**2 + accel * (nearest + speed * width)) * width**2 / 4.0
        return np.sqrt(np.maximum(squared, 0.0))

    return certified_minimum(distance, 0.0, np.pi, steps=max(2, steps // 2),
                             lipschitz=speed, curvature=curvature, floor=0.0,
                             interval_bound=squared_bound, atol=atol,
                             max_evaluations=max_evaluations)


@dataclass(frozen=True)
class HousingCircle:
    """A housing envelope circle of ``radius`` mm round the named axis of one gearbox."""

    gearbox: str
    point: str
    radius: float


def _lowest_of_circles(mechanism, circles, phi):
    lows = []
    for circle in circles:
        if circle.point == "O":
            centre_height = np.zeros_like(phi)
        else:
            centre_height = mechanism.motion(phi, circle.point).position[:, 1]
        lows.append(centre_height - circle.radius)
    return np.min(lows, axis=0)


def ground_clearance(mechanism: PlantingMechanism, circles, soil_level: float, *,
                     steps: int = tol.STEPS_PER_REVOLUTION):
    """Certified least gap between the housing envelope circles and a flat soil line.

    The lowest point of a hull of circles is the lowest point of one of them, so
    the gap is ``min over circles (y_centre - radius) - soil_level``.

    Returns
    -------
    minimum : CertifiedMinimum
    nearest : HousingCircle
        The circle that comes closest.
    """
    circles = list(circles)
    if not circles:
        raise ValueError("ground_clearance needs at least one housing circle")
    points = {c.point for c in circles if c.point != "O"}
    speed = max([mechanism.speed_bound(p) for p in points], default=0.0)
    accel = max([mechanism.acceleration_bound(p) for p in points], default=0.0)
    result = certified_minimum(
        lambda phi: _lowest_of_circles(mechanism, circles, phi) - soil_level,
        0.0, 2.0 * np.pi, steps=steps, lipschitz=speed, curvature=accel)
    phi = np.array([result.argument])
    gaps = [float(_lowest_of_circles(mechanism, [c], phi)[0]) for c in circles]
    return result, circles[int(np.argmin(gaps))]


@dataclass(frozen=True)
class KinematicClearance:
    """The kinematic clearance model: centre lines and housing envelope circles.

    :func:`kinematics.evaluation.evaluate_planting` asks a clearance model for
    ``arm_distance(mechanism, steps)`` and ``ground_clearance(mechanism,
    soil_level, steps)``, each returning a :class:`CertifiedMinimum` (the ground
    one also the nearest part); a solid-based (FCL) model with the same two
    methods takes over when a scene has solids.
    """

    circles: tuple
    arm_label: str = "arm distance (centre lines)"
    ground_label: str = "gearbox ground clearance (envelope circles)"
    method: str = "kinematic: centre lines C-E-P1-N and housing envelope circles"

    def arm_distance(self, mechanism, steps):
        return arm_distance(mechanism, steps=steps)

    def ground_clearance(self, mechanism, soil_level, steps):
        return ground_clearance(mechanism, self.circles, soil_level, steps=steps)
