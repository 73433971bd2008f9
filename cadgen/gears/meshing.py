"""Meshing check of a generated pair: run it through its whole cycle at its centre distance.

At each pose the gears stand where the pitch-curve law puts them. Turning the
driven gear about its own centre moves every point of it along a circle, so
the angle to first contact each way is exact for the polygon outlines: for each
vertex of one gear near the contact, the nearest crossing of the other gear's
outline with that vertex's circle about the driven centre (:mod:`cadgen.gears.turns`,
over a window round the contact, many poses at once). From the two angles
``phi_plus >= 0 >= phi_minus``:

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

from dataclasses import dataclass, field

import numpy as np

from cadgen.gears.turns import WindowEdges, first_contact_turns

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
    pose_state: object = field(default=None, repr=False, compare=False)   # see _PoseState


def _rotate(points, angle):
    c, s = np.cos(angle), np.sin(angle)
    return points @ np.array([[c, s], [-s, c]])


#: Overlap below this many square modules counts as touching, not interference
#: (the same threshold as the peer's, 20e-6 m^2).
OVERLAP_TOLERANCE = 20e-6


#: Poses whose turns are solved together: enough to spread numpy's per-call cost, few enough
#: that the candidate arrays stay in the processor's cache (measured: 16 is 1.4 x faster per
#: check than one pose at a time and than all poses at once).
POSE_BATCH = 16


@dataclass(frozen=True)
class _PoseState:
    """What a meshing check found per pose, kept so a re-check after a local change (tip
    relief) recomputes only the poses the change can reach: turns in rad, whether a drive
    vertex lay inside the driven gear, the overlap area (0 where not measured)."""

    plus: np.ndarray
    minus: np.ndarray
    inside: np.ndarray
    area: np.ndarray


def _windows(outline, centres, window):
    """Indices of the ``outline`` vertices within ``window`` of each of ``centres``: a list of
    int arrays. Only the vertices in the box round all centres go into the tree (a pair
    checked over one tooth pitch looks at a small part of its gears)."""
    if len(centres) == 0:
        return []
    from scipy.spatial import cKDTree

    low, high = centres.min(axis=0) - window, centres.max(axis=0) + window
    boxed = np.flatnonzero(np.all((outline >= low) & (outline <= high), axis=1))
    if boxed.size == 0:
        return [np.zeros(0, dtype=int) for _ in centres]
    near = cKDTree(outline[boxed]).query_ball_point(centres, window)
    return [boxed[np.asarray(indices, dtype=int)] for indices in near]


def _changed_vertices(outline, other):
    """Mask of the vertices of ``outline`` whose edge to the next vertex is not an edge of
    ``other`` (both closed rings, the first point not repeated), compared bit for bit."""
    def edges(ring):
        pairs = np.ascontiguousarray(np.hstack([ring, np.roll(ring, -1, axis=0)]))
        return pairs.view(np.dtype((np.void, pairs.dtype.itemsize * 4))).ravel()
    return ~np.isin(edges(outline), edges(other))


def _reusable(previous, drive_outline, contacts, window, poses):
    """``(state, todo)``: the per-pose results of ``previous`` = (report, drive outline it
    checked) and the poses a check of ``drive_outline`` must still compute (None: all).
    The others are those whose window holds no edge that is in one outline and not in the
    other. The window's vertices and the edges leaving them are then the same
    set in both (window membership is by coordinates), and a pose's turns and inside test
    depend on that set alone."""
    report, old_outline = previous
    state = report.pose_state
    if state is None or report.poses != poses:
        return None
    old_outline = np.asarray(old_outline, dtype=float)
    moved = np.vstack([drive_outline[_changed_vertices(drive_outline, old_outline)],
                       old_outline[_changed_vertices(old_outline, drive_outline)]])
    reach = np.zeros(poses, dtype=bool)
    if len(moved):
        distance = np.hypot(moved[None, :, 0] - contacts[:, None, 0],
                            moved[None, :, 1] - contacts[:, None, 1])
        # a margin over the tree's own distance test: a vertex on the window's edge counts
        reach = (distance <= window * (1 + 1e-9)).any(axis=1)
    return state, reach


def meshing_check(drive, driven, pair, *, poses: int = 384, window: float | None = None,
                  span: float | None = None, previous=None) -> MeshingReport:
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
    previous : (MeshingReport, (n, 2) float), optional
        The check of this pair with another drive outline (before tip relief, say), same
        poses, window, span and driven gear: poses that no changed edge of the drive can
        reach take its results (the same numbers a full check gives, see :func:`_reusable`).
    """
    import time

    import shapely

    start = time.perf_counter()
    module = drive.module
    window = 3.0 * module if window is None else window
    tau = (np.arange(poses) + 0.382) * ((pair.period if span is None else span) / poses)
    theta_a, theta_b = pair.rotations(tau)
    rho_a, _, psi_a, _ = pair.drive(tau)
    rho_b, _, psi_b, _ = pair.driven(tau)
    a_outline = np.asarray(drive.outline, dtype=float)
    b_outline = np.asarray(driven.outline, dtype=float)
    contact_a = rho_a[:, None] * np.c_[np.cos(psi_a), np.sin(psi_a)]
    plus, minus = np.empty(poses), np.empty(poses)
    inside, area = np.zeros(poses, dtype=bool), np.zeros(poses)
    todo = np.ones(poses, dtype=bool)
    reuse = None if previous is None else _reusable(previous, a_outline, contact_a, window, poses)
    if reuse is not None:
        state, todo = reuse
        plus[~todo], minus[~todo], inside[~todo] = (state.plus[~todo], state.minus[~todo],
                                                    state.inside[~todo])
    work = np.flatnonzero(todo)
    # the contact point in each body frame is known from the law: query vertices round it
    near_a = _windows(a_outline, contact_a[work], window)
    near_b = _windows(b_outline, (rho_b[:, None] * np.c_[np.cos(psi_b), np.sin(psi_b)])[work],
                      window)
    driven_poly = shapely.Polygon(b_outline)
    shapely.prepare(driven_poly)
    na, nb = len(a_outline), len(b_outline)
    offset = np.array([pair.centre_distance, 0.0])
    for first in range(0, len(work), POSE_BATCH):
        batch = range(first, min(first + POSE_BATCH, len(work)))
        ia, ib = [near_a[n] for n in batch], [near_b[n] for n in batch]
        ks = work[list(batch)]
        # the drive's window edges, carried into the driven gear's body frame
        a_start = np.concatenate([_rotate(_rotate(a_outline[i], theta_a[k]) - offset,
                                          -theta_b[k]) for i, k in zip(ia, ks)])
        a_end = np.concatenate([_rotate(_rotate(a_outline[(i + 1) % na], theta_a[k]) - offset,
                                        -theta_b[k]) for i, k in zip(ia, ks)])
        a_pose = np.repeat(np.arange(len(ks)), [len(i) for i in ia])
        b_index = np.concatenate(ib)
        b_start, b_end = b_outline[b_index], b_outline[(b_index + 1) % nb]
        b_pose = np.repeat(np.arange(len(ks)), [len(i) for i in ib])
        hits = a_pose[shapely.contains_xy(driven_poly, a_start[:, 0], a_start[:, 1])]
        inside[ks[np.unique(hits)]] = True
        drive_side = WindowEdges(a_start, a_end, a_pose)
        driven_side = WindowEdges(b_start, b_end, b_pose)
        # the driven gear turning by phi carries its edges onto drive vertices ...
        p1, m1 = first_contact_turns(drive_side, driven_side, len(ks))
        # ... and its vertices onto drive edges: there the turn measures -phi
        positive, negative = first_contact_turns(driven_side, drive_side, len(ks))
        plus[ks], minus[ks] = np.minimum(p1, -negative), np.maximum(m1, -positive)
    for k in np.flatnonzero(inside):  # overlap at the nominal pose: measure its area
        whole = _rotate(_rotate(a_outline, theta_a[k]) - offset, -theta_b[k])
        area[k] = shapely.Polygon(whole).intersection(driven_poly).area
    backlash = plus - minus
    return MeshingReport(
        poses=poses, interference_poses=int((area > OVERLAP_TOLERANCE * module**2).sum()),
        overlap_area_max=float(area.max()),
        backlash_min_deg=float(np.degrees(backlash.min())),
        backlash_max_deg=float(np.degrees(backlash.max())),
        backlash_arc_max=float((backlash * rho_b).max()),
        transmission_error_pp_deg=float(np.degrees(max(np.ptp(plus), np.ptp(minus)))),
        free_play_max_deg=float(np.degrees(np.minimum(plus, -minus).max())),
        phi_plus_deg=np.degrees(plus), phi_minus_deg=np.degrees(minus),
        seconds=time.perf_counter() - start, overlapping=area > 0.0,
        cycle_fraction=1.0 if span is None else float(span / pair.period),
        pose_state=_PoseState(plus, minus, inside, area))


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
    # the contact in the driven gear's frame at every fine pose; the driven gear within the
    # window round it (one vectorised call each: the same GEOS operations as one by one)
    contacts = np.array([_rotate(_rotate(rho_a[k] * np.array([np.cos(psi_a[k]),
                                                               np.sin(psi_a[k])])[None, :],
                                         theta_a[k]) - offset, -theta_b[k])[0]
                         for k in range(len(fine))]).reshape(-1, 2)
    # (quad_segs: the 16 of a geometry's buffer method, not the 8 of shapely.buffer's default)
    locals_ = shapely.intersection(driven_poly, shapely.buffer(
        shapely.points(contacts), window, quad_segs=16))
    shapely.prepare(drive_poly)   # many intersects tests against it, the same answers
    pieces = []
    for k, local in enumerate(locals_):
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
        depth = float(shapely.distance(boundary,
                                       shapely.points(shapely.get_coordinates(removed))).max())
    return ring, float(removed.area), float(depth)
