"""The report's lighter copy of assembly.glb (cadgen.report.view_glb, cadgen.report.decimate).

Both GLBs are read back with trimesh (an independent reader): the copy keeps every node,
its name, its placement and its material, has fewer vertices, keeps only vertices of the
file (half-edge collapses), and stays within the tolerance of the file's surface, checked
against the exact shapes (a cylinder's radius, a box's corners) and the file's volumes.
"""

from __future__ import annotations

import io
import json
import struct

import numpy as np
import pytest

from cadgen.export.meshes import assembly_bytes
from cadgen.report.decimate import simplify_mesh
from cadgen.report.view_glb import TOLERANCE_MM, lighter_glb, vertex_count

RADIUS_MM, HEIGHT_MM, SEGMENTS = 20.0, 10.0, 96


def _scene(data: bytes):
    import trimesh

    return trimesh.load_scene(io.BytesIO(data), file_type="glb", process=False)


def _gltf_json(data: bytes) -> dict:
    """The JSON chunk of a GLB, read by hand (glTF 2.0: 12-byte header, chunk length, type)."""
    length, kind = struct.unpack_from("<II", data, 12)
    assert kind == 0x4E4F534A
    return json.loads(data[20:20 + length])


@pytest.fixture(scope="module")
def parts():
    import trimesh

    cylinder = trimesh.creation.cylinder(radius=RADIUS_MM, height=HEIGHT_MM, sections=SEGMENTS)
    box = trimesh.creation.box(extents=(30.0, 20.0, 10.0))
    turned = np.eye(4)
    turned[:3, :3] = trimesh.transformations.rotation_matrix(0.3, [0, 0, 1])[:3, :3]
    turned[:3, 3] = (100.0, -40.0, 5.0)
    return [("shaft-O", cylinder, np.eye(4), "shaft"), ("gearbox-cover", box, turned, "housing"),
            ("shaft-O-copy", cylinder.copy(), turned, "shaft")]


@pytest.fixture(scope="module")
def glbs(parts):
    full = assembly_bytes(parts)
    return full, lighter_glb(full)


def test_every_node_keeps_its_name_placement_and_material(glbs):
    full, light = (_gltf_json(g) for g in glbs)
    assert [n["name"] for n in light["nodes"]] == [n["name"] for n in full["nodes"]]
    assert [n.get("matrix") for n in light["nodes"]] == [n.get("matrix") for n in full["nodes"]]
    assert [n.get("mesh") for n in light["nodes"]] == [n.get("mesh") for n in full["nodes"]]
    assert light["materials"] == full["materials"]
    assert "KHR_mesh_quantization" in light["extensionsRequired"]
    # read back by trimesh: the same nodes at the same transforms
    full_scene, light_scene = (_scene(g) for g in glbs)
    assert set(light_scene.graph.nodes_geometry) == set(full_scene.graph.nodes_geometry)
    for node in full_scene.graph.nodes_geometry:
        assert np.allclose(light_scene.graph[node][0], full_scene.graph[node][0], atol=1e-12)


def test_the_copy_has_fewer_vertices_all_of_them_the_files(glbs):
    full, light = glbs
    assert vertex_count(light) < vertex_count(full)
    full_scene, light_scene = _scene(full), _scene(light)
    counted = sum(len(g.vertices) for g in light_scene.geometry.values())
    assert counted == vertex_count(light)
    for name, geometry in light_scene.geometry.items():
        original = {tuple(v) for v in np.asarray(full_scene.geometry[name].vertices, np.float32)}
        kept = {tuple(v) for v in np.asarray(geometry.vertices, np.float32)}
        assert kept <= original, name   # half-edge collapses: no vertex is new


def test_the_cylinder_stays_within_the_tolerance_of_its_radius(glbs):
    full_scene, light_scene = _scene(glbs[0]), _scene(glbs[1])
    name = next(n for n in light_scene.geometry if n.startswith("shaft-O"))
    light = light_scene.geometry[name]
    file_rim = len(full_scene.geometry[name].vertices)
    assert len(light.vertices) < file_rim
    metres = 1e-3
    # every chord of the polygon round the side sags below the exact circle by at most the
    # tolerance: the edges of the side faces (normals across the axis) at one height
    side = light.faces[np.abs(light.face_normals[:, 2]) < 1e-6]
    chords = np.concatenate([side[:, [0, 1]], side[:, [1, 2]], side[:, [2, 0]]])
    ends = light.vertices[chords]
    ends = ends[np.abs(ends[:, 0, 2] - ends[:, 1, 2]) < 1e-12]
    assert np.allclose(np.linalg.norm(ends[:, :, :2], axis=2), RADIUS_MM * metres, atol=1e-9)
    sag = RADIUS_MM * metres - np.linalg.norm(ends.mean(axis=1)[:, :2], axis=1)
    assert len(ends) >= 2 * 3 and 0 < sag.max() <= TOLERANCE_MM * metres
    # and, its vertices welded (the file splits them where normals differ), it is closed and
    # its volume is the file's within what that sag can take
    import trimesh

    welded = trimesh.Trimesh(light.vertices, light.faces, process=True)
    assert welded.is_watertight
    assert welded.volume == pytest.approx(full_scene.geometry[name].volume, rel=2 * TOLERANCE_MM
                                         / RADIUS_MM)


def test_flat_faces_and_sharp_corners_stay():
    import trimesh

    box = trimesh.creation.box(extents=(30.0, 20.0, 10.0))
    grid = trimesh.remesh.subdivide_to_size(box.vertices, box.faces, max_edge=2.0)
    positions, faces = simplify_mesh(*grid, tolerance=0.05)
    simplified = trimesh.Trimesh(positions, faces, process=False)
    assert len(grid[0]) > 200
    assert len(positions) < 40 and simplified.is_watertight
    assert simplified.volume == pytest.approx(30.0 * 20.0 * 10.0, rel=1e-9)
    corners = {tuple(c) for c in box.vertices}
    assert corners <= {tuple(p) for p in positions}   # the eight corners are kept


def test_same_bytes_in_same_bytes_out(glbs, parts):
    assert lighter_glb(assembly_bytes(parts)) == glbs[1]


def test_a_bad_tolerance_or_a_glb_of_something_else_is_refused(glbs):
    with pytest.raises(ValueError, match="tolerance must be > 0"):
        simplify_mesh(np.zeros((3, 3)), [[0, 1, 2]], 0.0)
    with pytest.raises(ValueError, match="not binary glTF"):
        lighter_glb(b"solid ascii stl")
    with pytest.raises(ValueError, match="version 0"):
        lighter_glb(b"glTF" + bytes(16))


def test_the_3d_view_embeds_the_copy_and_says_how_light_it_is(glbs):
    import base64
    import re

    from cadgen.report.viewer import viewer_section

    section = viewer_section(glbs[0])
    embedded = re.search(r'id="cadgen-glb">([^<]+)</script>', section)[1]
    assert base64.b64decode(embedded) == glbs[1]
    assert f"{vertex_count(glbs[0]):,} vertices" in section
    assert f"{vertex_count(glbs[1]):,} vertices" in section
    assert viewer_section(glbs[0]) == section   # same input, same page bytes
