"""The two clearances of N planting designs: arm distance (centre lines) and ground clearance.

The screen's forms of :mod:`kinematics.clearance`:

* **ground clearance** of the housing envelope circles needs no search at all: every
  circle centre moves on a sinusoid of the carrier angle (O is fixed; A, B, C turn with
  carrier 1 at their radii; D and E add ``a`` and ``a + 2 r`` along ``u(phic + phi)`` to
  C's ``Rc u(phi0 - phi)``, a sum whose height is ``A cos phi + B sin phi``), so the lowest
  point of circle i is ``-hypot(A_i, B_i) - radius_i`` exactly;
* **arm distance** between the centre lines C-E-P1-N of the two arms: the least of the 24
  point-to-segment distances (every vertex of one arm to every segment of the other; a
  segment pair's distance is that of its nearest end to the other segment unless the two
  cross, then 0) on the grid of half a revolution (the distance repeats as the arms swap),
  then each of the three lowest local minima polished on shrinking grids of the
  continuous model, closed by the vertex of a parabola (a smooth minimum) and the meeting
  point of two lines (a kink). Every value it returns is a distance the arms reach, so
  its error is one-sided: the screen may report a little more room, never less, and
  only by the search's resolution (docs/accuracy.md).
"""

from __future__ import annotations

import numpy as np

from .population_tip import TrainArrays, arm_points_at, arm_points_on_grid

__all__ = ["CIRCLE_AXES", "ground_clearance", "arm_distance", "centre_line_distance"]

TWO_PI = 2.0 * np.pi

#: The envelope circles' columns, in the order of :func:`cadgen.solids.housings.envelope_circles`.
CIRCLE_AXES = (("gearbox1", "O"), ("gearbox1", "A"), ("gearbox1", "B"), ("gearbox1", "C"),
               ("gearbox2", "C"), ("gearbox2", "D"), ("gearbox2", "E"))
#: Rounds of the local search round the best grid sample, each halving its reach.
ARM_ROUNDS = 7
#: The grid of the arm distance takes every ``ARM_STRIDE``-th sample of the shared grid.
ARM_STRIDE = 1
#: How many of the grid's lowest local minima are polished.
ARM_BASINS = 3
#: Stencil-and-vertex passes closing the search (see :func:`arm_distance`).
ARM_VERTEX_PASSES = 2


def ground_clearance(designs: dict, train: TrainArrays, circles, soil_level):
    """Least gap (mm) between the envelope circles and the soil line, in closed form.

    Parameters
    ----------
    circles : (N, 7) float
        Radii in the order of :data:`CIRCLE_AXES`.
    soil_level : (N,) float
    """
    circles = np.asarray(circles, dtype=float)
    R = np.asarray(designs["R"], dtype=float)
    i12, i13 = np.asarray(designs["i12"], dtype=float), np.asarray(designs["i13"], dtype=float)
    Rc, phi0, phic = train.Rc[:, 0], train.phi0[:, 0], train.phic[:, 0]
    a = train.law.centre_distance

    def swing(reach):
        # height of C + reach u(phic + phi): (Rc sin phi0 + reach sin phic) cos phi
        #                                   + (reach cos phic - Rc cos phi0) sin phi
        return np.hypot(Rc * np.sin(phi0) + reach * np.sin(phic),
                        reach * np.cos(phic) - Rc * np.cos(phi0))

    amplitude = np.stack([np.zeros_like(Rc), R * (1.0 + i12), R * (1.0 + 2.0 * i12 + i13), Rc,
                          Rc, swing(a), swing(train.reach[:, 0])], axis=1)
    return (-amplitude - circles).min(axis=1) - np.asarray(soil_level, dtype=float)


