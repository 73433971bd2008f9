"""The meshing check's turn search (cadgen.gears.turns) and its re-check after tip relief.

Second methods: a brute-force search over every (vertex, edge) pair of a pose, with the
circle crossing solved by the numerically stable form of the quadratic; the meshing check as
it ran before (one pose at a time, a radius-span search per pose), written out here; a full
check against the one that reuses the poses a local change cannot reach.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import shapely

from cadgen.gears.meshing import meshing_check
from cadgen.gears.turns import ANGLE_BINS, WindowEdges, first_contact_turns


def _brute_force(points, point_pose, start, end, edge_pose, poses):
    """Every pair of a pose whose edge spans the point's radius: the turn of the edge onto
    the point where it crosses the point's circle (the crossing furthest along the edge)."""
    positive, negative = np.full(poses, np.inf), np.full(poses, -np.inf)
    for k in range(poses):
        p, s, e = points[point_pose == k], start[edge_pose == k], end[edge_pose == k]
        if len(p) == 0 or len(s) == 0:
            continue
        r = np.linalg.norm(p, axis=1)[:, None]
        r0, r1 = np.linalg.norm(s, axis=1)[None, :], np.linalg.norm(e, axis=1)[None, :]
        spans = (np.minimum(r0, r1) <= r) & (np.maximum(r0, r1) >= r)
        i, j = np.nonzero(spans)
        d = e[j] - s[j]
        a = (d**2).sum(axis=1)
        b = 2 * (s[j] * d).sum(axis=1)
        c = (s[j] ** 2).sum(axis=1) - r[i, 0] ** 2
        root = np.sqrt(np.maximum(b * b - 4 * a * c, 0.0))
        q = -0.5 * (b + np.copysign(root, b))          # no cancellation in either root
        roots = np.sort(np.stack([q / a, np.where(q != 0, c / np.where(q != 0, q, 1), q / a)]),
                        axis=0)
        t = np.where((roots[1] >= 0) & (roots[1] <= 1), roots[1], roots[0])
        hit = s[j] + np.clip(t, 0, 1)[:, None] * d
        turn = np.arctan2(p[i, 1], p[i, 0]) - np.arctan2(hit[:, 1], hit[:, 0])
        turn = (turn + np.pi) % (2 * np.pi) - np.pi
        if (turn > 0).any():
            positive[k] = turn[turn > 0].min()
        if (turn < 0).any():
            negative[k] = turn[turn < 0].max()
    return positive, negative


def _ring(rng, count, radius, lobes, wobble):
    angle = np.sort(rng.uniform(0, 2 * np.pi, count))
    rho = radius + wobble * np.sin(lobes * angle) + rng.normal(0, wobble / 20, count)
    return rho[:, None] * np.column_stack([np.cos(angle), np.sin(angle)])


CASES = {"dense teeth": (600, 40), "sparse (turns over a bin)": (25, 3), "mixed": (200, 12)}


@pytest.mark.parametrize("case", list(CASES), ids=list(CASES))
def test_first_contact_turns_match_a_brute_force_search(case, rng):
    count, lobes = CASES[case]
    poses = 7
    sides = []
    for wobble in (1.5, 2.0):
        starts, ends, pose = [], [], []
        for k in range(poses):
            ring = _ring(rng, count, 30.0, lobes, wobble)
            keep = rng.random(count) < 0.7            # a window: some of the ring's vertices
            starts.append(ring[keep])
            ends.append(np.roll(ring, -1, axis=0)[keep])
            pose.append(np.full(keep.sum(), k))
        sides.append((np.vstack(starts), np.vstack(ends), np.concatenate(pose)))
    (a_start, a_end, a_pose), (b_start, b_end, b_pose) = sides
    found = first_contact_turns(WindowEdges(a_start, a_end, a_pose),
                                WindowEdges(b_start, b_end, b_pose), poses)
    expected = _brute_force(a_start, a_pose, b_start, b_end, b_pose, poses)
    for got, want in zip(found, expected):
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
    if case.startswith("sparse"):   # the second pass ran: some turn is over one angular bin
        assert (np.abs(np.concatenate(expected)) > 2 * np.pi / ANGLE_BINS).any()


def test_no_edges_or_no_points_turn_nowhere():
    empty = WindowEdges(np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0, dtype=int))
    some = WindowEdges(np.array([[1.0, 0.0]]), np.array([[0.0, 1.0]]), np.array([0]))
    for points, edges in ((empty, some), (some, empty)):
        positive, negative = first_contact_turns(points, edges, 1)
        assert positive.tolist() == [np.inf] and negative.tolist() == [-np.inf]


# ----------------------------------------------------------------------------- the whole check
def _rotate(points, angle):
    c, s = np.cos(angle), np.sin(angle)
    return points @ np.array([[c, s], [-s, c]])


