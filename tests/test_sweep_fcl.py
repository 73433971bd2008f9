"""FCL collision sweep: closed forms for boxes, python-fcl's pitfalls, the planting assembly."""

import math
from pathlib import Path

import numpy as np
import pytest

fcl = pytest.importorskip("fcl")
m3d = pytest.importorskip("manifold3d")

from cadgen.solids.errors import SolidInputError  # noqa: E402
from cadgen.solids.parts import Assembly, Part, planar_transform  # noqa: E402
from cadgen.sweep.fcl import FclScene  # noqa: E402
from cadgen.sweep.scene import instance_pose, part_reach  # noqa: E402
from cadgen.sweep.search import certified_distance, plain_scan  # noqa: E402

REFERENCE = Path(__file__).resolve().parents[1] / "params" / "xin2024-planter.toml"
Z = (0.0, 0.0, 1.0)
# the carrier turns about an axis through ORIGIN (not the world origin, so frames matter)
ORIGIN = np.array([10.0, -20.0, 5.0])
R, HALF = 100.0, np.array([15.0, 10.0, 5.0])   # moving box: centre at (R, 0, 0) of the carrier
RHO = math.hypot(R + HALF[0], HALF[1])         # its outer vertical edges' radius
BETA = math.atan2(HALF[1], R + HALF[0])        # their angle in the carrier frame


def box(low, high):
    low, high = np.asarray(low, dtype=float), np.asarray(high, dtype=float)
    return m3d.Manifold.cube(tuple(high - low)).translate(tuple(low))


def carrier_scene(fixed_low, fixed_high):
    """A box on a carrier turning by phi about the z axis through ORIGIN, and a fixed box."""
    moving = Part("moving", "test", "carrier", box((R - HALF[0], -HALF[1], -HALF[2]),
                                                   (R + HALF[0], HALF[1], HALF[2])))
    fixed = Part("fixed", "test", "fixed", box(fixed_low, fixed_high))

    def pose(body, phi):
        if body == "carrier":
            return planar_transform(phi, ORIGIN[:2], ORIGIN[2])
        return np.eye(4)

    assembly = Assembly([moving, fixed], pose)
    return assembly, FclScene(assembly, ["moving"], ["fixed"])


def face_box(x_face, depth=50.0, half_y=60.0, half_z=20.0):
    """A fixed box whose face x = ORIGIN x + x_face looks at the carrier."""
    low = ORIGIN + (x_face, -half_y, -half_z)
    return low, low + (depth, 2 * half_y, 2 * half_z)


# ------------------------------------------------------------------ python-fcl itself
def _bvh(manifold):
    from cadgen.solids.extrude import to_trimesh
    from helpers import fcl_bvh

    return fcl_bvh(to_trimesh(manifold, "probe"))


def test_python_fcl_behaviour_the_scene_relies_on():
    cube = _bvh(box((-1, -1, -1), (1, 1, 1)))
    a = fcl.CollisionObject(cube, fcl.Transform(np.eye(3), np.array([5.0, 5.0, 5.0])))
    turn = planar_transform(math.pi / 2)[:3, :3]
    b = fcl.CollisionObject(cube, fcl.Transform(turn, np.array([15.0, 5.3, 5.0])))
    request = fcl.DistanceRequest(enable_nearest_points=True)
    result = fcl.DistanceResult()
    assert fcl.distance(a, b, request, result) == pytest.approx(8.0, abs=1e-12)
    # nearest points in the world frame: on the faces x = 6 and x = 14, in the shared y range
    near_a, near_b = (np.asarray(p) for p in result.nearest_points)
    assert near_a[0] == pytest.approx(6.0) and near_b[0] == pytest.approx(14.0)
    assert 4.3 - 1e-9 <= near_a[1] <= 6.0 + 1e-9 and near_a[1:] == pytest.approx(near_b[1:])
    # a reused result keeps the old minimum: hence a fresh one per query
    b.setTransform(fcl.Transform(turn, np.array([105.0, 5.3, 5.0])))
    assert fcl.distance(a, b, request, result) == pytest.approx(98.0)
    assert result.min_distance == pytest.approx(8.0)
    # crossing meshes: distance 0, never negative
    b.setTransform(fcl.Transform(turn, np.array([6.0, 5.0, 5.0])))
    assert fcl.distance(a, b, request, fcl.DistanceResult()) == 0.0
    assert fcl.collide(a, b, fcl.CollisionRequest(), fcl.CollisionResult()) == 1
    # a mesh inside another: FCL sees the gap between the surfaces and no collision
    small = fcl.CollisionObject(_bvh(box((-0.1, -0.1, -0.1), (0.1, 0.1, 0.1))),
                                fcl.Transform(np.eye(3), np.array([5.0, 5.0, 5.0])))
    assert fcl.distance(a, small, request, fcl.DistanceResult()) == pytest.approx(0.9)
    assert fcl.collide(a, small, fcl.CollisionRequest(), fcl.CollisionResult()) == 0


