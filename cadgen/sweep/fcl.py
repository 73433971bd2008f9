"""The python-fcl adapter of the sweep: part meshes as FCL models, posed and queried per carrier angle.

:class:`FclScene` answers the pair scene that :mod:`cadgen.sweep.pairwise` asks
of an engine, for two groups of an assembly's part instances, at three costs:
bounding-sphere gaps of every pair; one pair's convex-hull separation along the
direction of GJK's nearest points, snapped to the hull facets there, which is
often the exact distance already (:mod:`cadgen.sweep.proxies`); and FCL's exact
mesh distance. It is the only module of the package that imports ``fcl``
(inside its functions, so that importing it stays cheap).

The distance is the Euclidean distance between the two groups of *solids*: 0
when a surface of one crosses or touches a surface of the other, and also when
one solid lies wholly inside the other (FCL sees only triangles: it reports the
gap between the surfaces and ``collide`` says no, so the scene tests one vertex
of each closed surface by its winding number in the other mesh, wherever the
hulls do not rule it out).

Each part's geometry (hull, GJK convex, and the BVH, built on its first exact
query) is made once per mesh and shared by every scene and pose: the arm and
ground sweeps share gearbox 2's halves, and a part whose hull always answers
never gets a BVH.

python-fcl 0.7.0.11, measured (see ``tests/test_sweep_fcl.py``):

- ``DistanceResult.nearest_points`` of two meshes are in the *world* frame.
- Meshes whose triangles cross give distance 0 (never negative), with
  meaningless nearest points; the scene reports the contact from ``collide``.
- A mesh inside another with no crossing triangles gives the positive gap
  between the surfaces, and ``collide`` says False (handled as above).
- A reused ``DistanceResult`` keeps the old minimum in ``min_distance`` (the
  scene makes a fresh one per query); ``fcl.distance`` with a ``Plane`` or
  ``Halfspace`` crashes the interpreter (model the ground as a mesh).
- GJK on ``Convex`` shapes (libccd) takes microseconds but overshoots the hull
  distance by up to 1.6 mm on the planting parts: the scene uses only its
  direction, and bounds by exact support values along it.
- Mesh against mesh costs 0.5 to 1.5 ms whatever the triangle count, and up to
  20 ms when two large flat faces face each other (every triangle pair is as
  near as the best): hence the hull certificate first.
"""

from __future__ import annotations

import math
import weakref

import numpy as np

from cadgen.solids.errors import SolidInputError
from cadgen.sweep.pairwise import PairSamples
from cadgen.sweep.proxies import facet_certificate, hull_proxy
from cadgen.sweep.scene import Proximity, part_instances

__all__ = ["FclScene"]

#: A point counts as inside a mesh when its winding number exceeds this.
_WINDING_INSIDE = 0.5
#: GJK's nearest points closer than this (mm) give no direction: the centres' is used.
_DIRECTION_MIN = 1e-9


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


# ------------------------------------------------------------------ shapes, once per mesh
class _Shape:
    """One part mesh as the scene queries it: hull proxy and GJK convex now, BVH when asked."""

    def __init__(self, mesh):
        import fcl

        self.vertices = np.ascontiguousarray(mesh.vertices, dtype=np.float64)
        self.faces = np.ascontiguousarray(mesh.faces, dtype=np.int32)
        self.proxy = hull_proxy(self.vertices, self.faces)
        simplices = self.proxy.simplices
        flat = np.column_stack([np.full(len(simplices), 3), simplices]).ravel()
        self.convex = fcl.Convex(self.proxy.vertices, len(simplices), flat)
        self._model = None
        self._probes = None

    @property
    def model(self):
        """The mesh's ``fcl.BVHModel`` (built on first use: most parts never need it)."""
        if self._model is None:
            from cadgen.solids.contact import fcl_tree

            self._model = fcl_tree(self.vertices, self.faces)
        return self._model

    @property
    def triangles(self) -> np.ndarray:
        return self.vertices[self.faces]

    @property
    def probes(self) -> np.ndarray:
        """One vertex of each closed surface (k, 3): containment is decided by one point each."""
        if self._probes is None:
            from cadgen.solids.contact import surface_probes

            self._probes = surface_probes(self.vertices, self.faces)
        return self._probes


#: ``id(mesh) -> _Shape`` of the meshes alive (dropped with their mesh).
_SHAPES: dict = {}


def _shape(mesh) -> _Shape:
    """The shape of ``mesh``, made once while the mesh lives (meshes of parts are never edited)."""
    key = id(mesh)
    shape = _SHAPES.get(key)
    if shape is None:
        shape = _Shape(mesh)
        _SHAPES[key] = shape
        weakref.finalize(mesh, _SHAPES.pop, key, None)
    return shape


