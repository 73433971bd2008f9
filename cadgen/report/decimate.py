"""Triangle-mesh simplification within a distance tolerance: quadric half-edge collapses, in passes.

Garland and Heckbert's quadric error metric ("Surface simplification using quadric
error metrics", SIGGRAPH 1997) measures a vertex's distance to the planes of the
original faces round it; here every collapse moves one vertex onto a neighbour
(a *half-edge* collapse: the mesh's vertices stay a subset of the input's) and is
allowed only while the kept vertex lies within ``tolerance`` of every original
plane merged into it. Flat faces stay flat, sharp edges and corners stay where
they are (leaving them costs the distance to the other side's planes), and a
polygonal circle loses vertices only until its chords would sag by about the
tolerance.

Instead of one collapse at a time from a priority queue (a Python loop over every
vertex), each pass takes, at once, the allowed collapses that are the cheapest round
both ends of their edge, in rounds (the winners of a round set aside the collapses next
to them; the rest compete again): the ends of the collapses of a pass are two edges
apart or more, so they change disjoint sets of faces and are checked on the mesh before
the pass and applied together, vectorized. Passes go on until one collapses fewer than
a small share of the vertices (:data:`_PASSES_RATIO`). A collapse is allowed when the
edge has two faces, its two vertices share exactly two neighbours (the link condition:
the surface keeps its topology), they are not both of three neighbours (a tetrahedron)
and no face round the removed vertex turns over or degenerates. The order (cost, then a
scramble of the edge's ends' coordinates, then the edge) is total, so the same meshes
give the same result. :func:`simplify_meshes` runs several meshes' passes together.

numpy only.
"""

from __future__ import annotations

import numpy as np

__all__ = ["simplify_mesh", "simplify_meshes", "merge_vertices"]

#: A face round a removed vertex may turn by at most this (its normal's cosine); more is a fold.
_MIN_NORMAL_COSINE = 0.2
#: Passes at most (each takes every independent collapse; meshes here settle within ~10).
_MAX_PASSES = 200
#: A pass's rounds end when one collapses fewer than 1/this of its first round's edges, and
#: passes end when one collapses fewer than 1/this of the vertices: the few collapses left
#: would each cost a walk over every edge.
_ROUNDS_RATIO = 32
_PASSES_RATIO = 2000


def merge_vertices(positions, faces) -> tuple[np.ndarray, np.ndarray]:
    """Coincident vertices as one (a file splits a vertex per normal); faces re-indexed.

    Parameters
    ----------
    positions : (n, 3) float
    faces : (m, 3) int

    Returns
    -------
    positions : (k, 3) float
        The distinct positions, sorted by x, then y, then z.
    faces : (m, 3) int
    """
    positions = np.asarray(positions, dtype=float)
    faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    order = np.lexsort(positions.T[::-1])
    rows = positions[order]
    new = np.r_[True, np.any(rows[1:] != rows[:-1], axis=1)]
    index = np.empty(len(positions), dtype=np.int64)
    index[order] = np.cumsum(new) - 1
    return rows[new], index[faces]


#: The upper triangle of a symmetric 4 x 4 matrix, row by row: a quadric's ten numbers.
_UPPER = np.triu_indices(4)


def _monomials(positions) -> np.ndarray:
    """(n, 10): ``h_i h_j`` (doubled off the diagonal) of ``h = (x, y, z, 1)``, so that
    ``h^T Q h`` is this row's dot product with ``Q``'s ten numbers (:data:`_UPPER`)."""
    homogeneous = np.column_stack([positions, np.ones(len(positions))])
    rows, cols = _UPPER
    return homogeneous[:, rows] * homogeneous[:, cols] * np.where(rows == cols, 1.0, 2.0)


def _plane_quadrics(positions, faces, count) -> np.ndarray:
    """(count, 10): per vertex, the sum of ``p p^T`` over its faces' planes ``p = (n, d)``
    (its upper triangle, :data:`_UPPER`)."""
    triangles = positions[faces]
    cross = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    length = np.linalg.norm(cross, axis=1)
    normal = cross / np.where(length > 0, length, 1.0)[:, None]
    plane = np.column_stack([normal, -np.einsum("ij,ij->i", normal, triangles[:, 0])])
    plane[length == 0] = 0.0                          # a degenerate face constrains nothing
    outer = plane[:, _UPPER[0]] * plane[:, _UPPER[1]]
    corner = faces.ravel()
    return np.column_stack([np.bincount(corner, np.repeat(outer[:, k], 3), count)
                            for k in range(outer.shape[1])])