# ------------------------------------------------------------------ closed forms
def test_rotating_box_passes_a_fixed_box():
    x_face = 130.0
    assembly, scene = carrier_scene(*face_box(x_face))
    moving = assembly.parts[0]
    # the outer vertical edges are the farthest points from the axis; in 3-D the corners
    assert part_reach(moving, axis=Z) == pytest.approx(RHO, abs=1e-9)
    assert part_reach(moving) == pytest.approx(math.hypot(RHO, HALF[2]), abs=1e-9)
    # the box reaches furthest in x when an outer edge points along x: at phi = +-BETA
    truth, where = x_face - RHO, (BETA, 2 * math.pi - BETA)
    result = certified_distance(scene, lipschitz=RHO, acceleration=RHO, steps=360, atol=1e-9)
    assert result.certified and not result.interference_ranges
    assert result.bound <= truth + 1e-12 and truth <= result.minimum + 1e-12
    assert result.minimum == pytest.approx(truth, abs=1e-9)
    assert min(abs(result.argument - w) for w in where) < 1e-4   # flat bottom: sqrt(atol / K)
    # nearest points, world frame: the edge at radius RHO on the x axis through ORIGIN, and the face
    z_range = (ORIGIN[2] - HALF[2] - 1e-9, ORIGIN[2] + HALF[2] + 1e-9)
    assert result.point_a[:2] == pytest.approx(ORIGIN[:2] + (RHO, 0.0), abs=1e-3)
    assert result.point_b[:2] == pytest.approx(ORIGIN[:2] + (x_face, 0.0), abs=1e-3)
    assert z_range[0] <= result.point_a[2] <= z_range[1]
    assert result.point_b[2] == pytest.approx(result.point_a[2], abs=1e-9)
    gap = np.linalg.norm(result.point_b - result.point_a)
    assert gap == pytest.approx(result.minimum, abs=1e-9)
    assert result.pair == ("moving", "fixed")
    # the screening samples, for a plot: the closed form at every sample away from phi = 0, pi
    phi, distance = result.samples_phi, result.samples_distance
    facing = np.abs(np.angle(np.exp(1j * phi))) < 0.5
    reach_x = (R + HALF[0]) * np.cos(phi) + HALF[1] * np.abs(np.sin(phi))
    assert distance[facing] == pytest.approx(x_face - reach_x[facing], abs=1e-9)
    # the naive peer lands on a sample: above the truth by up to K h^2 / 8
    value, argument = plain_scan(scene, 3600)
    assert truth - 1e-12 <= value <= truth + RHO * (2 * math.pi / 3600) ** 2 / 8 + 1e-12


@pytest.mark.parametrize("x_face, case",
                         [(115.3, "wide"), (RHO * math.cos(0.005), "narrower than a step")],
                         ids=["wide", "narrower-than-a-step"])
def test_interference_ranges_match_the_closed_form(x_face, case):
    assembly, scene = carrier_scene(*face_box(x_face))
    # overlap while an outer edge is beyond the face: |phi -+ BETA| <= arccos(x_face / RHO)
    half = math.acos(x_face / RHO)
    assert half < BETA   # two separate ranges, the box clears the face at phi = 0
    expected = [(BETA - half, BETA + half), (2 * math.pi - BETA - half, 2 * math.pi - BETA + half)]
    result = certified_distance(scene, lipschitz=RHO, acceleration=RHO, steps=360)
    if case == "narrower than a step":
        assert 2 * half < 2 * math.pi / 360
    assert len(result.interference_ranges) == 2
    for (start, end), (start_true, end_true) in zip(result.interference_ranges, expected):
        assert start == pytest.approx(start_true, abs=1e-6)
        assert end == pytest.approx(end_true, abs=1e-6)
    assert result.minimum == 0.0 and result.bound <= 0.0 and result.interferes
    assert result.point_a == pytest.approx(result.point_b)
    inside = scene.distance(BETA)
    assert inside.overlap and inside.distance == 0.0


