"""The vertex text written in one pass is ezdxf's own, the probe catches a mismatch, and the
hub-hole check that skips the ring distance flags what the distance flagged.

Second methods: ezdxf's own vertex-by-vertex tags (``LWPolylinePoints.dxftags`` through a
``TagWriter``); the ring distance between outline and hole (the check as it was).
"""

from __future__ import annotations

import io

import numpy as np
import pytest

ezdxf = pytest.importorskip("ezdxf")
shapely = pytest.importorskip("shapely")

from ezdxf.entities.lwpolyline import LWPolylinePoints  # noqa: E402
from ezdxf.lldxf.tagwriter import TagWriter  # noqa: E402

from cadgen.export import dxf as export_dxf  # noqa: E402


def _ezdxf_vertex_text(points: np.ndarray) -> str:
    """What ezdxf writes for these vertices (no widths, no bulges), tag by tag."""
    values = np.zeros((len(points), 5))
    values[:, :2] = points
    vertices = LWPolylinePoints()
    vertices.set(values)
    stream = io.StringIO()
    writer = TagWriter(stream)
    for tag in vertices.dxftags():
        writer.write_tag(tag)
    return stream.getvalue()


def test_vertex_text_is_ezdxfs_own(rng):
    points = rng.normal(size=(500, 2)) * rng.choice([1e-9, 1.0, 37.5, 1e6, 1e15], size=(500, 1))
    points[:6] = [[0.0, -0.0], [0.1 + 0.2, 1 / 3], [5e-324, -1.5e300], [123456789.125, 2.0],
                  [1e16, -1e-5], [np.pi, -np.e]]
    assert export_dxf._vertex_text(points, LWPolylinePoints.VERTEX_CODE) == _ezdxf_vertex_text(points)
    # a strided view (the vertex array's x and y columns) reads the same
    wide = np.zeros((len(points), 5))
    wide[:, :2] = points
    assert export_dxf._vertex_text(wide[:, :2], 10) == _ezdxf_vertex_text(points)


def test_no_vertices_no_text():
    assert export_dxf._vertex_text(np.zeros((0, 2)), 10) == "" == _ezdxf_vertex_text(np.zeros((0, 2)))


def test_probe_catches_a_vertex_text_that_is_not_ezdxfs(monkeypatch):
    assert export_dxf._fast_vertices()
    right = export_dxf._vertex_text
    monkeypatch.setattr(export_dxf, "_vertex_text",
                        lambda points, code: right(points, code).replace("e-300", "e-0300"))
    try:
        export_dxf._FAST[1] = None          # probe again, with the wrong text
        assert not export_dxf._fast_vertices()
    finally:
        monkeypatch.setattr(export_dxf, "_vertex_text", right)
        export_dxf._FAST[1] = None          # and right again once restored
    assert export_dxf._fast_vertices()


def _circle(radius, centre=(0.0, 0.0), count=64):
    angles = np.linspace(0.0, 2.0 * np.pi, count, endpoint=False)
    return np.column_stack([np.cos(angles), np.sin(angles)]) * radius + centre


@pytest.mark.parametrize("radius, centre", [
    (3.0, (0.0, 0.0)),      # well inside
    (9.99, (0.0, 0.0)),     # inside, close
    (10.0, (0.0, 0.0)),     # on the outline's vertices: touching
    (4.0, (6.0, 0.0)),      # crossing the outline
    (3.0, (30.0, 0.0)),     # outside
])
def test_hole_check_flags_what_the_ring_distance_flags(radius, centre):
    outline = export_dxf.closed_points(_circle(10.0))
    hole = _circle(radius, centre)
    ring, inner = shapely.LinearRing(outline), shapely.LinearRing(export_dxf.closed_points(hole))
    flagged_before = (not shapely.Polygon(ring).contains(shapely.Polygon(inner))
                      or ring.distance(inner) <= 0.0)
    problems = export_dxf._hole_problems(outline, hole, "gear 'g'", [])
    assert bool(problems) == flagged_before
    if problems:
        assert f"{ring.distance(inner):.6g} mm from it" in problems[0]
