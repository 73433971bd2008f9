"""The train sheet: a drawing of a whole gear train for people, each gear plane in a view of its own.

Gears that mesh share a plane; gears on one shaft are in different planes, so each plane is
drawn apart along x, every shaft marked in every view, the names and view titles printed.
Written with the same layers and checks as the cutting files (:mod:`cadgen.export.dxf`).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cadgen.export.atomic import write_bytes_atomic
from cadgen.export.dxf import (CENTRE_MARK_HALF_LENGTH_MODULES, LABEL_GAP_MODULES, LABEL_HEIGHT,
                               LABEL_LAYER, SHARED_AXIS_TOLERANCE, TEXT_BOX_DEPTH, TITLE_SCALE,
                               TEXT_WIDTH_PER_CHARACTER, VIEW_GAP_FRACTION, VIEW_GAP_MIN,
                               VIEW_SHIFT_STEP, DxfInputError, DxfSummary, _add_centre_mark,
                               _add_gear, _add_label, _audited_bytes, _check_tolerance, _finite,
                               _gear_problems, _hole_reach, _new_document, _raise_gear_problems,
                               _text_box, _thin_gear, gear_dxf_bytes, writer_fingerprint)
from cadgen.geometry.contour import closed_points, ring_measures

__all__ = ["write_train_sheet", "write_train_files", "train_files", "CachedFiles", "SHEET_NAME"]

#: The train sheet's file name (a build writes it under ``drawings/``, apart from the gears'
#: cutting files).
SHEET_NAME = "train.dxf"


def write_train_sheet(path: str | os.PathLike, placements, *, chord_tolerance: float = 0.005,
                      label_height: float = LABEL_HEIGHT, planes=None) -> tuple[DxfSummary, ...]:
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
        mm, height of the name labels (titles are :data:`TITLE_SCALE` times taller).
    planes : sequence of int, optional
        The gear plane of each placement, each drawn as a view; gears on one shaft (centres
        within :data:`SHARED_AXIS_TOLERANCE`) must be in different planes. By default each
        gear goes to the first plane with no gear on its shaft.

    Returns
    -------
    tuple of DxfSummary
        One per placement, in order (all with the sheet's ``path``); area and
        perimeter are those of the written outline (a pose does not change them).

    Raises
    ------
    DxfInputError
        (also ``ValueError``) listing every bad placement, profile, plane or tolerance.
    DxfExportError
        If the document fails ``ezdxf``'s audit; no file is written then.

    Notes
    -----
    One view per plane (in plane order) side by side along x, the first at the placements'
    coordinates, each next shifted right by a whole multiple of :data:`VIEW_SHIFT_STEP` mm
    (named in its title): each gear's entities as in :func:`write_gear_dxf` and its name under
    its centre (inside the gear where it fits, else below it); a centre mark at every shaft.
    """
    tolerance = _check_tolerance(chord_tolerance)
    placements = list(placements)
    planes = _checked_sheet(placements, label_height, planes)
    thinned = {}  # the same profile placed twice is thinned once

    def cut(profile):
        if id(profile) not in thinned:
            thinned[id(profile)] = _thin_gear(profile, closed_points(profile.outline),
                                              closed_points(profile.pitch_curve), tolerance)
        return thinned[id(profile)]

    path = Path(path)
    data, summaries = _sheet_bytes(path, placements, planes, float(label_height), cut)
    write_bytes_atomic(path, data)
    return summaries


def _checked_sheet(placements, label_height, planes, *, profiles: bool = True) -> list:
    """The plane of each placement; raise :class:`DxfInputError` listing every bad placement,
    profile (unless ``profiles`` is False: checked already), plane or label height."""
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
        if not _finite(angle, ()):
            problems.append(f"{label}: angle must be a finite number (rad), got {angle!r}")
        if not _finite(offset, (2,)):
            problems.append(f"{label}: offset must be two finite numbers (mm), got {offset!r}")
        name = getattr(profile, "name", None)
        if not isinstance(name, str) or not name.strip() or any(ord(ch) < 32 for ch in name):
            problems.append(f"{label}: name must be a non-empty single-line string, got {name!r}")
        if profiles:
            problems += _gear_problems(profile, label=label)
    if not problems:
        planes, plane_problems = _sheet_planes(placements, planes)
        problems += plane_problems
    if problems:
        raise DxfInputError("cannot export the train sheet to DXF", problems)
    return planes


