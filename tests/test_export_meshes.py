"""The mesh files a viewer, a slicer and a workshop read: GLB in metres, STLs in a printing pose.

Every check reads the written files back, the GLB both with trimesh and by parsing
its JSON and binary chunks directly (json, struct, numpy), and compares with values
computed here from the parts' own meshes and poses, not from the writer's code:
the world bounds of every placed part, face normals and areas, the planes a part
can rest on.
"""

from __future__ import annotations

import io
import json
import struct
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
import pytest
import trimesh

from cadgen.export.meshes import assembly_bytes, material_key, write_solids
from cadgen.params import validate_text
from cadgen.solids.extrude import to_trimesh
from cadgen.solids.outcome import printing_pose, solids_outcome, solids_report

from helpers import reference_text

#: GLB coordinates are float32 (about 6e-8 relative); parts reach about 1 m.
GLB_ATOL_M = 1e-6
#: STL coordinates are float32 in mm.
STL_ATOL_MM = 1e-4
KINDS = ("gear", "housing", "shaft", "spacer", "cam", "planter", "blade", "ground")
#: Materials: one per kind, the housings' covers their own (see-through) one, and the bought
#: solids' (bright steel).
MATERIALS = KINDS + ("housing-cover", "bought")


def _params(build_volume=None, process="printed"):
    """The reference file with its parts printed (only printed parts meet the printer's bed)."""
    from tests.helpers import with_keys

    keys = {"process": f'"{process}"'}
    if build_volume is not None:
        keys["build_volume"] = str([float(v) for v in build_volume])
    return validate_text(with_keys(reference_text(), "manufacturing", **keys))


@pytest.fixture(scope="module")
def planting(planting_solids):
    params, _, _, _, _, assembly, housings, _ = planting_solids
    outcome = solids_outcome(params, assembly, {"gearbox1": housings[0], "gearbox2": housings[1]})
    return params, outcome


@pytest.fixture(scope="module")
def written(planting, tmp_path_factory):
    _, outcome = planting
    staging = tmp_path_factory.mktemp("build")
    files = write_solids(outcome, staging)
    return staging, files


def _glb_chunks(data: bytes):
    """(JSON tree, binary chunk) of a GLB, read by the container's layout (glTF 2.0, GLB)."""
    magic, version, length = struct.unpack_from("<III", data, 0)
    assert (magic, version, length) == (0x46546C67, 2, len(data))
    json_length, json_type = struct.unpack_from("<II", data, 12)
    assert json_type == 0x4E4F534A and json_length % 4 == 0
    tree = json.loads(data[20:20 + json_length])
    bin_length, bin_type = struct.unpack_from("<II", data, 20 + json_length)
    assert bin_type == 0x004E4942 and bin_length % 4 == 0
    start = 28 + json_length
    return tree, data[start:start + bin_length]


_COMPONENTS = {5126: np.float32, 5125: np.uint32, 5123: np.uint16}
_WIDTH = {"SCALAR": 1, "VEC3": 3}


def _accessor(tree, binary, index):
    accessor = tree["accessors"][index]
    view = tree["bufferViews"][accessor["bufferView"]]
    dtype = np.dtype(_COMPONENTS[accessor["componentType"]]).newbyteorder("<")
    offset = view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
    assert offset % dtype.itemsize == 0                       # aligned to its component
    count, width = accessor["count"], _WIDTH[accessor["type"]]
    assert offset + count * width * dtype.itemsize <= view.get("byteOffset", 0) + view["byteLength"]
    values = np.frombuffer(binary, dtype=dtype, count=count * width, offset=offset)
    return accessor, values.reshape(count, width) if width > 1 else values


def _node_matrix(node):
    if "matrix" in node:
        return np.array(node["matrix"], dtype=float).reshape(4, 4).T   # stored column-major
    assert not {"translation", "rotation", "scale"} & set(node)
    return np.eye(4)


def _world_bounds_mm(part, pose):
    vertices = np.asarray(part.mesh.vertices) @ pose[:3, :3].T + pose[:3, 3]
    return np.array([vertices.min(axis=0), vertices.max(axis=0)])


