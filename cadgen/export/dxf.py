"""DXF export of generated gears (one cutting file per gear, an assembled train sheet) and cams
(the cam's file: :mod:`cadgen.export.cam_dxf`, on this module's layers and document).

Layers, in millimetres. A *cutting file* (one gear, the cam) has the two cutting layers only,
so a CAM program takes it as it is, whatever it does with layers and plot flags. A *drawing*
(the train sheet, the cam's drawing) adds the construction geometry on ``CONSTRUCTION-...``
layers whose plot flag is off:

``OUTLINE`` (colour 7)
    The tooth outline (cam: the working profile), one closed ``LWPOLYLINE``.
``BORE`` (colour 1)
    The shaft bore: a gear's hub hole (bore and keyway or D-flat, :mod:`cadgen.machine.hubs`)
    as one closed ``LWPOLYLINE`` when its profile has a ``hole``, else a ``CIRCLE`` at the
    rotation centre (if the bore radius is > 0; a cam's bore is always a circle).
``CONSTRUCTION-PITCH`` (colour 3, centre line)
    The pitch curve (cam: the roller centre's path), one *open* ``LWPOLYLINE``: its closing
    stretch (at least :data:`PITCH_CURVE_GAP`) is left out, so chaining never closes it.
``CONSTRUCTION-CENTRE`` (colour 4, centre line)
    Centre marks: two ``LINE`` entities, each two modules long, crossing at the centre.
``CONSTRUCTION-LABELS`` (colour 7, black on paper; printed on the train sheet, which is for people)
    Train sheet only: a ``TEXT`` per gear and a title per view.

The train sheet (:func:`write_train_sheet`) draws one view per gear plane, side by side along
x, so gears sharing a shaft are never drawn on top of each other; every shaft is marked in
every view. The header extents (``$EXTMIN``/``$EXTMAX``, ``$LIMMIN``/``$LIMMAX``) are the
bounding box of the entities (``ezdxf.bbox``; a ``TEXT`` as :func:`_text_box`, font-free).

The dense outline is thinned by Douglas-Peucker to a chord tolerance (halved until the ring
stays simple and clear of the disc holding the bore and its keyway; the tolerance used is in :class:`DxfSummary`). Every
document passes ``ezdxf``'s audit and is written atomically and byte-identically for the same
input (fixed metadata). ``ezdxf`` and ``shapely`` are imported inside the functions.

Written fast, to ezdxf's own bytes: a polyline's vertices are set in one go and written as one
block of text (when that block is, in this process, what ezdxf writes vertex by vertex), the
extents are read off the vertex arrays, and a good ring is checked without sorting its points.
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
from cadgen.geometry.contour import (closed_points, open_ring, ring_measures, ring_problems,
                                     thin_outline, thin_ring)
from kinematics.errors import MechanismError

__all__ = [
    "DxfExportError",
    "DxfInputError",
    "DxfSummary",
    "LAYERS",
    "CUTTING_LAYERS",
    "CONSTRUCTION_LAYERS",
    "write_gear_dxf",
    "gear_dxf_bytes",
    "writer_fingerprint",
]

PITCH_LAYER, CENTRE_LAYER, LABEL_LAYER = "CONSTRUCTION-PITCH", "CONSTRUCTION-CENTRE", "CONSTRUCTION-LABELS"
#: Layer name -> AutoCAD colour index (7 black on paper, 1 red, 3 green, 4 cyan): cutting layers
#: (plotted) and construction layers (plot flag off).
CUTTING_LAYERS = {"OUTLINE": 7, "BORE": 1}
CONSTRUCTION_LAYERS = {PITCH_LAYER: 3, CENTRE_LAYER: 4, LABEL_LAYER: 7}
LAYERS = {**CUTTING_LAYERS, **CONSTRUCTION_LAYERS}
#: Layers drawn with the centre-line linetype (reference geometry, not cut).
_CENTRE_LINE_LAYERS = (PITCH_LAYER, CENTRE_LAYER)
_CENTRE_LINETYPE = "CENTER"
#: Dash pattern of the centre line in mm: total length, then dash (+) and gap (-) lengths.
_CENTRE_LINETYPE_PATTERN = [20.0, 12.0, -3.0, 2.0, -3.0]

DXF_VERSION = "R2010"
#: Half length of each centre-mark line, in modules (the whole mark is two modules wide).
CENTRE_MARK_HALF_LENGTH_MODULES = 1.0
#: mm: the pitch curve's closing stretch left out, well above any CAM program's joining tolerance.
PITCH_CURVE_GAP = 1.0
#: Train sheet: label height (mm), gap (modules) under a gear whose label does not fit inside
#: it, view titles TITLE_SCALE times taller than the labels.
LABEL_HEIGHT, LABEL_GAP_MODULES, TITLE_SCALE = 3.5, 2.0, 1.5
#: A TEXT's extents: TEXT_WIDTH_PER_CHARACTER heights a character (wider than the usual fonts'
#: average), TEXT_BOX_DEPTH heights down from its top (descenders included).
TEXT_WIDTH_PER_CHARACTER, TEXT_BOX_DEPTH = 0.8, 1.5
#: mm: gears whose centres are closer than this share a shaft (drawn in different views).
SHARED_AXIS_TOLERANCE = 0.01
#: Train sheet views: the gap between views is this fraction of the widest view (at least
#: VIEW_GAP_MIN mm); each view's shift along x is a whole multiple of VIEW_SHIFT_STEP mm.
VIEW_GAP_FRACTION, VIEW_GAP_MIN, VIEW_SHIFT_STEP = 0.15, 10.0, 10.0

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
                               profile.bore_radius, label, hole=getattr(profile, "hole", None))
    module = profile.module
    if not (isinstance(module, (int, float, np.number)) and math.isfinite(module) and module > 0):
        problems.append(f"{label}: module must be a finite number > 0, got {module!r}")
    return problems


def _plate_problems(outline, pitch_curve, centre, bore, label: str, hole=None) -> list[str]:
    """Problems of a cut plate (gear or cam): outline, pitch curve, centre, bore inside the outline.

    ``hole`` (a gear's hub hole, a closed ring) replaces the circular bore when given: it must
    be a simple ring strictly inside the outline, touching it nowhere.
    """
    import shapely

    problems = []
    outline = closed_points(outline)
    outline_problems = _ring_problems(f"{label}: outline", outline)
    problems += outline_problems
    problems += _ring_problems(f"{label}: pitch_curve", closed_points(pitch_curve))
    given_centre = centre
    centre = np.asarray(centre, dtype=float)
    if centre.shape != (2,) or not np.isfinite(centre).all():
        problems.append(f"{label}: centre must be two finite numbers, got {given_centre!r}")
        return problems
    if hole is not None:
        problems += _hole_problems(outline, hole, label, outline_problems)
    elif not (isinstance(bore, (int, float, np.number)) and math.isfinite(bore) and bore >= 0):
        problems.append(f"{label}: bore_radius must be a finite number >= 0, got {bore!r}")
    elif bore > 0 and not outline_problems:
        ring = shapely.LinearRing(outline)
        point = shapely.Point(centre)
        clearance = ring.distance(point)
        if not shapely.Polygon(ring).contains(point) or clearance <= bore:
            problems.append(f"{label}: bore (radius {bore} mm at {centre.tolist()}) is not inside the "
                            f"outline (nearest outline point {clearance:.6g} mm from the centre)")
    return problems


def _hole_problems(outline, hole, label: str, outline_problems) -> list[str]:
    """Problems of a hub hole: a simple closed ring strictly inside a valid outline."""
    import shapely

    hole = closed_points(hole)
    problems = _ring_problems(f"{label}: hole", hole)
    if problems or outline_problems:
        return problems
    ring, inner = shapely.LinearRing(outline), shapely.LinearRing(hole)
    # clear of the outline <=> the rings do not meet; their distance (every vertex against
    # every segment: most of a gear's checking time) is measured only to name a failure
    if not shapely.Polygon(ring).contains(shapely.Polygon(inner)) or ring.intersects(inner):
        clearance = ring.distance(inner)
        problems.append(f"{label}: hole (reaching {np.hypot(*hole.T).max():.6g} mm from the "
                        f"origin) is not inside the outline (nearest outline point "
                        f"{clearance:.6g} mm from it)")
    return problems


def _ring_problems(label: str, points: np.ndarray) -> list[str]:
    """:func:`cadgen.geometry.contour.ring_problems`, answered at once for a good ring.

    A finite (n, 2) ring whose polygon is simple and encloses area has at least three
    distinct points, so it has none of the problems; only a ring failing that is looked at
    in full, for the messages (whose distinct-points count sorts every point).
    """
    import shapely

    if (points.ndim == 2 and points.shape[1] == 2 and len(points) >= 3
            and np.isfinite(points).all()):
        ring = shapely.LinearRing(points)
        if ring.is_simple and shapely.Polygon(ring).area > 0.0:
            return []
    return ring_problems(label, points)


def _finite(value, shape: tuple) -> bool:
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return False
    return array.shape == shape and bool(np.isfinite(array).all())


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


def _new_document(printed=(), layers=None):
    """A millimetre document with the project's ``layers`` (default: every layer; a cutting
    file: :data:`CUTTING_LAYERS` only, so a CAM program that ignores plot flags finds nothing
    but cutting paths)."""
    import ezdxf

    with _fixed_metadata():
        doc = ezdxf.new(DXF_VERSION, units=ezdxf.units.MM)
    doc.units = ezdxf.units.MM
    doc.header["$INSUNITS"] = ezdxf.units.MM
    doc.header["$MEASUREMENT"] = 1  # metric
    doc.header["$LUNITS"] = 2  # decimal
    if _CENTRE_LINETYPE not in doc.linetypes:
        doc.linetypes.add(_CENTRE_LINETYPE, pattern=_CENTRE_LINETYPE_PATTERN, description="Centre ____ _ ____ _")
    for name, colour in (LAYERS if layers is None else layers).items():
        layer = doc.layers.add(name, color=colour)
        layer.dxf.plot = 1 if name in CUTTING_LAYERS or name in printed else 0
        layer.description = ("cutting path" if name in CUTTING_LAYERS else
                             "annotation: printed, never cut" if name in printed
                             else "construction: not cut, not plotted")
        if name in _CENTRE_LINE_LAYERS:
            layer.dxf.linetype = _CENTRE_LINETYPE
    return doc


def _add_centre_mark(msp, centre, half: float) -> None:
    cx, cy = float(centre[0]), float(centre[1])
    msp.add_line((cx - half, cy), (cx + half, cy), dxfattribs={"layer": CENTRE_LAYER})
    msp.add_line((cx, cy - half), (cx, cy + half), dxfattribs={"layer": CENTRE_LAYER})


def _add_polyline(msp, points, *, close: bool, layer: str, fast: bool | None = None):
    """An LWPOLYLINE through ``points`` ((n, 2) float), its vertices set in one go.

    ``add_lwpolyline`` appends vertex by vertex, copying the whole vertex array each time
    (quadratic: a third of a gear file's writing time); the entity stores each vertex as
    (x, y, start width, end width, bulge), which is what is set here, zeros but x and y.
    Its vertices are then written as one block of text (:func:`_vertex_block_class`) when
    ``fast`` (default: when this process's ezdxf writes that block byte for byte as it
    writes vertex by vertex, :func:`_fast_vertices`). ``tests/test_dxf_speed.py`` checks
    the bytes are those ``add_lwpolyline`` gives.
    """
    points = np.asarray(points, dtype=float)
    polyline = msp.add_lwpolyline([], format="xy", close=close, dxfattribs={"layer": layer})
    vertices = np.zeros((len(points), 5))
    vertices[:, :2] = points
    if _fast_vertices() if fast is None else fast:
        polyline.lwpoints = _vertex_block_class()()
    polyline.lwpoints.set(vertices)
    return polyline


_FAST: list = []


def _vertex_block_class():
    """ezdxf's LWPOLYLINE vertex array, written as one block of text.

    ezdxf writes each vertex as its own tag objects (an x and a y tag, each formatted on its
    own: half a gear file's writing time); these vertices (no widths, no bulges) are the
    same ``"%3d\\n%s\\n"`` lines, formatted in one pass. Anything else (a width or a bulge)
    is written by ezdxf's own code.
    """
    if len(_FAST) < 2:
        from ezdxf.entities.lwpolyline import LWPolylinePoints

        class _Block:      # what a text tag writer asks of a tag
            __slots__ = ("text",)
            code = LWPolylinePoints.VERTEX_CODE

            def __init__(self, text: str):
                self.text = text

            def dxfstr(self) -> str:
                return self.text

        class VertexBlock(LWPolylinePoints):
            __slots__ = ()

            def dxftags(self):
                if self.values[:, 2:].any():
                    yield from super().dxftags()
                    return
                yield _Block(_vertex_text(self.values[:, :2], self.VERTEX_CODE))

        _FAST.append(VertexBlock)
        _FAST.append(None)
    return _FAST[0]


def _vertex_text(points: np.ndarray, code: int) -> str:
    """``"%3d\\n%r\\n%3d\\n%r\\n"`` (x code, x, y code, y) for every (x, y) of ``points``.

    Each float is written by ``repr`` (ezdxf's own way, the shortest text that reads back to
    it: most of the time here), mapped over the flat list in one pass; the group codes are put
    between by slice assignment rather than formatted per vertex (a third less time).
    """
    lines = [f"{code:3d}", None, f"{code + 10:3d}", None] * len(points)
    lines[1::2] = map(repr, points.ravel().tolist())
    return "\n".join(lines) + "\n" if lines else ""


def _fast_vertices() -> bool:
    """Whether :func:`_vertex_block_class` writes what ezdxf writes, in this process: a probe
    polyline (awkward numbers among its coordinates, no document needed) written both ways,
    compared byte for byte, once."""
    block = _vertex_block_class()
    if _FAST[1] is None:
        from ezdxf import DXF2010
        from ezdxf.entities import LWPolyline
        from ezdxf.lldxf.tagwriter import TagWriter

        probe = np.zeros((5, 5))
        probe[:, :2] = [[0.0, -0.0], [1e-300, -1.5e300], [123456789.123456789, 1 / 3],
                        [-2.5, 1e16], [0.1 + 0.2, 5e-324]]
        polyline = LWPolyline.new(dxfattribs={"layer": "OUTLINE"})
        texts = []
        for points in (polyline.lwpoints, block()):
            points.set(probe)
            polyline.lwpoints = points
            stream = io.StringIO()
            polyline.export_dxf(TagWriter(stream, dxfversion=DXF2010))
            texts.append(stream.getvalue())
        _FAST[1] = texts[0] == texts[1]
    return _FAST[1]


def _add_gear(msp, outline: np.ndarray, pitch: np.ndarray, centre: np.ndarray, bore_radius: float,
              module: float, hole=None, *, construction: bool = True) -> None:
    """Add one placed gear's entities (already in sheet coordinates) to the modelspace; its
    ``hole`` (placed likewise) is drawn in place of the bore circle. ``construction`` False (a
    cutting file): the outline and the bore only, no pitch curve, no centre mark."""
    _add_polyline(msp, outline, close=True, layer="OUTLINE")
    if construction:
        _add_polyline(msp, open_ring(pitch, PITCH_CURVE_GAP), close=False, layer=PITCH_LAYER)
    if hole is not None:
        _add_polyline(msp, closed_points(hole), close=True, layer="BORE")
    elif bore_radius > 0:
        msp.add_circle(centre.tolist(), bore_radius, dxfattribs={"layer": "BORE"})
    if construction:
        _add_centre_mark(msp, centre, CENTRE_MARK_HALF_LENGTH_MODULES * module)


def _text_box(anchor, text: str, height: float) -> np.ndarray:
    """[[xmin, ymin], [xmax, ymax]] counted for a TOP_CENTER text hung from ``anchor``."""
    half = 0.5 * TEXT_WIDTH_PER_CHARACTER * len(text) * height
    x, y = float(anchor[0]), float(anchor[1])
    return np.array([[x - half, y - TEXT_BOX_DEPTH * height], [x + half, y]])


def _add_label(msp, anchor, text: str, height: float) -> None:
    from ezdxf.enums import TextEntityAlignment

    msp.add_text(text, height=float(height), dxfattribs={"layer": LABEL_LAYER}).set_placement(
        (float(anchor[0]), float(anchor[1])), align=TextEntityAlignment.TOP_CENTER)


def _set_extents(doc) -> None:
    """$EXTMIN/$EXTMAX and $LIMMIN/$LIMMAX from the drawn entities (TEXT as :func:`_text_box`)."""
    from ezdxf import bbox

    msp = doc.modelspace()
    # a polyline without bulges spans its vertices: their least and greatest coordinates are
    # what ezdxf's bounding box gives (a fifth of the writing time when it walks them)
    polylines, texts, others = [], [], []
    for entity in msp:   # sorted by type here, not by msp.query (which parses its query text)
        kind = entity.dxftype()
        if kind == "LWPOLYLINE" and not entity.lwpoints.values[:, 4].any():
            polylines.append(entity)
        else:
            (texts if kind == "TEXT" else others).append(entity)
    box = bbox.extents(others)
    corners = [np.array([box.extmin, box.extmax])[:, :2]] if box.has_data else []
    corners += [np.array([p.lwpoints.values[:, :2].min(axis=0), p.lwpoints.values[:, :2].max(axis=0)])
                for p in polylines if len(p.lwpoints)]
    corners += [_text_box(text.dxf.align_point, text.dxf.text, text.dxf.height) for text in texts]
    if not corners:
        return
    corners = np.vstack(corners)
    (x0, y0), (x1, y1) = corners.min(axis=0).tolist(), corners.max(axis=0).tolist()
    # ezdxf copies the modelspace's own extents and limits into the header when it writes
    msp.reset_extents((x0, y0, 0.0), (x1, y1, 0.0))
    msp.reset_limits((x0, y0), (x1, y1))
    # open zoomed to the drawing (a 3:2 window)
    doc.set_modelspace_vport(height=1.1 * max(y1 - y0, (x1 - x0) / 1.5),
                             center=((x0 + x1) / 2, (y0 + y1) / 2))


def _audited_bytes(doc, path: Path) -> bytes:
    """Set the extents, audit ``doc`` and serialise it; raise :class:`DxfExportError` rather
    than return a bad file."""
    _set_extents(doc)
    auditor = doc.audit()
    if auditor.has_errors or auditor.has_fixes:
        # A freshly built document needs no fixes; any fix means our geometry was wrong.
        messages = [f"error: {entry.message}" for entry in auditor.errors]
        messages += [f"fixed: {entry.message}" for entry in auditor.fixes]
        raise DxfExportError(f"{path}: the DXF document failed the ezdxf audit; nothing written", messages)
    _classes_in_order(doc)
    stream = io.StringIO()
    with _fixed_metadata():
        doc.write(stream)
    return doc.encode(stream.getvalue())


def _classes_in_order(doc) -> None:
    """Register the document's CLASS records now, sorted by name, so that the file's bytes do
    not depend on the process's string hashing.

    ezdxf adds a CLASS for each entity type in use, iterating a set of type names, at write
    time: the CLASSES section of the same drawing came out in one of two orders, run to run
    (PYTHONHASHSEED). Their order means nothing in a DXF file (an object names its class);
    the write adds none once they are all registered.
    """
    classes = doc.classes
    classes.add_required_classes(doc.dxfversion)
    ordered = sorted(classes.classes.items())
    classes.classes.clear()
    classes.classes.update(ordered)


def _thin_gear(profile, outline: np.ndarray, pitch: np.ndarray, tolerance: float):
    """Thinned outline, its tolerance, and thinned pitch curve of a validated profile (body frame).

    The outline keeps clear of the disc of the hole's reach (its keyway included); where the
    root comes closer to the centre than that reach (a keyway turned to a non-circular gear's
    far root) no thinning passes and the dense outline, checked clear of the hole, is kept.
    """
    thinned, used = thin_outline(outline, tolerance, profile.centre, _hole_reach(profile))
    thin_pitch, _ = thin_ring(pitch, tolerance)
    return thinned, used, thin_pitch


_WRITER: list = []


def writer_fingerprint() -> str:
    """SHA-256 of what decides a written gear file's bytes besides its inputs: the sources of
    the writers and of the thinning (this module, :mod:`cadgen.export.train_sheet`,
    :mod:`cadgen.export.cam_dxf`,
    :mod:`cadgen.geometry.contour`, :mod:`cadgen.machine.hubs`) and ezdxf's version. Part of
    the gear cache's key of a file (:func:`cadgen.gears.cache.file_key`): an edit is a new key."""
    if not _WRITER:
        import hashlib
        from importlib.metadata import version

        import cadgen.geometry.contour
        import cadgen.machine.hubs

        # the installed version, read without importing ezdxf: a warm build need not load it
        digest = hashlib.sha256(f"ezdxf={version('ezdxf')}\0".encode())
        here = Path(__file__).parent
        for source in (Path(__file__), here / "train_sheet.py", here / "cam_dxf.py",
                       Path(cadgen.geometry.contour.__file__), Path(cadgen.machine.hubs.__file__)):
            digest.update(f"{source.name}\0".encode() + source.read_bytes() + b"\0")
        _WRITER.append(digest.hexdigest())
    return _WRITER[0]


def _hole_reach(profile) -> float:
    """The disc the thinned outline keeps clear of (a profile without ``hole_reach``: its bore)."""
    return float(getattr(profile, "hole_reach", profile.bore_radius))


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
        inside the outline; or ``hole`` (the hub hole, a closed ring strictly inside
        the outline), drawn in place of the bore circle.
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
    A cutting file: its only layers are ``OUTLINE`` (one closed LWPOLYLINE,
    counter-clockwise) and ``BORE`` (the hole as a closed LWPOLYLINE, else a CIRCLE, if
    any), so a CAM program takes it as it is. The gear's pitch curve and centre mark are on
    the train sheet (:func:`cadgen.export.train_sheet.write_train_sheet`), a drawing.
    """
    tolerance = _check_tolerance(chord_tolerance)
    _raise_gear_problems(profile)
    path = Path(path)
    outline, used, pitch = _thin_gear(profile, closed_points(profile.outline),
                                      closed_points(profile.pitch_curve), tolerance)
    write_bytes_atomic(path, gear_dxf_bytes(profile, outline, pitch, path=path))
    area, perimeter = ring_measures(outline)
    return DxfSummary(path, len(outline), used, area, perimeter)


def gear_dxf_bytes(profile, outline: np.ndarray, pitch: np.ndarray, *, path="gear.dxf") -> bytes:
    """The bytes of a gear's DXF file (as :func:`write_gear_dxf` writes it), for a profile
    already checked (:func:`_raise_gear_problems`) and its outline and pitch curve already
    thinned (:func:`cadgen.machine.hubs.cutting_outline`). ``path`` only names the file in an
    audit failure."""
    doc = _new_document(layers=CUTTING_LAYERS)
    _add_gear(doc.modelspace(), outline, pitch, np.asarray(profile.centre, dtype=float),
              float(profile.bore_radius), float(profile.module), getattr(profile, "hole", None),
              construction=False)
    return _audited_bytes(doc, Path(path))


def _raise_gear_problems(profile) -> None:
    """Raise :class:`DxfInputError` listing every problem of ``profile``; nothing if none."""
    problems = _gear_problems(profile)
    if problems:
        raise DxfInputError(f"cannot export gear {getattr(profile, 'name', '?')!r} to DXF", problems)
