"""DXF export of generated gears (one cutting file per gear, an assembled train sheet) and cams.

Each gear file holds, in millimetres and on layers of their own:

``OUTLINE``
    The tooth outline as one closed ``LWPOLYLINE`` (the cutting path).
``BORE``
    The shaft bore as a ``CIRCLE`` at the rotation centre (only if the bore radius is > 0).
``PITCH``
    The pitch curve as one closed ``LWPOLYLINE`` (reference geometry).
``CENTRE``
    A centre mark: two ``LINE`` entities, each two modules long, crossing at the centre.

The train sheet (:func:`write_train_sheet`) places several gears at given poses
on one drawing, with a ``TEXT`` label per gear on ``LABELS``. A plate cam
(:func:`write_cam_dxf`) is laid out like a gear: its working profile on
``OUTLINE``, the roller centre's path on ``PITCH``, bore and centre mark.

The dense outline of the generator (thousands of points) is thinned by
Douglas-Peucker with a chord tolerance: every dropped point lies within the
tolerance of the written polyline. If thinning would make the ring cross itself
(or cut into the bore), the tolerance is halved until it does not; the tolerance
actually used is reported in :class:`DxfSummary`.

Every document passes ``ezdxf``'s audit before it is written, and files are written
atomically (:func:`cadgen.export.atomic.write_bytes_atomic`): a failure leaves either the
previous file or none, never a partial one. The same input gives byte-identical
files (fixed creation metadata).

``ezdxf`` and ``shapely`` are imported inside the functions, so importing this
module (and ``cadgen --help``) stays light.
"""

from __future__ import annotations

import contextlib
import io
import math
import os
import threading
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cadgen.export.atomic import write_bytes_atomic
from cadgen.geometry.contour import (closed_points, ring_measures, ring_problems, thin_outline,
                                     thin_ring)
from kinematics.errors import MechanismError

__all__ = [
    "DxfExportError",
    "DxfInputError",
    "DxfSummary",
    "LAYERS",
    "write_gear_dxf",
    "write_train_sheet",
    "write_cam_dxf",
    "write_train_files",
]

#: Layer name -> AutoCAD colour index (7 = white/black, 1 red, 3 green, 4 cyan, 2 yellow).
LAYERS = {
    "OUTLINE": 7,
    "BORE": 1,
    "PITCH": 3,
    "CENTRE": 4,
    "LABELS": 2,
}
#: Layers drawn with the centre-line linetype (reference geometry, not cut).
_CENTRE_LINE_LAYERS = ("PITCH", "CENTRE")
_CENTRE_LINETYPE = "CENTER"
#: Dash pattern of the centre line in mm: total length, then dash (+) and gap (-) lengths.
_CENTRE_LINETYPE_PATTERN = [20.0, 12.0, -3.0, 2.0, -3.0]

DXF_VERSION = "R2010"
#: Half length of each centre-mark line, in modules (the whole mark is two modules wide).
CENTRE_MARK_HALF_LENGTH_MODULES = 1.0
#: Half length of each centre-mark line of a cam drawing (mm).
CAM_CENTRE_MARK_HALF_LENGTH = 5.0
#: Height of the gear labels on the train sheet (mm) and their gap below the gear, in modules.
LABEL_HEIGHT = 3.5
LABEL_GAP_MODULES = 2.0
#: How many times the chord tolerance is halved before the dense outline is written as is.

_WRITE_LOCK = threading.Lock()


class DxfExportError(MechanismError):
    """A DXF document could not be produced (e.g. it failed ``ezdxf``'s audit).

    Parameters
    ----------
    message : str
        What went wrong.
    problems : list of str, optional
        Every problem found (audit messages, input problems), not just the first.
    """

    def __init__(self, message: str, problems=()):
        self.problems = [str(problem) for problem in problems]
        lines = "".join(f"\n  - {problem}" for problem in self.problems)
        super().__init__(f"{message}{lines}")


class DxfInputError(DxfExportError, ValueError):
    """Bad input to an exporter (also a ``ValueError``): every problem found, with its value."""


@dataclass(frozen=True)
class DxfSummary:
    """What was written for one gear.

    Attributes
    ----------
    path : Path
        The DXF file.
    outline_points_written : int
        Vertices of the written closed outline polyline (the closing point not repeated).
    chord_tolerance_used : float
        mm. Every point of the dense outline lies within this distance of the
        written polyline. Equal to the requested tolerance unless thinning had to be
        made finer to keep the ring simple (``0.0`` if the dense outline was written as is).
    outline_area : float
        mm^2, area enclosed by the written outline.
    outline_perimeter : float
        mm, length of the written outline.
    """

    path: Path
    outline_points_written: int
    chord_tolerance_used: float
    outline_area: float
    outline_perimeter: float


# --------------------------------------------------------------------------- validation


