"""The faster DXF writing gives ezdxf's own bytes: bulk vertices, vertex text in one block,
extents from the vertex arrays, a train's files from outlines checked and thinned once.

Second methods: the same documents written the plain ezdxf way (``add_lwpolyline`` vertex by
vertex, ``ezdxf.bbox``), the public one-file writers (``write_gear_dxf``,
``write_train_sheet``), contour's own ring check; every written file read back and audited.
"""

from __future__ import annotations

import io

import numpy as np
import pytest

ezdxf = pytest.importorskip("ezdxf")

from cadgen.export import dxf as export_dxf  # noqa: E402
from cadgen.export.dxf import write_gear_dxf  # noqa: E402
from cadgen.export.train_sheet import _mesh_planes, write_train_files, write_train_sheet  # noqa: E402
from cadgen.gears.cache import GearCache  # noqa: E402
from cadgen.gears.pairs import circle_pair, generate_pair  # noqa: E402
from cadgen.gears.teeth import ToothSystem  # noqa: E402
from cadgen.gears.trains import GearStage, GearTrain, _carry, _placements  # noqa: E402
from cadgen.geometry.contour import ring_problems  # noqa: E402


def _text(doc) -> str:
    stream = io.StringIO()
    with export_dxf._fixed_metadata():
        doc.write(stream)
    return stream.getvalue()


def _awkward_points(rng, count=400):
    points = rng.normal(size=(count, 2)) * rng.choice([1e-8, 1.0, 1e3, 1e12], size=(count, 1))
    points[:4] = [[0.0, -0.0], [0.1 + 0.2, 1 / 3], [5e-324, -1.5e300], [123456789.125, 2.0]]
    return points


@pytest.mark.parametrize("close", [True, False], ids=["closed", "open"])
def test_bulk_vertices_write_what_add_lwpolyline_writes(rng, close):
    points = _awkward_points(rng)
    texts = []
    for fast in (None, False, True):
        doc = export_dxf._new_document()
        msp = doc.modelspace()
        if fast is None:      # ezdxf's own way, vertex by vertex
            msp.add_lwpolyline(points.tolist(), format="xy", close=close,
                               dxfattribs={"layer": "OUTLINE"})
        else:
            export_dxf._add_polyline(msp, points, close=close, layer="OUTLINE", fast=fast)
        texts.append(_text(doc))
    assert texts[0] == texts[1] == texts[2]
    assert export_dxf._fast_vertices()


def test_a_polyline_with_widths_is_written_by_ezdxf_itself():
    doc = export_dxf._new_document()
    polyline = export_dxf._add_polyline(doc.modelspace(), [[0, 0], [1, 0], [1, 1]], close=True,
                                        layer="OUTLINE", fast=True)
    values = polyline.lwpoints.values.copy()
    values[1, 2:] = [0.5, 0.25, 0.3]          # start width, end width, bulge
    polyline.lwpoints.set(values)
    plain = export_dxf._new_document()
    plain.modelspace().add_lwpolyline(values.tolist(), format="xyseb", close=True,
                                      dxfattribs={"layer": "OUTLINE"})
    assert _text(doc) == _text(plain)


def test_extents_are_ezdxfs_bounding_box(rng):
    doc = export_dxf._new_document()
    msp = doc.modelspace()
    export_dxf._add_polyline(msp, rng.normal(size=(300, 2)) * 40, close=True, layer="OUTLINE")
    export_dxf._add_polyline(msp, rng.normal(size=(50, 2)) * 60, close=False, layer="OUTLINE")
    msp.add_circle((3.0, -2.0), 90.0, dxfattribs={"layer": "BORE"})
    msp.add_line((-200.5, 1.0), (0.0, 2.0), dxfattribs={"layer": "BORE"})
    export_dxf._set_extents(doc)
    box = ezdxf.bbox.extents(msp)
    header = ezdxf.read(io.StringIO(_text(doc))).header   # written into it as the file is
    assert tuple(header["$EXTMIN"])[:2] == tuple(box.extmin)[:2]
    assert tuple(header["$EXTMAX"])[:2] == tuple(box.extmax)[:2]


BOW_TIE = np.array([[0.0, 0.0], [10.0, 10.0], [10.0, 0.0], [0.0, 10.0]])


