"""Collision sweep of an assembly through a revolution: certified least distance, interference.

The FCL adapter of the clearance checks. :class:`FclScene` builds one
``fcl.BVHModel`` per part mesh (float64 vertices, ``endModel`` called) and one
``fcl.CollisionObject`` per part instance, once; each query only moves the
objects to the poses of carrier angle ``phi``. :func:`certified_distance` feeds
the scene's distance to :func:`kinematics.sweep.certified_minimum` and scans the
same samples for interference; :func:`plain_scan` is the sampling-only peer.

The distance is the Euclidean distance between the two groups of *solids*: 0
when a surface of one crosses or touches a surface of the other, and also when
one solid lies wholly inside the other (FCL sees only triangles: it reports the
gap between the surfaces and ``collide`` says no, so the scene tests one vertex
of each closed surface by its winding number in the other mesh). That distance
is continuous in ``phi`` with ``|d distance / d phi|`` at most the largest
relative speed of any point of one group against any point of the other.

Lipschitz bound (the caller's, mm per rad of carrier angle). For one body
whose origin moves at most ``v`` mm/rad, which turns at most ``w`` rad/rad, and
whose part moves in the body (a gear on its shaft, a blade on its hinge) at
most ``u`` mm/rad, every point of the part moves at most::

    v + w * part_reach(part, origin) + u

A group's bound is the largest over its instances, and the pair's is the sum
of the two groups' bounds (a fixed group contributes 0). :func:`part_reach`
gives the geometric factor; the speeds belong to the mechanism. The optional
acceleration bound is formed the same way from the origin's acceleration
``a``, the angular acceleration ``alpha`` and rate ``w``: ``a + (alpha + w**2)
* reach (+ the local motion's)``; with it the search is second order (see
:func:`certified_distance`).

python-fcl 0.7.0.11, measured (see ``tests/test_sweep_fcl.py``):

- ``DistanceResult.nearest_points`` of two meshes are in the *world* frame.
- Meshes whose triangles cross give distance 0 (never negative), with
  meaningless nearest points; the scene reports the contact from ``collide``.
- A mesh inside another with no crossing triangles gives the positive gap
  between the surfaces, and ``collide`` says False (handled as above).
- A reused ``DistanceResult`` keeps the old minimum in ``min_distance`` (the
  scene makes a fresh one per query); ``fcl.distance`` with a ``Plane`` or
  ``Halfspace`` crashes the interpreter (model the ground as a mesh).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from cadgen.solids.errors import SolidInputError

__all__ = [
    "INTERFERENCE_XTOL",
    "INTERFERENCE_RESOLUTION",
    "MAX_EVALUATIONS",
    "Proximity",
    "FclScene",
    "SweepResult",
    "certified_distance",
    "plain_scan",
    "part_reach",
    "instance_pose",
]

#: Carrier-angle tolerance (rad) of the ends of an interference range (bisection).
INTERFERENCE_XTOL = 1e-9
#: Narrowest interval (rad) the interference scan splits where the Lipschitz bound
#: cannot rule out an overlap; an overlap shorter than this can hide in one.
INTERFERENCE_RESOLUTION = 1e-6
#: Default budget of poses of :func:`certified_distance` (each pass).
MAX_EVALUATIONS = 20_000
#: Covering spheres of a part: 2**depth leaves, on triangles no longer than this
#: fraction of the part's bounding radius (they only prune pairs: speed, not accuracy).
_LEAF_DEPTH = 4
_LEAF_EDGE_FRACTION = 0.25
#: A point counts as inside a mesh when its winding number exceeds this.
_WINDING_INSIDE = 0.5


# ------------------------------------------------------------------ poses
def _instances(assembly):
    """``{instance name: (part, body, phase)}`` of every placed copy, in assembly order."""
    out = {}
    for part in assembly.parts:
        for name, body, phase in part.instances or ((part.name, part.body, 0.0),):
            out[name] = (part, body, float(phase))
    return out


def instance_pose(assembly, name: str, phi: float) -> np.ndarray:
    """World transform (4, 4) of one part instance at carrier angle ``phi`` (rad).

    The same pose :meth:`Assembly.placements` gives, without placing every other part.
    """
    instances = _instances(assembly)
    if name not in instances:
        raise SolidInputError("name", f"no part instance {name!r} in the assembly; "
                                      f"instances: {sorted(instances)}")
    part, body, phase = instances[name]
    return assembly.body_pose(body, phi + phase) @ part.local(phi + phase)


def part_reach(part, body_origin_local=(0.0, 0.0, 0.0), *, phi: float = 0.0, axis=None) -> float:
    """Largest distance (mm) of a part's vertices from a point of its body, placed in the body.

    Parameters
    ----------
    part : Part
    body_origin_local : (3,) float
        The point of the body frame the body's speed bound refers to (its origin,
        or the hub it turns about), mm.
    phi : float
        Carrier angle of the local placement (rad). Exact for a part fixed in its
        body; a part moving in its body needs its own motion bound on top.
    axis : (3,) float, optional
        Measure the distance from the line through ``body_origin_local`` along
        ``axis`` instead (a body turning about that axis: the tighter factor).

    Returns
    -------
    float
    """
    origin = np.asarray(body_origin_local, dtype=float)
    if origin.shape != (3,) or not np.all(np.isfinite(origin)):
        raise SolidInputError("body_origin_local",
                              f"must be 3 finite numbers, not {body_origin_local!r}")
    vertices = np.asarray(part.mesh.vertices, dtype=float)
    local = np.asarray(part.local(phi), dtype=float)
    offsets = vertices @ local[:3, :3].T + local[:3, 3] - origin
    if axis is not None:
        direction = np.asarray(axis, dtype=float)
        norm = float(np.linalg.norm(direction)) if direction.shape == (3,) else 0.0
        if not (np.isfinite(norm) and norm > 0.0):
            raise SolidInputError("axis", f"must be a non-zero 3-vector, not {axis!r}")
        direction = direction / norm
        offsets = offsets - np.outer(offsets @ direction, direction)
    return float(np.linalg.norm(offsets, axis=1).max())


# ------------------------------------------------------------------ containment
def _winding_numbers(points, triangles):
    """Generalised winding numbers of ``points`` (m, 3) in a closed mesh ``triangles`` (n, 3, 3).

    Solid angles by Van Oosterom and Strackee; about 1 inside, 0 outside (and in
    a void of the mesh), for a consistently outward-wound closed mesh.
    """
    relative = triangles[None, :, :, :] - points[:, None, None, :]
    a, b, c = relative[..., 0, :], relative[..., 1, :], relative[..., 2, :]
    la, lb, lc = (np.linalg.norm(v, axis=-1) for v in (a, b, c))
    dot = lambda u, v: np.einsum("...i,...i->...", u, v)   # noqa: E731
    numerator = dot(a, np.cross(b, c))
    denominator = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la
    return np.arctan2(numerator, denominator).sum(axis=1) / (2.0 * math.pi)


@dataclass
class _Shape:
    """One part mesh as FCL sees it, plus the bounds that let a query skip it (local frame)."""

    model: object              # fcl.BVHModel
    triangles: np.ndarray      # (n, 3, 3)
    probes: np.ndarray         # (k, 3) one vertex of each closed surface
    centre: np.ndarray         # (3,) bounding sphere of the whole part
    radius: float
    leaf_centres: np.ndarray   # (m, 3) spheres that together cover every triangle
    leaf_radii: np.ndarray     # (m,)


def _sphere(points):
    centre = 0.5 * (points.min(axis=0) + points.max(axis=0))
    return centre, float(np.linalg.norm(points - centre, axis=1).max())


def _leaf_spheres(triangles, depth):
    """Spheres covering the triangles: median splits along the longest extent, ``2**depth`` leaves.

    A sphere holding a triangle's corners holds the triangle, so the spheres'
    gaps bound the distance between two surfaces from below.
    """
    groups = [triangles]
    for _ in range(depth):
        split = []
        for group in groups:
            if len(group) < 2:
                split.append(group)
                continue
            centroids = group.mean(axis=1)
            axis = int(np.argmax(np.ptp(centroids, axis=0)))
            order = np.argsort(centroids[:, axis], kind="stable")
            half = len(group) // 2
            split += [group[order[:half]], group[order[half:]]]
        groups = split
    spheres = [_sphere(group.reshape(-1, 3)) for group in groups]
    return np.array([c for c, _ in spheres]), np.array([r for _, r in spheres])


def _shape(mesh, depth=_LEAF_DEPTH, edge_fraction=_LEAF_EDGE_FRACTION):
    import fcl
    import trimesh

    vertices = np.ascontiguousarray(mesh.vertices, dtype=np.float64)
    faces = np.ascontiguousarray(mesh.faces, dtype=np.int32)
    model = fcl.BVHModel()
    model.beginModel(len(faces), len(vertices))
    model.addSubModel(vertices, faces)
    model.endModel()  # without it the first query crashes
    components = trimesh.graph.connected_components(mesh.face_adjacency,
                                                    nodes=np.arange(len(faces)))
    probes = np.array([vertices[faces[component[0], 0]] for component in components])
    centre, radius = _sphere(vertices)
    triangles = vertices[faces]
    # the covering spheres are built on a finer copy: long slivers (the fans of a
    # prism's caps) would make every leaf sphere as large as the part
    v, f = trimesh.remesh.subdivide_to_size(vertices, faces, max_edge=edge_fraction * radius)
    cover = v[f]
    leaf_centres, leaf_radii = _leaf_spheres(cover, depth)
    return _Shape(model, triangles, probes, centre, radius, leaf_centres, leaf_radii)


# ------------------------------------------------------------------ scene
class Proximity(NamedTuple):
    """The closest approach of two groups at one pose.

    ``distance`` (mm) is exactly 0.0 when the groups overlap (surfaces cross or
    touch, or one solid lies inside the other); the two points (world frame, mm)
    are then both a point of the overlap. ``pair`` names the instances.
    """

    distance: float
    point_a: np.ndarray
    point_b: np.ndarray
    pair: tuple

    @property
    def overlap(self) -> bool:
        return self.distance <= 0.0


class FclScene:
    """Two groups of an assembly's part instances, as FCL objects that follow the carrier angle.

    Parameters
    ----------
    assembly : Assembly
    group_a, group_b : sequence of str
        Instance names (see :meth:`Assembly.placements`); disjoint, non-empty.

    Notes
    -----
    Each part's triangles are covered by a few spheres (median splits); pairs
    are visited by the gap between their spheres, nearest first, and skipped
    once that gap (a lower bound) reaches the best distance found, which leaves
    the minimum unchanged. Only the instances of the two groups are posed.

    Cost, measured on the paper's planting parts (about 400 to 1,400 triangles):
    one FCL mesh distance takes 0.1 to 1.5 ms whatever the gap, so a pose of
    the arm-to-arm scene (9 pairs) costs 3 to 5 ms, about 1 ms of it the poses.
    """

    def __init__(self, assembly, group_a, group_b):
        import fcl

        group_a, group_b = tuple(group_a), tuple(group_b)
        instances = _instances(assembly)
        unknown = [n for n in group_a + group_b if n not in instances]
        if unknown:
            raise SolidInputError("groups", f"unknown part instances {unknown}; "
                                            f"the assembly has {sorted(instances)}")
        if not group_a or not group_b:
            raise SolidInputError("groups",
                                  f"both groups need an instance, got {group_a} and {group_b}")
        shared = sorted(set(group_a) & set(group_b))
        if shared:
            raise SolidInputError("groups", f"instances {shared} are in both groups")
        if len(set(group_a)) < len(group_a) or len(set(group_b)) < len(group_b):
            raise SolidInputError("groups", f"an instance is repeated in {group_a} or {group_b}")
        self.assembly = assembly
        self.group_a, self.group_b = group_a, group_b
        shapes = {}
        self._instances = {}
        for name in group_a + group_b:
            part, body, phase = instances[name]
            if part.name not in shapes:
                shapes[part.name] = _shape(part.mesh)
            shape = shapes[part.name]
            self._instances[name] = (part, body, phase, shape,
                                     fcl.CollisionObject(shape.model, fcl.Transform()))
        self._pairs = [(a, b) for a in group_a for b in group_b]
        self.queries = 0   # poses evaluated since construction

    # -------------------------------------------------------------- poses
    def poses(self, phi: float) -> dict:
        """``{instance name: (4, 4) world transform}`` of both groups at carrier angle ``phi``."""
        bodies = {}
        out = {}
        for name, (part, body, phase, _, _) in self._instances.items():
            key = (body, phase)
            if key not in bodies:   # one body pose serves every part riding on it
                bodies[key] = np.asarray(self.assembly.body_pose(body, phi + phase), dtype=float)
            out[name] = bodies[key] @ np.asarray(part.local(phi + phase), dtype=float)
        return out

    def _place(self, phi):
        import fcl

        poses = self.poses(phi)
        for name, pose in poses.items():
            obj = self._instances[name][4]
            obj.setTransform(fcl.Transform(pose[:3, :3].copy(), pose[:3, 3].copy()))
        return poses

    # -------------------------------------------------------------- queries
    def distance(self, phi: float) -> Proximity:
        """Least distance between the groups at carrier angle ``phi`` (rad), and where it occurs."""
        import fcl

        phi = float(phi)
        if not math.isfinite(phi):
            raise SolidInputError("phi", f"carrier angle must be finite, not {phi!r}")
        poses = self._place(phi)
        self.queries += 1
        gaps = self._sphere_gaps(poses)
        for index, (a, b) in enumerate(self._pairs):
            # a solid inside another: no triangles meet and FCL sees a gap; it can only
            # happen where the two parts' covering spheres meet
            if gaps[index] > 0.0:
                continue
            point = self._contained(a, b, poses)
            if point is not None:
                return Proximity(0.0, point, point.copy(), (a, b))
        best = Proximity(math.inf, np.full(3, np.nan), np.full(3, np.nan), self._pairs[0])
        request = fcl.DistanceRequest(enable_nearest_points=True)
        for index in np.argsort(gaps, kind="stable"):
            if gaps[index] >= best.distance:
                break   # no later pair can come closer
            a, b = self._pairs[index]
            object_a, object_b = self._instances[a][4], self._instances[b][4]
            if gaps[index] <= 0.0:   # covering spheres meet: the triangles may cross
                contact = fcl.CollisionResult()
                asked = fcl.CollisionRequest(num_max_contacts=1, enable_contact=True)
                if fcl.collide(object_a, object_b, asked, contact):
                    point = np.array(contact.contacts[0].pos, dtype=float)
                    return Proximity(0.0, point, point.copy(), (a, b))
            result = fcl.DistanceResult()   # a reused one keeps the old minimum
            d = fcl.distance(object_a, object_b, request, result)
            if d <= 0.0:   # touching without crossing
                point = np.array(result.nearest_points[0], dtype=float)
                return Proximity(0.0, point, point.copy(), (a, b))
            if d < best.distance:
                best = Proximity(float(d), np.array(result.nearest_points[0], dtype=float),
                                 np.array(result.nearest_points[1], dtype=float), (a, b))
        return best

    def _sphere_gaps(self, poses):
        """Lower bound (mm) of each pair's surface distance, from the covering spheres: (pairs,)."""
        world = {}
        for name, pose in poses.items():
            shape = self._instances[name][3]
            world[name] = shape.leaf_centres @ pose[:3, :3].T + pose[:3, 3]
        gaps = np.empty(len(self._pairs))
        for index, (a, b) in enumerate(self._pairs):
            centre_gap = np.linalg.norm(world[a][:, None, :] - world[b][None, :, :], axis=-1)
            radii = (self._instances[a][3].leaf_radii[:, None]
                     + self._instances[b][3].leaf_radii[None, :])
            gaps[index] = float((centre_gap - radii).min())
        return gaps

    def _contained(self, a, b, poses):
        """A world point of ``a`` inside ``b`` or of ``b`` inside ``a``, else None.

        If no triangles of two closed surfaces meet, each of them lies wholly
        inside or wholly outside the other solid: one vertex per surface decides.
        """
        for inner, outer in ((a, b), (b, a)):
            inner_shape, outer_shape = self._instances[inner][3], self._instances[outer][3]
            pose, outer_pose = poses[inner], poses[outer]
            probes = inner_shape.probes @ pose[:3, :3].T + pose[:3, 3]
            local = (probes - outer_pose[:3, 3]) @ outer_pose[:3, :3]
            near = np.linalg.norm(local - outer_shape.centre, axis=1) <= outer_shape.radius
            if not near.any():
                continue
            inside = _winding_numbers(local[near], outer_shape.triangles) > _WINDING_INSIDE
            if inside.any():
                return probes[near][int(np.argmax(inside))]
        return None

    def distances(self, phis) -> np.ndarray:
        """Distances ``(n,)`` at carrier angles ``phis`` ``(n,)``, for :func:`certified_minimum`."""
        phis = np.atleast_1d(np.asarray(phis, dtype=float))
        return np.array([self.distance(phi).distance for phi in phis.ravel()]).reshape(phis.shape)


