"""The spec's example loops, mirrored into this project's frame (x = forward travel)."""

import numpy as np

SPEC_KERNEL_A = [(-120, -135), (-110, -180), (-80, -215), (-45, -255), (5, -288), (60, -262),
                 (95, -215), (125, -160), (125, -110), (85, -78), (10, -70), (-75, -92)]
SPEC_KERNEL_B = [(-112.6, -139.3), (-105.5, -187.5), (-82.6, -223.4), (-41.9, -265.5),
                 (8.6, -290.1), (57.3, -272.6), (100.7, -223.4), (129.1, -169.0),
                 (128.0, -117.4), (85.8, -87.3), (14.0, -79.0), (-72.7, -98.4)]


def mirrored(points):
    points = np.array(points, dtype=float)
    points[:, 0] *= -1.0
    return points


KERNEL_A = mirrored(SPEC_KERNEL_A)
KERNEL_B = mirrored(SPEC_KERNEL_B)


# --------------------------------------------------------------- an independent reference
def _cross(x, y):
    return x[..., 0] * y[..., 1] - x[..., 1] * y[..., 0]


def reference_ratio(curve, centre, sense, samples=200_000):
    """The planet's ratio ``i = 1 - phi2'/phi1'`` by a direct evaluation at dense samples.

    Independent of the design's Chebyshev machinery: the dead centres are the
    samples' radial extremes, the arccos branch switches there, and the angle
    rates solve ``p' = 2a phi1' e1 + l phi2' e2`` (e1, e2 the normals of OB and BD)
    at each sample. Returns ``(u, ratio, |e1 x e2|)``; the solve is singular at the
    dead centres, so callers keep samples where the last is not small.
    """
    centre = np.asarray(centre, dtype=float)
    u = np.linspace(0.0, curve.period, samples, endpoint=False)
    p = curve(u) - centre
    dp = curve(u, 1)
    radius = np.linalg.norm(p, axis=1)
    u_max, u_min = u[radius.argmax()], u[radius.argmin()]
    a = (radius.max() - radius.min()) / 4
    l = (radius.max() + radius.min()) / 2
    cosine = np.clip((radius**2 + 4 * a * a - l * l) / (4 * a * radius), -1, 1)
    w = np.mod(u - u_max, curve.period)
    branch = np.where(w < np.mod(u_min - u_max, curve.period), sense, -sense)
    phi1 = np.arctan2(p[:, 1], p[:, 0]) + branch * np.arccos(cosine)
    along = (p - 2 * a * np.stack([np.cos(phi1), np.sin(phi1)], axis=1)) / l
    e1 = np.stack([-np.sin(phi1), np.cos(phi1)], axis=1)
    e2 = np.stack([-along[:, 1], along[:, 0]], axis=1)
    det = _cross(e1, e2)
    with np.errstate(divide="ignore", invalid="ignore"):
        rate1 = _cross(dp, e2) / (2 * a * det)
        rate2 = -_cross(dp, e1) / (l * det)
        return u, 1 - rate2 / rate1, np.abs(det)


def reference_extremes(curve, centre, sense, samples=200_000, singular=1e-3):
    """Smallest and largest ratio of :func:`reference_ratio` away from the dead centres."""
    _, ratio, det = reference_ratio(curve, centre, sense, samples)
    kept = ratio[det > singular]
    return float(kept.min()), float(kept.max())


def point_on_curve_near_dead_centre(points, degree, which, offset, centre=(0.0, 0.0)):
    """``points`` with one more, on their own curve, ``offset`` mm (of curve parameter)
    after the inner or outer dead centre, inserted in the loop's order."""
    from kinematics.spline import ClosedCurve

    curve = ClosedCurve(points, degree)
    (u_min, _), (u_max, _) = curve.radius_extrema(centre)
    u = np.mod((u_min if which == "inner" else u_max) + offset, curve.period)
    k = int(np.searchsorted(curve.knots, u, side="right"))
    return np.insert(np.asarray(points, dtype=float), k, curve(u), axis=0), curve
