"""The solids' faster paths give the same bits as the computations they replaced.

Each is checked against an independent computation: the per-corner pairing the GLB's
shading used before (kept here as the reference), trimesh's own facet areas and normals
and volume, a box's closed-form volume, and cross sections built without the memo.
"""

import numpy as np
import pytest
import trimesh

from cadgen.export.meshes import _shaded
from cadgen.solids.extrude import _SECTIONS, _enclosed_volume, extrude
from cadgen.solids.outcome import _flat_faces, printing_pose
from kinematics.errors import DesignError


def _shaded_by_pairs(mesh, crease_deg=30.0):
    """The shading as first written: every corner paired with every corner of its vertex."""
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    faces = np.asarray(mesh.faces, dtype=np.int64)
    triangles = vertices[faces]
    cross = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    length = np.linalg.norm(cross, axis=1)
    face_normals = cross / np.where(length > 0, length, 1.0)[:, None]
    edges = np.roll(triangles, -1, axis=1) - triangles
    before = -np.roll(edges, 1, axis=1)
    norms = np.linalg.norm(edges, axis=2) * np.linalg.norm(before, axis=2)
    cosines = np.einsum("fkc,fkc->fk", edges, before) / np.where(norms > 0, norms, 1.0)
    corner_angles = np.arccos(np.clip(cosines, -1.0, 1.0)).ravel()
    corner_vertex = faces.ravel()
    corner_face = np.repeat(np.arange(len(faces)), 3)
    order = np.argsort(corner_vertex, kind="stable")
    runs = np.flatnonzero(np.r_[True, corner_vertex[order][1:] != corner_vertex[order][:-1]])
    counts = np.diff(np.r_[runs, len(order)])
    run_of = np.repeat(np.arange(len(runs)), counts)
    repeat = counts[run_of]
    first = np.repeat(np.arange(len(order)), repeat)
    offset = np.arange(len(first)) - np.repeat(np.cumsum(repeat) - repeat, repeat)
    second = runs[run_of[first]] + offset
    this, other = order[first], order[second]
    near = np.einsum("ij,ij->i", face_normals[corner_face[this]], face_normals[corner_face[other]]) \
        >= np.cos(np.radians(crease_deg))
    into, weighted = this[near], corner_angles[other[near], None] * face_normals[corner_face[other[near]]]
    summed = np.column_stack([np.bincount(into, weights=weighted[:, axis], minlength=len(corner_vertex))
                              for axis in range(3)])
    size = np.linalg.norm(summed, axis=1)
    fallback = face_normals[corner_face]
    fallback[np.linalg.norm(fallback, axis=1) == 0] = (0.0, 0.0, 1.0)
    normals = np.where((size > 1e-12)[:, None], summed / np.where(size > 0, size, 1.0)[:, None], fallback)
    order = np.lexsort((normals[:, 2], normals[:, 1], normals[:, 0], corner_vertex))
    keyed_vertex, keyed_normal = corner_vertex[order], normals[order]
    starts = np.r_[True, (keyed_vertex[1:] != keyed_vertex[:-1])
                   | np.any(keyed_normal[1:] != keyed_normal[:-1], axis=1)]
    inverse = np.empty(len(order), dtype=np.int64)
    inverse[order] = np.cumsum(starts) - 1
    return vertices[keyed_vertex[starts]], keyed_normal[starts], inverse.reshape(-1, 3)


def _gear_like():
    """A prism of a wavy outline with a bore, off the origin: fans, flanks, flat faces."""
    angle = np.linspace(0.0, 2 * np.pi, 120, endpoint=False)
    radius = 20.0 + 1.5 * np.sin(12 * angle)
    outline = np.column_stack([radius * np.cos(angle), radius * np.sin(angle)]) + (150.0, -40.0)
    bore = np.column_stack([4 * np.cos(angle[::4]), 4 * np.sin(angle[::4])]) + (150.0, -40.0)
    solid = extrude(outline, 8.0, holes=[bore], z0=3.0, path="test")
    mesh = solid.to_mesh64()
    return trimesh.Trimesh(np.asarray(mesh.vert_properties)[:, :3], np.asarray(mesh.tri_verts),
                           process=False)


MESHES = {
    "cone": lambda: trimesh.creation.cone(5.0, 10.0, sections=48),
    "cylinder": lambda: trimesh.creation.cylinder(3.0, 5.0, sections=40),
    "icosphere": lambda: trimesh.creation.icosphere(2),
    "box": lambda: trimesh.creation.box((3.0, 2.0, 1.0)),
    "gear-like": _gear_like,
}


@pytest.mark.parametrize("name", sorted(MESHES))
def test_shading_is_the_corner_pairing_bit_for_bit(name):
    mesh = MESHES[name]()
    for ours, reference in zip(_shaded(mesh), _shaded_by_pairs(mesh)):
        assert ours.dtype == reference.dtype and ours.shape == reference.shape
        assert ours.tobytes() == reference.tobytes()


@pytest.mark.parametrize("name", sorted(MESHES))
def test_flat_faces_are_trimeshs_facet_areas_and_normals(name):
    mesh = MESHES[name]()
    areas, normals, _ = _flat_faces(mesh)
    count = len(mesh.facets)
    assert areas[:count].tobytes() == np.asarray(mesh.facets_area, dtype=float).tobytes()
    assert normals[:count].tobytes() == np.asarray(mesh.facets_normal, dtype=float).reshape(-1, 3).tobytes()
    pose = printing_pose(mesh)
    assert np.allclose(pose[:3, :3] @ pose[:3, :3].T, np.eye(3))


@pytest.mark.parametrize("name", sorted(MESHES))
def test_enclosed_volume_is_trimeshs_and_flips_inside_out(name):
    mesh = MESHES[name]()
    volume = _enclosed_volume(mesh.vertices, mesh.faces)
    assert volume == pytest.approx(mesh.volume, rel=1e-12)
    assert _enclosed_volume(mesh.vertices, mesh.faces[:, ::-1]) == pytest.approx(-volume, rel=1e-12)


def test_enclosed_volume_of_a_box_far_out_is_its_closed_form():
    box = trimesh.creation.box((3.0, 2.0, 1.0))
    box.apply_translation((1e4, -2e4, 5e3))
    assert _enclosed_volume(box.vertices, box.faces) == pytest.approx(6.0, rel=1e-12)


def test_a_remembered_cross_section_extrudes_to_the_same_solid():
    square = np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]])
    hole = square * 0.2 + 4.0
    _SECTIONS.clear()
    fresh = extrude(square, 2.0, holes=[hole], path="a").to_mesh64()
    again = extrude(square, 2.0, holes=[hole], path="b").to_mesh64()   # from the memo
    assert len(_SECTIONS) == 1
    assert np.asarray(fresh.vert_properties).tobytes() == np.asarray(again.vert_properties).tobytes()
    assert np.asarray(fresh.tri_verts).tobytes() == np.asarray(again.tri_verts).tobytes()


def test_an_invalid_outline_is_reported_at_its_path_every_time():
    bowtie = np.array([[0.0, 0.0], [10.0, 10.0], [10.0, 0.0], [0.0, 10.0]])
    for path in ("first.outline", "second.outline"):
        with pytest.raises(DesignError) as raised:
            extrude(bowtie, 2.0, path=path)
        assert [p.path for p in raised.value.problems] == [path]