@pytest.fixture(scope="module")
def glb(written):
    staging, _ = written
    return (staging / "solids" / "assembly.glb").read_bytes()


def test_glb_is_in_metres_and_places_every_part_where_the_assembly_does(planting, glb):
    _, outcome = planting
    tree, binary = _glb_chunks(glb)
    # the made parts and the bought solids (bearings, keys, screws, ...) riding on them
    placements = outcome.assembly.placements(outcome.carrier_angle, bought=True)
    nodes = {node["name"]: node for node in tree["nodes"]}
    assert sorted(nodes) == sorted(name for name, _, _ in placements)
    bought = [name for name in nodes if name.startswith("bought/")]
    assert len(bought) == sum(len(part.instances) for part in outcome.assembly.bought) > 100
    materials = [material["name"] for material in tree["materials"]]
    for name in bought:   # their own material, none of the made parts'
        assert materials[tree["meshes"][nodes[name]["mesh"]]["primitives"][0]["material"]] \
            == "bought", name
    everything = []
    for name, part, pose in placements:
        node = nodes[name]
        _, positions = _accessor(tree, binary, tree["meshes"][node["mesh"]]["primitives"][0]
                                 ["attributes"]["POSITION"])
        matrix = _node_matrix(node)
        world = positions.astype(float) @ matrix[:3, :3].T + matrix[:3, 3]
        expected = _world_bounds_mm(part, pose) * 1e-3
        np.testing.assert_allclose([world.min(axis=0), world.max(axis=0)], expected, atol=GLB_ATOL_M,
                                   err_msg=name)
        everything.append(expected)
    low = np.min([b[0] for b in everything], axis=0)
    high = np.max([b[1] for b in everything], axis=0)
    scene = trimesh.load_scene(io.BytesIO(glb), file_type="glb")
    np.testing.assert_allclose(scene.bounds, [low, high], atol=GLB_ATOL_M)
    assert 0.1 < np.max(high - low) < 10.0       # a machine of about a metre, not a kilometre


def test_glb_follows_the_gltf_rules_a_validator_checks(glb):
    tree, binary = _glb_chunks(glb)
    assert tree["asset"]["version"] == "2.0"
    assert tree["buffers"] == [{"byteLength": len(binary)}] or \
        0 <= len(binary) - tree["buffers"][0]["byteLength"] < 4
    for view in tree["bufferViews"]:
        assert view["byteOffset"] + view["byteLength"] <= tree["buffers"][0]["byteLength"]
    for mesh in tree["meshes"]:
        for primitive in mesh["primitives"]:
            attributes = primitive["attributes"]
            assert {"POSITION", "NORMAL"} <= set(attributes)
            position, positions = _accessor(tree, binary, attributes["POSITION"])
            # min and max are required on POSITION and must be the data's
            assert position["min"] == positions.min(axis=0).tolist()
            assert position["max"] == positions.max(axis=0).tolist()
            normal, normals = _accessor(tree, binary, attributes["NORMAL"])
            assert normal["count"] == position["count"]
            np.testing.assert_allclose(np.linalg.norm(normals.astype(float), axis=1), 1.0, atol=1e-6)
            _, indices = _accessor(tree, binary, primitive["indices"])
            assert len(indices) % 3 == 0 and indices.max() < position["count"]
            assert primitive.get("mode", 4) == 4
            assert 0 <= primitive["material"] < len(tree["materials"])
    for node in tree["nodes"]:
        assert isinstance(node.get("name"), str) and node["name"]
        rotation = _node_matrix(node)[:3, :3]
        np.testing.assert_allclose(rotation @ rotation.T, np.eye(3), atol=1e-9)   # rigid: TRS
    assert sorted(tree["scenes"][tree["scene"]]["nodes"]) == list(range(len(tree["nodes"])))


