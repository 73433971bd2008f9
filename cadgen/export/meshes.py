"""Export of parts (binary STL) and assemblies (GLB, 3MF) as deterministic bytes.

The same meshes give the same bytes, so outputs can be compared by hash and
rebuilt without churn:

STL
    trimesh writes an all-zero 80-byte header (no name, no date) followed by the
    face count and float32 normals and vertices: deterministic as it stands.
GLB
    trimesh's glTF writer has no clock or random input; its JSON carries each
    mesh's ``metadata`` as ``extras``, though, and loaded meshes carry things like
    a file path there. So the scene is built from fresh copies whose metadata is
    only the part's name.
3MF
    Needs ``lxml`` and ``networkx`` (trimesh's soft dependencies). trimesh fixes
    the zip timestamps (1980-01-01) but gives every object, item and the build a
    random ``p:UUID`` (``uuid.uuid4``); those are replaced here, in order of
    appearance, by UUIDs derived from the model's content, and the zip is written
    again with the same entries, order, compression and timestamps.

File writers go through :func:`cadgen.export.atomic.write_bytes_atomic`. trimesh is
imported inside the functions.
"""

from __future__ import annotations

import hashlib
import io
import re
import uuid
import zipfile
from enum import Enum
from pathlib import Path

import numpy as np

from cadgen.export.atomic import write_bytes_atomic
from cadgen.solids.errors import ExportFormatError, SolidInputError

__all__ = [
    "AssemblyFormat",
    "stl_bytes",
    "assembly_bytes",
    "load_volume",
    "write_stl",
    "write_assembly",
    "write_solids",
]

#: Fixed zip timestamp (the earliest a zip can hold; the one trimesh uses).
_ZIP_EPOCH = (1980, 1, 1, 0, 0, 0)
_UUID = re.compile(rb"[0-9a-fA-F]{8}-[0-9a-fA-F]{4}-[0-9a-fA-F]{4}-[0-9a-fA-F]{4}-[0-9a-fA-F]{12}")
#: Namespace of the UUIDs written into 3MF files (uuid5 of the project's name).
_UUID_NAMESPACE = uuid.uuid5(uuid.NAMESPACE_DNS, "cadgen.solids")


class AssemblyFormat(str, Enum):
    """Assembly file formats (a closed choice)."""

    GLB = "glb"
    THREE_MF = "3mf"


def stl_bytes(mesh) -> bytes:
    """Binary STL of a mesh (float32 coordinates, zero header), deterministic.

    Parameters
    ----------
    mesh : trimesh.Trimesh

    Returns
    -------
    bytes
    """
    from trimesh.exchange.stl import export_stl

    return export_stl(mesh)


def _clean_copy(mesh, name: str):
    import trimesh

    # Fresh geometry: only the name travels as metadata (see the module notes),
    # and no cached visuals or normals of the caller's mesh leak into the file.
    return trimesh.Trimesh(vertices=np.asarray(mesh.vertices, dtype=np.float64),
                           faces=np.asarray(mesh.faces, dtype=np.int64),
                           process=False, metadata={"name": name})


def _scene(parts):
    import trimesh

    scene = trimesh.Scene()
    seen = set()
    for index, part in enumerate(parts):
        try:
            name, mesh, transform = part
        except (TypeError, ValueError):
            raise SolidInputError("parts", f"part {index} must be (name, mesh, 4x4 transform), not {part!r}") from None
        name = str(name)
        if not name or name in seen:
            raise SolidInputError("parts", f"part names must be unique and non-empty; part {index} is {name!r}")
        seen.add(name)
        transform = np.asarray(transform, dtype=np.float64)
        if transform.shape != (4, 4) or not np.isfinite(transform).all() \
                or not np.array_equal(transform[3], [0.0, 0.0, 0.0, 1.0]):
            raise SolidInputError("parts", f"part {name!r} needs a finite 4x4 homogeneous transform "
                                           f"(last row 0 0 0 1), not {transform.tolist()}")
        scene.add_geometry(_clean_copy(mesh, name), node_name=name, geom_name=name, transform=transform)
    if not seen:
        raise SolidInputError("parts", "an assembly needs at least one part")
    return scene


def _three_mf_writer():
    import importlib.util

    # trimesh registers a placeholder that fails at call time when these are
    # missing; checking first gives the caller a message that says what to install.
    missing = [name for name in ("lxml", "networkx") if importlib.util.find_spec(name) is None]
    if missing:
        raise ExportFormatError(f"3MF export needs the packages lxml and networkx, which trimesh uses "
                                f"for it; missing: {', '.join(missing)}. Install them or export GLB")
    from trimesh.exchange.threemf import export_3MF

    return export_3MF


