"""Convex-hull proxies of a part: lower bounds of the distance between two solids, and when they are exact.

Numpy and scipy only (the engine that finds a good direction, or the exact
distance when the proxies cannot, lives in :mod:`cadgen.sweep.fcl`).

A solid lies inside the convex hull of its vertices, so for any unit direction
``n`` (from solid A towards solid B)::

    distance(A, B) >= min over hull(B) of n . b  -  max over hull(A) of n . a

(the *separation* along ``n``; equal to the distance between the hulls when
``n`` is the direction of their nearest points). It is a true lower bound of
the distance between the *solids*, containment included: a solid inside another
has its hull inside the other's, and every separation is then <= 0.

The bound is also the exact distance when it is attained: when a vertex ``a``
of A (a point of A) plus ``gap * n`` lands inside a triangle of B's surface (or
the other way round), ``|a - q|`` is a distance between points of the two
solids and cannot be less than the minimum. That happens wherever the nearest
features are a vertex and a face on the hulls (a corner over a flat face: a
housing over the soil, a plate edge facing a wall), found by snapping ``n`` to
the hull facets at the supporting vertices (:func:`facet_certificate`). Edge
against edge, or a nearest point in a concavity, is left to the exact engine.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from cadgen.solids.errors import SolidInputError

__all__ = ["HullProxy", "hull_proxy", "separation", "facet_certificate", "sphere_gaps",
           "EXACT_GAP", "SUPPORT_TOL", "FACET_CANDIDATES"]

#: A certificate counts as exact when the attained distance exceeds its lower bound by
#: no more than this (mm): rounding of coordinates of a few hundred mm, far below any
#: sweep tolerance.
EXACT_GAP = 1e-10
#: Vertices within this (mm) of the supporting plane are tried as the nearest vertex:
#: a face of a part lies in one plane only up to rounding.
SUPPORT_TOL = 1e-7
#: Hull facets tried per side at each supporting vertex (the most aligned first).
FACET_CANDIDATES = 2
#: A mesh triangle lies in a hull facet's plane when its corners are this close (mm).
_PLANE_TOL = 1e-7
#: Vertices of the supporting set tried per facet (a flat face of a housing has many).
_MAX_SUPPORT = 64


@dataclass
class HullProxy:
    """A part's convex hull in the part's own frame, and the surface it bounds.

    Attributes
    ----------
    vertices : (h, 3) float
        Hull vertices (each a vertex of the part: a point of the solid). qhull
        drops a vertex that is within its rounding of a facet: on the planting
        parts no vertex is outside the hull by more than 2e-13 mm, which is all
        a support value can miss.
    normals : (f, 3) float
        Outward unit normals of the hull facets.
    offsets : (f,) float
        ``normals . x <= offsets`` inside the hull.
    vertex_facets : (h + 1,) int and (3 f,) int
        CSR lists of the facets at each hull vertex (``indptr``, ``indices``).
    simplices : (f, 3) int
        The facets' corners (indices into ``vertices``), outward wound.
    centre, radius : (3,) float, float
        A sphere holding the whole part (every vertex).
    surface_vertices, surface_faces : (n, 3) float, (m, 3) int
        The part's mesh, for the triangles lying in a facet's plane.
    surface_ids : (h,) int
        Each hull vertex's index in ``surface_vertices``.
    """

    vertices: np.ndarray
    normals: np.ndarray
    offsets: np.ndarray
    indptr: np.ndarray
    indices: np.ndarray
    simplices: np.ndarray
    centre: np.ndarray
    radius: float
    surface_vertices: np.ndarray
    surface_faces: np.ndarray
    surface_ids: np.ndarray
    _planes: dict = field(default_factory=dict, repr=False)
    _faces_at: tuple = field(default=None, repr=False)

    def facets_at(self, vertex: int) -> np.ndarray:
        """Facet indices at hull vertex ``vertex``."""
        return self.indices[self.indptr[vertex]:self.indptr[vertex + 1]]

    def edges_at(self, vertex: int) -> np.ndarray:
        """The surface's edges ``(k, 2, 3)`` at hull vertex ``vertex`` (segments of the part).

        Each edge twice (once per face at it): harmless, and no sorting of the
        mesh's edges. Faces at each vertex found once per part (CSR).
        """
        if self._faces_at is None:
            flat = self.surface_faces.ravel()
            order = np.argsort(flat, kind="stable")
            indptr = np.searchsorted(flat[order], np.arange(len(self.surface_vertices) + 1))
            self._faces_at = (indptr, order // 3)
        indptr, owner = self._faces_at
        at = int(self.surface_ids[vertex])
        faces = self.surface_faces[owner[indptr[at]:indptr[at + 1]]]
        others = faces[faces != at].reshape(-1, 2)   # each face's two other corners
        return self.surface_vertices[np.column_stack([np.full(others.size, at),
                                                      others.ravel()])]

    def plane_triangles(self, facet: int):
        """The part's surface triangles lying in the plane of hull facet ``facet``.

        As :func:`_triangle_frames` of them: found once per facet and kept (the
        flat faces of a part that the hull shares: a flange face, the soil's top).
        """
        found = self._planes.get(facet)
        if found is None:
            heights = self.surface_vertices @ self.normals[facet] - self.offsets[facet]
            on_plane = np.abs(heights) <= _PLANE_TOL
            faces = self.surface_faces[on_plane[self.surface_faces].all(axis=1)]
            found = _triangle_frames(self.surface_vertices[faces])
            self._planes[facet] = found
        return found


def _triangle_frames(triangles):
    """Per triangle (m, 3, 3): its first corner, unit normal, and the two vectors whose dot
    products with ``point - corner`` are its barycentric coordinates (degenerate ones dropped)."""
    origin = triangles[:, 0]
    u, v = triangles[:, 1] - origin, triangles[:, 2] - origin
    normal = np.cross(u, v)
    area2 = np.einsum("ij,ij->i", normal, normal)
    keep = area2 > 0.0
    origin, u, v, normal, area2 = origin[keep], u[keep], v[keep], normal[keep], area2[keep]
    # (w x v) . n = w . (v x n) and (u x w) . n = w . (n x u): no projection needed to test
    beta = np.cross(v, normal) / area2[:, None]
    gamma = np.cross(normal, u) / area2[:, None]
    return origin, normal / np.sqrt(area2)[:, None], beta, gamma


def hull_proxy(vertices, faces) -> HullProxy:
    """The :class:`HullProxy` of a closed mesh ``vertices`` (n, 3), ``faces`` (m, 3) (local frame)."""
    from scipy.spatial import ConvexHull, QhullError

    vertices = np.asarray(vertices, dtype=float)
    faces = np.asarray(faces, dtype=np.int64)
    if vertices.ndim != 2 or vertices.shape[1] != 3 or len(vertices) < 4 \
            or not np.all(np.isfinite(vertices)):
        raise SolidInputError("mesh", f"a hull needs at least 4 finite 3-D vertices, "
                                      f"not an array of shape {vertices.shape}")
    try:
        hull = ConvexHull(vertices)
    except QhullError as error:   # flat or degenerate: no solid
        raise SolidInputError("mesh", f"the part has no volume to bound: {error}") from None
    used = np.unique(hull.simplices)
    remap = np.full(len(vertices), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    simplices = remap[hull.simplices]
    normals = hull.equations[:, :3]
    # qhull leaves a facet's winding arbitrary: make each turn about its outward normal
    corners = vertices[hull.simplices]
    turn = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    flip = np.einsum("ij,ij->i", turn, normals) < 0.0
    simplices[flip] = simplices[flip][:, ::-1]
    offsets = -hull.equations[:, 3]
    # facets at each vertex, as CSR: the facets a supporting vertex can snap to
    flat = simplices.ravel()
    order = np.argsort(flat, kind="stable")
    indptr = np.searchsorted(flat[order], np.arange(len(used) + 1))
    indices = (order // 3).astype(np.int64)
    centre = 0.5 * (vertices.min(axis=0) + vertices.max(axis=0))
    radius = float(np.linalg.norm(vertices - centre, axis=1).max())
    return HullProxy(np.ascontiguousarray(vertices[used]), np.ascontiguousarray(normals),
                     np.ascontiguousarray(offsets), indptr, indices, simplices, centre, radius,
                     vertices, faces, used)


def sphere_gaps(centres_a, radii_a, centres_b, radii_b) -> np.ndarray:
    """Gaps ``(n,)`` between spheres ``a`` and ``b`` paired row by row: a lower bound of the
    distance between any solids they hold (negative when they meet)."""
    return (np.linalg.norm(np.asarray(centres_b) - np.asarray(centres_a), axis=-1)
            - np.asarray(radii_a) - np.asarray(radii_b))


def _support(proxy, rotation, translation, direction, lowest: bool):
    """Support value of the posed hull along ``direction`` (world) and the supporting vertex."""
    heights = proxy.vertices @ (rotation.T @ direction)
    index = int(np.argmin(heights) if lowest else np.argmax(heights))
    return float(heights[index] + direction @ translation), index, heights


def separation(a: HullProxy, pose_a, b: HullProxy, pose_b, direction):
    """Separation of the posed hulls along the world direction ``direction`` (from a to b).

    Parameters
    ----------
    a, b : HullProxy
    pose_a, pose_b : (4, 4) float
        World transforms of the two parts.
    direction : (3,) float
        Non-zero; normalised here.

    Returns
    -------
    gap : float
        ``min n . b - max n . a``: a lower bound of the distance between the solids (mm).
    vertex_a, vertex_b : int
        The supporting hull vertices.
    """
    direction = np.asarray(direction, dtype=float)
    norm = float(np.linalg.norm(direction))
    if not (np.isfinite(norm) and norm > 0.0):
        raise SolidInputError("direction", f"must be a finite non-zero 3-vector, not {direction!r}")
    direction = direction / norm
    top_a, vertex_a, _ = _support(a, pose_a[:3, :3], pose_a[:3, 3], direction, lowest=False)
    low_b, vertex_b, _ = _support(b, pose_b[:3, :3], pose_b[:3, 3], direction, lowest=True)
    return low_b - top_a, vertex_a, vertex_b


def _in_triangles(points, frames):
    """``(index, projection)`` of the first point (k, 3) inside one of the triangles, or None.

    ``frames`` from :func:`_triangle_frames`. Barycentric coordinates in each
    triangle's own plane, all >= 0 (no slack: a point on a shared edge that
    rounding puts just outside both is left to the exact engine).
    """
    origin, normal, beta_axis, gamma_axis = frames
    if not len(origin):
        return None
    w = points[:, None, :] - origin[None, :, :]                      # (k, m, 3)
    beta = np.einsum("kmi,mi->km", w, beta_axis)
    gamma = np.einsum("kmi,mi->km", w, gamma_axis)
    inside = (beta >= 0.0) & (gamma >= 0.0) & (beta + gamma <= 1.0)
    hits = np.flatnonzero(inside.any(axis=1))
    if not hits.size:
        return None
    index = int(hits[0])
    triangle = int(np.argmax(inside[index]))
    # the point's projection on that triangle's plane: a point of the surface
    height = float(w[index, triangle] @ normal[triangle])
    return index, points[index] - height * normal[triangle]


def _segment_pairs(first, second):
    """Closest points of every segment of ``first`` (k, 2, 3) to every one of ``second`` (l, 2, 3).

    Returns ``(points_first, points_second)``, each (k, l, 3) (Ericson,
    *Real-Time Collision Detection*, 5.1.9, vectorised; segments of length 0
    are points).
    """
    p1, q1 = first[:, None, 0], first[:, None, 1]
    p2, q2 = second[None, :, 0], second[None, :, 1]
    d1, d2 = q1 - p1, q2 - p2
    r = p1 - p2
    a = np.einsum("...i,...i->...", d1, d1)
    e = np.einsum("...i,...i->...", d2, d2)
    f = np.einsum("...i,...i->...", d2, r)
    c = np.einsum("...i,...i->...", d1, r)
    b = np.einsum("...i,...i->...", d1, d2)
    a, e = np.broadcast_arrays(a, e)
    with np.errstate(divide="ignore", invalid="ignore"):
        denominator = a * e - b * b
        alone = np.where(a > 0.0, np.clip(-c / a, 0.0, 1.0), 0.0)   # first against a point
        s = np.where(denominator > 0.0, np.clip((b * f - c * e) / denominator, 0.0, 1.0),
                     np.where(e > 0.0, 0.0, alone))
        t = np.where(e > 0.0, (b * s + f) / e, 0.0)
        # t outside [0, 1]: clamp it and recompute s for that end
        s = np.where(t < 0.0, alone,
                     np.where(t > 1.0, np.where(a > 0.0, np.clip((b - c) / a, 0.0, 1.0), 0.0), s))
    t = np.clip(t, 0.0, 1.0)
    return p1 + d1 * s[..., None], p2 + d2 * t[..., None]


def _certify_edges(a, pose_a, b, pose_b, vertex_a, vertex_b):
    """The nearest points of the surface edges at two supporting vertices, when attained.

    Any two points of the edges are points of the solids: their distance is an
    upper bound; the separation along the line through the closest two is a
    lower bound; equal, they are the distance (edge against edge, a vertex
    against an edge, two vertices: what a facet's plane cannot certify).
    Returns ``(gap, (distance, point_a, point_b))`` or ``(gap, None)``.
    """
    first = a.edges_at(vertex_a) @ pose_a[:3, :3].T + pose_a[:3, 3]
    second = b.edges_at(vertex_b) @ pose_b[:3, :3].T + pose_b[:3, 3]
    if not (len(first) and len(second)):
        return -np.inf, None
    near_a, near_b = _segment_pairs(first, second)
    lengths = np.linalg.norm(near_b - near_a, axis=-1)
    k, m = np.unravel_index(int(np.argmin(lengths)), lengths.shape)
    point_a, point_b, distance = near_a[k, m], near_b[k, m], float(lengths[k, m])
    if not distance > 0.0:
        return -np.inf, None
    gap, _, _ = separation(a, pose_a, b, pose_b, point_b - point_a)
    if distance - gap <= EXACT_GAP:
        return gap, (distance, point_a, point_b)
    return gap, None


def _certify_facet(a, pose_a, b, pose_b, facet_side, facet):
    """Try the direction of one hull facet (of ``b`` if ``facet_side == 1`` else of ``a``).

    Returns ``(gap, certificate)``: the separation along the facet's normal (a
    lower bound), and ``(distance, point_a, point_b)`` when a vertex of the other
    part lands on a surface triangle in the facet's plane, else None.
    """
    owner, owner_pose = (b, pose_b) if facet_side else (a, pose_a)
    other, other_pose = (a, pose_a) if facet_side else (b, pose_b)
    # from a to b: b's facet faces a (its outward normal points back), a's faces b
    normal = owner_pose[:3, :3] @ owner.normals[facet]
    direction = -normal if facet_side else normal
    gap, _, _ = separation(a, pose_a, b, pose_b, direction)
    if not gap > 0.0:
        return gap, None
    # the other part's vertices on its supporting plane along the facet's normal (towards it)
    rotation, translation = other_pose[:3, :3], other_pose[:3, 3]
    heights = other.vertices @ (rotation.T @ normal)
    nearest = np.flatnonzero(heights <= heights.min() + SUPPORT_TOL)
    # nearest first: the first that lands on the surface is the best certificate
    nearest = nearest[np.argsort(heights[nearest], kind="stable")][:_MAX_SUPPORT]
    points = other.vertices[nearest] @ rotation.T + translation
    # those points carried across the gap, in the owner's frame, on the owner's surface?
    targets = (points - gap * normal - owner_pose[:3, 3]) @ owner_pose[:3, :3]
    found = _in_triangles(targets, owner.plane_triangles(facet))
    if found is None:
        return gap, None
    index, on_surface = found
    vertex = points[index]
    surface = on_surface @ owner_pose[:3, :3].T + owner_pose[:3, 3]
    distance = float(np.linalg.norm(surface - vertex))
    pair = (surface, vertex) if not facet_side else (vertex, surface)
    return gap, (distance, pair[0], pair[1])


def facet_certificate(a: HullProxy, pose_a, b: HullProxy, pose_b, direction,
                      candidates: int = FACET_CANDIDATES, below: float = np.inf,
                      edges_first: bool = False):
    """Best lower bound near ``direction`` and, when attained, the exact distance.

    The separation along ``direction`` (world, from a to b; say from an
    approximate nearest-point search) and along the normals of the hull facets at
    the two supporting vertices most aligned with it, ``candidates`` per side.
    A facet whose normal is the true nearest direction gives the exact distance
    when a vertex of the other part lands on the part's own surface in that
    facet's plane; then (or first, ``edges_first``) the surface edges at the
    two supporting vertices (:func:`_certify_edges`: edge against edge). The
    certificates are looked for only while the bound is below ``below`` (a pair
    already known to be farther than what matters needs none).

    Returns
    -------
    lower : float
        The largest separation found: a lower bound of the distance (mm).
    exact : tuple or None
        ``(distance, point_a, point_b)`` (mm, world points of a and b) when a
        separation is attained within :data:`EXACT_GAP`; then ``distance`` is the
        distance between the solids (it is both attained and at most
        ``EXACT_GAP`` above a lower bound).
    upper : float
        The distance between the two supporting vertices along ``direction``:
        two points of the solids, so an upper bound of their distance (mm).
    by_edges : bool
        The certificate came from the edges (a caller may try them first next time).
    """
    gap, vertex_a, vertex_b = separation(a, pose_a, b, pose_b, direction)
    point_a = pose_a[:3, :3] @ a.vertices[vertex_a] + pose_a[:3, 3]
    point_b = pose_b[:3, :3] @ b.vertices[vertex_b] + pose_b[:3, 3]
    upper = float(np.linalg.norm(point_b - point_a))
    lower = gap
    if not 0.0 < gap < below:
        return lower, None, upper, False
    direction = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    tries = []
    for side, proxy, pose, vertex, sign in ((1, b, pose_b, vertex_b, -1.0),
                                            (0, a, pose_a, vertex_a, 1.0)):
        facets = proxy.facets_at(vertex)
        alignment = (proxy.normals[facets] @ (pose[:3, :3].T @ direction)) * sign
        for k in np.argsort(-alignment, kind="stable")[:candidates]:
            tries.append((alignment[k], side, int(facets[k])))
    attempts = [(False, lambda side=side, facet=facet:
                  _certify_facet(a, pose_a, b, pose_b, side, facet))
                for _, side, facet in sorted(tries, key=lambda t: -t[0])]
    attempts.insert(0 if edges_first else len(attempts),
                    (True, lambda: _certify_edges(a, pose_a, b, pose_b, vertex_a, vertex_b)))
    for by_edges, attempt in attempts:
        gap, exact = attempt()
        lower = max(lower, gap)
        if exact is not None and exact[0] - gap <= EXACT_GAP:
            # every bound found is a true one: above the attained distance only by rounding
            return min(lower, exact[0]), exact, exact[0], by_edges
    return lower, None, upper, False
