"""A lighter copy of ``solids/assembly.glb`` for the report's 3D view (the file stays as written).

The page embeds the assembly as base64, so every byte of the GLB costs 4/3 of a
byte in the page. The file is made for CAD use (round parts at the build's
``solids.segments_per_circle``, gear flanks at the gears' flank points), far finer
than a screen shows at the view's scale. The copy for the page keeps every node
(its name, its matrix, its mesh and material: the same parts at the same
placement) and thins each mesh:

1. **Fewer vertices**: :func:`cadgen.report.decimate.simplify_meshes` collapses
   edges while every kept vertex stays within :data:`TOLERANCE_MM` of the planes of
   the file's faces it stands for. Flat faces stay flat, sharp edges and corners
   stay; the kept vertices are the file's own. (Vertex clustering on a grid, the
   simpler method, was measured first: on the planting assembly a 0.5 mm grid takes
   away only 23 % of the vertices, because the file's round parts and housings have
   vertices 1 to 5 mm apart; a grid coarse enough to thin them loses gear teeth.)
2. **Normals again**, split at the file's crease angle
   (:func:`cadgen.export.meshes._shaded`, the function that made the file's).
3. **Smaller numbers**: normals as normalized bytes (``KHR_mesh_quantization``,
   which the vendored three.js GLTFLoader reads), indices as 16-bit integers where a
   mesh has fewer than 65,536 vertices. Positions stay 32-bit floats, so node
   matrices are the file's.

Pure numpy on the GLB's own accessors: trimesh's
``simplify_quadric_decimation`` needs ``fast_simplification``, not a dependency of
this project. The same bytes in give the same bytes out.
"""

from __future__ import annotations

import json
import struct
from types import SimpleNamespace

import numpy as np

from cadgen.report.decimate import simplify_meshes

__all__ = ["TOLERANCE_MM", "lighter_glb", "vertex_count", "read_glb", "glb_bytes",
           "mesh_arrays"]

#: How far (mm) a kept vertex may be from the planes of the faces it replaces: under a third
#: of a pixel at the view's framing (the whole machine, 300 to 700 mm, across about 1,000
#: px), under a tenth of the smallest module of the bundled gears (1.8 mm). A round part's
#: chords then sag by half of it at most (the planes of the faces next to a removed vertex
#: lean more than the new chord does).
TOLERANCE_MM = 0.1
_GLB_MAGIC, _JSON, _BIN = b"glTF", 0x4E4F534A, 0x004E4942
_COMPONENTS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}
_DTYPES = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32,
           5126: np.float32}


# ----------------------------------------------------------------------------------------------
# reading and writing binary glTF


def read_glb(data: bytes) -> tuple[dict, bytes]:
    """The JSON and the binary chunk of a GLB (glTF 2.0 binary container).

    Raises
    ------
    ValueError
        If ``data`` is not a GLB of version 2 with a JSON chunk.
    """
    data = bytes(data)
    if len(data) < 20 or data[:4] != _GLB_MAGIC:
        raise ValueError(f"not binary glTF: starts {data[:4]!r}")
    version, length = struct.unpack_from("<II", data, 4)
    if version != 2 or length > len(data):
        raise ValueError(f"GLB version {version}, length {length} of {len(data)} bytes: "
                         "need version 2, whole")
    gltf, binary, offset = None, b"", 12
    while offset + 8 <= length:
        size, kind = struct.unpack_from("<II", data, offset)
        chunk = data[offset + 8: offset + 8 + size]
        if kind == _JSON:
            gltf = json.loads(chunk.decode("utf-8"))
        elif kind == _BIN:
            binary = chunk
        offset += 8 + size
    if not isinstance(gltf, dict):
        raise ValueError("GLB has no JSON chunk")
    return gltf, binary


def glb_bytes(gltf: dict, binary: bytes) -> bytes:
    """A GLB of ``gltf`` (its one buffer being ``binary``); compact JSON, chunks padded to 4."""
    text = json.dumps(gltf, separators=(",", ":"), ensure_ascii=False).encode("utf-8")
    text += b" " * (-len(text) % 4)
    binary = bytes(binary) + b"\0" * (-len(binary) % 4)
    chunks = struct.pack("<II", len(text), _JSON) + text
    if binary:
        chunks += struct.pack("<II", len(binary), _BIN) + binary
    return _GLB_MAGIC + struct.pack("<II", 2, 12 + len(chunks)) + chunks


def _accessor(gltf: dict, binary: bytes, index: int) -> np.ndarray:
    """Accessor ``index`` as an array (n,) or (n, components), dequantized when normalized."""
    accessor = gltf["accessors"][index]
    view = gltf["bufferViews"][accessor["bufferView"]]
    dtype = np.dtype(_DTYPES[accessor["componentType"]]).newbyteorder("<")
    components = _COMPONENTS[accessor["type"]]
    count = accessor["count"]
    start = view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
    stride = view.get("byteStride") or dtype.itemsize * components
    raw = np.frombuffer(binary, dtype=np.uint8, count=stride * (count - 1)
                        + dtype.itemsize * components, offset=start)
    rows = np.lib.stride_tricks.as_strided(raw, shape=(count, dtype.itemsize * components),
                                           strides=(stride, 1))
    values = np.ascontiguousarray(rows).view(dtype).reshape(count, components)
    if accessor.get("normalized"):
        values = np.maximum(values / float(np.iinfo(dtype).max), -1.0)
    return values[:, 0] if components == 1 else values