def _deterministic_3mf(data: bytes) -> bytes:
    source = zipfile.ZipFile(io.BytesIO(data))
    entries = [(info, source.read(info.filename)) for info in source.infolist()]
    # Seed the replacement UUIDs with the content (UUIDs blanked), so different
    # models still get different UUIDs, and the same model the same ones.
    digest = hashlib.sha256()
    for info, payload in entries:
        digest.update(info.filename.encode() + b"\0" + _UUID.sub(b"", payload))
    namespace = uuid.uuid5(_UUID_NAMESPACE, digest.hexdigest())
    replacements: dict[bytes, bytes] = {}

    def replace(match):
        found = match.group(0).lower()
        if found not in replacements:
            replacements[found] = str(uuid.uuid5(namespace, str(len(replacements)))).encode()
        return replacements[found]

    out = io.BytesIO()
    with zipfile.ZipFile(out, "w") as target:
        for info, payload in entries:
            entry = zipfile.ZipInfo(info.filename, date_time=_ZIP_EPOCH)
            entry.compress_type = info.compress_type
            entry.external_attr = info.external_attr
            target.writestr(entry, _UUID.sub(replace, payload))
    return out.getvalue()


def assembly_bytes(parts, file_type: str | AssemblyFormat = AssemblyFormat.GLB) -> bytes:
    """An assembly file: one node per part, placed by its transform.

    Parameters
    ----------
    parts : sequence of (str, trimesh.Trimesh, (4, 4) float)
        ``(name, mesh, transform)``: unique non-empty names, meshes in mm in the
        part's frame, homogeneous transforms part frame -> assembly frame.
    file_type : {"glb", "3mf"} or AssemblyFormat

    Returns
    -------
    bytes
        Deterministic (see the module notes).

    Raises
    ------
    ExportFormatError
        For an unknown format, or 3MF without lxml and networkx installed.
    SolidInputError
        For duplicate names or a bad transform.
    """
    try:
        kind = AssemblyFormat(str(getattr(file_type, "value", file_type)).lower())
    except ValueError:
        raise ExportFormatError(f"unknown assembly format {file_type!r}; "
                                f"choose one of {[f.value for f in AssemblyFormat]}") from None
    if kind is AssemblyFormat.THREE_MF:
        writer = _three_mf_writer()  # before building anything: fail fast
        return _deterministic_3mf(writer(_scene(parts)))
    from trimesh.exchange.gltf import export_glb

    return export_glb(_scene(parts))


def load_volume(data: bytes, file_type: str) -> float:
    """Total volume (mm^3) of an exported file, read back with trimesh.

    Each geometry's volume is counted once per node that places it, scaled by
    the determinant of the node's transform (1 for a rigid placement).

    Parameters
    ----------
    data : bytes
    file_type : str
        ``"stl"``, ``"glb"``, ``"3mf"``, ... (what trimesh reads).

    Returns
    -------
    float
    """
    import trimesh

    scene = trimesh.load_scene(io.BytesIO(bytes(data)), file_type=file_type, process=False)
    total = 0.0
    for node in scene.graph.nodes_geometry:
        transform, geometry_name = scene.graph[node]
        total += scene.geometry[geometry_name].volume * float(np.linalg.det(transform[:3, :3]))
    return total


def write_stl(path, mesh) -> Path:
    """Write a part's binary STL atomically; returns the path."""
    return write_bytes_atomic(path, stl_bytes(mesh))


def write_assembly(path, parts, file_type: str | AssemblyFormat | None = None) -> Path:
    """Write an assembly atomically, the format from ``file_type`` or the path's suffix.

    Parameters
    ----------
    path : str or path-like
    parts : sequence of (str, trimesh.Trimesh, (4, 4) float)
    file_type : {"glb", "3mf"}, optional
        Defaults to the suffix of ``path``.

    Returns
    -------
    Path
    """
    path = Path(path)
    return write_bytes_atomic(path, assembly_bytes(parts, file_type or path.suffix.lstrip(".")))


def write_solids(outcome, staging) -> list:
    """Write ``solids/<part>.stl`` and ``solids/assembly.<glb|3mf>``; return the relative paths.

    ``outcome`` is a :class:`cadgen.solids.outcome.SolidsOutcome`. One binary STL per
    distinct part in its own frame (a part both planting arms use is written once), and
    the assembly with every instance placed at the outcome's carrier angle.
    """
    folder = staging / "solids"
    folder.mkdir()
    written = []
    for part in outcome.assembly.parts:
        (folder / f"{part.name}.stl").write_bytes(stl_bytes(part.mesh))
        written.append(f"solids/{part.name}.stl")
    placed = [(name, part.mesh, pose) for name, part, pose
              in outcome.assembly.placements(outcome.carrier_angle)]
    (folder / f"assembly.{outcome.file_type}").write_bytes(
        assembly_bytes(placed, outcome.file_type))
    written.append(f"solids/assembly.{outcome.file_type}")
    return written
