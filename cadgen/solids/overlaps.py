"""Parts that share material at the assembly pose: every pair, intersected exactly (manifold3d).

Two solid parts of a machine never share material, except where a fit is designed: a hub on its
shaft, a shaft's end in its seat. At the assembly file's pose every placed instance is moved
into the world and each pair whose boxes meet is intersected; the overlap's volume ``V`` and
surface area ``S`` give its mean thickness ``2 V / S`` (a thin shell round a joint's cylinder
is as thick as the fit and the polygons' chord error; a part run into another is millimetres
thick), so one rule serves every size:

- a pair the assembly model joins (a gear keyed to its shaft, a shaft in its housing) may
  overlap by a shell no thicker than the chord error of a circle as large as the overlap
  (``r (1 - cos(pi / segments))``) plus the process's largest designed interference;
- a bought solid (:mod:`cadgen.solids.bought`) is joined to the made parts it is fitted to (a
  bearing to its seat's housing and its shaft, a key to its shaft and its gear, a screw to the
  parts it holds) and to the other bought solids of the part that holds it (a screw to its
  washers and nut); it may overlap them by the same shell, or by its own designed overlap when
  that is larger: a screw's thread in a tapped hole reaches half the difference of its nominal
  and tap-drill diameters into the material round the hole (modelled as the nominal cylinder
  in the drilled hole). A screw's head sunk into a wall is millimetres thick: it fails;
- a pair the model does not join may share no material beyond :data:`VOLUME_FLOOR`.

Every other overlap fails the check, named by its pair with its volume and thickness. Moving
pairs over the cycle are the sweeps' (:mod:`cadgen.pipeline.clearances`).

Cost. The pairs whose boxes meet are found at once (numpy). A pair of made parts is
intersected exactly. A bought solid mostly lies on its seat's faces by design (a washer on a
flange, a key in its keyseat), and a boolean of coincident faces with a ten-thousand-triangle
housing takes tens of milliseconds: such a pair is intersected only where
:func:`cadgen.solids.contact.may_overlap` finds its surface, inset by 0.1 um, crossing the
other's or one solid holding the other (an overlap thinner than that is not measured). The
solids of one stack (a screw, its washers and its nut) are placed on each other's faces by one
rule and are not intersected with each other.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["overlap_check", "VOLUME_FLOOR"]

#: Any pair may share this much (mm^3): the booleans' own rounding on touching faces.
VOLUME_FLOOR = 1e-3
#: Parts that are not the machine's (the soil slab).
_ENVIRONMENT = frozenset({"ground"})


def _joined(model) -> set:
    """The unordered instance pairs a joint of ``model`` ties directly."""
    if model is None:
        return set()
    return {frozenset((j.a, j.b)) for j in model.joints}


def _fit(part_a, part_b, joined: bool) -> tuple:
    """``(joined, designed overlap mm)`` of two placed parts: the model's joint, or a bought
    solid's fit with what it is fitted to (its ``fitted`` stems, or a bought solid of the same
    host) and that fit's own overlap (a thread)."""
    from cadgen.solids.bought import BoughtPart, fits_part

    best = (joined, 0.0)
    for mine, other in ((part_a, part_b), (part_b, part_a)):
        if not isinstance(mine, BoughtPart) or mine.host == "":
            continue
        if fits_part(other.name, mine.fitted) or (isinstance(other, BoughtPart)
                                                 and other.host == mine.host):
            best = (True, max(best[1], mine.allowance))
    return best


def _screened(placed, poses, boxes, first, second) -> tuple:
    """The pairs (index arrays) worth intersecting: every pair of made parts, and a pair with
    a bought solid only where :func:`cadgen.solids.contact.may_overlap` cannot rule out shared
    material (the bought solid inset, as its faces lie on its seat's by design)."""
    from cadgen.solids.bought import BoughtPart

    bought = np.array([isinstance(part, BoughtPart) and bool(part.host)
                       for _, part, _ in placed], dtype=bool)
    screened = bought[first] | bought[second]
    if not screened.any():
        return first, second
    from cadgen.solids.contact import may_overlap

    # a screw, its washers and its nut (one stack, placed by one rule) sit on each other's
    # faces by construction: not intersected with each other
    stack = np.array([getattr(part, "stack", "") for _, part, _ in placed], dtype=object)
    same = (stack[first] == stack[second]) & (stack[first] != "")
    screened &= ~same
    items = [(part.mesh, pose, flag) for (_, part, _), pose, flag in zip(placed, poses, bought)]
    keep = ~screened & ~same
    keep[screened] = may_overlap(items, np.column_stack([first[screened], second[screened]]),
                                 boxes)
    return first[keep], second[keep]