# ------------------------------------------------------------------ sweep
@dataclass(frozen=True)
class SweepResult:
    """Outcome of :func:`certified_distance`.

    Attributes
    ----------
    minimum : float
        Least distance found (mm); 0 when the groups interfere.
    argument : float
        Carrier angle where it occurs (rad).
    bound : float
        Certified lower bound: no carrier angle of the interval gives less (mm).
    certified : bool
        The bound is within ``atol`` of the minimum.
    evaluations : int
        Poses evaluated in all (screen, refinement and interference scan).
    point_a, point_b : (3,) float
        Nearest points at ``argument``, world frame (mm); equal when overlapping.
    pair : tuple of str
        The instances they belong to.
    interference_ranges : list of (float, float)
        Carrier-angle ranges (rad) where the groups overlap, ends within
        ``INTERFERENCE_XTOL``; an overlap that runs through ``upper`` and on from
        ``lower`` is two ranges.
    unresolved : int
        Intervals no wider than ``resolution`` (or left when the budget ran out)
        where the Lipschitz bound could not rule out a brief overlap and none was
        sampled (see :func:`certified_distance`).
    samples_phi, samples_distance : (steps + 1,) float
        The screening grid and its distances, to plot distance against carrier angle.
    lipschitz, acceleration, atol : float
        As given (``acceleration`` None when not given).
    seconds : float
        Wall time of the sweep.
    """

    minimum: float
    argument: float
    bound: float
    certified: bool
    evaluations: int
    point_a: np.ndarray
    point_b: np.ndarray
    pair: tuple
    interference_ranges: list
    unresolved: int
    samples_phi: np.ndarray = field(repr=False)
    samples_distance: np.ndarray = field(repr=False)
    lipschitz: float = 0.0
    acceleration: float | None = None
    atol: float = 0.0
    seconds: float = 0.0

    @property
    def interferes(self) -> bool:
        return bool(self.interference_ranges) or self.minimum <= 0.0