def test_a_solid_wholly_inside_another_interferes():
    # a deep block: at phi = 0 the moving box lies wholly inside it, no triangles meet
    x_face = 60.0
    assembly, scene = carrier_scene(*face_box(x_face, depth=500.0, half_y=300.0, half_z=50.0))
    pose = instance_pose(assembly, "moving", 0.0)
    moving = fcl.CollisionObject(_bvh(assembly.parts[0].solid),
                                 fcl.Transform(pose[:3, :3].copy(), pose[:3, 3].copy()))
    fixed = fcl.CollisionObject(_bvh(assembly.parts[1].solid), fcl.Transform())
    proximity = scene.distance(0.0)
    assert fcl.collide(moving, fixed, fcl.CollisionRequest(), fcl.CollisionResult()) == 0
    assert proximity.overlap and proximity.distance == 0.0
    corner = proximity.point_a - pose[:3, 3]
    assert np.abs(pose[:3, :3].T @ corner - (R, 0, 0)) == pytest.approx(HALF, abs=1e-9)   # a vertex
    half = math.acos(x_face / RHO)
    result = certified_distance(scene, lipschitz=RHO, steps=360, lower=-math.pi, upper=math.pi)
    assert len(result.interference_ranges) == 1
    assert result.interference_ranges[0] == pytest.approx((-BETA - half, BETA + half), abs=1e-6)


def test_box_gaps_along_an_axis_and_a_diagonal_and_no_stale_results():
    # a block sliding along x by phi past a fixed block; closed-form gaps
    fixed = Part("fixed", "test", "fixed", box((0, 0, 0), (10, 20, 30)))
    level = Part("level", "test", "slider", box((0, 5, 5), (5, 15, 25)))
    above = Part("above", "test", "slider", box((0, 25, 5), (5, 35, 25)))   # 5 mm above in y
    pose = lambda body, phi: planar_transform(0.0, (phi, 0.0)) if body == "slider" else np.eye(4)
    assembly = Assembly([fixed, level, above], pose)
    side = FclScene(assembly, ["level"], ["fixed"])
    diagonal = FclScene(assembly, ["above"], ["fixed"])
    for phi in (1000.0, 10.5, 1000.0, 12.25, 10.0 + 1e-6, 777.0):
        gap = phi - 10.0
        near = side.distance(phi)
        assert near.distance == pytest.approx(gap, rel=1e-12, abs=1e-12)
        assert near.point_a[0] == pytest.approx(phi) and near.point_b[0] == pytest.approx(10.0)
        assert diagonal.distance(phi).distance == pytest.approx(math.hypot(gap, 5.0), rel=1e-12)
    assert side.distances([1000.0, 10.5]) == pytest.approx([990.0, 0.5], rel=1e-12)
    assert side.distance(8.0).overlap and side.distance(9.5).distance == 0.0


def test_bad_groups_and_arguments():
    assembly, scene = carrier_scene(*face_box(130.0))
    with pytest.raises(ValueError, match="unknown"):
        FclScene(assembly, ["moving"], ["nowhere"])
    with pytest.raises(SolidInputError, match="both groups"):
        FclScene(assembly, ["moving", "fixed"], ["fixed"])
    with pytest.raises(ValueError, match="lipschitz"):
        certified_distance(scene, lipschitz=-1.0)
    with pytest.raises(ValueError, match="steps"):
        certified_distance(scene, lipschitz=1.0, steps=1)
    with pytest.raises(ValueError, match="no part instance"):
        instance_pose(assembly, "nowhere", 0.0)


# ------------------------------------------------------------------ the paper's planting assembly
# blades: no bound on their cam-driven turn
GEARBOX2_FIXED = ("gearbox2-base", "gearbox2-cover", "shaft-D", "shaft-E", "cam")
ARM_PARTS = GEARBOX2_FIXED + ("planter-shell",)
HOUSINGS = ("gearbox1-base", "gearbox1-cover", "gearbox2-base-arm1", "gearbox2-base-arm2",
            "gearbox2-cover-arm1", "gearbox2-cover-arm2")