def mesh_arrays(gltf: dict, binary: bytes, primitive: dict) -> tuple[np.ndarray, np.ndarray]:
    """A triangle primitive's positions ``(n, 3)`` and faces ``(m, 3)`` (int64)."""
    positions = _accessor(gltf, binary, primitive["attributes"]["POSITION"]).astype(np.float64)
    if "indices" in primitive:
        faces = _accessor(gltf, binary, primitive["indices"]).astype(np.int64).reshape(-1, 3)
    else:
        faces = np.arange(len(positions), dtype=np.int64).reshape(-1, 3)
    return positions, faces


# ----------------------------------------------------------------------------------------------
# the decimation


def _quantized_normals(normals: np.ndarray) -> np.ndarray:
    """Unit normals as normalized signed bytes, padded to 4 bytes a vertex (glTF alignment)."""
    packed = np.zeros((len(normals), 4), dtype=np.int8)
    packed[:, :3] = np.clip(np.round(normals * 127.0), -127, 127).astype(np.int8)
    return packed


def _primitive(positions, faces, material, out) -> dict:
    """Crease-split normals for the simplified mesh; its accessors appended to ``out``."""
    from cadgen.export.meshes import _shaded

    vertices, normals, triangles = _shaded(SimpleNamespace(vertices=positions, faces=faces))
    vertices = vertices.astype(np.float32)
    index_type = np.uint16 if len(vertices) < 65536 else np.uint32
    attributes = {
        "POSITION": out.add(vertices, 5126, "VEC3", 34962,
                            bounds=(vertices.min(axis=0), vertices.max(axis=0))),
        "NORMAL": out.add(_quantized_normals(normals), 5120, "VEC3", 34962, normalized=True,
                          stride=4, count=len(normals))}
    primitive = {"attributes": attributes,
                 "indices": out.add(triangles.astype(index_type).ravel(),
                                    5123 if index_type is np.uint16 else 5125, "SCALAR", 34963),
                 "mode": 4}
    if material is not None:
        primitive["material"] = material
    return primitive


class _Buffer:
    """The new binary chunk, its buffer views and accessors, as they are appended."""

    def __init__(self):
        self.data, self.views, self.accessors = bytearray(), [], []

    def add(self, array, component, kind, target, *, bounds=None, normalized=False, stride=None,
            count=None) -> int:
        self.data += b"\0" * (-len(self.data) % 4)
        raw = np.ascontiguousarray(array).tobytes()
        view = {"buffer": 0, "byteOffset": len(self.data), "byteLength": len(raw),
                "target": target}
        if stride:
            view["byteStride"] = stride
        self.data += raw
        self.views.append(view)
        accessor = {"bufferView": len(self.views) - 1, "componentType": component,
                    "count": int(count if count is not None else len(array)), "type": kind}
        if normalized:
            accessor["normalized"] = True
        if bounds is not None:
            accessor["min"] = [float(v) for v in bounds[0]]
            accessor["max"] = [float(v) for v in bounds[1]]
        self.accessors.append(accessor)
        return len(self.accessors) - 1


def lighter_glb(data: bytes, tolerance_mm: float = TOLERANCE_MM) -> bytes:
    """A copy of an assembly GLB (in metres) with every mesh thinned for viewing.

    Every node, its name, matrix and mesh, every material and the scene are the
    file's; each triangle mesh is simplified within ``tolerance_mm``
    (:func:`~cadgen.report.decimate.simplify_meshes`, all meshes' passes together) and gets
    crease normals again.

    Raises
    ------
    ValueError
        If ``data`` is not a GLB this module reads: glTF 2.0 binary, one buffer,
        no images, skins or animations (which would need their buffer views).
    """
    gltf, binary = read_glb(data)
    if len(gltf.get("buffers", [])) > 1 or any(k in gltf for k in ("images", "skins",
                                                                    "animations")):
        raise ValueError("GLB holds more than meshes (images, skins, animations or several "
                         "buffers): not simplified")
    tolerance = tolerance_mm * 1e-3   # the file is in metres (cadgen.export.meshes)
    primitives = [(mesh, primitive) for mesh in gltf.get("meshes", [])
                  for primitive in mesh["primitives"]]
    for mesh, primitive in primitives:
        if primitive.get("mode", 4) != 4 or "POSITION" not in primitive["attributes"]:
            raise ValueError(f"mesh {mesh.get('name')!r} has a primitive that is not "
                             "triangles: not simplified")
    simplified = iter(simplify_meshes([mesh_arrays(gltf, binary, primitive)
                                       for _, primitive in primitives], tolerance))
    out = _Buffer()
    meshes = [{**mesh, "primitives": [_primitive(*next(simplified), primitive.get("material"),
                                                 out) for primitive in mesh["primitives"]]}
              for mesh in gltf.get("meshes", [])]
    light = {**gltf, "meshes": meshes, "accessors": out.accessors, "bufferViews": out.views,
             "buffers": [{"byteLength": len(out.data)}]}
    light["asset"] = {**gltf.get("asset", {}),
                      "extras": {"cadgen": f"simplified within {tolerance_mm:g} mm for viewing"}}
    light["extensionsUsed"] = sorted(set(gltf.get("extensionsUsed", []))
                                     | {"KHR_mesh_quantization"})
    light["extensionsRequired"] = sorted(set(gltf.get("extensionsRequired", []))
                                         | {"KHR_mesh_quantization"})
    return glb_bytes(light, bytes(out.data))


def vertex_count(data: bytes) -> int:
    """How many vertices a GLB's meshes store (each mesh once, however many nodes use it)."""
    gltf, _ = read_glb(data)
    return sum(gltf["accessors"][primitive["attributes"]["POSITION"]]["count"]
               for mesh in gltf.get("meshes", []) for primitive in mesh["primitives"])
