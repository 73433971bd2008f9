"""Meshing check of a generated pair: run it through its whole cycle at its centre distance.

At each pose the gears stand where the pitch-curve law puts them. Turning the
driven gear about its own centre moves every point of it along a circle, so
the angle to first contact each way is exact for the polygon outlines: for each
vertex of one gear near the contact, the nearest crossing of the other gear's
outline with that vertex's circle about the driven centre (vectorized over a
window round the contact). From the two angles ``phi_plus >= 0 >= phi_minus``:

* interference: the nominal pose overlaps (a vertex inside the other gear)
  by more than ``OVERLAP_TOLERANCE`` square modules; its area is measured with
  shapely and the largest is always reported;
* backlash: ``phi_plus - phi_minus`` (driven-gear angle), also as arc length on
  the driven pitch curve;
* transmission error: how far the driven gear stands from the law when one
  flank drives, ``phi_plus`` or ``phi_minus``; reported as the peak-to-peak over
  the cycle of either driving flank, and as the largest free turn to first
  contact ``min(phi_plus, -phi_minus)`` (the peer's definition).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["MeshingReport", "meshing_check"]


@dataclass(frozen=True)
class MeshingReport:
    """Result of :func:`meshing_check` (angles in degrees of the driven gear, lengths mm)."""

    poses: int
    interference_poses: int
    overlap_area_max: float
    backlash_min_deg: float
    backlash_max_deg: float
    backlash_arc_max: float
    transmission_error_pp_deg: float
    free_play_max_deg: float
    phi_plus_deg: np.ndarray
    phi_minus_deg: np.ndarray
    seconds: float = 0.0
    overlapping: np.ndarray = None  # poses whose nominal placement overlaps at all
    cycle_fraction: float = 1.0     # part of the pair's cycle run through (one pitch: 1/z)


def _rotate(points, angle):
    c, s = np.cos(angle), np.sin(angle)
    return points @ np.array([[c, s], [-s, c]])


def _turns(points, edges_start, edges_end):
    """Turns about the origin that bring each point onto the edges' circle crossings.

    Only the (point, edge) pairs whose edge spans the point's radius are solved
    (a segment crosses a circle where its radial span contains that radius).
    Returns ``(smallest positive, largest negative)`` turn of the *points* that
    would carry one onto an edge; +-inf where none.
    """
    radii = np.linalg.norm(points, axis=1)
    r0 = np.linalg.norm(edges_start, axis=1)
    r1 = np.linalg.norm(edges_end, axis=1)
    low, high = np.minimum(r0, r1), np.maximum(r0, r1)
    # interval stabbing with short edges: candidates have low in [R - widest span, R]
    order = np.argsort(low)
    sorted_low = low[order]
    first = np.searchsorted(sorted_low, radii - (high - low).max(), side="left")
    last = np.searchsorted(sorted_low, radii, side="right")
    counts = last - first
    if counts.sum() == 0:
        return np.inf, -np.inf
    i = np.repeat(np.arange(len(radii)), counts)
    within = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    j = order[np.repeat(first, counts) + within]
    keep = high[j] >= radii[i]
    i, j = i[keep], j[keep]
    if i.size == 0:
        return np.inf, -np.inf
    start, d = edges_start[j], edges_end[j] - edges_start[j]
    a = np.einsum("ij,ij->i", d, d)
    b = 2 * np.einsum("ij,ij->i", start, d)
    c = np.einsum("ij,ij->i", start, start) - radii[i] ** 2
    root = np.sqrt(np.maximum(b * b - 4 * a * c, 0.0))
    t = (-b + root) / (2 * a)
    t = np.where((t >= 0) & (t <= 1), t, (-b - root) / (2 * a))
    hit = start + np.clip(t, 0.0, 1.0)[:, None] * d
    angle = np.arctan2(points[i, 1], points[i, 0]) - np.arctan2(hit[:, 1], hit[:, 0])
    angle = (angle + np.pi) % (2 * np.pi) - np.pi   # turn of the edge onto the point
    positive = angle[angle > 0]
    negative = angle[angle < 0]
    return (positive.min() if positive.size else np.inf,
            negative.max() if negative.size else -np.inf)


#: Overlap below this many square modules counts as touching, not interference
#: (the same threshold as the peer's, 20e-6 m^2).
OVERLAP_TOLERANCE = 20e-6


def meshing_check(drive, driven, pair, *, poses: int = 384, window: float | None = None,
                  span: float | None = None) -> MeshingReport:
    """Run a pair through one cycle and measure interference, backlash and transmission error.

    Parameters
    ----------
    drive, driven : GearProfile
        Outlines in their body frames (drive at the origin, driven at ``(a, 0)``).
    pair : cadgen.gears.pairs.PitchPair
        The pitch-curve law: contact functions and rotations over one cycle.
    poses : int
        Poses over the cycle (offset from any tooth symmetry).
    window : float
        Radius (mm) round the contact point within which vertices are tested
        (default three modules: the whole path of contact of both flanks).
    span : float, optional
        Part of the cycle to run through (default all of it). A pair of circular
        gears repeats its mesh every tooth pitch of the drive, so one pitch
        (``period / z_drive``) checks every pose there is.
    """
    import time

    import shapely
    from scipy.spatial import cKDTree

    start = time.perf_counter()
    module = drive.module
    window = 3.0 * module if window is None else window
    tau = (np.arange(poses) + 0.382) * ((pair.period if span is None else span) / poses)
    theta_a, theta_b = pair.rotations(tau)
    rho_a, _, psi_a, _ = pair.drive(tau)
    rho_b, _, psi_b, _ = pair.driven(tau)
    a_outline = np.asarray(drive.outline, dtype=float)
    b_outline = np.asarray(driven.outline, dtype=float)
    # the contact point in each body frame is known from the law: query vertices round it
    near_a = cKDTree(a_outline).query_ball_point(rho_a[:, None] * np.c_[np.cos(psi_a),
                                                                       np.sin(psi_a)], window)
    near_b = cKDTree(b_outline).query_ball_point(rho_b[:, None] * np.c_[np.cos(psi_b),
                                                                       np.sin(psi_b)], window)
    driven_poly = shapely.Polygon(b_outline)
    shapely.prepare(driven_poly)
    na, nb = len(a_outline), len(b_outline)
    offset = np.array([pair.centre_distance, 0.0])
    plus = np.empty(poses)
    minus = np.empty(poses)
    interfering = 0
    overlap_max = 0.0
    overlapping = np.zeros(poses, dtype=bool)
    for k in range(poses):
        ia = np.asarray(near_a[k], dtype=int)
        ib = np.asarray(near_b[k], dtype=int)
        # the drive's window edges, carried into the driven gear's body frame
        a_start = _rotate(_rotate(a_outline[ia], theta_a[k]) - offset, -theta_b[k])
        a_end = _rotate(_rotate(a_outline[(ia + 1) % na], theta_a[k]) - offset, -theta_b[k])
        b_start, b_end = b_outline[ib], b_outline[(ib + 1) % nb]
        inside = shapely.contains_xy(driven_poly, a_start[:, 0], a_start[:, 1])
        if inside.any():  # overlap at the nominal pose: measure its area
            whole = _rotate(_rotate(a_outline, theta_a[k]) - offset, -theta_b[k])
            area = shapely.Polygon(whole).intersection(driven_poly).area
            overlap_max = max(overlap_max, area)
            overlapping[k] = area > 0.0
            interfering += area > OVERLAP_TOLERANCE * module**2
        # the driven gear turning by phi carries its edges onto drive vertices ...
        p1, m1 = _turns(a_start, b_start, b_end)
        # ... and its vertices onto drive edges: there _turns measures -phi
        positive, negative = _turns(b_start, a_start, a_end)
        plus[k], minus[k] = min(p1, -negative), max(m1, -positive)
    backlash = plus - minus
    return MeshingReport(
        poses=poses, interference_poses=interfering, overlap_area_max=overlap_max,
        backlash_min_deg=float(np.degrees(backlash.min())),
        backlash_max_deg=float(np.degrees(backlash.max())),
        backlash_arc_max=float((backlash * rho_b).max()),
        transmission_error_pp_deg=float(np.degrees(max(np.ptp(plus), np.ptp(minus)))),
        free_play_max_deg=float(np.degrees(np.minimum(plus, -minus).max())),
        phi_plus_deg=np.degrees(plus), phi_minus_deg=np.degrees(minus),
        seconds=time.perf_counter() - start, overlapping=overlapping,
        cycle_fraction=1.0 if span is None else float(span / pair.period))


def relieve_interference(drive, driven, pair, report: MeshingReport, *, substeps: int = 12,
                         window: float | None = None):
    """Tip relief: remove from the drive whatever its mate sweeps through where they overlap.

    Around every interfering pose the driven gear (its part near the contact)
    is placed at ``substeps`` finer poses in the drive's frame and subtracted.
    Only material that the mate occupies while meshing is removed, so the
    conjugate flanks elsewhere are untouched.

    Returns
    -------
    outline : (n, 2) float
        The relieved drive outline (counter-clockwise).
    removed_area : float
        mm^2 taken off.
    depth : float
        Largest distance from the removed material to the relieved outline (mm).
    """
    import shapely

    if report.overlap_area_max == 0.0:
        return np.asarray(drive.outline), 0.0, 0.0
    window = 3.0 * drive.module if window is None else window
    step = pair.period / report.poses
    drive_poly = shapely.Polygon(drive.outline)
    b_outline = np.asarray(driven.outline, dtype=float)
    driven_poly = shapely.Polygon(b_outline)
    # fine poses round every pose that overlapped, one pose step either side
    around = np.flatnonzero(report.overlapping)
    coarse = (np.arange(report.poses) + 0.382) * step
    offsets = (np.arange(-substeps, substeps + 1) / substeps) * step
    fine = np.unique(np.mod((coarse[around][:, None] + offsets[None, :]).ravel(), pair.period))
    theta_a, theta_b = pair.rotations(fine)
    rho_a, _, psi_a, _ = pair.drive(fine)
    offset = np.array([pair.centre_distance, 0.0])
    pieces = []
    for k in range(len(fine)):
        contact = rho_a[k] * np.array([np.cos(psi_a[k]), np.sin(psi_a[k])])
        local = driven_poly.intersection(shapely.Point(*_rotate(
            _rotate(contact[None, :], theta_a[k]) - offset, -theta_b[k])[0]).buffer(window))
        if local.is_empty:
            continue
        # driven (local part) into the drive's frame
        coords = shapely.get_coordinates(local)
        moved = _rotate(_rotate(coords, theta_b[k]) + offset, -theta_a[k])
        placed = shapely.set_coordinates(local, moved)
        if placed.intersects(drive_poly):
            pieces.append(placed)
    if not pieces:
        return np.asarray(drive.outline), 0.0, 0.0
    swept = shapely.union_all(pieces)
    relieved = drive_poly.difference(swept)
    if relieved.geom_type != "Polygon":
        relieved = max(relieved.geoms, key=lambda g: g.area)
    removed = drive_poly.difference(relieved)
    ring = np.asarray(relieved.exterior.coords)[:-1]
    if not shapely.LinearRing(ring).is_ccw:
        ring = ring[::-1]
    depth = 0.0
    if not removed.is_empty:
        boundary = relieved.exterior
        depth = max(boundary.distance(shapely.Point(p)) for p in shapely.get_coordinates(removed))
    return ring, float(removed.area), float(depth)