def _point_segment_squared(px, py, ax, ay, bx, by):
    dx, dy = bx - ax, by - ay
    length2 = dx * dx + dy * dy
    with np.errstate(invalid="ignore", divide="ignore"):
        along = ((px - ax) * dx + (py - ay) * dy) / length2
    along = np.where(length2 > 0.0, np.clip(along, 0.0, 1.0), 0.0)
    ex, ey = ax + along * dx - px, ay + along * dy - py
    return ex * ex + ey * ey


def _cross(ox, oy, ax, ay, bx, by):
    """z of (a - o) x (b - o)."""
    return (ax - ox) * (by - oy) - (ay - oy) * (bx - ox)


#: Every vertex of one arm against every segment of the other: (vertex, segment start) pairs.
_VERTEX, _SEGMENT = np.repeat(np.arange(4), 3), np.tile(np.arange(3), 4)
#: Every segment of arm 0 against every segment of arm 1.
_FIRST, _SECOND = np.repeat(np.arange(3), 3), np.tile(np.arange(3), 3)


#: Samples per block of :func:`centre_line_distance`: its 24-fold arrays stay in the cache.
BLOCK_SAMPLES = 4096


def centre_line_distance(arm0, arm1):
    """Least distance between two centre lines (four (x, y) vertices each, arrays (N, m) alike).

    The 24 vertex-segment distances and the 9 segment-crossing tests are each one array
    operation over a leading axis, not a loop of small ones, in blocks of rows so the
    24-fold arrays stay small (each row is computed alone either way).
    """
    rows = arm0[0][0].shape[0]
    step = max(1, BLOCK_SAMPLES // max(1, arm0[0][0].size // max(rows, 1)))
    if rows <= step:
        return _centre_line_distance(arm0, arm1)

    def block(arm, start):
        return [(x[start:start + step], y[start:start + step]) for x, y in arm]

    return np.concatenate([_centre_line_distance(block(arm0, start), block(arm1, start))
                           for start in range(0, rows, step)])


def _centre_line_distance(arm0, arm1):
    x0, y0 = np.stack([p[0] for p in arm0]), np.stack([p[1] for p in arm0])   # (4, ...)
    x1, y1 = np.stack([p[0] for p in arm1]), np.stack([p[1] for p in arm1])

    px = np.concatenate([x0[_VERTEX], x1[_VERTEX]])
    py = np.concatenate([y0[_VERTEX], y1[_VERTEX]])
    ax = np.concatenate([x1[_SEGMENT], x0[_SEGMENT]])
    ay = np.concatenate([y1[_SEGMENT], y0[_SEGMENT]])
    bx = np.concatenate([x1[_SEGMENT + 1], x0[_SEGMENT + 1]])
    by = np.concatenate([y1[_SEGMENT + 1], y0[_SEGMENT + 1]])
    best = _point_segment_squared(px, py, ax, ay, bx, by).min(axis=0)
    p0 = (x0[_FIRST], y0[_FIRST])
    p1 = (x0[_FIRST + 1], y0[_FIRST + 1])
    q0 = (x1[_SECOND], y1[_SECOND])
    q1 = (x1[_SECOND + 1], y1[_SECOND + 1])
    crossing = ((_cross(*p0, *p1, *q0) * _cross(*p0, *p1, *q1) < 0.0)
                & (_cross(*q0, *q1, *p0) * _cross(*q0, *q1, *p1) < 0.0)).any(axis=0)
    return np.where(crossing, 0.0, np.sqrt(best))


def _candidates(distance, count: int):
    """Indices (N, count) of each row's ``count`` lowest local minima of a periodic sequence
    (a row with fewer repeats its lowest)."""
    local = (distance <= np.roll(distance, 1, axis=1)) & (distance <= np.roll(distance, -1, axis=1))
    ranked = np.where(local, distance, np.inf)
    order = np.argsort(ranked, axis=1, kind="stable")[:, :count]
    lowest = order[:, :1]
    found = np.take_along_axis(ranked, order, axis=1)
    return np.where(np.isfinite(found), order, lowest)


def arm_distance(train: TrainArrays, samples: int):
    """Least distance (mm) between the two arms' centre lines over a revolution, (N,).

    Each of the :data:`ARM_BASINS` lowest local minima of the grid is polished (two arms
    often pass close twice, and a sharp minimum between samples can look higher on the
    grid than a flat one), and the least polished value is the answer: always a distance
    the arms really reach at some angle, so the screen never reports more room than the
    centre lines have by more than the search's resolution.
    """
    phi, arm0, arm1 = arm_points_on_grid(train, samples, ARM_STRIDE)
    distance = centre_line_distance(arm0, arm1)
    count = distance.shape[0]
    k = _candidates(distance, ARM_BASINS)                          # (N, B)
    centre = phi[k]
    best = np.take_along_axis(distance, k, axis=1)
    reach = ARM_STRIDE * TWO_PI / samples
    offsets = np.array([-1.0, -0.5, 0.5, 1.0])
    for _ in range(ARM_ROUNDS):
        trial = (centre[:, :, None] + reach * offsets).reshape(count, -1)
        values = centre_line_distance(*arm_points_at(train, trial)).reshape(
            count, ARM_BASINS, len(offsets))
        j = values.argmin(axis=2)[..., None]
        low = np.take_along_axis(values, j, axis=2)[..., 0]
        lower = low < best
        centre = np.where(lower, np.take_along_axis(trial.reshape(values.shape), j, axis=2)[..., 0],
                          centre)
        best = np.where(lower, low, best)
        reach *= 0.5
    # then a stencil of five samples round the best one, and two more samples where the
    # minimum would be: at the vertex of the parabola through the middle three (a smooth
    # minimum) and where the lines through the two samples on either side meet (a kink, where
    # the nearest pair of the arms changes). Twice, the second time eight times closer: a
    # near-touch is a hyperbola, a kink from afar and a parabola close up. Each is a real
    # sample of the distance, so the answer is always a distance the arms reach.
    q = reach
    for _ in range(ARM_VERTEX_PASSES):
        centre, best = _vertex_pass(train, centre, best, q)
        q /= 8.0
    return best.min(axis=1)


def _vertex_pass(train, centre, best, q):
    """One stencil-and-vertices pass of :func:`arm_distance`: the new (centre, best), (N, B)."""
    count, basins = centre.shape
    offsets = np.array([-2.0, -1.0, 1.0, 2.0])
    stencil = (centre[:, :, None] + q * offsets).reshape(count, -1)
    values = centre_line_distance(*arm_points_at(train, stencil)).reshape(count, basins, 4)
    far_left, left, right, far_right = np.moveaxis(values, 2, 0)
    curvature = left + right - 2.0 * best
    with np.errstate(divide="ignore", invalid="ignore"):
        parabola = np.where(curvature > 0.0, -q * (right - left) / (2.0 * curvature), 0.0)
        slope_left, slope_right = (left - far_left) / q, (far_right - right) / q
        kink = (right - left - (slope_right + slope_left) * q) / (slope_left - slope_right)
    kink = np.where((slope_left < 0.0) & (slope_right > 0.0), kink, 0.0)
    shifts = np.stack([np.clip(np.nan_to_num(v), -2.0 * q, 2.0 * q) for v in (parabola, kink)],
                      axis=2)
    at_vertices = centre_line_distance(*arm_points_at(
        train, (centre[:, :, None] + shifts).reshape(count, -1))).reshape(count, basins, 2)
    # every sample of this pass with its place: keep the least
    places = np.concatenate([np.zeros((count, basins, 1)), q * np.broadcast_to(
        offsets, (count, basins, 4)), shifts], axis=2)
    found = np.concatenate([best[:, :, None], values, at_vertices], axis=2)
    j = found.argmin(axis=2)[..., None]
    return (centre + np.take_along_axis(places, j, axis=2)[..., 0],
            np.take_along_axis(found, j, axis=2)[..., 0])
