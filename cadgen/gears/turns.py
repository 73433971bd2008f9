"""First contact by turning: how far one gear turns about its centre until it touches its mate.

Turning the driven gear about its own centre moves every point of it along a circle, so the
angle to first contact each way is exact for polygon outlines: for each vertex of one gear,
the nearest crossing of the other gear's outline with that vertex's circle about the driven
centre. :func:`first_contact_turns` solves it for many poses at once, over the vertices near
each pose's contact (:class:`WindowEdges`), without a pass over every vertex and edge pair:

* interval stabbing by radius bins: an edge can only cross the circles of radii within its
  own radial span;
* angular bins first: the turns that decide a mesh are small, so a point is first tried
  only against the edges within one angular bin of it; a pose settles there when its turns
  both ways are shorter than a bin (the pairs not tried turn further). Fine bins first
  (:data:`FINE_ANGLE_BINS`), then coarse ones (:data:`ANGLE_BINS`) for the poses left, and
  the points of any pose still unsettled are tried against every edge of its window.

numpy only.
"""

from __future__ import annotations

import numpy as np

__all__ = ["WindowEdges", "first_contact_turns", "ANGLE_BINS", "FINE_ANGLE_BINS"]


class WindowEdges:
    """One gear's window vertices for a batch of poses and the edges leaving them, in the
    frame the turns are measured in (the driven gear's body frame: turns about its origin).

    Parameters
    ----------
    start, end : (n, 2) float
        Each vertex and the next vertex of its outline.
    pose : (n,) int
        The pose (of the batch) each vertex belongs to.

    The radii and polar angles of both ends are computed once here: each side's vertices
    are the points of one search and the edges of the other.
    """

    def __init__(self, start, end, pose):
        self.start, self.end, self.pose = start, end, np.asarray(pose, dtype=np.int64)
        self.radius = np.linalg.norm(start, axis=1)
        self.radius_end = np.linalg.norm(end, axis=1)
        self.polar = np.arctan2(start[:, 1], start[:, 0])
        self.polar_end = np.arctan2(end[:, 1], end[:, 0])

    def __len__(self) -> int:
        return len(self.start)


#: Angular bins of the turn search (2 deg each): a pose's first contact either way is looked
#: for among the edges within one bin of each point's polar angle first (the turns that
#: decide a mesh are tenths of a degree); a pose with nothing that close either way is
#: searched again over every edge of its window.
ANGLE_BINS = 180
#: Angular bins of the first try (0.25 deg each): a mesh's first contacts are about a tenth of
#: a degree away (measured: at most 0.13 deg on the paper's pairs, kernel-b's 0.12), so the
#: poses settle there among an eighth of the pairs of :data:`ANGLE_BINS`' 2 deg bins; the
#: poses that do not are tried again with those.
FINE_ANGLE_BINS = 1440
#: rad: an edge's polar extent is widened by this before binning (the crossing's polar angle
#: is computed, not exact), and a turn must be this much inside one bin to be taken.
_ANGLE_SLACK = 1e-9


def _spread(first, counts):
    """``(owner, index)``: for every k, the indices ``first[k] .. first[k] + counts[k] - 1``,
    each with the k it came from."""
    total = int(counts.sum())
    owner = np.repeat(np.arange(len(counts)), counts)
    # index - position in the output is constant over each k's run: first[k] - run start
    index = np.arange(total) + np.repeat(first - (np.cumsum(counts) - counts), counts)
    return owner, index


class _Listing:
    """Edges listed under integer keys, sorted once, looked up by many points."""

    def __init__(self, key, edge):
        order = np.argsort(key)
        self.key, self.edge = key[order], edge[order]

    def pairs(self, wanted, last=None):
        """``(i, j)``: each point ``i`` with every edge ``j`` listed under a key from
        ``wanted[i]`` to ``last[i]`` (default: ``wanted[i]`` alone)."""
        first = np.searchsorted(self.key, wanted, side="left")
        stop = wanted if last is None else last
        counts = np.searchsorted(self.key, stop, side="right") - first
        i, index = _spread(first, counts)
        return i, self.edge[index]