def _curvature(acceleration, lipschitz):
    """``d'' <= A + L^2 / d`` on an interval whose first-order lower bound is ``d > 0``."""

    def bound(first_order_bounds):
        with np.errstate(divide="ignore"):
            return np.where(first_order_bounds > 0.0,
                            acceleration + lipschitz**2 / first_order_bounds, np.inf)

    return bound


class _Memo:
    """The scene's distance with a cache, so the screening grid is posed once for both passes."""

    def __init__(self, scene):
        self.scene = scene
        self.values = {}

    def __call__(self, phis):
        phis = np.atleast_1d(np.asarray(phis, dtype=float))
        out = np.empty(phis.shape)
        for index, phi in np.ndenumerate(phis):
            key = float(phi)
            if key not in self.values:
                self.values[key] = self.scene.distance(key)
            out[index] = self.values[key].distance
        return out

    def proximity(self, phi):
        self(np.array([phi]))
        return self.values[float(phi)]


def _interference(distance, grid, values, lipschitz, xtol, resolution, budget):
    """Overlap ranges from the screening samples, refined where the bound allows an overlap.

    Level by level, as :func:`certified_minimum` does: an interval with both ends
    overlapping counts as overlapping; both ends clear and
    ``(d_left + d_right - L h) / 2 > 0``: clear, certified; one end of each:
    split until narrower than ``xtol`` (bisection of the boundary); otherwise
    split until narrower than ``resolution``. Returns ``(ranges, unresolved,
    evaluations)``; intervals left when ``budget`` evaluations are spent count
    as unresolved.
    """
    left, right = grid[:-1], grid[1:]
    f_left, f_right = values[:-1], values[1:]
    ranges, unresolved, evaluations = [], 0, 0
    while left.size:
        o_left, o_right = f_left <= 0.0, f_right <= 0.0
        width = right - left
        both = o_left & o_right
        ranges += list(zip(left[both], right[both]))
        mixed = o_left ^ o_right
        settled = mixed & (width <= xtol)
        middle = 0.5 * (left + right)
        ranges += [(a, m) if oa else (m, b) for a, b, m, oa in
                   zip(left[settled], right[settled], middle[settled], o_left[settled])]
        clear = ~(o_left | o_right)
        possible = clear & (0.5 * (f_left + f_right - lipschitz * width) <= 0.0)
        small = possible & (width <= resolution)
        unresolved += int(small.sum())
        split = (mixed & ~settled) | (possible & ~small)
        if evaluations + int(split.sum()) > budget:
            unresolved += int(split.sum())
            break
        left, right, middle = left[split], right[split], middle[split]
        f_left, f_right = f_left[split], f_right[split]
        if not left.size:
            break
        f_middle = distance(middle)
        evaluations += middle.size
        left, right = np.concatenate([left, middle]), np.concatenate([middle, right])
        f_left, f_right = np.concatenate([f_left, f_middle]), np.concatenate([f_middle, f_right])
    merged = []
    for start, end in sorted((float(a), float(b)) for a, b in ranges):
        if merged and start <= merged[-1][1]:
            merged[-1] = (merged[-1][0], max(merged[-1][1], end))
        else:
            merged.append((start, end))
    return merged, unresolved, evaluations