def _pose_by_pose(drive, driven, pair, poses, span=None):
    """The meshing check's turns and overlaps one pose at a time over every vertex within
    three modules of the contact (a brute-force window, no tree), as it ran before."""
    window = 3.0 * drive.module
    tau = (np.arange(poses) + 0.382) * ((pair.period if span is None else span) / poses)
    theta_a, theta_b = pair.rotations(tau)
    rho_a, _, psi_a, _ = pair.drive(tau)
    rho_b, _, psi_b, _ = pair.driven(tau)
    a, b = np.asarray(drive.outline), np.asarray(driven.outline)
    offset = np.array([pair.centre_distance, 0.0])
    plus, minus, areas = np.empty(poses), np.empty(poses), np.zeros(poses)
    driven_polygon = shapely.Polygon(b)
    for k in range(poses):
        ca = rho_a[k] * np.array([np.cos(psi_a[k]), np.sin(psi_a[k])])
        cb = rho_b[k] * np.array([np.cos(psi_b[k]), np.sin(psi_b[k])])
        ia = np.flatnonzero(np.linalg.norm(a - ca, axis=1) <= window)
        ib = np.flatnonzero(np.linalg.norm(b - cb, axis=1) <= window)
        a_start = _rotate(_rotate(a[ia], theta_a[k]) - offset, -theta_b[k])
        a_end = _rotate(_rotate(a[(ia + 1) % len(a)], theta_a[k]) - offset, -theta_b[k])
        zero_a, zero_b = np.zeros(len(ia), int), np.zeros(len(ib), int)
        p1, m1 = _brute_force(a_start, zero_a, b[ib], b[(ib + 1) % len(b)], zero_b, 1)
        positive, negative = _brute_force(b[ib], zero_b, a_start, a_end, zero_a, 1)
        plus[k], minus[k] = min(p1[0], -negative[0]), max(m1[0], -positive[0])
        if shapely.contains_xy(driven_polygon, a_start[:, 0], a_start[:, 1]).any():
            whole = _rotate(_rotate(a, theta_a[k]) - offset, -theta_b[k])
            areas[k] = shapely.Polygon(whole).intersection(driven_polygon).area
    return plus, minus, areas


@pytest.fixture(scope="module")
def paper_pair():
    from cadgen.design import build_mechanism
    from cadgen.gears.pairs import generate_pair
    from cadgen.gears.trains import _system, planting_pair
    from cadgen.params import load_params
    from tests.helpers import REFERENCE

    params = load_params(REFERENCE)
    mechanism = build_mechanism(params)
    pair = planting_pair(mechanism)
    teeth = params.pitch_curve.teeth
    system = dataclasses.replace(_system(params.gears, mechanism.module(teeth)), backlash=0.05)
    return pair, generate_pair(pair, teeth, system=system, flank_points=48)


def test_the_check_agrees_with_a_pose_by_pose_brute_force(paper_pair):
    pair, generated = paper_pair
    poses = 8 * generated.teeth[0]
    report = meshing_check(*generated.profiles, pair, poses=poses)
    plus, minus, areas = _pose_by_pose(*generated.profiles, pair, poses)
    np.testing.assert_allclose(np.radians(report.phi_plus_deg), plus, rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.radians(report.phi_minus_deg), minus, rtol=0, atol=1e-12)
    assert report.overlap_area_max == pytest.approx(areas.max(), rel=1e-9)
    assert report.overlapping.tolist() == (areas > 0).tolist()
    assert report.interference_poses > 0     # this pair overlaps before its tip relief


def test_a_recheck_after_relief_equals_a_full_check(paper_pair):
    from cadgen.gears.meshing import relieve_interference

    pair, generated = paper_pair
    drive, driven = generated.profiles
    poses = 8 * generated.teeth[0]
    before = meshing_check(drive, driven, pair, poses=poses)
    outline, area, _ = relieve_interference(drive, driven, pair, before)
    assert area > 0
    relieved = dataclasses.replace(drive, outline=outline)
    full = meshing_check(relieved, driven, pair, poses=poses)
    reused = meshing_check(relieved, driven, pair, poses=poses, previous=(before, drive.outline))
    for name in ("phi_plus_deg", "phi_minus_deg", "overlapping"):
        np.testing.assert_array_equal(getattr(reused, name), getattr(full, name), err_msg=name)
    for name in ("interference_poses", "overlap_area_max", "backlash_min_deg",
                 "backlash_max_deg", "backlash_arc_max", "transmission_error_pp_deg",
                 "free_play_max_deg"):
        assert getattr(reused, name) == getattr(full, name), name
    # and it did reuse: the relief reaches only the poses round the ones that interfered
    changed = ~np.isclose(full.phi_plus_deg, before.phi_plus_deg, rtol=0, atol=0)
    assert 0 < changed.sum() < poses


def test_a_recheck_of_an_unchanged_outline_reuses_every_pose(paper_pair):
    pair, generated = paper_pair
    drive, driven = generated.profiles
    poses = 2 * generated.teeth[0]
    first = meshing_check(drive, driven, pair, poses=poses)
    again = meshing_check(dataclasses.replace(drive, outline=drive.outline.copy()), driven, pair,
                          poses=poses, previous=(first, drive.outline))
    np.testing.assert_array_equal(again.phi_plus_deg, first.phi_plus_deg)
    np.testing.assert_array_equal(again.phi_minus_deg, first.phi_minus_deg)
    assert again.overlap_area_max == first.overlap_area_max