def _crossing_turns(points, i, edges, j):
    """Turn of the edge ``j`` onto point ``i`` about the origin where ``j`` crosses the
    point's circle (rad in [-pi, pi)), for pairs whose edge spans the point's radius."""
    radii = points.radius
    start, d = edges.start[j], edges.end[j] - edges.start[j]
    a = np.einsum("ij,ij->i", d, d)
    b = 2 * np.einsum("ij,ij->i", start, d)
    c = np.einsum("ij,ij->i", start, start) - radii[i] ** 2
    root = np.sqrt(np.maximum(b * b - 4 * a * c, 0.0))
    t = (-b + root) / (2 * a)
    t = np.where((t >= 0) & (t <= 1), t, (-b - root) / (2 * a))
    hit = start + np.clip(t, 0.0, 1.0)[:, None] * d
    angle = points.polar[i] - np.arctan2(hit[:, 1], hit[:, 0])
    return (angle + np.pi) % (2 * np.pi) - np.pi


def first_contact_turns(points: WindowEdges, edges: WindowEdges, poses: int):
    """Turns about the origin that bring ``points``' vertices onto their pose's ``edges``.

    Several poses at once: each vertex and edge is tagged with its pose. Only the (vertex,
    edge) pairs of one pose whose edge spans the vertex's radius are solved (a segment
    crosses a circle where its radial span contains that radius), and of those first only
    the pairs whose polar angles are within one of :data:`ANGLE_BINS` bins.

    Returns
    -------
    positive, negative : (poses,) float
        Per pose, the smallest positive and the largest negative turn of the *points* that
        would carry one onto an edge; +-inf where none.
    """
    positive = np.full(poses, np.inf)
    negative = np.full(poses, -np.inf)
    if len(points) == 0 or len(edges) == 0:
        return positive, negative
    radii = points.radius
    low = np.minimum(edges.radius, edges.radius_end)
    high = np.maximum(edges.radius, edges.radius_end)
    # radius bins about as wide as a typical edge's radial span; an edge is listed in every
    # bin its span touches and a point looks in its own: x -> floor(x / width) is monotone,
    # so an edge spanning a point's radius is always listed in the point's bin (the exact
    # test drops the others listed there)
    width = max(float(np.median(high - low)), 1e-9 * float(high.max()), 1e-300)
    bins = int(np.floor(max(high.max(), radii.max()) / width)) + 2
    low_bin = np.floor(low / width).astype(np.int64)
    radial = np.floor(high / width).astype(np.int64) - low_bin + 1
    point_bin = np.floor(radii / width).astype(np.int64)
    spans = (low, high, bins, low_bin, radial, point_bin)
    settled = np.zeros(poses, dtype=bool)
    points_in, edges_in = None, None     # None: every point and edge
    for count in (FINE_ANGLE_BINS, ANGLE_BINS):
        found = _nearest_turns(points, edges, poses, spans, count, points_in, edges_in)
        if found is None:
            continue
        # a pose's extremes among the pairs tried are its true ones once it settles
        found_positive, found_negative, done = found
        done &= ~settled
        positive[done], negative[done] = found_positive[done], found_negative[done]
        settled |= done
        if settled.all():
            return positive, negative
        points_in, edges_in = ~settled[points.pose], ~settled[edges.pose]
    # the rest: every edge of the pose's window at the point's radius
    if points_in is None:
        points_in = np.ones(len(points), dtype=bool)
        edges_in = np.ones(len(edges), dtype=bool)
    edge, offset = _spread(low_bin[edges_in], radial[edges_in])
    edge = np.flatnonzero(edges_in)[edge]
    key = edges.pose[edge] * bins + offset
    which = np.flatnonzero(points_in)
    i, j = _Listing(key, edge).pairs(points.pose[which] * bins + point_bin[which])
    i = which[i]
    keep = (low[j] <= radii[i]) & (high[j] >= radii[i])
    i, j = i[keep], j[keep]
    rest_positive, rest_negative = _extremes(_crossing_turns(points, i, edges, j),
                                             points.pose[i], poses)
    positive[~settled], negative[~settled] = rest_positive[~settled], rest_negative[~settled]
    return positive, negative