@pytest.fixture(scope="module")
def planting():
    from cadgen.cam.design import design_cam
    from cadgen.design import build_mechanism, evaluate
    from cadgen.params import load_params
    from cadgen.solids.planting import planting_assembly

    params = load_params(REFERENCE)
    mechanism = build_mechanism(params)
    evaluation = evaluate(params, mechanism, steps=720)
    cam = design_cam(params, mechanism, evaluation.events)
    assembly, housings, _ = planting_assembly(params, mechanism, None, cam,
                                              evaluation.events.soil_level)
    return params, mechanism, evaluation, assembly, housings


def test_instance_pose_is_the_placement(planting):
    _, _, _, assembly, _ = planting
    for phi in (0.0, 2.1):
        for name, _, pose in assembly.placements(phi):
            assert instance_pose(assembly, name, phi) == pytest.approx(pose, abs=1e-12)


def arm_bounds(mechanism, parts):
    """(speed, acceleration) bounds of any point of one arm's gearbox 2 (base, cover, shafts),
    cam and planter shell."""
    closure, rc = mechanism.closure, mechanism.carrier_radii["C"]
    spin = max(abs(1.0 - closure.ratio_min), abs(1.0 - closure.ratio_max))
    # angular term of the planter (spin rate + spin^2), read off the P1 bound: E + term * L1
    turn = (mechanism.acceleration_bound("P1") - mechanism.acceleration_bound("E")) / mechanism.L1
    # gearbox 2: C on a circle of radius rc, the body turning at rate 1 (no angular acceleration)
    box = rc + max(part_reach(parts[n], axis=Z) for n in GEARBOX2_FIXED)
    planter_reach = part_reach(parts["planter-shell"], axis=Z)
    speed = max(box, mechanism.speed_bound("E") + spin * planter_reach)
    acceleration = max(box, mechanism.acceleration_bound("E") + turn * planter_reach)
    return speed, acceleration


def test_arm_to_arm_distance_is_confirmed_by_dense_scans(planting):
    _, mechanism, _, assembly, _ = planting
    parts = {part.name: part for part in assembly.parts}
    scene = FclScene(assembly, [f"{n}-arm1" for n in ARM_PARTS], [f"{n}-arm2" for n in ARM_PARTS])
    speed, acceleration = arm_bounds(mechanism, parts)
    # arm 2 is arm 1 half a turn on: the distance repeats every pi
    result = certified_distance(scene, lipschitz=2 * speed, acceleration=2 * acceleration,
                                steps=90, upper=math.pi, atol=1e-6)
    assert result.certified and not result.interference_ranges and result.bound > 0
    # brute force: a global scan off the certified grid, then a fine window round its best pose
    coarse = np.linspace(0.0, math.pi, 720, endpoint=False) + math.pi / 1440 * 0.37
    values = scene.distances(coarse)
    best = coarse[int(np.argmin(values))]
    window = np.linspace(best - math.pi / 720, best + math.pi / 720, 201)
    dense = min(values.min(), scene.distances(window).min())
    assert dense >= result.bound - 1e-9
    assert result.minimum <= dense + 1e-9
    # the window's spacing leaves at most K h^2 / 8 between its best sample and the bottom
    spacing = window[1] - window[0]
    curvature = 2 * acceleration + (2 * speed) ** 2 / result.bound
    assert dense - result.minimum <= curvature * spacing**2 / 8
    gap = np.linalg.norm(result.point_a - result.point_b)
    assert gap == pytest.approx(result.minimum, abs=1e-9)
    assert result.pair[0].endswith("-arm1") and result.pair[1].endswith("-arm2")


def test_housing_ground_clearance_agrees_with_the_envelope_circles(planting):
    from cadgen.solids.housings import housing_circles

    params, mechanism, evaluation, assembly, housings = planting
    parts = {part.name: part for part in assembly.parts}
    rc = mechanism.carrier_radii["C"]
    # gearbox 1 turns about O (fixed) at rate 1; gearbox 2 about C, which circles at rc
    speed = max(max(part_reach(parts[f"gearbox1-{n}"], axis=Z) for n in ("base", "cover")),
                rc + max(part_reach(parts[f"gearbox2-{n}"], axis=Z) for n in ("base", "cover")))
    scene = FclScene(assembly, HOUSINGS, ["ground"])
    result = certified_distance(scene, lipschitz=speed, acceleration=speed, steps=360)
    kinematic = [m.value for m in evaluation.metrics if m.key == "ground_clearance"][0]
    # the housing's outermost edge (its parting flange) is the wall's hull of circumscribed
    # polygons offset by the flange width, which the envelope circles include: it contains
    # every envelope disc and reaches at most the polygons' sag beyond them
    radius = max(c.radius for c in housing_circles(params, mechanism))
    n = params.solids.segments_per_circle
    sag = radius * (1.0 / math.cos(math.pi / n) - 1.0)
    low = kinematic - sag - 1e-6
    assert result.certified and not result.interference_ranges
    assert low <= result.minimum <= kinematic + 1e-6
    assert result.bound >= low - result.atol
    assert result.pair[1] == "ground"
    assert result.point_b[1] == pytest.approx(evaluation.events.soil_level)


