"""Export of parts (binary STL) and assemblies (GLB, 3MF) as deterministic bytes.

The same meshes give the same bytes, so outputs can be compared by hash and
rebuilt without churn:

STL
    trimesh writes an all-zero 80-byte header (no name, no date) followed by the
    face count and float32 normals and vertices: deterministic as it stands. A
    build writes each part in its printing pose (:meth:`SolidsOutcome.printing_mesh
    <cadgen.solids.outcome.SolidsOutcome.printing_mesh>`), in mm.
GLB
    trimesh's exporter, given: metres, glTF's unit (the millimetres are scaled,
    vertices and node translations both, so every viewer agrees without a root
    scale); vertex normals split where faces meet at more than
    :data:`CREASE_ANGLE_DEG` (``trimesh.graph.smooth_shade``: flat faces stay flat,
    tessellated curves shade smooth); one named node per placed part with its rigid
    transform (the bought solids' nodes named ``bought/<item>-<n>``, e.g.
    ``bought/bearing-6202-2Z-1``); one geometry per distinct mesh (a part both arms use,
    every screw of one size, is stored once); one material per part kind
    (:data:`PART_MATERIALS`: base colour, the bought items all ``"bought"``; housing
    covers and the soil translucent with ``alphaMode`` BLEND, so the gears and shafts
    show through the cover while the base stays solid; see :func:`material_key`).
    Deterministic as trimesh writes it.
3MF
    Needs ``lxml`` and ``networkx`` (trimesh's soft dependencies). trimesh fixes
    the zip timestamps (1980-01-01) but gives every object, item and the build a
    random ``p:UUID`` (``uuid.uuid4``); those are replaced here, in order of
    appearance, by UUIDs derived from the model's content, and the zip is written
    again with the same entries, order, compression and timestamps. 3MF declares
    its unit (``unit="millimeter"`` on the model), so it stays in mm.

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
    "solids_files",
    "AssemblyFormat",
    "GLTF_METRES_PER_MM",
    "CREASE_ANGLE_DEG",
    "PART_MATERIALS",
    "material_key",
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

#: glTF's unit is the metre (glTF 2.0, "Coordinate System and Units"); parts are in mm.
GLTF_METRES_PER_MM = 1e-3
#: Faces meeting at more than this angle (deg) get separate vertex normals (a sharp edge).
CREASE_ANGLE_DEG = 30.0
#: Part kinds bought, not made (the case's chain sprocket): placed in the assembly (GLB) as
#: their envelope, listed in the bill from the drivetrain, never written as a file to make.
BOUGHT_KINDS = frozenset({"sprocket"})
#: A material per part kind: sRGB colour, opacity (below 1: alphaMode BLEND), metalness.
#: Housing covers and the soil are see-through, so the gears inside them show; a housing's
#: base is opaque (one looks into it through the cover). ``"housing-cover"`` is not a part
#: kind but the material of a housing part named ``...-cover`` (:func:`material_key`).
PART_MATERIALS = {
    "gear": (0x7F93AA, 1.0, 0.35),
    "housing": (0xAAB4C0, 1.0, 0.1),
    "housing-cover": (0xC4CCD6, 0.35, 0.1),
    "shaft": (0x6E747C, 1.0, 0.8),     # turned steel: grey, metallic
    "cam": (0x6D8F3C, 1.0, 0.1),
    "planter": (0xE08A2C, 1.0, 0.1),
    "blade": (0xC8432B, 1.0, 0.2),
    "rocker": (0x3C7FB0, 1.0, 0.1),
    "needle": (0x3A3F47, 1.0, 0.3),
    "lever": (0x2F6FA8, 1.0, 0.5),      # the duckbill's lever, push rod and links: steel
    "push-rod": (0x6E747C, 1.0, 0.8),
    "link": (0x4D7FB0, 1.0, 0.5),
    "spacer": (0xA7ADB5, 1.0, 0.7),     # the turned spacers between the parts on a shaft
    "ground": (0x9B7653, 0.35, 0.0),
    "sprocket": (0x4A4F57, 1.0, 0.6),   # a bought steel chain wheel (its envelope)
    # the bought items (bearings, keys, screws, nuts, washers, dowels): bright steel, lighter
    # and more metallic than the turned shafts, so a fitter tells what is bought at a glance
    "bought": (0xC9CED4, 1.0, 0.95),
    "part": (0x8C8C8C, 1.0, 0.1),   # a part of no known kind
}


class AssemblyFormat(str, Enum):
    """Assembly file formats (a closed choice)."""

    GLB = "glb"
    THREE_MF = "3mf"


def stl_bytes(mesh) -> bytes:
    """Binary STL of a mesh (float32 coordinates, zero header), deterministic.

    STL stores float32: two vertices of a boolean's sliver (a drilled hole meeting a curved
    wall) closer than float32 resolves become one, and the sliver's triangle then has two
    equal corners and an edge used three times: a reader that welds vertices (a slicer,
    admesh) sees the solid open. The vertices are rounded to float32 and welded first and the
    triangles collapsed by it dropped, so the file is as closed as the solid.

    Parameters
    ----------
    mesh : trimesh.Trimesh

    Returns
    -------
    bytes
    """
    from trimesh.exchange.stl import export_stl

    return export_stl(_float32_welded(mesh))


def _float32_welded(mesh):
    """``mesh`` with its vertices rounded to float32 and welded, and the triangles that
    collapsed (two equal corners) dropped."""
    import trimesh

    vertices, inverse = np.unique(np.asarray(mesh.vertices, dtype=np.float32), axis=0,
                                  return_inverse=True)
    faces = inverse.reshape(-1)[np.asarray(mesh.faces)]
    whole = ((faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2])
             & (faces[:, 0] != faces[:, 2]))
    return trimesh.Trimesh(vertices.astype(np.float64), faces[whole], process=False)


def _clean_copy(mesh, name: str):
    import trimesh

    # Fresh geometry for trimesh's 3MF writer: only the name travels as metadata, and
    # no cached visuals of the caller's mesh (or a loaded file's path) leak into the file.
    return trimesh.Trimesh(vertices=np.asarray(mesh.vertices, dtype=np.float64),
                           faces=np.asarray(mesh.faces, dtype=np.int64),
                           process=False, metadata={"name": name})


def _checked(parts) -> list:
    """``[(name, mesh, transform, kind)]`` of ``(name, mesh, transform[, kind])`` parts, checked."""
    checked, seen = [], set()
    for index, part in enumerate(parts):
        try:
            name, mesh, transform, *rest = part
            if len(rest) > 1:
                raise ValueError
        except (TypeError, ValueError):
            raise SolidInputError("parts", f"part {index} must be (name, mesh, 4x4 transform[, kind]), "
                                           f"not {part!r}") from None
        name = str(name)
        if not name or name in seen:
            raise SolidInputError("parts", f"part names must be unique and non-empty; part {index} is {name!r}")
        seen.add(name)
        transform = np.asarray(transform, dtype=np.float64)
        if transform.shape != (4, 4) or not np.isfinite(transform).all() \
                or not np.array_equal(transform[3], [0.0, 0.0, 0.0, 1.0]):
            raise SolidInputError("parts", f"part {name!r} needs a finite 4x4 homogeneous transform "
                                           f"(last row 0 0 0 1), not {transform.tolist()}")
        kind = str(rest[0]) if rest and rest[0] is not None else "part"
        checked.append((name, mesh, transform, kind))
    if not checked:
        raise SolidInputError("parts", "an assembly needs at least one part")
    return checked


def _scene(parts):
    import trimesh

    scene = trimesh.Scene()
    for name, mesh, transform, _ in _checked(parts):
        scene.add_geometry(_clean_copy(mesh, name), node_name=name, geom_name=name, transform=transform)
    return scene


def _shaded(mesh, crease_deg: float = CREASE_ANGLE_DEG):
    """Vertices split at sharp edges, with vertex normals: (positions (n, 3), normals (n, 3), faces (m, 3)).

    Each corner's normal is the corner-angle-weighted mean of the normals of the
    faces round its vertex that lie within ``crease_deg`` of its own face; corners
    of a vertex with equal normals share one vertex. Unit length; a corner whose
    faces cancel (degenerate) takes its face's normal, or +z.
    """
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    faces = np.asarray(mesh.faces, dtype=np.int64)
    triangles = vertices[faces]
    cross = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    length = np.linalg.norm(cross, axis=1)
    face_normals = cross / np.where(length > 0, length, 1.0)[:, None]
    edges = np.roll(triangles, -1, axis=1) - triangles            # corner k -> k + 1
    before = -np.roll(edges, 1, axis=1)                            # corner k -> k - 1
    norms = np.linalg.norm(edges, axis=2) * np.linalg.norm(before, axis=2)
    cosines = np.einsum("fkc,fkc->fk", edges, before) / np.where(norms > 0, norms, 1.0)
    corner_angles = np.arccos(np.clip(cosines, -1.0, 1.0)).ravel()
    corner_vertex = faces.ravel()
    corner_normals = np.repeat(face_normals, 3, axis=0)            # each corner's face's
    keys, key_of = _corner_keys(corner_vertex, corner_normals)
    summed = _smoothed_sums(corner_vertex, corner_normals, corner_angles, keys,
                            np.cos(np.radians(crease_deg)))
    size = np.linalg.norm(summed, axis=1)
    fallback = corner_normals[keys]
    fallback[np.linalg.norm(fallback, axis=1) == 0] = (0.0, 0.0, 1.0)
    normals = np.where((size > 1e-12)[:, None], summed / np.where(size > 0, size, 1.0)[:, None], fallback)
    # one vertex per distinct (vertex, normal), sorted by vertex then normal (np.unique's
    # row order, by a lexsort: np.unique(axis=0) sorts rows as structured bytes, slowly);
    # of equal normals the one of the lowest corner is kept (a zero's sign may differ)
    key_vertex = corner_vertex[keys]
    order = np.lexsort((keys, normals[:, 2], normals[:, 1], normals[:, 0], key_vertex))
    keyed_vertex, keyed_normal = key_vertex[order], normals[order]
    starts = np.r_[True, (keyed_vertex[1:] != keyed_vertex[:-1])
                   | np.any(keyed_normal[1:] != keyed_normal[:-1], axis=1)]
    inverse = np.empty(len(order), dtype=np.int64)
    inverse[order] = np.cumsum(starts) - 1
    return vertices[keyed_vertex[starts]], keyed_normal[starts], inverse[key_of].reshape(-1, 3)


def _corner_keys(corner_vertex, corner_normals):
    """Corners grouped by (vertex, face normal's bits): ``(keys, key_of)``, the lowest corner of
    each group (groups sorted by vertex) and each corner's group. The corners of one group see
    the same faces within the crease angle, so they get the same smoothed normal: it is
    summed once per group, not once per corner (half the pairs on these meshes)."""
    faces_bits = corner_normals[::3].view(np.int64)          # a face's corners share its normal
    by_bits = np.lexsort(faces_bits.T[::-1])
    new_bits = np.r_[True, np.any(faces_bits[by_bits][1:] != faces_bits[by_bits][:-1], axis=1)]
    normal_id = np.empty(len(by_bits), dtype=np.int64)
    normal_id[by_bits] = np.cumsum(new_bits) - 1
    key = corner_vertex * int(new_bits.sum()) + np.repeat(normal_id, 3)
    by_key = np.argsort(key, kind="stable")
    grouped = key[by_key]
    new = np.r_[True, grouped[1:] != grouped[:-1]]
    key_of = np.empty(len(by_key), dtype=np.int64)
    key_of[by_key] = np.cumsum(new) - 1
    return by_key[new], key_of


def _smoothed_sums(corner_vertex, corner_normals, corner_angles, keys, cos_crease):
    """(k, 3) per group of :func:`_corner_keys`: the sum of ``angle * normal`` over the corners
    of its vertex whose face normal is within the crease of the group's (dot >= ``cos_crease``),
    added in corner order (bincount adds in input order, as np.add.at does: the same sums, bit
    for bit, as pairing every corner with every corner of its vertex)."""
    order = np.argsort(corner_vertex, kind="stable")        # each vertex's corners, in order
    sorted_vertex = corner_vertex[order]
    runs = np.flatnonzero(np.r_[True, sorted_vertex[1:] != sorted_vertex[:-1]])
    counts = np.diff(np.r_[runs, len(order)])
    key_vertex = corner_vertex[keys]
    key_run = np.cumsum(np.r_[True, key_vertex[1:] != key_vertex[:-1]]) - 1   # keys by vertex
    repeat = counts[key_run]
    # pair p: key first[p] with the corner at sorted position other[p] (its vertex's run, in
    # order); both sides read in sorted order, so the gathers walk memory forwards
    first = np.repeat(np.arange(len(keys)), repeat)
    other = np.arange(len(first)) + np.repeat(runs[key_run] - (np.cumsum(repeat) - repeat), repeat)
    sorted_normals = corner_normals[order]
    near = np.einsum("ij,ij->i", np.repeat(corner_normals[keys], repeat, axis=0),
                     sorted_normals[other]) >= cos_crease
    weighted = (corner_angles[order, None] * sorted_normals)[other[near]]
    return np.column_stack([np.bincount(first[near], weights=weighted[:, axis], minlength=len(keys))
                            for axis in range(3)])


def _linear(srgb: int) -> list:
    """An sRGB colour (0xRRGGBB) as glTF's linear base colour components."""
    channels = np.array([(srgb >> 16) & 255, (srgb >> 8) & 255, srgb & 255]) / 255.0
    linear = np.where(channels <= 0.04045, channels / 12.92, ((channels + 0.055) / 1.055) ** 2.4)
    return [round(float(c), 6) for c in linear]


def material_key(name: str, kind: str) -> str:
    """The :data:`PART_MATERIALS` key of a placed part: its kind, except a housing's cover.

    A split housing's base and cover are both of kind ``"housing"`` (one made part
    family: same material, same process); only the cover is drawn see-through, told
    by its name (``gearbox2-cover``, ``gearbox2-cover-arm1``, ``gear-case-cover``).
    """
    if kind == "housing" and re.search(r"-cover(-|$)", name):
        return "housing-cover"
    return kind


def _material(kind: str):
    """The glTF material of a part kind (:data:`PART_MATERIALS`), for trimesh's exporter."""
    from trimesh.visual.material import PBRMaterial

    colour, opacity, metalness = PART_MATERIALS.get(kind, PART_MATERIALS["part"])
    rgba = [round(255 * c) for c in _linear(colour)] + [round(255 * opacity)]
    see_through = opacity < 1.0   # blended, and both sides drawn so the inner walls show
    return PBRMaterial(name=kind, baseColorFactor=rgba, metallicFactor=metalness,
                       roughnessFactor=0.6, alphaMode="BLEND" if see_through else None,
                       doubleSided=see_through)


def _glb(parts, extras=None) -> bytes:
    """Binary glTF 2.0 of checked parts, in metres (see the module notes), by trimesh; each
    node's ``extras`` from ``extras`` (``{part name: dict}``), if any."""
    import trimesh
    from trimesh.exchange.gltf import export_glb

    scene = trimesh.Scene()
    shared = {}   # one geometry per distinct (kind, mesh): a part both arms use, stored once
    for name, mesh, transform, kind in parts:
        if len(mesh.faces) == 0:
            raise SolidInputError("parts", f"part {name!r} has no faces")
        placed = np.array(transform, dtype=float)
        placed[:3, 3] *= GLTF_METRES_PER_MM
        material = material_key(name, kind)
        node_extras = (extras or {}).get(name) or None
        key = hashlib.sha256(material.encode() + b"\0" + np.ascontiguousarray(mesh.vertices).tobytes()
                             + np.ascontiguousarray(mesh.faces).tobytes()).digest()
        if key in shared:
            scene.graph.update(frame_to=name, frame_from=scene.graph.base_frame,
                               geometry=shared[key], matrix=placed, metadata=node_extras)
            continue
        # vertices split where faces meet at more than the crease angle, each corner's normal
        # from its own smooth neighbourhood only (trimesh's smoothing groups let a normal
        # lean up to 80 deg from its face at a cone's tip)
        positions, normals, triangles = _shaded(mesh)
        shaded = trimesh.Trimesh(positions * GLTF_METRES_PER_MM, triangles,
                                 vertex_normals=normals, process=False)
        shaded.visual = trimesh.visual.TextureVisuals(material=_material(material))
        scene.add_geometry(shaded, node_name=name, geom_name=name, transform=placed,
                           metadata=node_extras)
        shared[key] = name
    return export_glb(scene, include_normals=True)


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


def assembly_bytes(parts, file_type: str | AssemblyFormat = AssemblyFormat.GLB, *,
                   extras=None) -> bytes:
    """An assembly file: one named node per part, placed by its transform.

    Parameters
    ----------
    parts : sequence of (str, trimesh.Trimesh, (4, 4) float[, str])
        ``(name, mesh, transform[, kind])``: unique non-empty names, meshes in mm in
        the part's frame, homogeneous transforms part frame -> assembly frame (mm),
        and the part's kind (a key of :data:`PART_MATERIALS`; its material in a GLB).
    file_type : {"glb", "3mf"} or AssemblyFormat
    extras : dict, optional
        ``{part name: JSON-able dict}``: each GLB node's ``extras`` (the viewers read
        ``"explode"``, :func:`cadgen.solids.explode.explode_offsets` in metres); not in 3MF.

    Returns
    -------
    bytes
        Deterministic (see the module notes). GLB in metres, 3MF in millimetres.

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
    return _glb(_checked(parts), extras)


def load_volume(data: bytes, file_type: str) -> float:
    """Total volume (mm^3) of an exported file, read back with trimesh.

    Each geometry's volume is counted once per node that places it, scaled by
    the determinant of the node's transform (1 for a rigid placement). glTF is
    in metres (its unit by definition): its volumes are converted to mm^3.

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
    if str(file_type).lower() in ("glb", "gltf"):
        total /= GLTF_METRES_PER_MM ** 3
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
    distinct made part in its printing pose (largest flat face down on z = 0, centred on
    x = y = 0; a part both planting arms use is written once), and the assembly with
    every instance placed, from its part's own frame, at the outcome's carrier angle: the
    made parts and the bought solids (``Assembly.bought``, material ``"bought"``). A bought
    item has no STL: it is bought, not made, and the assembly file is the one that shows it.
    """
    folder = staging / "solids"
    folder.mkdir()
    written = []
    for name, data in solids_files(outcome):
        (folder / name).write_bytes(data)
        written.append(f"solids/{name}")
    return written


def _bought_offsets(assembly, offsets: dict) -> dict:
    """Each bought solid's explode offset: its host copy's (a screw comes off with its flange)."""
    hosts = {part.name: part for part in assembly.parts}
    out = {}
    for item in getattr(assembly, "bought", ()):
        host = hosts.get(item.host)
        if host is None:
            continue
        copies = host.instances or ((host.name, host.body, 0.0),)
        for (name, _, _), (host_name, _, _) in zip(item.instances, copies):
            if host_name in offsets:
                out[name] = offsets[host_name]
    return out


def solids_files(outcome):
    """``(file name, bytes)`` of each file :func:`write_solids` writes, each made once per
    outcome (:meth:`~cadgen.solids.outcome.SolidsOutcome.once`), as it is asked for."""
    for part in outcome.assembly.parts:
        if part.kind in BOUGHT_KINDS:   # a bought part: in the assembly, not a file to make
            continue
        yield f"{part.name}.stl", outcome.once(("stl", part.name),
                                               lambda: stl_bytes(outcome.printing_mesh(part)))

    def assembly():
        bought = {id(part) for part in getattr(outcome.assembly, "bought", ())}
        every = (outcome.assembly.placements(outcome.carrier_angle, bought=True) if bought
                 else outcome.assembly.placements(outcome.carrier_angle))
        placed = [(name, part.mesh, pose, "bought" if id(part) in bought else part.kind)
                  for name, part, pose in every]
        extras = None
        if outcome.file_type == AssemblyFormat.GLB.value:   # the views' explode slider
            from cadgen.solids.explode import explode_offsets

            offsets = explode_offsets(outcome.assembly, outcome.carrier_angle)
            offsets.update(_bought_offsets(outcome.assembly, offsets))
            extras = {name: {"explode": [round(float(v) * GLTF_METRES_PER_MM, 7)
                                         for v in offset]}
                      for name, offset in offsets.items() if np.any(offset)}
        return assembly_bytes(placed, outcome.file_type, extras=extras)

    yield f"assembly.{outcome.file_type}", outcome.once("assembly", assembly)