def certified_distance(scene: FclScene, *, lipschitz: float, acceleration: float | None = None,
                       steps: int = 360, atol: float = 1e-6,
                       lower: float = 0.0, upper: float = 2.0 * math.pi,
                       xtol: float = INTERFERENCE_XTOL,
                       resolution: float = INTERFERENCE_RESOLUTION,
                       max_evaluations: int = MAX_EVALUATIONS) -> SweepResult:
    """Certified least distance of the scene's groups over ``[lower, upper]``, and interference.

    Parameters
    ----------
    scene : FclScene
    lipschitz : float
        Upper bound ``L`` (mm/rad) on ``|d distance / d phi|``: the largest
        relative speed of any point of group A against any point of group B (see
        the module notes). The caller's responsibility: too small a bound voids
        the certificate.
    acceleration : float, optional
        Upper bound ``A`` (mm/rad^2) on the relative acceleration of any point of
        A against any point of B. The distance is then screened to second order,
        ``d'' <= A + L^2 / d`` (it is the least of point-to-point distances, each
        obeying that), which a smooth minimum needs: with ``L`` alone the search
        splits down to intervals of ``2 atol / L`` round it, thousands of poses.
        A kink (the nearest features switching) needs only ``L``.
    steps : int
        Intervals of the screening grid.
    atol : float
        The true minimum lies in ``[bound, minimum]`` and ``minimum - bound <= atol``
        when ``certified``.
    lower, upper : float
        Carrier-angle interval (rad); for two arms half a turn apart the
        distance repeats every ``pi``.
    xtol : float
        Tolerance (rad) of the ends of interference ranges.
    resolution : float
        Narrowest interval (rad) split in search of an overlap.
    max_evaluations : int
        Budget of poses, for the minimum search and again for the interference
        scan; when spent, ``certified`` is False (or ``unresolved`` counts the
        intervals left).

    Notes
    -----
    Interference is scanned on the screening samples first. An overlap shorter
    than a step can fall between two samples; the Lipschitz bound rules that
    out wherever ``d_left + d_right > L h`` (the distance cannot reach 0 in
    between), so only the remaining intervals are split further (a collide and
    distance query per midpoint), down to ``resolution``; the ends of each
    overlap are bisected to ``xtol``. What is left (``unresolved``) are
    intervals narrower than ``resolution`` in which the distance comes within
    ``L * resolution / 2`` of 0, next to a range found or at a near touch: an
    overlap missed there lasts less than ``resolution``. A brief separation
    inside an overlap (both ends of an interval overlapping) is not looked for:
    the parts interfere either way. When ``bound > 0`` no overlap exists at all.

    The scan runs first: when it finds an overlap the minimum is 0, certified
    (the distance is never negative), at the first overlapping pose sampled.
    """
    from kinematics.sweep import certified_minimum

    if not (math.isfinite(lipschitz) and lipschitz >= 0.0):
        raise SolidInputError("lipschitz", f"must be a finite bound >= 0, not {lipschitz!r}")
    if acceleration is not None and not (math.isfinite(acceleration) and acceleration >= 0.0):
        raise SolidInputError("acceleration", f"must be a finite bound >= 0, not {acceleration!r}")
    if not (isinstance(steps, (int, np.integer)) and steps >= 2):
        raise SolidInputError("steps", f"must be an integer >= 2, not {steps!r}")
    if not (math.isfinite(lower) and math.isfinite(upper) and upper > lower):
        raise SolidInputError("interval", f"need finite lower < upper, got [{lower!r}, {upper!r}]")
    if not (xtol > 0.0 and resolution >= xtol):
        raise SolidInputError("xtol",
                              f"need 0 < xtol <= resolution, got {xtol!r} and {resolution!r}")
    start = time.perf_counter()
    lipschitz = float(lipschitz)
    curvature = None if acceleration is None else _curvature(float(acceleration), lipschitz)
    memo = _Memo(scene)
    grid = np.linspace(lower, upper, int(steps) + 1)   # certified_minimum's screening grid
    values = memo(grid)
    ranges, unresolved, _ = _interference(memo, grid, values, lipschitz, xtol, resolution,
                                          max_evaluations)
    if ranges:
        # the distance is never negative: an overlap is the certified minimum, and
        # searching on would only split the overlap down to 2 atol / L
        minimum = bound = 0.0
        argument = min(phi for phi, near in memo.values.items() if near.overlap)
    else:
        found = certified_minimum(memo, lower, upper, steps=int(steps), lipschitz=lipschitz,
                                  curvature=curvature, atol=atol, max_evaluations=max_evaluations)
        minimum, argument, bound = found.value, found.argument, max(found.bound, 0.0)
    near = memo.proximity(argument)
    return SweepResult(
        minimum=float(minimum), argument=float(argument), bound=float(bound),
        certified=bool(minimum - bound <= atol * (1.0 + 1e-9)), evaluations=len(memo.values),
        point_a=near.point_a, point_b=near.point_b, pair=near.pair,
        interference_ranges=ranges, unresolved=unresolved, samples_phi=grid,
        samples_distance=values, lipschitz=lipschitz, acceleration=acceleration, atol=float(atol),
        seconds=time.perf_counter() - start)


def plain_scan(scene: FclScene, poses: int = 3600, *, lower: float = 0.0,
               upper: float = 2.0 * math.pi) -> tuple:
    """The sampling-only peer: least distance over ``poses`` evenly spaced carrier angles.

    Returns ``(minimum, argument)`` (mm, rad). No bound: the true minimum may be
    lower by up to ``L * step / 2``.
    """
    if not (isinstance(poses, (int, np.integer)) and poses >= 1):
        raise SolidInputError("poses", f"must be a positive integer, not {poses!r}")
    phis = np.linspace(lower, upper, int(poses), endpoint=False)
    values = scene.distances(phis)
    best = int(np.argmin(values))
    return float(values[best]), float(phis[best])