def _sheet_bytes(path: Path, placements, planes, label_height: float, cut):
    """The sheet's bytes and one :class:`DxfSummary` per placement, for checked placements;
    ``cut(profile) -> (outline, tolerance used, pitch curve)`` thinned, in the body frame."""
    # a sheet for people, never cut: its gear names and view titles are printed
    doc = _new_document(printed=(LABEL_LAYER,))
    summaries, gears = [], []
    for (profile, angle, offset), plane in zip(placements, planes):
        outline, used, pitch = cut(profile)
        rotation = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
        centre = np.asarray(profile.centre, dtype=float)
        move = np.asarray(offset, dtype=float)
        hole = getattr(profile, "hole", None)
        if hole is not None:  # the hub hole turns with its gear
            hole = (closed_points(hole) - centre) @ rotation.T + centre + move
        gears.append(_PlacedGear(profile, plane, (outline - centre) @ rotation.T + centre + move,
                                 (pitch - centre) @ rotation.T + centre + move, centre + move,
                                 hole))
        area, perimeter = ring_measures(outline)
        summaries.append(DxfSummary(path, len(outline), used, area, perimeter))
    _draw_views(doc.modelspace(), gears, label_height)
    return _audited_bytes(doc, path), tuple(summaries)


@dataclass(frozen=True)
class _PlacedGear:
    profile: object
    plane: int
    outline: np.ndarray   # (n, 2) in train coordinates
    pitch: np.ndarray     # (m, 2)
    centre: np.ndarray    # (2,)
    hole: np.ndarray | None = None   # (k, 2) the hub hole, placed; None: the bore circle


def _shares_axis(first, second) -> bool:
    return bool(np.linalg.norm(np.asarray(first) - np.asarray(second)) < SHARED_AXIS_TOLERANCE)


def _sheet_planes(placements, planes) -> tuple[list, list[str]]:
    """The plane of each placement (given and checked, or assigned) and the problems found."""
    centres = [np.asarray(p.centre, dtype=float) + np.asarray(o, dtype=float) for p, _, o in placements]
    if planes is None:  # each gear in the first plane with no gear on its shaft
        planes = []
        for centre in centres:
            taken = {plane for plane, other in zip(planes, centres) if _shares_axis(centre, other)}
            planes.append(min(set(range(len(taken) + 1)) - taken))
        return planes, []
    planes = list(planes)
    if len(planes) != len(placements):
        return planes, [f"planes must give one plane per placement ({len(placements)}), got {len(planes)}"]
    problems = [f"planes[{i}] must be an integer >= 0, got {plane!r}" for i, plane in enumerate(planes)
                if isinstance(plane, bool) or not isinstance(plane, (int, np.integer)) or plane < 0]
    pairs = [] if problems else [(i, j) for i in range(len(planes)) for j in range(i)]
    for i, j in pairs:
        if planes[i] == planes[j] and _shares_axis(centres[i], centres[j]):
            problems.append(f"placements[{j}] and [{i}] (gears {placements[j][0].name!r} and "
                            f"{placements[i][0].name!r}) share a shaft but are both in plane "
                            f"{planes[i]}: gears on one shaft must be in different planes")
    return [int(plane) for plane in planes], problems