def _extremes(angle, pose, poses: int):
    """Per pose, the smallest positive and the largest negative of ``angle``."""
    positive, negative = np.full(poses, np.inf), np.full(poses, -np.inf)
    up, down = angle > 0, angle < 0
    np.minimum.at(positive, pose[up], angle[up])
    np.maximum.at(negative, pose[down], angle[down])
    return positive, negative


def _nearest_turns(points: WindowEdges, edges: WindowEdges, poses: int, spans,
                   angle_bins: int = ANGLE_BINS, points_in=None, edges_in=None):
    """A first pass of :func:`first_contact_turns`: only the pairs whose polar angles are
    within one angular bin (``2 pi / angle_bins``) of each other, among the points and edges
    of ``points_in`` and ``edges_in`` (masks; None: all).

    A pair turning by at most one bin width has the crossing's polar angle in the point's
    bin or a neighbour, and the edge is listed in every bin its polar extent (so the
    crossing) touches: every pair turning by less than a bin is found. So a pose whose
    smallest positive turn found is under a bin has its true smallest positive turn (the
    pairs not found turn further), and likewise the largest negative. Returns ``(positive,
    negative, settled)``, ``settled`` the poses where both hold; None where binning by angle
    cannot help (an edge spanning a third of the turn).
    """
    low, high, bins, low_bin, radial, point_bin = spans
    step = 2 * np.pi / angle_bins
    chosen = np.arange(len(edges)) if edges_in is None else np.flatnonzero(edges_in)
    a0 = edges.polar[chosen]
    sweep = edges.polar_end[chosen] - a0
    sweep = (sweep + np.pi) % (2 * np.pi) - np.pi     # the shorter way round
    # bins counted from -pi without wrapping; an edge across +-pi lists bins past the end,
    # taken modulo the count below
    first_angle = np.floor((a0 + np.minimum(sweep, 0.0) - _ANGLE_SLACK + np.pi) / step)
    last_angle = np.floor((a0 + np.maximum(sweep, 0.0) + _ANGLE_SLACK + np.pi) / step)
    angular = (last_angle - first_angle + 1).astype(np.int64)
    if angular.size == 0 or angular.max() >= angle_bins // 3:
        return None
    cells = radial[chosen] * angular
    if (cells == 1).all():     # short edges, the usual case: one cell each
        edge, offset = np.arange(len(cells)), np.zeros(len(cells), dtype=np.int64)
    else:
        edge, offset = _spread(np.zeros(len(cells), dtype=np.int64), cells)
    radius_bin = low_bin[chosen][edge] + offset // angular[edge]
    angle_bin = (first_angle[edge].astype(np.int64) + offset % angular[edge]) % angle_bins
    edge = chosen[edge]
    key = (edges.pose[edge] * bins + radius_bin) * angle_bins + angle_bin
    which = np.arange(len(points)) if points_in is None else np.flatnonzero(points_in)
    own = np.floor((points.polar[which] + np.pi) / step).astype(np.int64) % angle_bins
    base = (points.pose[which] * bins + point_bin[which]) * angle_bins
    listing = _Listing(key, edge)
    # the point's angular bin and its two neighbours: one run of keys, but for a point in the
    # first or the last bin, whose neighbour across -pi is looked up on its own
    i, j = listing.pairs(base + np.maximum(own - 1, 0), base + np.minimum(own + 1,
                                                                           angle_bins - 1))
    edge_wise = [(i, j)]
    for end, other in ((0, angle_bins - 1), (angle_bins - 1, 0)):
        at = np.flatnonzero(own == end)
        if at.size:
            k, j_end = listing.pairs(base[at] + other)
            edge_wise.append((at[k], j_end))
    i = which[np.concatenate([pair[0] for pair in edge_wise])]
    j = np.concatenate([pair[1] for pair in edge_wise])
    radii = points.radius
    keep = (low[j] <= radii[i]) & (high[j] >= radii[i])
    i, j = i[keep], j[keep]
    positive, negative = _extremes(_crossing_turns(points, i, edges, j), points.pose[i], poses)
    limit = step - 2 * _ANGLE_SLACK
    return positive, negative, (positive <= limit) & (negative >= -limit)
