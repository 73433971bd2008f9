"""The python-fcl adapter of the sweep: part meshes as FCL models, posed and queried per carrier angle.

:class:`FclScene` builds one ``fcl.BVHModel`` per part mesh (float64 vertices,
``endModel`` called) and one ``fcl.CollisionObject`` per part instance, once;
each query only moves the objects to the poses of carrier angle ``phi``. It is
the engine behind the certified search of :mod:`cadgen.sweep.search`, and the
only module of the package that imports ``fcl`` (inside its functions, so that
importing it stays cheap).

The distance is the Euclidean distance between the two groups of *solids*: 0
when a surface of one crosses or touches a surface of the other, and also when
one solid lies wholly inside the other (FCL sees only triangles: it reports the
gap between the surfaces and ``collide`` says no, so the scene tests one vertex
of each closed surface by its winding number in the other mesh).

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
from dataclasses import dataclass

import numpy as np

from cadgen.solids.errors import SolidInputError
from cadgen.sweep.scene import Proximity, part_instances

__all__ = ["FclScene"]

#: Covering spheres of a part: 2**depth leaves, on triangles no longer than this
#: fraction of the part's bounding radius (they only prune pairs: speed, not accuracy).
_LEAF_DEPTH = 4
_LEAF_EDGE_FRACTION = 0.25
#: A point counts as inside a mesh when its winding number exceeds this.
_WINDING_INSIDE = 0.5


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
        instances = part_instances(assembly)
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