def _label_anchor(gear: _PlacedGear, height: float, others=()) -> np.ndarray:
    """Inside the gear under its centre mark (or bore and keyway), else above it, where the label fits;
    else outside the gear, below, above, left or right of it, the first place clear of
    ``others`` (the outlines of the view's other gears, shapely polygons; a label once fell
    below planet gear E into gear D, which meshes under it); below if none is."""
    import shapely

    name, module = gear.profile.name, float(gear.profile.module)
    clear = max(_hole_reach(gear.profile), CENTRE_MARK_HALF_LENGTH_MODULES * module) + module
    body = shapely.Polygon(gear.outline)
    for anchor in (gear.centre - [0.0, clear], gear.centre + [0.0, clear + TEXT_BOX_DEPTH * height]):
        (x0, y0), (x1, y1) = _text_box(anchor, name, height)
        if body.contains(shapely.box(x0, y0, x1, y1)):
            return anchor
    gap, depth = LABEL_GAP_MODULES * module, TEXT_BOX_DEPTH * height
    half = float(_text_box((0.0, 0.0), name, height)[1, 0])   # the box the writer counts
    (x_low, y_low), (x_high, y_high) = gear.outline.min(axis=0), gear.outline.max(axis=0)
    x, y = float(gear.centre[0]), float(gear.centre[1])
    outside = [np.array(anchor) for anchor in ((x, y_low - gap), (x, y_high + gap + depth),
                                                (x_low - gap - half, y + depth / 2),
                                                (x_high + gap + half, y + depth / 2))]
    for anchor in outside:
        box = shapely.box(*_text_box(anchor, name, height).ravel())
        if not any(other.intersects(box) for other in others):
            return anchor
    return outside[0]


def _draw_views(msp, gears: list, label_height: float) -> None:
    """One view per plane, side by side along x, each titled, every shaft marked in each."""
    import shapely

    title_height = TITLE_SCALE * label_height
    axes = []  # every shaft of the sheet once: (centre, centre-mark half length)
    for gear in gears:
        if not any(_shares_axis(gear.centre, centre) for centre, _ in axes):
            axes.append((gear.centre, CENTRE_MARK_HALF_LENGTH_MODULES * float(gear.profile.module)))
    planes = sorted({gear.plane for gear in gears})
    views = []
    for plane in planes:
        members = [gear for gear in gears if gear.plane == plane]
        bodies = [shapely.Polygon(gear.outline) for gear in members]
        anchors = [_label_anchor(gear, label_height, bodies[:k] + bodies[k + 1:])
                   for k, gear in enumerate(members)]
        corners = [gear.outline for gear in members]
        corners += [_text_box(anchor, gear.profile.name, label_height)
                    for gear, anchor in zip(members, anchors)]
        corners += [np.array([centre - half, centre + half]) for centre, half in axes]
        corners = np.vstack(corners)
        views.append((members, anchors, corners.min(axis=0), corners.max(axis=0)))
    top = max(high[1] for _, _, _, high in views) + TEXT_BOX_DEPTH * title_height + label_height
    # the widest title a view can get (shift unknown yet) counts in its width
    widths = [max(high[0] - low[0], len(_view_title(k, len(views), 99999.0)) * title_height
                  * TEXT_WIDTH_PER_CHARACTER) for k, (_, _, low, high) in enumerate(views)]
    gap = max(VIEW_GAP_MIN, VIEW_GAP_FRACTION * max(widths))
    shift, right = 0.0, None
    for k, ((members, anchors, low, high), width) in enumerate(zip(views, widths)):
        middle = 0.5 * (low[0] + high[0])
        if right is not None:
            shift = VIEW_SHIFT_STEP * math.ceil((right + gap - (middle - width / 2)) / VIEW_SHIFT_STEP)
        right = middle + width / 2 + shift
        move = np.array([shift, 0.0])
        for gear, anchor in zip(members, anchors):
            _add_gear(msp, gear.outline + move, gear.pitch + move, gear.centre + move,
                      float(gear.profile.bore_radius), float(gear.profile.module),
                      None if gear.hole is None else gear.hole + move)
            _add_label(msp, anchor + move, gear.profile.name, label_height)
        for centre, half in axes:
            if not any(_shares_axis(centre, gear.centre) for gear in members):
                _add_centre_mark(msp, centre + move, half)  # a shaft of another plane
        _add_label(msp, (middle + shift, top), _view_title(k, len(views), shift), title_height)


def _view_title(index: int, count: int, shift: float) -> str:
    return f"gear plane {index + 1} of {count}" + (f" (x + {shift:g} mm)" if shift else "")