# ------------------------------------------------------------------ the engine against brute force
def _brute_distance(assembly, group_a, group_b, phi, models={}):
    """Least FCL distance over every pair, fresh objects (0 when a pair collides): the
    exhaustive peer of the scene's pruned evaluation."""
    best = math.inf
    parts = {part.name: part for part in assembly.parts}
    for a in group_a:
        for b in group_b:
            objects = []
            for name in (a, b):
                part = parts.get(name) or parts[name.rsplit("-arm", 1)[0]]
                if part.name not in models:
                    models[part.name] = _bvh(part.solid)
                pose = instance_pose(assembly, name, phi)
                objects.append(fcl.CollisionObject(models[part.name],
                                                   fcl.Transform(pose[:3, :3].copy(),
                                                                 pose[:3, 3].copy())))
            if fcl.collide(*objects, fcl.CollisionRequest(), fcl.CollisionResult()):
                return 0.0
            best = min(best, fcl.distance(*objects, fcl.DistanceRequest(), fcl.DistanceResult()))
    return best


def _arm_groups(assembly):
    from cadgen.pipeline.clearances import arm_groups

    return arm_groups(assembly)


def test_scene_distance_is_the_least_of_every_pair_by_brute_force(planting):
    # the scene skips pairs by bounds and hulls: at random poses it must agree with the
    # exhaustive FCL minimum (arms: every part of both arms, blades included; housings: ground)
    _, _, _, assembly, _ = planting
    rng = np.random.default_rng(20261121)
    for group_a, group_b in (_arm_groups(assembly), (HOUSINGS, ("ground",))):
        scene = FclScene(assembly, group_a, group_b)
        for phi in rng.uniform(0.0, 2 * math.pi, 12):
            near = scene.distance(phi)
            truth = _brute_distance(assembly, group_a, group_b, phi)
            assert near.distance == pytest.approx(truth, abs=1e-9)
            assert np.linalg.norm(near.point_b - near.point_a) == pytest.approx(truth, abs=1e-9)


def _stage_inputs(planting):
    from types import SimpleNamespace

    from cadgen.cam.design import design_cam

    params, mechanism, evaluation, assembly, _ = planting
    cam = design_cam(params, mechanism, evaluation.events)
    return params, mechanism, evaluation, SimpleNamespace(assembly=assembly), cam


def test_arm_clearance_with_per_part_bounds_is_confirmed_by_dense_scans(planting):
    from cadgen.pipeline.clearances import arm_interference

    params, mechanism, evaluation, solids, cam = _stage_inputs(planting)
    section = arm_interference(params, mechanism, solids, cam)
    minimum, bound = section["minimum_mm"], section["certified_bound_mm"]
    assert section["certified"] and section["verdict"] == "pass"
    assert minimum - bound <= params.resolution.sweep_atol * (1 + 1e-9)
    # dense scans off the certified grid, through a scene of its own
    scene = FclScene(solids.assembly, *_arm_groups(solids.assembly))
    coarse = np.linspace(0.0, math.pi, 720, endpoint=False) + math.pi / 1440 * 0.37
    values = scene.distances(coarse)
    where = math.radians(section["carrier_angle_deg"])
    window = np.linspace(where - 1e-3, where + 1e-3, 201)
    dense = min(values.min(), scene.distances(window).min())
    assert bound <= dense + 1e-12
    assert minimum <= dense + 1e-9
    # the window's spacing leaves at most K h^2 / 8 between its best sample and the bottom
    from cadgen.pipeline.clearances import _arm_bounds

    speed, acceleration = _arm_bounds(mechanism, {p.name: p for p in solids.assembly.parts}, cam)
    curvature = 2 * acceleration + (2 * speed) ** 2 / bound
    assert dense - minimum <= curvature * (window[1] - window[0]) ** 2 / 8
    assert _brute_distance(solids.assembly, *_arm_groups(solids.assembly), where) \
        == pytest.approx(minimum, abs=1e-9)