def test_glb_normals_face_out_of_the_solid(glb):
    # each vertex normal agrees with the faces it belongs to (an inside-out normal would not)
    tree, binary = _glb_chunks(glb)
    for mesh in tree["meshes"]:
        primitive = mesh["primitives"][0]
        _, positions = _accessor(tree, binary, primitive["attributes"]["POSITION"])
        _, normals = _accessor(tree, binary, primitive["attributes"]["NORMAL"])
        _, indices = _accessor(tree, binary, primitive["indices"])
        triangles = positions.astype(float)[indices.reshape(-1, 3)]
        cross = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
        big = np.linalg.norm(cross, axis=1) > 1e-12
        faces = cross[big] / np.linalg.norm(cross[big], axis=1)[:, None]
        corner_normals = normals.astype(float)[indices.reshape(-1, 3)[big]]
        assert (np.einsum("fc,fkc->fk", faces, corner_normals) > 0.5).all(), mesh["name"]


def test_glb_materials_differ_by_part_kind_and_housing_covers_are_translucent(planting, glb):
    _, outcome = planting
    tree, _ = _glb_chunks(glb)
    kind_of = {name: material_key(name, part.kind)
               for name, part, _ in outcome.assembly.placements(outcome.carrier_angle)}
    kind_of.update({name: "bought" for part in outcome.assembly.bought
                    for name, _, _ in part.instances})
    assert kind_of["gearbox2-cover-arm1"] == "housing-cover" == kind_of["gearbox1-cover"]
    assert kind_of["gearbox2-base-arm1"] == "housing"
    material_of_kind = {}
    for node in tree["nodes"]:
        material = tree["meshes"][node["mesh"]]["primitives"][0]["material"]
        material_of_kind.setdefault(kind_of[node["name"]], set()).add(material)
    assert set(material_of_kind) == set(MATERIALS)
    assert all(len(found) == 1 for found in material_of_kind.values())    # one per kind
    chosen = {kind: tree["materials"][found.pop()] for kind, found in material_of_kind.items()}
    colours = {tuple(m["pbrMetallicRoughness"]["baseColorFactor"]) for m in chosen.values()}
    assert len(colours) == len(MATERIALS)                                 # all different
    for kind, material in chosen.items():
        colour = material["pbrMetallicRoughness"]["baseColorFactor"]
        assert len(colour) == 4 and all(0 <= c <= 1 for c in colour)
        if kind in ("housing-cover", "ground"):
            assert material["alphaMode"] == "BLEND" and colour[3] < 1
        else:
            assert material.get("alphaMode", "OPAQUE") == "OPAQUE" and colour[3] == 1


def _planes(vertices, faces):
    """Faces grouped by plane: [(area, unit normal, offset)], from the triangles alone."""
    triangles = vertices[faces]
    cross = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    area = np.linalg.norm(cross, axis=1) / 2
    keep = area > 1e-9
    normal = cross[keep] / (2 * area[keep])[:, None]
    offset = np.einsum("ij,ij->i", normal, triangles[keep, 0])
    key = np.column_stack([np.round(normal, 5), np.round(offset, 3)])
    groups, inverse = np.unique(key, axis=0, return_inverse=True)
    areas = np.bincount(inverse.ravel(), weights=area[keep])
    return [(areas[i], groups[i, :3], groups[i, 3]) for i in range(len(groups))]


def _read_stl(path):
    data = path.read_bytes()
    count = struct.unpack_from("<I", data, 80)[0]
    records = np.frombuffer(data, dtype=np.dtype([("normal", "<f4", 3), ("corners", "<f4", (3, 3)),
                                                  ("attribute", "<u2")]), count=count, offset=84)
    corners = records["corners"].astype(float).reshape(-1, 3)
    return corners, np.arange(len(corners)).reshape(-1, 3)


def test_every_stl_lies_on_the_bed_on_its_largest_flat_face(planting, written):
    staging, files = written
    _, outcome = planting
    stls = [f for f in files if f.endswith(".stl")]
    assert len(stls) == len(outcome.assembly.parts)
    for name in stls:
        vertices, faces = _read_stl(staging / name)
        assert vertices[:, 2].min() == 0.0, name
        low, high = vertices.min(axis=0), vertices.max(axis=0)
        np.testing.assert_allclose((low + high)[:2] / 2, 0.0, atol=STL_ATOL_MM, err_msg=name)
        planes = _planes(vertices, faces)
        # the faces on the bed: normal -z, at z = 0
        on_bed = sum(a for a, n, d in planes if n[2] < -1 + 1e-6 and abs(d) < 1e-3)
        # the largest plane the part can rest on: no vertex beyond it
        resting = max(a for a, n, d in planes if (vertices @ n - d).max() < 1e-3)
        assert on_bed == pytest.approx(resting, rel=1e-4), name


