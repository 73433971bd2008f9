"""Convex-hull proxies (cadgen.sweep.proxies): true lower bounds, and exact only when attained.

Truth: FCL's mesh distance between fresh BVH models of the same meshes (and its
collision test for crossing solids), closed forms for boxes, and the plane
distance of a box over a slab by hand. Float rounding of coordinates of a few
hundred mm is about 1e-13 mm; the comparisons allow 1e-9 mm for it.
"""

import math

import numpy as np
import pytest

fcl = pytest.importorskip("fcl")
m3d = pytest.importorskip("manifold3d")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from cadgen.solids.extrude import to_trimesh  # noqa: E402
from helpers import fcl_bvh  # noqa: E402
from cadgen.solids.parts import planar_transform  # noqa: E402
from cadgen.sweep.proxies import (EXACT_GAP, facet_certificate, hull_proxy,  # noqa: E402
                                  separation, sphere_gaps)

ROUNDING = 1e-9


def _box(size, centre=(0.0, 0.0, 0.0)):
    size = np.asarray(size, dtype=float)
    return m3d.Manifold.cube(tuple(size)).translate(tuple(np.asarray(centre) - size / 2))


def _solids():
    """Named solids: convex ones, and concave ones whose hull is not the solid."""
    cylinder = m3d.Manifold.cylinder(30.0, 12.0, 12.0, 24).translate((0.0, 0.0, -15.0))
    l_shape = _box((40, 40, 20)) - _box((25, 25, 30), (10, 10, 0))
    plate = _box((60, 40, 8)) - m3d.Manifold.cylinder(20.0, 10.0, 10.0, 32).translate((0, 0, -10))
    frame = _box((50, 50, 10)) - _box((30, 30, 20))
    return {"box": _box((30, 20, 10)), "cylinder": cylinder, "l-shape": l_shape,
            "plate with hole": plate, "frame": frame}


SOLIDS = _solids()
MESHES = {name: to_trimesh(solid, name) for name, solid in SOLIDS.items()}
PROXIES = {name: hull_proxy(mesh.vertices, mesh.faces) for name, mesh in MESHES.items()}


BVHS = {name: fcl_bvh(mesh) for name, mesh in MESHES.items()}


