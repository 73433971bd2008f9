"""Which placed solids may share material: FCL's test of their surfaces, and whether one holds the other.

The overlap check (:mod:`cadgen.solids.overlaps`) intersects two parts exactly with manifold3d,
which costs milliseconds when one of them is a housing of ten thousand triangles, and ten
times that when their faces lie on each other (a washer on a flange, a key in its keyseat:
every triangle pair coplanar). Most of the pairs a bought solid forms are such contacts, by
design, with no material shared. This module tells them apart first, at a fraction of a
millisecond a pair:

- the bought solid's surface is *inset* by :data:`INSET` (each vertex moved that far into the
  solid along its normal), so a face lying on another no longer touches it; then
- when some triangle of the larger surface has a box meeting the smaller solid's box (seen in
  the larger's frame; else they cannot cross, and no tree is built), FCL's exact triangle
  test says whether the two surfaces cross (one tree per distinct mesh), and if they do not,
- a ray from one vertex of each surface tells whether that solid lies inside the other (a
  screw sunk whole in a wall crosses no surface), by the parity of the ray's crossings.

Two solids that neither cross nor hold one another share nothing thicker than the inset;
every other pair is intersected exactly. fcl is imported inside the functions.
"""

from __future__ import annotations

import functools

import numpy as np

__all__ = ["INSET", "may_overlap", "fcl_tree", "surface_probes"]

#: How far (mm) a bought solid's surface is moved into it before the test: a contact on a face
#: is no overlap. An overlap thinner than this is not measured (0.1 um: below any fit).
INSET = 1e-4
#: The parity test's ray: a direction along no axis and no simple ratio, so it meets no edge of
#: the extruded, axis-aligned parts but by accident of measure zero.
_RAY = np.array([0.5773502691896258, 0.6234898018587335, 0.5271751356520036])
_RAY /= np.linalg.norm(_RAY)
_ACROSS = np.linalg.svd(_RAY[None, :])[2][1:]   # two unit vectors normal to the ray

class _Surface:
    """A mesh as the test reads it: its (inset) vertices, FCL tree, probes and boxes."""

    def __init__(self, mesh, inset: float):
        vertices = np.asarray(mesh.vertices, dtype=np.float64)
        if inset > 0.0:
            vertices = vertices - inset * np.asarray(mesh.vertex_normals, dtype=np.float64)
        self.vertices = np.ascontiguousarray(vertices)
        self.faces = np.ascontiguousarray(mesh.faces, dtype=np.int32)
        self.low, self.high = self.vertices.min(axis=0), self.vertices.max(axis=0)

    # each built on first use only: most large surfaces never need their tree
    @functools.cached_property
    def model(self):
        """The whole surface's FCL tree."""
        return fcl_tree(self.vertices, self.faces)

    @functools.cached_property
    def boxes(self) -> tuple:
        """Each triangle's box (low (f, 3), high (f, 3))."""
        corners = self.vertices[self.faces]
        return corners.min(axis=1), corners.max(axis=1)

    @functools.cached_property
    def probes(self) -> np.ndarray:
        """One vertex of each closed surface (k, 3)."""
        return surface_probes(self.vertices, self.faces)

    @functools.cached_property
    def _ray(self) -> tuple:
        """The triangles seen along :data:`_RAY`: their corners across it (f, 3, 2), those
        corners' boxes, and the corners' depths along it (f, 3)."""
        corners = (self.vertices @ _ACROSS.T)[self.faces]
        return (corners, corners.min(axis=1), corners.max(axis=1),
                (self.vertices @ _RAY)[self.faces])

    def inside(self, points) -> np.ndarray:
        """Whether each point (m, 3, in the mesh's frame) is inside the closed surface: the
        parity of a ray's crossings, the triangles first picked by their boxes across it."""
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        corners, low, high, depth = self._ray
        flat, along = points @ _ACROSS.T, points @ _RAY
        near = np.all((low[None] <= flat[:, None]) & (flat[:, None] <= high[None]), axis=2)
        out = np.zeros(len(points), dtype=bool)
        for k in range(len(points)):
            picked = np.flatnonzero(near[k])
            a, b, c = (corners[picked, i] for i in range(3))
            # barycentric weights of the point in each triangle (seen along the ray)
            ab, ac, aq = b - a, c - a, flat[k] - a
            det = ab[:, 0] * ac[:, 1] - ac[:, 0] * ab[:, 1]
            ok = np.abs(det) > 0.0
            det = np.where(ok, det, 1.0)
            u = (aq[:, 0] * ac[:, 1] - ac[:, 0] * aq[:, 1]) / det
            v = (ab[:, 0] * aq[:, 1] - aq[:, 0] * ab[:, 1]) / det
            hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1)
            at = (1 - u - v) * depth[picked, 0] + u * depth[picked, 1] + v * depth[picked, 2]
            out[k] = int(np.count_nonzero(hit & (at > along[k]))) % 2 == 1
        return out


def surface_probes(vertices, faces) -> np.ndarray:
    """One vertex of each closed surface of a mesh (k, 3): whether a closed surface that
    crosses no other lies inside it is decided by one point of it."""
    import trimesh

    faces = np.asarray(faces)
    adjacency = trimesh.graph.face_adjacency(faces=faces)
    groups = trimesh.graph.connected_components(adjacency, nodes=np.arange(len(faces)))
    return np.array([np.asarray(vertices)[faces[group[0], 0]] for group in groups])