def _gear_problems(profile, *, label: str | None = None) -> list[str]:
    """Every problem of one gear profile, each naming the bad value."""
    label = label or f"gear {getattr(profile, 'name', '?')!r}"
    problems = _plate_problems(profile.outline, profile.pitch_curve, profile.centre,
                               profile.bore_radius, label)
    module = profile.module
    if not (isinstance(module, (int, float, np.number)) and math.isfinite(module) and module > 0):
        problems.append(f"{label}: module must be a finite number > 0, got {module!r}")
    return problems


def _plate_problems(outline, pitch_curve, centre, bore, label: str) -> list[str]:
    """Problems of a cut plate (gear or cam): outline, pitch curve, centre, bore inside the outline."""
    import shapely

    problems = []
    outline = closed_points(outline)
    outline_problems = ring_problems(f"{label}: outline", outline)
    problems += outline_problems
    problems += ring_problems(f"{label}: pitch_curve", closed_points(pitch_curve))
    given_centre = centre
    centre = np.asarray(centre, dtype=float)
    if centre.shape != (2,) or not np.isfinite(centre).all():
        problems.append(f"{label}: centre must be two finite numbers, got {given_centre!r}")
        return problems
    if not (isinstance(bore, (int, float, np.number)) and math.isfinite(bore) and bore >= 0):
        problems.append(f"{label}: bore_radius must be a finite number >= 0, got {bore!r}")
    elif bore > 0 and not outline_problems:
        ring = shapely.LinearRing(outline)
        point = shapely.Point(centre)
        clearance = ring.distance(point)
        if not shapely.Polygon(ring).contains(point) or clearance <= bore:
            problems.append(f"{label}: bore (radius {bore} mm at {centre.tolist()}) is not inside the "
                            f"outline (nearest outline point {clearance:.6g} mm from the centre)")
    return problems


def _check_tolerance(chord_tolerance) -> float:
    try:
        tolerance = float(chord_tolerance)
    except (TypeError, ValueError):
        tolerance = math.nan
    if not (math.isfinite(tolerance) and tolerance > 0):
        raise DxfInputError("bad chord tolerance",
                            [f"chord_tolerance must be a finite number > 0 mm, got {chord_tolerance!r}"])
    return tolerance


# --------------------------------------------------------------------------- document


@contextlib.contextmanager
def _fixed_metadata():
    """Fixed creation dates, GUIDs and ezdxf markers: the same input gives the same bytes."""
    import ezdxf

    # The switch is process-global; the lock keeps our own threads from racing on it.
    with _WRITE_LOCK:
        previous = ezdxf.options.write_fixed_meta_data_for_testing
        ezdxf.options.write_fixed_meta_data_for_testing = True
        try:
            yield
        finally:
            ezdxf.options.write_fixed_meta_data_for_testing = previous


def _new_document():
    import ezdxf

    with _fixed_metadata():
        doc = ezdxf.new(DXF_VERSION, units=ezdxf.units.MM)
    doc.units = ezdxf.units.MM
    doc.header["$INSUNITS"] = ezdxf.units.MM
    doc.header["$MEASUREMENT"] = 1  # metric
    doc.header["$LUNITS"] = 2  # decimal
    if _CENTRE_LINETYPE not in doc.linetypes:
        doc.linetypes.add(_CENTRE_LINETYPE, pattern=_CENTRE_LINETYPE_PATTERN, description="Centre ____ _ ____ _")
    for name, colour in LAYERS.items():
        layer = doc.layers.add(name, color=colour)
        if name in _CENTRE_LINE_LAYERS:
            layer.dxf.linetype = _CENTRE_LINETYPE
    return doc


def _add_gear(msp, outline: np.ndarray, pitch: np.ndarray, centre: np.ndarray, bore_radius: float,
              module: float) -> None:
    """Add one placed gear's entities (already in sheet coordinates) to the modelspace."""
    msp.add_lwpolyline(outline.tolist(), format="xy", close=True, dxfattribs={"layer": "OUTLINE"})
    msp.add_lwpolyline(pitch.tolist(), format="xy", close=True, dxfattribs={"layer": "PITCH"})
    if bore_radius > 0:
        msp.add_circle(centre.tolist(), bore_radius, dxfattribs={"layer": "BORE"})
    half = CENTRE_MARK_HALF_LENGTH_MODULES * module
    cx, cy = float(centre[0]), float(centre[1])
    msp.add_line((cx - half, cy), (cx + half, cy), dxfattribs={"layer": "CENTRE"})
    msp.add_line((cx, cy - half), (cx, cy + half), dxfattribs={"layer": "CENTRE"})


