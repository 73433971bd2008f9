"""The duckbill cam's DXF files: the cutting file (the plate's outline, its bore and its screws'
holes, nothing else) and its drawing (the same with the roller's pitch curve and a centre mark
as construction), laid out like a gear's file (:mod:`cadgen.export.dxf`: its layers, document,
thinning and audit).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from cadgen.export.atomic import write_bytes_atomic
from cadgen.export.dxf import (CENTRE_MARK_HALF_LENGTH_MODULES, CUTTING_LAYERS, DxfInputError,
                               DxfSummary, _add_gear, _audited_bytes, _check_tolerance, _new_document,
                               _plate_problems)
from cadgen.geometry.contour import closed_points, ring_measures, thin_outline, thin_ring

__all__ = ["write_cam_dxf", "cam_dxf_bytes", "CAM_CENTRE_MARK_HALF_LENGTH"]

#: Half length of each centre-mark line of a cam drawing (mm).
CAM_CENTRE_MARK_HALF_LENGTH = 5.0


def write_cam_dxf(path: str | os.PathLike, contour, pitch_curve, *, bore_radius: float = 0.0,
                  chord_tolerance: float = 0.005, label: str = "cam", holes=(),
                  drawing: bool = False) -> DxfSummary:
    """Write a plate cam as a DXF cutting file (mm), laid out like a gear file.

    ``contour`` (the working profile) on ``OUTLINE`` (the one closed cutting path), the bore
    and the screws' clearance holes (``holes``: ``((x, y), radius)`` each) on ``BORE``: the
    only layers of the cutting file. ``drawing``: the cam's drawing instead, with
    ``pitch_curve`` (the roller centre's path, open) on ``CONSTRUCTION-PITCH`` and a 10-mm
    centre mark at the origin on ``CONSTRUCTION-CENTRE``; otherwise as
    :func:`cadgen.export.dxf.write_gear_dxf`.
    """
    path = Path(path)
    data, outline, used = _cam_file(path, contour, pitch_curve, bore_radius, chord_tolerance,
                                    label, holes, drawing)
    write_bytes_atomic(path, data)
    area, perimeter = ring_measures(outline)
    return DxfSummary(path, len(outline), used, area, perimeter)


def cam_dxf_bytes(contour, pitch_curve, *, bore_radius: float = 0.0,
                  chord_tolerance: float = 0.005, label: str = "cam",
                  path: str | os.PathLike = "cam.dxf", holes=(), drawing: bool = False) -> bytes:
    """The bytes :func:`write_cam_dxf` writes (``path`` names the file in error messages
    only), for a build that makes them before its output folder exists."""
    return _cam_file(Path(path), contour, pitch_curve, bore_radius, chord_tolerance, label,
                     holes, drawing)[0]


def _cam_file(path: Path, contour, pitch_curve, bore_radius, chord_tolerance, label, holes=(),
              drawing=False):
    """``(bytes, thinned outline, tolerance used)`` of a cam's DXF file."""
    tolerance = _check_tolerance(chord_tolerance)
    centre = np.zeros(2)
    problems = _plate_problems(contour, pitch_curve, centre, bore_radius, label)
    if problems:
        raise DxfInputError(f"cannot export {label} to DXF", problems)
    outline, used = thin_outline(closed_points(contour), tolerance, centre, bore_radius)
    pitch, _ = thin_ring(closed_points(pitch_curve), tolerance)
    doc = _new_document(layers=None if drawing else CUTTING_LAYERS)
    msp = doc.modelspace()
    _add_gear(msp, outline, pitch, centre, float(bore_radius),
              CAM_CENTRE_MARK_HALF_LENGTH / CENTRE_MARK_HALF_LENGTH_MODULES, construction=drawing)
    for (x, y), radius in holes:   # the screws' clearance holes, cut like the bore
        msp.add_circle((float(x), float(y)), float(radius), dxfattribs={"layer": "BORE"})
    return _audited_bytes(doc, path), outline, used