@pytest.mark.parametrize("points", [
    np.array([[0.0, 0.0], [4.0, 0.0], [0.0, 3.0]]), BOW_TIE, np.zeros((5, 2)),
    np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]), np.array([[0.0, np.nan], [1, 0], [0, 1]]),
    np.zeros((4, 3)), np.array([[0.0, 0.0], [1.0, 0.0]]), np.array([[0, 0], [2, 0], [1, 0]]),
], ids=["triangle", "bow tie", "one point", "collinear", "nan", "3 columns", "two points",
        "folded"])
def test_the_quick_ring_check_is_contours(points):
    points = np.asarray(points, dtype=float)
    assert export_dxf._ring_problems("ring", points) == ring_problems("ring", points)


# ----------------------------------------------------------------------------- a train's files
@pytest.fixture(scope="module")
def small_train():
    system = ToothSystem(2.0, backlash=0.05)
    first = circle_pair(("wheel a", "wheel b"), 24.0, 30.0)
    cut = generate_pair(first, (24, 30), system=system, bore_radius=5.0)
    stage = GearStage("a to b", cut, None, (0.3, np.zeros(2)))
    second = circle_pair(("wheel b", "wheel c"), 30.0, 20.0)
    phase, gear = _carry(cut)      # wheel b, cut once, drives the second mesh
    cut2 = generate_pair(second, (30, 20), system=system, bore_radius=5.0, drive_phase=phase,
                         drive_gear=gear)
    stage2 = GearStage("b to c", cut2, None, (0.3, 54.0 * np.array([np.cos(0.3), np.sin(0.3)])))
    return GearTrain((stage, stage2))


def _read_and_audit(path):
    document = ezdxf.readfile(path)
    auditor = document.audit()
    assert not auditor.has_errors and not auditor.has_fixes, path
    return path.read_bytes()


def test_a_trains_files_are_the_one_file_writers_bytes(small_train, tmp_path):
    tolerance = 0.004
    written = write_train_files(small_train, tmp_path, tolerance)
    assert [p.name for p in written] == ["wheel-a.dxf", "wheel-b.dxf", "wheel-c.dxf", "train.dxf"]
    for profile, _, _, _ in small_train.gears:
        reference = write_gear_dxf(tmp_path / "reference.dxf", profile, chord_tolerance=tolerance)
        assert (tmp_path / f"{profile.file_stem}.dxf").read_bytes() == \
            reference.path.read_bytes()
    placements = _placements(small_train)
    write_train_sheet(tmp_path / "sheet.dxf", placements, chord_tolerance=tolerance,
                      planes=_mesh_planes(small_train, [p.name for p, _, _ in placements]))
    assert (tmp_path / "train.dxf").read_bytes() == (tmp_path / "sheet.dxf").read_bytes()
    for path in written:
        _read_and_audit(path)


def test_a_cached_trains_files_are_made_once(small_train, tmp_path, monkeypatch):
    import cadgen.export.train_sheet as train_sheet

    cache = GearCache(tmp_path / "cache")
    (tmp_path / "cold").mkdir()
    (tmp_path / "warm").mkdir()
    cold = {p.name: p.read_bytes()
            for p in write_train_files(small_train, tmp_path / "cold", 0.005, cache=cache)}
    assert (cache.hits, cache.misses) == (0, 4)

    def made(*args, **kwargs):
        raise AssertionError("made again")

    monkeypatch.setattr(train_sheet, "gear_dxf_bytes", made)
    monkeypatch.setattr(train_sheet, "_sheet_bytes", made)
    warm = {p.name: p.read_bytes()
            for p in write_train_files(small_train, tmp_path / "warm", 0.005, cache=cache)}
    assert warm == cold and (cache.hits, cache.misses) == (4, 4)
    # another tolerance is another file: made, not looked up
    monkeypatch.undo()
    (tmp_path / "finer").mkdir()
    write_train_files(small_train, tmp_path / "finer", 0.001, cache=cache)
    assert cache.misses == 8


def test_a_bad_profile_in_a_train_is_refused_like_write_gear_dxf(small_train, tmp_path):
    import dataclasses

    stage = small_train.stages[0]
    bad = dataclasses.replace(stage.generated.profiles[0], bore_radius=100.0)
    train = dataclasses.replace(small_train, stages=(dataclasses.replace(
        stage, generated=dataclasses.replace(stage.generated, profiles=(
            bad, stage.generated.profiles[1]))),) + small_train.stages[1:])
    with pytest.raises(export_dxf.DxfInputError, match="bore") as caught:
        write_train_files(train, tmp_path, 0.005)
    with pytest.raises(export_dxf.DxfInputError) as reference:
        write_gear_dxf(tmp_path / "one.dxf", bad)
    assert caught.value.problems == reference.value.problems