def _audited_bytes(doc, path: Path) -> bytes:
    """Audit ``doc`` and serialise it; raise :class:`DxfExportError` rather than return a bad file."""
    auditor = doc.audit()
    if auditor.has_errors or auditor.has_fixes:
        # A freshly built document needs no fixes; any fix means our geometry was wrong.
        messages = [f"error: {entry.message}" for entry in auditor.errors]
        messages += [f"fixed: {entry.message}" for entry in auditor.fixes]
        raise DxfExportError(f"{path}: the DXF document failed the ezdxf audit; nothing written", messages)
    stream = io.StringIO()
    with _fixed_metadata():
        doc.write(stream)
    return doc.encode(stream.getvalue())


def _thin_gear(profile, outline: np.ndarray, pitch: np.ndarray, tolerance: float):
    """Thinned outline, its tolerance, and thinned pitch curve of a validated profile (body frame)."""
    thinned, used = thin_outline(outline, tolerance, profile.centre, profile.bore_radius)
    thin_pitch, _ = thin_ring(pitch, tolerance)
    return thinned, used, thin_pitch


# --------------------------------------------------------------------------- public API


def write_gear_dxf(path: str | os.PathLike, profile, *, chord_tolerance: float = 0.005) -> DxfSummary:
    """Write one gear as a DXF cutting file (mm).

    Parameters
    ----------
    path : str or path-like
        Target file; its directory must exist. An existing file is replaced atomically.
    profile : cadgen.gears.teeth.GearProfile
        The gear, in its body frame: ``outline`` (n, 2) and ``pitch_curve`` (m, 2)
        closed, simple, finite; ``module`` > 0; ``bore_radius`` >= 0, the bore
        inside the outline.
    chord_tolerance : float, default 0.005
        mm, finite and > 0. The dense outline (and pitch curve) are thinned so that
        every dropped point lies within this distance of the written polyline.

    Returns
    -------
    DxfSummary
        Points written, tolerance used, area and perimeter of the written outline.

    Raises
    ------
    DxfInputError
        (also ``ValueError``) for a bad profile or tolerance, listing every problem.
    DxfExportError
        If the document fails ``ezdxf``'s audit; no file is written then.

    Notes
    -----
    Layers: ``OUTLINE`` (one closed LWPOLYLINE), ``BORE`` (CIRCLE, if any),
    ``PITCH`` (closed LWPOLYLINE), ``CENTRE`` (two LINEs crossing at the centre,
    two modules long). The outline is written counter-clockwise.
    """
    tolerance = _check_tolerance(chord_tolerance)
    problems = _gear_problems(profile)
    if problems:
        raise DxfInputError(f"cannot export gear {getattr(profile, 'name', '?')!r} to DXF", problems)
    path = Path(path)
    outline, used, pitch = _thin_gear(profile, closed_points(profile.outline),
                                      closed_points(profile.pitch_curve), tolerance)
    doc = _new_document()
    _add_gear(doc.modelspace(), outline, pitch, np.asarray(profile.centre, dtype=float),
              float(profile.bore_radius), float(profile.module))
    write_bytes_atomic(path, _audited_bytes(doc, path))
    area, perimeter = ring_measures(outline)
    return DxfSummary(path, len(outline), used, area, perimeter)