def _edges(faces, count) -> tuple[np.ndarray, np.ndarray]:
    """Undirected edges ``(e, 2)`` (low, high), sorted, and how many faces each has."""
    pairs = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]),
                    axis=1)
    keys, counts = np.unique(pairs[:, 0] * count + pairs[:, 1], return_counts=True)
    return np.column_stack([keys // count, keys % count]), counts


def _gather(sorted_keys, values, queries):
    """For each query ``q``, every ``values[i]`` whose ``sorted_keys[i] == queries[q]``:
    ``(query index, value)`` arrays (a CSR row gather, vectorized)."""
    starts = np.searchsorted(sorted_keys, queries)
    lengths = np.searchsorted(sorted_keys, queries, side="right") - starts
    query = np.repeat(np.arange(len(queries)), lengths)
    at = np.repeat(starts - np.cumsum(lengths) + lengths, lengths) + np.arange(lengths.sum())
    return query, values[at]


def _neighbours(edges):
    """Each vertex's neighbours: ``(vertices, neighbours)``, sorted by vertex (for
    :func:`_gather`)."""
    source = np.concatenate([edges[:, 0], edges[:, 1]])
    target = np.concatenate([edges[:, 1], edges[:, 0]])
    order = np.argsort(source, kind="stable")
    return source[order], target[order]


def _common_neighbours(neighbours, first, second, count) -> np.ndarray:
    """For each pair ``(first[k], second[k])``: how many vertices neighbour both."""
    query, around_first = _gather(*neighbours, first)
    other, around_second = _gather(*neighbours, second)
    shared = np.isin(query * count + around_first, other * count + around_second)
    return np.bincount(query[shared], minlength=len(first))


def _folds(positions, faces, corners, removed, kept) -> np.ndarray:
    """For each collapse ``removed[c] -> kept[c]``: whether a face round ``removed`` that
    does not hold ``kept`` would turn over (or collapse to a line). ``corners``: the faces'
    corners' vertices, sorted, and the corners (:func:`_corners`)."""
    collapse, corner = _gather(*corners, removed)
    face = faces[corner // 3]
    holds_kept = np.any(face == kept[collapse, None], axis=1)
    before = positions[face]
    after = before.copy()
    after[np.arange(len(face)), corner % 3] = positions[kept[collapse]]
    old = np.cross(before[:, 1] - before[:, 0], before[:, 2] - before[:, 0])
    new = np.cross(after[:, 1] - after[:, 0], after[:, 2] - after[:, 0])
    sizes = np.linalg.norm(old, axis=1) * np.linalg.norm(new, axis=1)
    bad = (~holds_kept) & (np.einsum("ij,ij->i", old, new) <= _MIN_NORMAL_COSINE * sizes)
    return np.bincount(collapse[bad], minlength=len(removed)) > 0


def _corners(faces):
    """The faces' corners' vertices, sorted, and the corners in that order."""
    order = np.argsort(faces.ravel(), kind="stable")
    return faces.ravel()[order], order


def _scramble(first, second) -> np.ndarray:
    """A deterministic key per edge from its ends' coordinates' bits, uncorrelated with where
    the edge is (a multiplicative hash, wrapping round 2^64): the same edge, the same key,
    whatever the vertices' numbering (so a mesh alone or among others orders alike)."""
    bits = np.ascontiguousarray(np.hstack([first, second])).view(np.uint64)
    key = np.zeros(len(bits), dtype=np.uint64)
    with np.errstate(over="ignore"):
        for column in range(bits.shape[1]):
            key = (key ^ bits[:, column]) * np.uint64(0x9E3779B97F4A7C15)
            key ^= key >> np.uint64(29)
    return key


def _ring_minimum(values, edges) -> np.ndarray:
    """Per vertex, the least of ``values`` over the vertex and its neighbours."""
    out = values.copy()
    np.minimum.at(out, edges[:, 0], values[edges[:, 1]])
    np.minimum.at(out, edges[:, 1], values[edges[:, 0]])
    return out


def _ring_any(flags, edges) -> np.ndarray:
    """Per vertex, whether it or a neighbour is flagged."""
    out = flags.copy()
    out[edges[flags[edges[:, 1]], 0]] = True
    out[edges[flags[edges[:, 0]], 1]] = True
    return out


def _one_pass(positions, faces, quadrics, tolerance_squared):
    """The independent allowed collapses of one pass: ``(removed, kept)`` vertex arrays."""
    count = len(positions)
    edges, face_counts = _edges(faces, count)
    # keeping an end: its distance to the planes of both ends, h^T (Q_a + Q_b) h; a vertex's
    # own part once per vertex, its neighbour's per edge
    monomials = _monomials(positions)
    own = np.einsum("vk,vk->v", monomials, quadrics)
    cost = np.stack([own[edges[:, k]] + np.einsum("ek,ek->e", monomials[edges[:, k]],
                                                  quadrics[edges[:, 1 - k]])
                     for k in (0, 1)], axis=1)
    keep_first = cost[:, 0] <= cost[:, 1]    # keep the end that sits closer to all the planes
    best = np.where(keep_first, cost[:, 0], cost[:, 1])
    kept = np.where(keep_first, edges[:, 0], edges[:, 1])
    removed = np.where(keep_first, edges[:, 1], edges[:, 0])
    # vertices on an open or non-manifold edge stay (their surface is not a disc round them)
    odd = np.zeros(count, dtype=bool)
    odd[edges[face_counts != 2].ravel()] = True
    # two vertices of three neighbours each: a tetrahedron (or its like), which a collapse
    # would flatten; such a small closed part is left whole
    valence = np.bincount(edges.ravel(), minlength=count)
    candidates = np.flatnonzero((best <= tolerance_squared) & (face_counts == 2)
                                & ~odd[removed] & ((valence[removed] > 3) | (valence[kept] > 3)))
    # a total order (cost, then a scramble of the edge's ends, then the edge: many costs tie
    # at 0 on flat faces, and an order that follows the vertices' own would let only a thin
    # front win each round); in rounds, a collapse competes when it is first among the
    # collapses round both its ends; a winner that passes the link and fold checks goes, and
    # the collapses next to it wait for the next pass. The ends of the collapses of a pass
    # are two edges apart or more, so the faces they change and the links they rest on are
    # apart too, and the checks made on the mesh before the pass hold for each.
    scramble = _scramble(positions[edges[candidates, 0]], positions[edges[candidates, 1]])
    candidates = candidates[np.lexsort((candidates, scramble, best[candidates]))]
    order = np.arange(len(candidates))
    neighbours = corners = None
    chosen = []
    while len(candidates) and (len(chosen) < 2 or len(chosen[-1]) * _ROUNDS_RATIO
                               >= len(chosen[0])):
        ends = edges[candidates]
        first = np.full(count, len(edges), dtype=np.int64)
        np.minimum.at(first, ends[:, 0], order)
        np.minimum.at(first, ends[:, 1], order)
        ring = _ring_minimum(first, edges)
        won = (ring[ends[:, 0]] == order) & (ring[ends[:, 1]] == order)
        winners = candidates[won]
        if neighbours is None:
            neighbours, corners = _neighbours(edges), _corners(faces)
        common = _common_neighbours(neighbours, edges[winners, 0], edges[winners, 1], count)
        good = winners[common == 2]
        good = good[~_folds(positions, faces, corners, removed[good], kept[good])]
        chosen.append(good)
        near = np.zeros(count, dtype=bool)
        near[edges[good].ravel()] = True
        near = _ring_any(near, edges)
        stay = ~won & ~(near[ends[:, 0]] | near[ends[:, 1]])
        candidates, order = candidates[stay], order[stay]
    chosen = np.concatenate(chosen) if chosen else candidates
    return removed[chosen], kept[chosen]


def simplify_meshes(meshes, tolerance: float) -> list[tuple[np.ndarray, np.ndarray]]:
    """:func:`simplify_mesh` of several meshes at once: each pass walks all their edges
    together (a few array operations for all, not for each), and the passes end when they
    collapse little in all of them.

    Parameters
    ----------
    meshes : sequence of ((n, 3) float, (m, 3) int)
    tolerance : float
        As for :func:`simplify_mesh`.

    Returns
    -------
    list of ((k, 3) float, (j, 3) int)
    """
    if not tolerance > 0:
        raise ValueError(f"tolerance must be > 0, not {tolerance!r}")
    merged = []
    for positions, faces in meshes:
        positions, faces = merge_vertices(positions, faces)
        if positions.ndim != 2 or positions.shape[1] != 3:
            raise ValueError(f"positions must be (n, 3), not {positions.shape}")
        merged.append((positions, faces))
    if not merged:
        return []
    starts = np.cumsum([0] + [len(p) for p, _ in merged])
    positions = np.vstack([p for p, _ in merged])
    faces = np.vstack([f + start for (_, f), start in zip(merged, starts)])
    count = len(positions)
    quadrics = _plane_quadrics(positions, faces, count)
    for _ in range(_MAX_PASSES):
        removed, kept = _one_pass(positions, faces, quadrics, tolerance * tolerance)
        if len(removed) * _PASSES_RATIO < count or not len(removed):
            break   # the last few collapses: not worth another walk over every edge
        quadrics[kept] += quadrics[removed]
        target = np.arange(count)
        target[removed] = kept
        faces = target[faces]
        faces = faces[(faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2])
                      & (faces[:, 0] != faces[:, 2])]
    out = []
    mesh_of_face = np.searchsorted(starts, faces[:, 0], side="right") - 1
    for index in range(len(merged)):
        own = faces[mesh_of_face == index]
        used, own = np.unique(own, return_inverse=True)
        out.append((positions[used], own.reshape(-1, 3)))
    return out


def simplify_mesh(positions, faces, tolerance: float) -> tuple[np.ndarray, np.ndarray]:
    """A closed triangle mesh with as few vertices as keep it within ``tolerance`` of its planes.

    Parameters
    ----------
    positions : (n, 3) float
    faces : (m, 3) int
        Triangles, counter-clockwise seen from outside (kept so); coincident vertices
        are merged first.
    tolerance : float
        The largest distance (the positions' unit) of a kept vertex from any original
        face plane merged into it, > 0.

    Returns
    -------
    positions : (k, 3) float
        A subset of the input's distinct positions, in their sorted order.
    faces : (j, 3) int
    """
    return simplify_meshes([(positions, faces)], tolerance)[0]