# ------------------------------------------------------------------ scene
class FclScene:
    """Two groups of an assembly's part instances, as FCL objects that follow the carrier angle.

    Parameters
    ----------
    assembly : Assembly
    group_a, group_b : sequence of str
        Instance names (see :meth:`Assembly.placements`); disjoint, non-empty.

    Attributes
    ----------
    pairs : list of (str, str)
        Every instance of group A with every instance of group B, in that order.
    queries : int
        Poses placed since construction.
    exact_queries : int
        FCL mesh distances computed since construction.

    Notes
    -----
    :meth:`distance` evaluates the pairs in order of their bounding-sphere gaps
    and stops at the first that cannot come closer than the best found; a pair
    goes to FCL only when its hull bound is below the best and not attained.
    Measured on the build's arm sweep of the paper's design (81 pairs, 162
    poses): one pair-pose in 18 needed its hull, one pose in 7 an FCL query
    (a concave part's nearest point inside its hull); the ground sweep (6 pairs,
    166 poses) needed none, every housing's lowest corner over the soil's top
    face being attained.
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
        self._names = group_a + group_b
        self._placement = [instances[name] for name in self._names]   # (part, body, phase)
        self._shapes = [_shape(part.mesh) for part, _, _ in self._placement]
        index = {name: k for k, name in enumerate(self._names)}
        self.pairs = [(a, b) for a in group_a for b in group_b]
        self._first = np.array([index[a] for a, _ in self.pairs])
        self._second = np.array([index[b] for _, b in self.pairs])
        self._centres = np.array([s.proxy.centre for s in self._shapes])
        self._radii = np.array([s.proxy.radius for s in self._shapes])
        self._hulls = [fcl.CollisionObject(s.convex, fcl.Transform()) for s in self._shapes]
        self._meshes = [None] * len(self._names)
        self._hull_at = [None] * len(self._names)    # the pose each FCL object was last set to
        self._mesh_at = [None] * len(self._names)
        self._request = fcl.DistanceRequest(enable_nearest_points=True)
        self._placed: dict = {}
        self._by_edges = [False] * len(self.pairs)
        self._samples = PairSamples(self)
        self.queries = 0
        self.exact_queries = 0

    # -------------------------------------------------------------- poses
    def _place(self, phi: float, instances=None) -> np.ndarray:
        """World transforms ``(N, 4, 4)`` at carrier angle ``phi``, of ``instances`` (indices;
        default all) at least: placed on demand and kept (a part's placement in its body, a
        turning shaft or an opening blade, costs as much as its body's)."""
        entry = self._placed.get(phi)
        if entry is None:
            if not math.isfinite(phi):
                raise SolidInputError("phi", f"carrier angle must be finite, not {phi!r}")
            entry = ({}, np.empty((len(self._names), 4, 4)), np.zeros(len(self._names), bool))
            self._placed[phi] = entry
            self.queries += 1
        bodies, placed, done = entry
        wanted = range(len(self._names)) if instances is None else instances
        for k in wanted:
            if done[k]:
                continue
            part, body, phase = self._placement[k]
            key = (body, phase)
            if key not in bodies:   # one body pose serves every part riding on it
                bodies[key] = np.asarray(self.assembly.body_pose(body, phi + phase), dtype=float)
            placed[k] = bodies[key] @ np.asarray(part.local(phi + phase), dtype=float)
            done[k] = True
        return placed

    def poses(self, phi: float) -> dict:
        """``{instance name: (4, 4) world transform}`` of both groups at carrier angle ``phi``."""
        placed = self._place(float(phi))
        return {name: placed[k].copy() for k, name in enumerate(self._names)}

    def _posed(self, objects, at, k, phi, placed):
        import fcl

        if at[k] != phi:
            objects[k].setTransform(fcl.Transform(placed[k, :3, :3].copy(),
                                                  placed[k, :3, 3].copy()))
            at[k] = phi
        return objects[k]

    def _mesh_object(self, k, phi, placed):
        import fcl

        if self._meshes[k] is None:
            self._meshes[k] = fcl.CollisionObject(self._shapes[k].model, fcl.Transform())
        return self._posed(self._meshes, self._mesh_at, k, phi, placed)

    # -------------------------------------------------------------- the pair scene
    def lower_bounds(self, phi: float, pairs=None) -> np.ndarray:
        """Bounding-sphere gaps (mm) of every pair, or of the ``pairs`` (P,) bool mask (the
        others -inf): lower bounds of their distances."""
        first, second = self._first, self._second
        out = np.full(len(self.pairs), -np.inf)
        wanted = np.ones(len(self.pairs), bool) if pairs is None else np.asarray(pairs, bool)
        if not wanted.any():
            return out
        first, second = first[wanted], second[wanted]
        used = np.union1d(first, second)
        placed = self._place(float(phi), used)
        centres = np.full((len(self._names), 3), np.nan)
        centres[used] = (np.einsum("nij,nj->ni", placed[used, :3, :3], self._centres[used])
                         + placed[used, :3, 3])
        out[wanted] = (np.linalg.norm(centres[second] - centres[first], axis=1)
                       - self._radii[first] - self._radii[second])
        return out

    def refine(self, phi: float, pair: int, below: float = math.inf):
        """Hull bound of one pair: ``(lower, attained, Proximity or None)``.

        ``lower`` is a true lower bound of the pair's distance; ``attained`` the
        distance of two points of the solids (an upper bound); the Proximity, when
        the bound is attained (:func:`cadgen.sweep.proxies.facet_certificate`),
        looked for only while the bound is below ``below``.
        """
        import fcl

        phi = float(phi)
        i, j = int(self._first[pair]), int(self._second[pair])
        placed = self._place(phi, (i, j))
        hull_a = self._posed(self._hulls, self._hull_at, i, phi, placed)
        hull_b = self._posed(self._hulls, self._hull_at, j, phi, placed)
        result = fcl.DistanceResult()
        gap = fcl.distance(hull_a, hull_b, self._request, result)
        direction = np.asarray(result.nearest_points[1], dtype=float) \
            - np.asarray(result.nearest_points[0], dtype=float) if gap > 0.0 else np.zeros(3)
        if not (np.all(np.isfinite(direction)) and np.linalg.norm(direction) > _DIRECTION_MIN):
            # touching or overlapping hulls (or GJK gave up): the centres' direction still bounds
            centre_a = placed[i, :3, :3] @ self._centres[i] + placed[i, :3, 3]
            centre_b = placed[j, :3, :3] @ self._centres[j] + placed[j, :3, 3]
            direction = centre_b - centre_a
            if not np.linalg.norm(direction) > _DIRECTION_MIN:
                direction = np.array([1.0, 0.0, 0.0])
        lower, exact, attained, by_edges = facet_certificate(
            self._shapes[i].proxy, placed[i], self._shapes[j].proxy, placed[j], direction,
            below=below, edges_first=self._by_edges[pair])
        if exact is None:
            return lower, attained, None
        self._by_edges[pair] = by_edges   # the nearest features change little from pose to pose
        distance, point_a, point_b = exact
        return lower, distance, Proximity(float(distance), point_a, point_b, self.pairs[pair])

    def exact(self, phi: float, pair: int, lower: float = 0.0) -> Proximity:
        """FCL's distance of one pair, 0 when the solids overlap (``lower`` > 0 rules that out)."""
        import fcl

        phi = float(phi)
        i, j = int(self._first[pair]), int(self._second[pair])
        placed = self._place(phi, (i, j))
        names = self.pairs[pair]
        object_a = self._mesh_object(i, phi, placed)
        object_b = self._mesh_object(j, phi, placed)
        self.exact_queries += 1
        if not lower > 0.0:   # the hulls meet: the triangles may cross, or one solid hold the other
            contact = fcl.CollisionResult()
            asked = fcl.CollisionRequest(num_max_contacts=1, enable_contact=True)
            if fcl.collide(object_a, object_b, asked, contact):
                point = np.array(contact.contacts[0].pos, dtype=float)
                return Proximity(0.0, point, point.copy(), names)
            point = self._contained(i, j, placed)
            if point is not None:
                return Proximity(0.0, point, point.copy(), names)
        result = fcl.DistanceResult()   # a reused one keeps the old minimum
        d = fcl.distance(object_a, object_b, self._request, result)
        if d <= 0.0:   # touching without crossing
            point = np.array(result.nearest_points[0], dtype=float)
            return Proximity(0.0, point, point.copy(), names)
        return Proximity(float(d), np.array(result.nearest_points[0], dtype=float),
                         np.array(result.nearest_points[1], dtype=float), names)

    def _contained(self, a, b, placed):
        """A world point of ``a`` inside ``b`` or of ``b`` inside ``a``, else None.

        If no triangles of two closed surfaces meet, each of them lies wholly
        inside or wholly outside the other solid: one vertex per surface decides.
        """
        for inner, outer in ((a, b), (b, a)):
            inner_shape, outer_shape = self._shapes[inner], self._shapes[outer]
            pose, outer_pose = placed[inner], placed[outer]
            probes = inner_shape.probes @ pose[:3, :3].T + pose[:3, 3]
            local = (probes - outer_pose[:3, 3]) @ outer_pose[:3, :3]
            hull = outer_shape.proxy
            near = (local @ hull.normals.T <= hull.offsets).all(axis=1)   # inside its hull
            if not near.any():
                continue
            inside = _winding_numbers(local[near], outer_shape.triangles) > _WINDING_INSIDE
            if inside.any():
                return probes[near][int(np.argmax(inside))]
        return None

    # -------------------------------------------------------------- whole poses
    def distance(self, phi: float) -> Proximity:
        """Least distance between the groups at carrier angle ``phi`` (rad), and where it occurs."""
        phi = float(phi)
        if not math.isfinite(phi):
            raise SolidInputError("phi", f"carrier angle must be finite, not {phi!r}")
        return self._samples.pose(phi).nearest

    def distances(self, phis) -> np.ndarray:
        """Distances ``(n,)`` at carrier angles ``phis`` ``(n,)``."""
        phis = np.atleast_1d(np.asarray(phis, dtype=float))
        return np.array([self.distance(phi).distance for phi in phis.ravel()]).reshape(phis.shape)