def write_train_files(train, folder, chord_tolerance: float, cache=None) -> list:
    """One DXF per gear and an assembled sheet of the train at the start position, one view
    per gear plane (the gears linked by meshes; gears on one shaft are in different planes).

    Each gear is checked once and thinned once (:func:`cadgen.machine.hubs.cutting_outline`,
    shared with its solid): its file and the sheet draw that outline. With a gear ``cache``
    (:class:`~cadgen.gears.cache.GearCache`; by default the one the train was cut with,
    ``train.cache``) each file's bytes are looked up under the SHA-256 of everything that
    decides them (:func:`cadgen.gears.cache.file_key`) and stored once made: a warm build
    writes the same bytes without making them.
    """
    folder = Path(folder)
    written = []
    for name, data in train_files(train, chord_tolerance, cache, folder=folder):
        write_bytes_atomic(folder / name, data)
        written.append(folder / name)
    return written


def train_files(train, chord_tolerance: float, cache=None, *, folder=Path(".")) -> list:
    """``[(file name, bytes)]`` of what :func:`write_train_files` writes (``folder`` only names
    the files in error messages)."""
    from cadgen.gears.trains import _placements

    cache = cache if cache is not None else getattr(train, "cache", None)
    tolerance = _check_tolerance(chord_tolerance)
    folder = Path(folder)
    profiles = [profile for profile, _, _, _ in train.gears]
    placements = _placements(train)
    planes = _mesh_planes(train, [profile.name for profile, _, _ in placements])
    files = CachedFiles(cache, tolerance)
    made = []
    for profile in profiles:
        path = folder / f"{profile.file_stem}.dxf"
        made.append((path.name, files.get(("gear dxf", profile), lambda profile=profile, path=path:
                                          gear_dxf_bytes(profile, *_cut(profile, tolerance)[::2],
                                                         path=path))))
    sheet = folder / SHEET_NAME

    def make_sheet():
        checked = _checked_sheet(placements, LABEL_HEIGHT, planes, profiles=False)
        return _sheet_bytes(sheet, placements, checked, LABEL_HEIGHT,
                            lambda profile: _cut(profile, tolerance))[0]

    made.append((sheet.name, files.get(("train sheet", placements, planes), make_sheet)))
    return made


def _cut(profile, tolerance: float):
    """``(outline, tolerance used, pitch)`` of a profile, checked once (raising
    :class:`DxfInputError` as :func:`write_gear_dxf` does) and thinned once."""
    from cadgen.machine.hubs import cutting_outline

    def check():
        _raise_gear_problems(profile)
        return True   # remembered only when no problem was raised

    derived = getattr(profile, "derived", None)
    derived(("dxf checked",), check) if derived else check()
    cut = cutting_outline(profile, tolerance)
    return cut.outline, cut.tolerance_used, cut.pitch


class CachedFiles:
    """What the cutting files are made from and of, from the gear cache, or made and stored
    there (no cache: made): a file's bytes, a gear's thinned cutting outline. Keyed by
    :func:`cadgen.gears.cache.file_key` on the inputs, the chord tolerance and the writers'
    fingerprint (:func:`cadgen.export.dxf.writer_fingerprint`)."""

    def __init__(self, cache, tolerance: float):
        self.cache, self.tolerance = cache, tolerance

    def get(self, inputs, make, kind=bytes):
        """The stored value of ``inputs`` if it is a ``kind`` (an entry of another kind, or
        a damaged one, is no entry), else ``make()``, stored."""
        if self.cache is None:
            return make()
        from cadgen.gears.cache import file_key

        key = file_key(inputs, chord_tolerance=self.tolerance, writer=writer_fingerprint())
        stored = self.cache.get(key)
        if isinstance(stored, kind):
            return stored
        data = make()
        self.cache.put(key, data)
        return data


def _mesh_planes(train, names: list) -> list:
    """The plane of each named gear: gears in mesh lie in one plane (numbered in ``names`` order)."""
    plane = {name: index for index, name in enumerate(names)}
    for stage in train.stages:  # a stage's two gears mesh: merge their planes
        drive, driven = (plane[profile.name] for profile in stage.generated.profiles)
        plane = {name: drive if number == driven else number for name, number in plane.items()}
    numbers = {}
    return [numbers.setdefault(plane[name], len(numbers)) for name in names]