def write_train_sheet(path: str | os.PathLike, placements, *, chord_tolerance: float = 0.005,
                      label_height: float = LABEL_HEIGHT) -> tuple[DxfSummary, ...]:
    """Write an assembled sheet: several gears at given poses on one DXF drawing (mm).

    Parameters
    ----------
    path : str or path-like
        Target file; its directory must exist. An existing file is replaced atomically.
    placements : sequence of (GearProfile, float, (float, float))
        ``(profile, angle, offset)``: each gear rotated by ``angle`` (rad) about its
        centre, then moved by ``offset`` (mm), as :meth:`GearProfile.placed` does.
    chord_tolerance : float, default 0.005
        mm, finite and > 0; as in :func:`write_gear_dxf`.
    label_height : float, default 3.5
        mm, height of the name labels.

    Returns
    -------
    tuple of DxfSummary
        One per placement, in order (all with the sheet's ``path``); area and
        perimeter are those of the written outline (a pose does not change them).

    Raises
    ------
    DxfInputError
        (also ``ValueError``) listing every bad placement, profile or tolerance.
    DxfExportError
        If the document fails ``ezdxf``'s audit; no file is written then.

    Notes
    -----
    Per gear: a closed LWPOLYLINE on ``OUTLINE`` and on ``PITCH``, a CIRCLE on
    ``BORE`` (if any), a centre mark on ``CENTRE``, and a TEXT with the gear's
    name on ``LABELS``, centred below the gear.
    """
    from ezdxf.enums import TextEntityAlignment

    tolerance = _check_tolerance(chord_tolerance)
    placements = list(placements)
    problems = []
    if not placements:
        problems.append("placements is empty: a sheet needs at least one gear")
    if not (isinstance(label_height, (int, float)) and math.isfinite(label_height) and label_height > 0):
        problems.append(f"label_height must be a finite number > 0 mm, got {label_height!r}")
    for index, placement in enumerate(placements):
        try:
            profile, angle, offset = placement
        except (TypeError, ValueError):
            problems.append(f"placements[{index}] must be (profile, angle, (x, y)), got {placement!r}")
            continue
        label = f"placements[{index}] (gear {getattr(profile, 'name', '?')!r})"
        try:
            angle_ok = math.isfinite(float(angle))
        except (TypeError, ValueError):
            angle_ok = False
        if not angle_ok:
            problems.append(f"{label}: angle must be a finite number (rad), got {angle!r}")
        try:
            offset_array = np.asarray(offset, dtype=float)
            offset_ok = offset_array.shape == (2,) and bool(np.isfinite(offset_array).all())
        except (TypeError, ValueError):
            offset_ok = False
        if not offset_ok:
            problems.append(f"{label}: offset must be two finite numbers (mm), got {offset!r}")
        name = getattr(profile, "name", None)
        if not isinstance(name, str) or not name.strip() or any(ord(ch) < 32 for ch in name):
            problems.append(f"{label}: name must be a non-empty single-line string, got {name!r}")
        problems += _gear_problems(profile, label=label)
    if problems:
        raise DxfInputError("cannot export the train sheet to DXF", problems)

    path = Path(path)
    doc = _new_document()
    msp = doc.modelspace()
    summaries = []
    thinned = {}  # the same profile placed twice is thinned once
    for profile, angle, offset in placements:
        key = id(profile)
        if key not in thinned:
            thinned[key] = _thin_gear(profile, closed_points(profile.outline),
                                      closed_points(profile.pitch_curve), tolerance)
        outline, used, pitch = thinned[key]
        rotation = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
        centre = np.asarray(profile.centre, dtype=float)
        move = np.asarray(offset, dtype=float)
        placed_outline = (outline - centre) @ rotation.T + centre + move
        placed_pitch = (pitch - centre) @ rotation.T + centre + move
        placed_centre = centre + move
        module = float(profile.module)
        _add_gear(msp, placed_outline, placed_pitch, placed_centre, float(profile.bore_radius), module)
        label_y = float(placed_outline[:, 1].min()) - LABEL_GAP_MODULES * module
        msp.add_text(profile.name, height=float(label_height), dxfattribs={"layer": "LABELS"}).set_placement(
            (float(placed_centre[0]), label_y), align=TextEntityAlignment.TOP_CENTER)
        area, perimeter = ring_measures(outline)
        summaries.append(DxfSummary(path, len(outline), used, area, perimeter))
    write_bytes_atomic(path, _audited_bytes(doc, path))
    return tuple(summaries)


def write_cam_dxf(path: str | os.PathLike, contour, pitch_curve, *, bore_radius: float = 0.0,
                  chord_tolerance: float = 0.005, label: str = "cam") -> DxfSummary:
    """Write a plate cam as a DXF cutting file (mm), laid out like a gear file.

    ``contour`` (the working profile) goes on ``OUTLINE`` as the one closed cutting
    path, ``pitch_curve`` (the roller centre's path) on ``PITCH``, the bore on
    ``BORE`` and a 10-mm centre mark at the origin (the cam's axis) on ``CENTRE``.
    Thinning, audit, atomic and deterministic writing as :func:`write_gear_dxf`.
    """
    tolerance = _check_tolerance(chord_tolerance)
    centre = np.zeros(2)
    problems = _plate_problems(contour, pitch_curve, centre, bore_radius, label)
    if problems:
        raise DxfInputError(f"cannot export {label} to DXF", problems)
    path = Path(path)
    outline, used = thin_outline(closed_points(contour), tolerance, centre, bore_radius)
    pitch, _ = thin_ring(closed_points(pitch_curve), tolerance)
    doc = _new_document()
    _add_gear(doc.modelspace(), outline, pitch, centre, float(bore_radius),
              CAM_CENTRE_MARK_HALF_LENGTH / CENTRE_MARK_HALF_LENGTH_MODULES)
    write_bytes_atomic(path, _audited_bytes(doc, path))
    area, perimeter = ring_measures(outline)
    return DxfSummary(path, len(outline), used, area, perimeter)


def write_train_files(train, folder, chord_tolerance: float) -> list:
    """One DXF per gear and an assembled sheet of the train at the start position."""
    from cadgen.gears.trains import _placements

    written = []
    for profile, _, _, _ in train.gears:
        summary = write_gear_dxf(folder / f"{profile.file_stem}.dxf", profile,
                                 chord_tolerance=chord_tolerance)
        written.append(summary.path)
    write_train_sheet(folder / "train.dxf", _placements(train), chord_tolerance=chord_tolerance)
    written.append(folder / "train.dxf")
    return written