def test_ground_clearance_with_per_part_bounds_matches_the_one_bound_sweep(planting):
    from cadgen.pipeline.clearances import ground_clearance

    params, mechanism, evaluation, solids, _ = _stage_inputs(planting)
    section = ground_clearance(params, mechanism, solids, evaluation)
    parts = {part.name: part for part in solids.assembly.parts}
    rc = mechanism.carrier_radii["C"]
    speed = max(max(part_reach(parts[f"gearbox1-{n}"], axis=Z) for n in ("base", "cover")),
                rc + max(part_reach(parts[f"gearbox2-{n}"], axis=Z) for n in ("base", "cover")))
    one = certified_distance(FclScene(solids.assembly, HOUSINGS, ["ground"]), lipschitz=speed,
                             acceleration=speed, steps=90, atol=params.resolution.sweep_atol)
    atol = params.resolution.sweep_atol
    assert section["certified"] and one.certified
    # both certified: each minimum within atol above the true one, each bound below it
    assert section["minimum_mm"] == pytest.approx(one.minimum, abs=atol)
    assert section["certified_bound_mm"] <= one.minimum + 1e-12
    assert one.bound <= section["minimum_mm"] + 1e-12
    # the lowest housing corner over the soil: a plane distance, by hand at the argument
    where = math.radians(section["carrier_angle_deg"])
    # the slab's top as meshed: manifold3d's turn of the extrusion leaves it 1e-9 mm off
    soil = float(parts["ground"].mesh.vertices[:, 1].max())
    assert soil == pytest.approx(evaluation.events.soil_level, abs=1e-8)
    lowest = min(float((part.mesh.vertices @ instance_pose(solids.assembly, name, where)[:3, :3].T
                        + instance_pose(solids.assembly, name, where)[:3, 3])[:, 1].min())
                 for name in HOUSINGS
                 for part in [parts[name.rsplit("-arm", 1)[0]]])
    assert section["minimum_mm"] == pytest.approx(lowest - soil, abs=1e-9)


def test_per_instance_bounds_are_checked():
    assembly, scene = carrier_scene(*face_box(130.0))
    with pytest.raises(ValueError, match="no speed bound"):
        certified_distance(scene, instance_bounds={"moving": (RHO, RHO)})
    with pytest.raises(ValueError, match="finite >= 0"):
        certified_distance(scene, instance_bounds={"moving": (-1.0, RHO), "fixed": (0.0, 0.0)})
    with pytest.raises(ValueError, match="speed bound is needed"):
        certified_distance(scene)
    # the sum of the two instances' bounds is the pair's: the same certified minimum
    both = certified_distance(scene, instance_bounds={"moving": (RHO, RHO), "fixed": (0.0, 0.0)},
                              steps=360, atol=1e-9)
    assert both.certified and both.minimum == pytest.approx(130.0 - RHO, abs=1e-9)


def test_every_interval_of_the_arm_certificate_holds_its_bound(planting):
    # the pairwise search proves a lower bound on each interval of a partition of [0, pi]:
    # the distance sampled inside each (quarter points, through a scene of its own) is above it
    from cadgen.pipeline.clearances import _arm_part_bounds

    params, mechanism, evaluation, solids, cam = _stage_inputs(planting)
    assembly = solids.assembly
    group_a, group_b = _arm_groups(assembly)
    bounds = _arm_part_bounds(mechanism, {part.name: part for part in assembly.parts}, cam)
    instance = {name: bounds[name.rsplit("-arm", 1)[0]] for name in group_a + group_b}
    result = certified_distance(FclScene(assembly, group_a, group_b), steps=90, upper=math.pi,
                                atol=1e-6, instance_bounds=instance)
    certificate = result.certificate[np.argsort(result.certificate[:, 0])]
    assert certificate[0, 0] == 0.0 and certificate[-1, 1] == math.pi
    assert np.all(certificate[1:, 0] == certificate[:-1, 1])
    assert result.certified and certificate[:, 2].min() == pytest.approx(result.bound, abs=0)
    scene = FclScene(assembly, group_a, group_b)
    inside = certificate[:, :1] + np.array([0.25, 0.5, 0.75]) * np.diff(certificate[:, :2])
    distances = scene.distances(inside.ravel()).reshape(inside.shape)
    assert np.all(certificate[:, 2:] <= distances + 1e-12)