def overlap_check(assembly, phi: float = 0.0, *, segments: int, interference: float = 0.0
                  ) -> dict:
    """Every pair of placed parts at carrier angle ``phi``: the overlaps beyond their allowance.

    Parameters
    ----------
    assembly : cadgen.solids.parts.Assembly
        Its ``model`` says which pairs are joined (without one, none is).
    segments : int
        The solids' polygons per circle (their chord error bounds a joined pair's shell).
    interference : float
        The process's largest designed interference (mm, diametral; 0 for clearance fits).

    Returns
    -------
    dict
        ``pairs_examined`` (pairs whose boxes meet), ``pairs_intersected`` (those intersected
        exactly: every pair of made parts, a bought solid's only where its surface crosses the
        other's or one holds the other, :mod:`cadgen.solids.contact`), ``overlaps``: one entry
        per pair sharing more than :data:`VOLUME_FLOOR` (``a``, ``b``, ``volume_mm3``, ``thickness_mm``,
        ``allowed_mm``, ``joined``, ``passed``), ``failures`` (the failing ones' words),
        ``passed``.
    """
    joined = _joined(getattr(assembly, "model", None))
    placed, poses = [], []
    # the made parts and the bought solids riding on them (an assembly without any: its own)
    every = (assembly.placements(phi, bought=True) if getattr(assembly, "bought", None)
             else assembly.placements(phi))
    for name, part, pose in every:
        if part.kind in _ENVIRONMENT:
            continue
        pose = np.asarray(pose, dtype=float)
        placed.append((name, part, part.solid.transform(pose[:3, :])))
        poses.append(pose)
    boxes = np.array([solid.bounding_box() for _, _, solid in placed], dtype=float).reshape(-1, 6)
    low, high = boxes[:, :3], boxes[:, 3:]
    # pairs whose boxes meet (touching counts), each once, in placement order
    meet = np.all((high[:, None, :] >= low[None, :, :]) & (high[None, :, :] >= low[:, None, :]),
                  axis=2)
    chord = 1.0 - math.cos(math.pi / segments)
    overlaps = []
    first, second = np.nonzero(np.triu(meet, k=1))
    examined = int(len(first))
    first, second = _screened(placed, poses, boxes, first, second)
    for i, j in zip(first.tolist(), second.tolist()):
        (name_a, part_a, solid_a), (name_b, part_b, solid_b) = placed[i], placed[j]
        common = solid_a ^ solid_b
        volume = float(common.volume())
        if volume <= VOLUME_FLOOR:
            continue
        area = float(common.surface_area())
        thickness = 2.0 * volume / area if area > 0 else math.inf
        box = np.asarray(common.bounding_box(), dtype=float)
        radius = 0.5 * float(max(box[3] - box[0], box[4] - box[1]))
        is_joined, designed = _fit(part_a, part_b, frozenset((name_a, name_b)) in joined)
        allowed = (radius * chord + max(max(interference, 0.0) / 2, designed)
                   if is_joined else 0.0)
        overlaps.append({"a": name_a, "b": name_b, "volume_mm3": volume,
                         "thickness_mm": thickness, "allowed_mm": allowed,
                         "joined": is_joined, "passed": is_joined and thickness <= allowed})
    failures = [f"{o['a']} and {o['b']} share {o['volume_mm3']:.1f} mm^3 (a "
                f"{o['thickness_mm']:.2f} mm thick overlap"
                + (f", more than the {o['allowed_mm']:.3f} mm their joint's fit allows)"
                   if o["joined"] else "; no joint between them allows any)")
                for o in overlaps if not o["passed"]]
    return {"carrier_angle_deg": float(np.degrees(phi)), "pairs_examined": examined,
            "pairs_intersected": int(len(first)),
            "overlaps": overlaps, "failures": failures, "passed": not failures}