def _pose(quaternion, translation):
    w, x, y, z = np.asarray(quaternion, dtype=float) / np.linalg.norm(quaternion)
    rotation = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                         [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                         [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    pose = np.eye(4)
    pose[:3, :3], pose[:3, 3] = rotation, translation
    return pose


def _fcl_distance(name_a, pose_a, name_b, pose_b):
    """FCL's distance of the two posed meshes (0 when they cross) and its nearest points."""
    a = fcl.CollisionObject(BVHS[name_a], fcl.Transform(pose_a[:3, :3].copy(), pose_a[:3, 3].copy()))
    b = fcl.CollisionObject(BVHS[name_b], fcl.Transform(pose_b[:3, :3].copy(), pose_b[:3, 3].copy()))
    if fcl.collide(a, b, fcl.CollisionRequest(), fcl.CollisionResult()):
        return 0.0, None
    result = fcl.DistanceResult()
    d = fcl.distance(a, b, fcl.DistanceRequest(enable_nearest_points=True), result)
    return d, np.asarray(result.nearest_points, dtype=float)


def _on_surface(name, pose, point):
    """Distance of a world point from the posed mesh's surface (FCL, a point-sized sphere)."""
    mesh = fcl.CollisionObject(BVHS[name], fcl.Transform(pose[:3, :3].copy(), pose[:3, 3].copy()))
    probe = fcl.CollisionObject(fcl.Sphere(1e-12), fcl.Transform(np.eye(3), np.asarray(point)))
    return fcl.distance(mesh, probe, fcl.DistanceRequest(), fcl.DistanceResult())


unit = st.floats(-1.0, 1.0, allow_nan=False)
quaternions = st.tuples(unit, unit, unit, unit).filter(lambda q: np.linalg.norm(q) > 0.1)
offsets = st.tuples(*(st.floats(-70.0, 70.0, allow_nan=False),) * 3)
names = st.sampled_from(sorted(SOLIDS))


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(names, names, quaternions, quaternions, offsets, st.tuples(unit, unit, unit))
def test_proxy_bounds_never_exceed_the_exact_distance(name_a, name_b, qa, qb, offset, direction):
    pose_a, pose_b = _pose(qa, (0.0, 0.0, 0.0)), _pose(qb, offset)
    truth, nearest = _fcl_distance(name_a, pose_a, name_b, pose_b)
    a, b = PROXIES[name_a], PROXIES[name_b]
    centres = [pose[:3, :3] @ p.centre + pose[:3, 3] for p, pose in ((a, pose_a), (b, pose_b))]
    assert sphere_gaps(centres[0], a.radius, centres[1], b.radius) <= truth + ROUNDING
    if np.linalg.norm(direction) > 1e-3:
        assert separation(a, pose_a, b, pose_b, direction)[0] <= truth + ROUNDING
    # from the true nearest direction (what GJK approximates) and from an arbitrary one
    guesses = [direction] if nearest is None else [nearest[1] - nearest[0], direction]
    for guess in guesses:
        if np.linalg.norm(guess) <= 1e-3:
            continue
        lower, exact, upper, _ = facet_certificate(a, pose_a, b, pose_b, guess,
                                                   edges_first=bool(sum(qa) > 0))
        assert lower <= truth + ROUNDING
        assert upper >= truth - ROUNDING   # two points of the solids
        if exact is not None:
            distance, point_a, point_b = exact
            assert distance == pytest.approx(truth, abs=ROUNDING)
            assert np.linalg.norm(point_b - point_a) == pytest.approx(distance, abs=ROUNDING)
            assert _on_surface(name_a, pose_a, point_a) <= ROUNDING
            assert _on_surface(name_b, pose_b, point_b) <= ROUNDING
            assert distance - lower <= EXACT_GAP


# ------------------------------------------------------------------ closed forms
def _certify(name_a, pose_a, name_b, pose_b, direction):
    return facet_certificate(PROXIES[name_a], pose_a, PROXIES[name_b], pose_b, direction)


def test_face_against_face_is_attained():
    # the 30 x 20 x 10 box, and one 45 mm further along x: faces 15 mm apart, overlapping in y, z
    pose_b = planar_transform(0.0, (45.0, 3.0))
    lower, exact, _, _ = _certify("box", np.eye(4), "box", pose_b, (1.0, 0.2, -0.1))
    assert exact is not None and exact[0] == pytest.approx(15.0, abs=1e-12)
    assert lower == pytest.approx(15.0, abs=1e-12)


def test_corner_against_face_is_attained():
    # box B turned 30 deg about z, 60 mm along x: its corner of least x faces A's face x = 15
    # (B's faces are not parallel to it), the gap being that corner's x less 15 by hand
    turn = math.radians(30.0)
    pose_b = planar_transform(turn, (60.0, 0.0))
    corners = np.array([[sx * 15.0, sy * 10.0] for sx in (-1, 1) for sy in (-1, 1)])
    x = (corners @ np.array([[math.cos(turn), math.sin(turn)],
                             [-math.sin(turn), math.cos(turn)]]))[:, 0] + 60.0
    truth = x.min() - 15.0
    lower, exact, _, _ = _certify("box", np.eye(4), "box", pose_b, (1.0, 0.0, 0.0))
    assert exact is not None and exact[0] == pytest.approx(truth, abs=1e-12)
    assert truth == pytest.approx(_fcl_distance("box", np.eye(4), "box", pose_b)[0], abs=1e-9)


def test_edge_against_edge_is_attained_by_the_edges():
    # two cubes of half-size 10: A turned 45 deg about z (edges along z at radius 10 sqrt 2),
    # B turned 45 deg about x (edges along x), B's centre D along y: crossed edges,
    # D - 20 sqrt 2 apart, and no face parallel to a face
    cube = to_trimesh(_box((20, 20, 20)), "cube")
    proxy = hull_proxy(cube.vertices, cube.faces)
    pose_a = planar_transform(math.pi / 4)
    pose_b = np.eye(4)
    c, s = math.cos(math.pi / 4), math.sin(math.pi / 4)
    pose_b[:3, :3] = [[1, 0, 0], [0, c, -s], [0, s, c]]
    pose_b[:3, 3] = (0.0, 50.0, 0.0)
    truth = 50.0 - 20.0 * math.sqrt(2.0)
    lower, exact, _, by_edges = facet_certificate(proxy, pose_a, proxy, pose_b, (0.1, 1.0, 0.05))
    assert exact is not None and by_edges
    assert exact[0] == pytest.approx(truth, abs=1e-12)
    assert exact[1] == pytest.approx((0.0, 10.0 * math.sqrt(2.0), 0.0), abs=1e-9)


def test_a_solid_inside_another_has_no_positive_bound():
    # the box wholly inside a big box: the solids overlap (distance 0), no triangles meet
    big = to_trimesh(_box((200, 200, 200)), "big")
    big_proxy = hull_proxy(big.vertices, big.faces)
    for direction in ((1, 0, 0), (0, 1, 0), (0.3, -0.2, 0.9)):
        lower, exact, _, _ = facet_certificate(PROXIES["box"], planar_transform(0.4, (20, 5)),
                                               big_proxy, np.eye(4), direction)
        assert lower <= 0.0 and exact is None


def test_a_solid_in_a_concavity_is_never_called_exact():
    # the cylinder (radius 12) in the L-shape's notch, 3 mm from both inner walls:
    # the hull of the L holds it (bound <= 0), the true distance is 3 mm
    l_corner = np.array([-2.5, -2.5])   # the notch's inner corner (the L is 40 wide, notch 25)
    pose_b = planar_transform(0.0, l_corner + 15.0)
    truth, _ = _fcl_distance("l-shape", np.eye(4), "cylinder", pose_b)
    assert truth == pytest.approx(3.0, abs=0.05)   # the 24-gon's flat sides, not its circle
    lower, exact, _, _ = _certify("l-shape", np.eye(4), "cylinder", pose_b, (1.0, 1.0, 0.0))
    assert exact is None and lower <= 0.0


def test_a_box_over_a_slab_is_its_lowest_corner_by_hand():
    # the ground: a slab whose top is y = -100; the box turned about z at height 40
    slab = to_trimesh(_box((2000, 50, 2000), (0.0, -125.0, 0.0)), "ground")
    ground = hull_proxy(slab.vertices, slab.faces)
    for turn in (0.0, 0.3, 1.1, 2.5):
        pose = planar_transform(turn, (17.0, 40.0))
        corners = np.array([[sx * 15.0, sy * 10.0, 0.0, 1.0] for sx in (-1, 1)
                            for sy in (-1, 1)]) @ pose.T
        truth = corners[:, 1].min() + 100.0
        lower, exact, _, _ = facet_certificate(PROXIES["box"], pose, ground, np.eye(4),
                                               (0.05, -1.0, 0.02))
        assert exact is not None and exact[0] == pytest.approx(truth, abs=1e-12)
        assert exact[2][1] == pytest.approx(-100.0, abs=1e-12)
