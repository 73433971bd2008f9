"""A printed part's orientation on the bed: the resting face that leaves the least overhang.

An FDM printer lays each layer on the one below; a downward face more than 45 deg from the
vertical (its outward normal within 45 deg of -z) has nothing under it and needs supports,
unless it lies on the bed. :func:`overhang_area` sums those faces of a part in a pose;
:func:`least_overhang_pose` tries the part on each face it can rest on (the largest few, as
:func:`cadgen.solids.outcome.printing_pose` does for the largest) and keeps the one with the
least overhang that fits the printer (ties: the larger face, the steadier part).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["overhang_area", "least_overhang_pose", "OVERHANG_ANGLE_DEG", "SUPPORT_FREE_MM2",
           "CANDIDATE_FACES"]

#: Faces more than this far from the vertical, facing down, need supports (deg).
OVERHANG_ANGLE_DEG = 45.0
#: Below this overhang area (mm^2) a part prints without supports (the booleans' slivers and a
#: few polygon facets of a bore's crown, which a printer bridges).
SUPPORT_FREE_MM2 = 1.0
#: The resting faces tried, largest first.
CANDIDATE_FACES = 8
#: A face within this height of the bed lies on it (mm).
_ON_BED = 1e-6


def overhang_area(mesh, pose=None, *, angle_deg: float = OVERHANG_ANGLE_DEG) -> float:
    """The area (mm^2) of the faces of ``mesh`` placed by ``pose`` (4x4; None: as it is) that
    face down more steeply than ``angle_deg`` from the vertical and do not lie on the bed (the
    part's lowest height)."""
    vertices = np.asarray(mesh.vertices, dtype=float)
    normals = np.asarray(mesh.face_normals, dtype=float)
    if pose is not None:
        pose = np.asarray(pose, dtype=float)
        vertices = vertices @ pose[:3, :3].T + pose[:3, 3]
        normals = normals @ pose[:3, :3].T
    heights = vertices[np.asarray(mesh.faces)][:, :, 2]
    on_bed = np.all(heights <= heights.min() + _ON_BED, axis=1)
    down = normals[:, 2] < -math.cos(math.radians(90.0 - angle_deg)) - 1e-12
    return float(np.asarray(mesh.area_faces, dtype=float)[down & ~on_bed].sum())


def least_overhang_pose(mesh, build_volume=None) -> tuple[np.ndarray, float]:
    """``(pose, overhang area)``: the part on the resting face with the least overhang.

    ``build_volume`` (mm, x y z): only poses whose extents fit (turned 90 deg about z too)
    are kept, when any does; None keeps every one.
    """
    from cadgen.solids.outcome import fits_build_volume, printing_pose, resting_faces

    faces = resting_faces(mesh)[:CANDIDATE_FACES]
    if not faces:
        pose = printing_pose(mesh)
        return pose, overhang_area(mesh, pose)
    tried = []
    for area, normal in faces:
        pose = printing_pose(mesh, normal=normal)
        vertices = np.asarray(mesh.vertices, dtype=float) @ pose[:3, :3].T
        fits = build_volume is None or fits_build_volume(np.ptp(vertices, axis=0), build_volume)
        tried.append((not fits, overhang_area(mesh, pose), -area, len(tried), pose))
    _, overhang, _, _, pose = min(tried, key=lambda t: t[:4])
    return pose, overhang
