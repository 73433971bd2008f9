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
- a pair the model does not join may share no material beyond :data:`VOLUME_FLOOR`.

Every other overlap fails the check, named by its pair with its volume and thickness. Moving
pairs over the cycle are the sweeps' (:mod:`cadgen.pipeline.clearances`).
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
        ``pairs_examined`` (pairs whose boxes meet), ``overlaps``: one entry per pair sharing
        more than :data:`VOLUME_FLOOR` (``a``, ``b``, ``volume_mm3``, ``thickness_mm``,
        ``allowed_mm``, ``joined``, ``passed``), ``failures`` (the failing ones' words),
        ``passed``.
    """
    joined = _joined(getattr(assembly, "model", None))
    placed = []
    for name, part, pose in assembly.placements(phi):
        if part.kind in _ENVIRONMENT:
            continue
        solid = part.solid.transform(np.asarray(pose, dtype=float)[:3, :])
        box = np.asarray(solid.bounding_box(), dtype=float)
        placed.append((name, solid, box[:3], box[3:]))
    chord = 1.0 - math.cos(math.pi / segments)
    examined, overlaps = 0, []
    for i, (name_a, solid_a, low_a, high_a) in enumerate(placed):
        for name_b, solid_b, low_b, high_b in placed[i + 1:]:
            if np.any(high_a < low_b) or np.any(high_b < low_a):
                continue
            examined += 1
            common = solid_a ^ solid_b
            volume = float(common.volume())
            if volume <= VOLUME_FLOOR:
                continue
            area = float(common.surface_area())
            thickness = 2.0 * volume / area if area > 0 else math.inf
            box = np.asarray(common.bounding_box(), dtype=float)
            radius = 0.5 * float(max(box[3] - box[0], box[4] - box[1]))
            is_joined = frozenset((name_a, name_b)) in joined
            allowed = radius * chord + max(interference, 0.0) / 2 if is_joined else 0.0
            overlaps.append({"a": name_a, "b": name_b, "volume_mm3": volume,
                             "thickness_mm": thickness, "allowed_mm": allowed,
                             "joined": is_joined, "passed": is_joined and thickness <= allowed})
    failures = [f"{o['a']} and {o['b']} share {o['volume_mm3']:.1f} mm^3 (a "
                f"{o['thickness_mm']:.2f} mm thick overlap"
                + (f", more than the {o['allowed_mm']:.3f} mm their joint's fit allows)"
                   if o["joined"] else "; no joint between them allows any)")
                for o in overlaps if not o["passed"]]
    return {"carrier_angle_deg": float(np.degrees(phi)), "pairs_examined": examined,
            "overlaps": overlaps, "failures": failures, "passed": not failures}