def test_each_stl_is_its_part_moved_rigidly(planting, written):
    # the STL holds the part's own mesh, turned and moved (Kabsch fit of the corners,
    # written in face order): same shape, a proper rotation; the blades, the planter
    # shell, the cam and gearbox 2 sat up to 137 mm above z = 0 in their own frames
    _, outcome = planting
    staging, _ = written
    for part in outcome.assembly.parts:
        stl, _ = _read_stl(staging / "solids" / f"{part.name}.stl")
        own = np.asarray(part.mesh.vertices)[np.asarray(part.mesh.faces)].reshape(-1, 3)
        a, b = own - own.mean(axis=0), stl - stl.mean(axis=0)
        u, _, vt = np.linalg.svd(a.T @ b)
        rotation = (u @ vt).T
        assert np.linalg.det(rotation) == pytest.approx(1.0)
        assert np.abs(a @ rotation.T - b).max() < STL_ATOL_MM, part.name
        if part.kind in ("blade", "planter", "cam"):
            assert own[:, 2].min() > 50.0          # far above the bed where it was built
    moved = [p.name for p in outcome.assembly.parts
             if not np.allclose(outcome.printing_pose(p), np.eye(4))]
    assert {"blade-left", "blade-right", "planter-shell", "cam", "gearbox2-base"} <= set(moved)


def test_printing_pose_skips_a_large_face_the_part_cannot_rest_on():
    import manifold3d

    # a plate on two corner legs, a rib along its top: the plate's underside (9800 mm^2)
    # is the largest flat face but the legs stand below it; the top is split by the rib
    plate = manifold3d.Manifold.cube([100.0, 100.0, 5.0]).translate([0.0, 0.0, 10.0])
    legs = (manifold3d.Manifold.cube([10.0, 10.0, 10.0])
            + manifold3d.Manifold.cube([10.0, 10.0, 10.0]).translate([90.0, 90.0, 0.0]))
    rib = manifold3d.Manifold.cube([100.0, 2.0, 3.0]).translate([0.0, 49.0, 15.0])
    mesh = to_trimesh(plate + legs + rib, "plate")
    vertices = np.asarray(mesh.vertices)
    planes = _planes(vertices, np.asarray(mesh.faces))
    largest = max(planes, key=lambda p: p[0])
    assert largest[0] == pytest.approx(9800.0) and largest[1][2] < -0.99    # the underside
    posed = mesh.copy().apply_transform(printing_pose(mesh))
    vertices = np.asarray(posed.vertices)
    planes = _planes(vertices, np.asarray(posed.faces))
    on_bed = sum(a for a, n, d in planes if n[2] < -1 + 1e-6 and abs(d) < 1e-6)
    resting = max(a for a, n, d in planes if (vertices @ n - d).max() < 1e-6)
    assert vertices[:, 2].min() == 0.0
    assert on_bed == pytest.approx(resting) and on_bed < 9800.0
    assert posed.volume == pytest.approx(mesh.volume)


@pytest.mark.parametrize("angle", [0.0, 0.4, 2.0], ids=["as-is", "tilted", "upside-down"])
def test_printing_pose_of_a_turned_box_puts_its_largest_face_down(angle):
    box = trimesh.creation.box([30.0, 20.0, 5.0])
    box.apply_transform(trimesh.transformations.rotation_matrix(angle, [1.0, 0.3, 0.0]))
    box.apply_translation([7.0, -3.0, 40.0])
    posed = box.copy().apply_transform(printing_pose(box))
    np.testing.assert_allclose(posed.bounds, [[-15, -10, 0], [15, 10, 5]], atol=1e-9)