def fcl_tree(vertices, faces):
    """A python-fcl BVH model of a triangle mesh (its ``endModel`` called: a model without it
    crashes the first query)."""
    import fcl

    model = fcl.BVHModel()
    model.beginModel(len(faces), len(vertices))
    model.addSubModel(np.ascontiguousarray(vertices, dtype=np.float64),
                      np.ascontiguousarray(faces, dtype=np.int32))
    model.endModel()
    return model





def _collide(tree_a, pose_a, tree_b, pose_b) -> bool:
    import fcl

    return bool(fcl.collide(
        fcl.CollisionObject(tree_a, fcl.Transform(pose_a[:3, :3].copy(), pose_a[:3, 3].copy())),
        fcl.CollisionObject(tree_b, fcl.Transform(pose_b[:3, :3].copy(), pose_b[:3, 3].copy())),
        fcl.CollisionRequest(num_max_contacts=1), fcl.CollisionResult()))


def _seen_boxes(surfaces, poses, smalls, big_pose) -> tuple:
    """The boxes (low (k, 3), high (k, 3)) of the ``smalls`` (indices) seen in a frame posed at
    ``big_pose``: each the box of its own box's turned corners."""
    unit = np.array(np.meshgrid([0, 1], [0, 1], [0, 1])).T.reshape(-1, 3)
    lows = np.array([surfaces[k].low for k in smalls])
    highs = np.array([surfaces[k].high for k in smalls])
    corners = lows[:, None, :] + unit[None] * (highs - lows)[:, None, :]          # (k, 8, 3)
    relative = np.linalg.solve(big_pose[None], np.array([poses[k] for k in smalls]))
    seen = np.einsum("kij,kcj->kci", relative[:, :3, :3], corners) + relative[:, None, :3, 3]
    return seen.min(axis=1), seen.max(axis=1)


def _near_any(triangle_boxes, low, high, chunk: int = 1 << 22) -> np.ndarray:
    """Whether any triangle's box meets each box ``low[k]``..``high[k]`` (k, 3): (k,) bool,
    the comparisons made a few million at a time."""
    tri_low, tri_high = triangle_boxes
    rows = max(1, chunk // max(len(tri_low), 1))
    out = np.zeros(len(low), dtype=bool)
    for start in range(0, len(low), rows):
        part = slice(start, start + rows)
        meet = ((tri_low[None] <= high[part, None]) & (tri_high[None] >= low[part, None]))
        out[part] = meet.all(axis=2).any(axis=1)
    return out


def may_overlap(items, pairs, boxes) -> np.ndarray:
    """Whether each pair of placed solids may share material.

    Parameters
    ----------
    items : sequence of (trimesh.Trimesh, (4, 4) float, bool)
        Each solid's closed mesh in its own frame, its pose in the world, and whether it is
        inset by :data:`INSET` first (a bought solid lying on its seat).
    pairs : (k, 2) int
        Indices into ``items``.
    boxes : (n, 6) float
        Each solid's box in the world (low, high): one can hold the other only if its box does.

    Returns
    -------
    (k,) bool
        False only where the two surfaces do not cross and neither solid holds the other.
    """
    made: dict = {}   # one surface per distinct mesh and inset (the bought solids share theirs)
    surfaces = []
    for mesh, _, inset in items:
        key = (id(mesh), bool(inset))
        if key not in made:
            made[key] = _Surface(mesh, INSET if inset else 0.0)
        surfaces.append(made[key])
    poses = [np.asarray(pose, dtype=float) for _, pose, _ in items]
    boxes = np.asarray(boxes, dtype=float)
    pairs = np.asarray(pairs, dtype=int).reshape(-1, 2)
    # each pair under its larger surface, whose triangles near the smaller one are picked
    groups: dict = {}
    for index, (i, j) in enumerate(pairs):
        big, small = (i, j) if len(surfaces[i].faces) >= len(surfaces[j].faces) else (j, i)
        groups.setdefault(big, []).append((index, small))
    out = np.zeros(len(pairs), dtype=bool)
    for big, members in groups.items():
        surface, pose = surfaces[big], poses[big]
        smalls = [small for _, small in members]
        seen_low, seen_high = _seen_boxes(surfaces, poses, smalls, pose)
        near = _near_any(surface.boxes, seen_low, seen_high)
        clear = []
        for m, (index, small) in enumerate(members):
            # the larger surface's tree is built only when some of its triangles come near
            if near[m] and _collide(surface.model, pose, surfaces[small].model, poses[small]):
                out[index] = True
            else:
                clear.append((index, small))
        # no surfaces cross: each solid lies wholly inside or wholly outside the other, and
        # one can hold the other only if its box does
        held = [(index, small) for index, small in clear
                if np.all((boxes[big, :3] <= boxes[small, :3]) & (boxes[small, 3:] <= boxes[big, 3:]))]
        if held:
            probes = [surfaces[small].probes @ poses[small][:3, :3].T + poses[small][:3, 3]
                      for _, small in held]
            local = (np.vstack(probes) - pose[:3, 3]) @ pose[:3, :3]
            inside = surface.inside(local)
            starts = np.cumsum([0] + [len(p) for p in probes])
            for (index, _), a, b in zip(held, starts[:-1], starts[1:]):
                out[index] |= bool(inside[a:b].any())
        for index, small in clear:
            if not out[index] and np.all((boxes[small, :3] <= boxes[big, :3])
                                         & (boxes[big, 3:] <= boxes[small, 3:])):
                probes = surface.probes @ pose[:3, :3].T + pose[:3, 3]
                local = (probes - poses[small][:3, 3]) @ poses[small][:3, :3]
                out[index] = bool(surfaces[small].inside(local).any())
    return out
