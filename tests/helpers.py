"""Small helpers shared by tests: edited copies of the reference parameter file, an FCL model."""

import re
from pathlib import Path

REFERENCE = Path(__file__).resolve().parents[1] / "params" / "xin2024-planter.toml"


def reference_text() -> str:
    return REFERENCE.read_text(encoding="utf-8")


def edited(**changes) -> str:
    """The reference file with ``key = value`` lines replaced (key names are unique in it)."""
    text = reference_text()
    for key, value in changes.items():
        text, count = re.subn(rf"(?m)^{re.escape(key)}\s*=\s*[^#\n]*", f"{key} = {value} ", text)
        assert count == 1, f"key {key!r} not found exactly once in the reference file"
    return text


def with_keys(text: str, table: str, **keys) -> str:
    """``text`` with ``key = value`` set in ``[table]``: a key already there is replaced, a
    missing one added under the header, a missing table appended (values are TOML text)."""
    header = re.search(rf"(?m)^\[{re.escape(table)}\][^\n]*\n", text)
    if header is None:
        return text + f"\n[{table}]\n" + "".join(f"{k} = {v}\n" for k, v in keys.items())
    start = header.end()
    following = re.search(r"(?m)^\[", text[start:])
    end = start + following.start() if following else len(text)
    body = text[start:end]
    for key, value in keys.items():
        body, count = re.subn(rf"(?m)^{re.escape(key)}\s*=\s*[^#\n]*", f"{key} = {value} ", body)
        if not count:
            body = f"{key} = {value}\n" + body
    return text[:start] + body + text[end:]


def fcl_bvh(mesh):
    """A python-fcl BVH model of a trimesh mesh (the scene builds its own; tests compare)."""
    import fcl
    import numpy as np

    model = fcl.BVHModel()
    model.beginModel(len(mesh.faces), len(mesh.vertices))
    model.addSubModel(np.asarray(mesh.vertices, dtype=np.float64),
                      np.asarray(mesh.faces, dtype=np.int32))
    model.endModel()
    return model


def gears_in_their_housings(assembly, housings, phi: float):
    """``(part, housing name, housing, 4x4 pose in the housing's body)`` of every gear of a
    planting assembly at carrier angle ``phi``: its housing is the one whose cavity holds its
    face (the central shaft's and the sleeve's gears turn in the frame though they ride on
    carrier 1's body), found from the world placements, not from the parts' bodies."""
    import numpy as np

    bodies = {"gearbox1": "carrier1", "gearbox2": "gearbox2", "frame": "frame"}
    boxes = dict(zip(("gearbox1", "gearbox2", "frame"), housings))
    world = {name: pose for name, _, pose in assembly.placements(phi)}
    for part in assembly.parts:
        if part.kind != "gear":
            continue
        first = part.instances[0] if part.instances else (part.name, part.body, 0.0)
        pose = world[first[0]]
        middle = pose[2, 3] + float(part.mesh.bounds[:, 2].mean())
        name = next(n for n, h in boxes.items()
                    if h.z_cavity_bottom <= middle <= h.z_cavity_bottom + h.cavity_height)
        yield part, name, boxes[name], np.linalg.solve(
            assembly.body_pose(bodies[name], phi + first[2]), pose)