def test_parts_too_big_for_the_build_volume_are_listed(planting, written):
    params, outcome = planting
    # machined parts never meet a printer's bed: nothing is checked against it
    assert params.manufacturing.process == "machined"
    assert solids_report(outcome)["too_big_for_build_volume"] == []
    report = solids_report(solids_outcome(_params(), outcome.assembly, outcome.housings))
    staging, _ = written
    assert report["build_volume_mm"] == [256.0, 256.0, 256.0]
    # gearbox 1 (base and cover) spans both arms' side of the carrier, over half a metre
    rows = report["too_big_for_build_volume"]
    assert [row["part"] for row in rows] == ["gearbox1-base", "gearbox1-cover"]
    for row in rows:
        vertices, _ = _read_stl(staging / "solids" / f"{row['part']}.stl")
        np.testing.assert_allclose(row["print_extents_mm"], np.ptp(vertices, axis=0),
                                   atol=STL_ATOL_MM)
        assert max(row["print_extents_mm"]) > 500


def test_a_small_build_volume_lists_every_part_that_does_not_fit(planting, written):
    _, outcome = planting
    staging, _ = written
    small = _params(build_volume=[60, 60, 60])
    assert small.manufacturing.build_volume == (60.0, 60.0, 60.0)
    report = solids_report(solids_outcome(small, outcome.assembly, outcome.housings))
    listed = {row["part"] for row in report["too_big_for_build_volume"]}
    expected = set()
    for part in outcome.assembly.parts:
        if part.kind in ("ground", "shaft"):   # the soil is not made, shafts are turned
            continue
        # flat side down, any turn about z: it fits when its footprint's box does
        x, y, z = np.ptp(_read_stl(staging / "solids" / f"{part.name}.stl")[0], axis=0)
        if z > 60 or max(x, y) > 60:
            expected.add(part.name)
    assert listed == expected
    assert {"sun", "gearbox1-base", "gearbox2-base", "gearbox2-cover", "planter-shell"} <= listed
    assert "gear-D" in {r["part"] for r in report["parts"]} - listed     # 57.6 x 57.4 x 11


def test_a_part_that_fits_only_turned_about_z_fits(planting):
    _, outcome = planting
    extents = next(r for r in solids_report(outcome)["parts"] if r["part"] == "gearbox2-base")[
        "print_extents_mm"]
    long, short, height = extents[0], extents[1], extents[2]
    assert long > short
    bed = _params(build_volume=[short + 1, long + 1, height + 1])
    assert "gearbox2-base" not in {r["part"] for r in solids_report(solids_outcome(
        bed, outcome.assembly, outcome.housings))["too_big_for_build_volume"]}
    bed = _params(build_volume=[short + 1, short + 1, height + 1])
    assert "gearbox2-base" in {r["part"] for r in solids_report(solids_outcome(
        bed, outcome.assembly, outcome.housings))["too_big_for_build_volume"]}


def test_three_mf_declares_millimetres(planting):
    _, outcome = planting
    placed = [(name, part.mesh, pose, part.kind)
              for name, part, pose in outcome.assembly.placements(0.0)][:3]
    data = assembly_bytes(placed, "3mf")
    model = zipfile.ZipFile(io.BytesIO(data)).read("3D/3dmodel.model")
    assert ET.fromstring(model).attrib["unit"] == "millimeter"
    scene = trimesh.load_scene(io.BytesIO(data), file_type="3mf")
    expected = np.array([_world_bounds_mm(part, pose) for _, part, pose in
                         outcome.assembly.placements(0.0)[:3]])
    np.testing.assert_allclose(scene.bounds, [expected[:, 0].min(0), expected[:, 1].max(0)], atol=1e-6)


def test_bad_build_volumes_name_the_field():
    from cadgen.params import ParameterError
    from tests.helpers import with_keys

    for value, code in (("[0, 100, 100]", "out_of_range"), ('[100, "a", 100]', "wrong_type")):
        with pytest.raises(ParameterError) as caught:
            validate_text(with_keys(reference_text(), "manufacturing", build_volume=value))
        assert any(p.path.startswith("manufacturing.build_volume") and p.code == code
                   for p in caught.value.problems)
