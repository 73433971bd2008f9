"""The scene of a sweep: part instances, their poses and reach, and what a distance query returns.

The engine-agnostic side of the clearance checks, numpy only. A sweep scene is
two groups of an assembly's part instances that follow the carrier angle
``phi``; :class:`SweepScene` is what the certified search
(:mod:`cadgen.sweep.search`) asks of one, :class:`PairScene` what the pair-by-pair
search (:mod:`cadgen.sweep.pairwise`) asks on top, and :class:`Proximity` is the
answer of one pose. The FCL adapter (:class:`cadgen.sweep.fcl.FclScene`) is the engine
that answers.

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
:func:`cadgen.sweep.search.certified_distance`).
"""

from __future__ import annotations

from typing import NamedTuple, Protocol

import numpy as np

from cadgen.solids.errors import SolidInputError

__all__ = ["Proximity", "SweepScene", "PairScene", "part_instances", "instance_pose",
           "part_reach"]


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


class SweepScene(Protocol):
    """Two groups of part instances whose distance is asked pose by pose.

    The distance is the Euclidean distance between the two groups of *solids*:
    0 when a surface of one crosses or touches a surface of the other, and also
    when one solid lies wholly inside the other. It is continuous in ``phi``
    with ``|d distance / d phi|`` at most the largest relative speed of any
    point of one group against any point of the other (the module notes).
    """

    def distance(self, phi: float) -> Proximity:
        """Least distance between the groups at carrier angle ``phi`` (rad), and where it occurs."""

    def distances(self, phis) -> np.ndarray:
        """Distances ``(n,)`` at carrier angles ``phis`` ``(n,)``."""


class PairScene(SweepScene, Protocol):
    """A sweep scene that also answers pair by pair (what :mod:`cadgen.sweep.pairwise` needs).

    ``pairs`` lists every (instance of A, instance of B); the group distance is
    the least of theirs. Each answer at ``phi`` is a true bound: ``lower_bounds``
    and the ``lower`` of ``refine`` never exceed the pair's distance, ``attained``
    is the distance of two points of the two solids, and a Proximity is the
    pair's distance itself.
    """

    pairs: list

    def lower_bounds(self, phi: float, pairs=None) -> np.ndarray:
        """Cheap lower bounds (P,) of the pairs' distances (-inf outside the ``pairs`` mask)."""

    def refine(self, phi: float, pair: int, below: float = np.inf) -> tuple:
        """``(lower, attained, Proximity or None)`` of one pair: a better bound, exact when it
        can be shown so (looked for only below ``below``)."""

    def exact(self, phi: float, pair: int, lower: float = 0.0) -> Proximity:
        """The pair's distance (0 when the solids overlap; ``lower`` > 0 rules that out)."""


def part_instances(assembly) -> dict:
    """``{instance name: (part, body, phase)}`` of every placed copy, in assembly order: the
    made parts', then the bought solids' (``assembly.bought``, riding on the same bodies)."""
    out = {}
    for part in list(assembly.parts) + list(getattr(assembly, "bought", ())):
        for name, body, phase in part.instances or ((part.name, part.body, 0.0),):
            out[name] = (part, body, float(phase))
    return out


def instance_pose(assembly, name: str, phi: float) -> np.ndarray:
    """World transform (4, 4) of one part instance at carrier angle ``phi`` (rad).

    The same pose :meth:`Assembly.placements` gives, without placing every other part.
    """
    instances = part_instances(assembly)
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
