"""The exploded view's offsets (issue 29): every placed part has one, along the way it goes on."""

import re

import numpy as np
import pytest

from cadgen.assembly.sequence import assembly_sequence
from cadgen.solids.explode import RIDING, GAP_FRACTION, explode_offsets

#: The two bundled designs, and the paper's printed (its gearbox 1 in spliced segments).
DESIGNS = ["xin2024-planter", "kernel-b", "xin2024-printed"]


def _parts_of(name):
    """The parts stage's outcome of a design (gears cut: the build's gear cache)."""
    import cadgen.pipeline.build as build_module
    from cadgen.params import load_params, validate_text
    from tests.helpers import reference_text, with_keys

    made = {}
    original = build_module.STAGE_FUNCTIONS["parts"]

    def keep(run):
        made["parts"] = original(run)
        return made["parts"]

    params = (validate_text(with_keys(reference_text(), "manufacturing", process='"printed"'))
              if name == "xin2024-printed" else load_params(f"params/{name}.toml"))
    stages = ["kinematics", "metrics", "drivetrain", "teeth", "parts"]
    if name.startswith("xin"):
        stages.insert(2, "cam")
    run = build_module._Build(params, stages, None)
    run.effects, run.case = ["solids"], "field"
    run.run(dict(build_module.STAGE_FUNCTIONS, parts=keep))
    return made["parts"]


@pytest.fixture(scope="module", params=DESIGNS, ids=["planting", "pricking", "printed"])
def exploded(request):
    outcome = _parts_of(request.param)
    assembly, phi = outcome.assembly, outcome.carrier_angle
    boxes, kinds = {}, {}
    for name, part, pose in assembly.placements(phi):
        vertices = part.mesh.vertices @ pose[:3, :3].T + pose[:3, 3]
        boxes[name] = np.array([vertices.min(axis=0), vertices.max(axis=0)])
        kinds[name] = part.kind
    offsets = explode_offsets(assembly, phi)
    solid = np.vstack([b for n, b in boxes.items() if kinds[n] != "ground"])
    gap = GAP_FRACTION * float(np.ptp(solid, axis=0).max())
    return request.param, assembly, boxes, kinds, offsets, gap


def _clash(a, b) -> bool:
    return bool(np.all(np.minimum(a[1], b[1]) - np.maximum(a[0], b[0]) > 1e-6))


def _steps(assembly, kinds, riding=False):
    """The assembly order's steps between placed parts: the gears onto their shafts (``riding``)
    or the others."""
    return [s for s in assembly_sequence(assembly.model) if s["part"] in kinds
            and s["onto"] in kinds
            and ({kinds[s["part"]], kinds[s["onto"]]} in RIDING) == riding]


def _placing_steps(steps):
    """The steps that put a part in, in the order they can be taken from the first one's base:
    a step joining two parts already in (a part held by a second joint, as the push rod's slot
    on the lever) is not one, its part came off with the step that put it in."""
    done, out, pending = {steps[0]["onto"]}, [], list(steps)
    while pending:
        step = next((s for s in pending if (s["part"] in done) != (s["onto"] in done)), None)
        if step is None:
            break
        out.append(step)
        done.update((step["part"], step["onto"]))
        pending = [s for s in pending if not (s["part"] in done and s["onto"] in done)]
    return out


def test_every_placed_part_has_an_offset_and_the_soil_none(exploded):
    _, _, boxes, kinds, offsets, _ = exploded
    assert set(offsets) == set(boxes)
    for name, offset in offsets.items():
        assert offset.shape == (3,) and np.isfinite(offset).all(), name
        if kinds[name] == "ground":
            assert not offset.any()
    moved = [n for n, o in offsets.items() if np.any(o)]
    # all but the part the machine stands on, and a gear left in place on its shaft
    assert len(moved) >= len([n for n in boxes if kinds[n] not in ("ground", "gear")]) - 1


def test_each_part_comes_off_what_it_goes_onto_along_the_shafts(exploded):
    """Relative to the part it goes onto, a part moves along z (the shaft axes) by a gap at least;
    only an arm's housing also moves in the plane, out from the housing that carries it; a shaft
    leaves its base towards the base's cover; a printed segment stays with its neighbour."""
    design, assembly, boxes, kinds, offsets, gap = exploded
    arms = 0
    for step in _placing_steps(_steps(assembly, kinds)):
        part, onto = step["part"], step["onto"]
        relative = offsets[part] - offsets[onto]
        if "splice" in step["how"]:
            assert not relative.any(), step
            continue
        assert abs(relative[2]) >= gap - 1e-9, step
        # an arm's base on the shaft of the housing that carries it (the one step leaving the arm)
        arm = (re.search(r"-base-arm\d$", part) or re.search(r"-base-arm\d$", onto)) and not (
            re.search(r"-arm\d$", part) and re.search(r"-arm\d$", onto))
        if arm:
            arms += 1
            base = part if re.search(r"-base-arm\d$", part) else onto
            outward = boxes[base][:, :2].mean(axis=0)   # carrier 1 turns about O, at the origin
            sideways = relative[:2] * (1 if base == part else -1)
            across = sideways[0] * outward[1] - sideways[1] * outward[0]
            assert np.dot(sideways, outward) > 0 and abs(across) < 1e-6 * (
                np.linalg.norm(sideways) * np.linalg.norm(outward)), step
        else:
            assert np.allclose(relative[:2], 0.0), step
        if (kinds[part] == "shaft" and step["joint"] == "revolute"   # on bearings in the base
                and re.search(r"-base(-\d+)?(-(arm|side)\d)?$", onto)):
            cover = re.sub(r"-base", "-cover", onto, count=1)
            side = np.sign(boxes[cover][:, 2].mean() - boxes[onto][:, 2].mean())
            assert np.sign(relative[2]) == side, step
    assert arms == (2 if design.startswith("xin") else 0)   # each arm's base on its shaft C


def test_exploded_parts_clear_what_they_go_onto_and_clash_with_nothing_new(exploded):
    """Fully exploded, each part is clear of what it goes onto (a gear stays on its shaft), and no
    two parts meet that did not meet assembled (a shaft through a gear's bore meets it either way)."""
    _, assembly, boxes, kinds, offsets, _ = exploded
    apart = {n: boxes[n] + offsets[n] for n in boxes if kinds[n] != "ground"}
    for step in _steps(assembly, kinds):
        if "splice" not in step["how"]:
            assert not _clash(apart[step["part"]], apart[step["onto"]]), step
    names = sorted(apart)
    new = [(a, b) for i, a in enumerate(names) for b in names[i + 1:]
           if _clash(apart[a], apart[b]) and not _clash(boxes[a], boxes[b])]
    assert not new


def test_the_order_along_the_shafts_is_the_assembly_order(exploded):
    """What goes on later lies further out: a cover beyond every shaft of its base, and each
    later step's part beyond the earlier parts it overlaps seen along z."""
    _, assembly, boxes, kinds, offsets, _ = exploded
    apart = {n: boxes[n] + offsets[n] for n in boxes}
    for step in _steps(assembly, kinds):
        if not re.search(r"-cover(-\d+)?(-arm\d)?$", step["part"]) or "splice" in step["how"]:
            continue
        base = step["onto"]
        up = np.sign(boxes[step["part"]][:, 2].mean() - boxes[base][:, 2].mean())
        housing = re.sub(r"-base(-\d+)?", "-base", base)   # a printed half's segments: one
        shafts = [s["part"] for s in _steps(assembly, kinds) if kinds[s["part"]] == "shaft"
                  and re.sub(r"-base(-\d+)?", "-base", s["onto"]) == housing]
        assert shafts
        for shaft in shafts:
            if up > 0:
                assert apart[step["part"]][0, 2] >= apart[shaft][1, 2], (step, shaft)
            else:
                assert apart[step["part"]][1, 2] <= apart[shaft][0, 2], (step, shaft)


def test_meshing_gears_stay_level_and_the_layers_spread(exploded):
    design, assembly, boxes, kinds, offsets, gap = exploded
    meshes = [j for j in assembly.model.joints if j.kind == "gear"
              and j.a in offsets and j.b in offsets]
    assert meshes
    shaft_of = {}
    for step in _steps(assembly, kinds, riding=True):
        gear, shaft = ((step["part"], step["onto"]) if kinds[step["part"]] == "gear"
                       else (step["onto"], step["part"]))
        shaft_of[gear] = shaft
    base_of = {s["part"]: s["onto"] for s in _steps(assembly, kinds) if kinds[s["part"]] == "shaft"}
    layers = {}
    for joint in meshes:   # two gears on shafts put into one base, level: one layer, one lift
        bases = [base_of.get(shaft_of.get(gear)) for gear in (joint.a, joint.b)]
        same = bases[0] is not None and bases[0] == bases[1]
        level = abs(boxes[joint.a][:, 2].mean() - boxes[joint.b][:, 2].mean()) < 0.5
        if same and level:   # their teeth stay in mesh
            assert offsets[joint.a] == pytest.approx(offsets[joint.b]), joint
            layers.setdefault(base_of[shaft_of[joint.a]], set()).add(
                round(float(offsets[joint.a][2] - offsets[shaft_of[joint.a]][2]), 6))
    assert layers
    for base, spread in layers.items():   # the layers of a base spread a gap apart
        steps = np.diff(sorted(spread))
        assert np.all(steps >= gap - 1e-6), (base, spread)


def test_the_glb_carries_the_offsets_in_its_nodes_and_the_page_copy_keeps_them(exploded):
    from cadgen.export.meshes import GLTF_METRES_PER_MM, assembly_bytes
    from cadgen.report.view_glb import lighter_glb, read_glb

    _, assembly, _, _, offsets, _ = exploded
    placed = [(name, part.mesh, pose, part.kind) for name, part, pose in assembly.placements(0.0)]
    extras = {name: {"explode": [float(v) * GLTF_METRES_PER_MM for v in offset]}
              for name, offset in offsets.items() if np.any(offset)}
    glb = assembly_bytes(placed, "glb", extras=extras)
    for data in (glb, lighter_glb(glb)):
        nodes = {n["name"]: n.get("extras", {}) for n in read_glb(data)[0]["nodes"]}
        assert {n: e["explode"] for n, e in nodes.items() if "explode" in e} == {
            n: e["explode"] for n, e in extras.items()}
    assert assembly_bytes(placed, "glb") != glb   # without extras: the file as it was


def test_the_bought_solids_come_off_with_the_part_they_sit_in(exploded):
    """A cover lifted off takes its bearings, dowels and flange screws with it; a shaft's keys
    and rings come off with the shaft: each bought solid's offset is its host copy's, and
    those in a moving host move (none is left floating where the assembly was)."""
    from cadgen.export.meshes import _bought_offsets

    _, assembly, _, _, offsets, _ = exploded
    bought = _bought_offsets(assembly, offsets)
    hosts = {part.name: part for part in assembly.parts}
    moved = 0
    for item in assembly.bought:
        copies = hosts[item.host].instances or ((item.host, None, None),)
        for (name, _, _), (host, _, _) in zip(item.instances, copies):
            np.testing.assert_array_equal(bought[name], offsets[host])
            moved += bool(np.any(offsets[host]))
            if "-cover" in host:   # a cover lifts off: what sits in it goes with it
                assert np.any(bought[name]), name
    assert moved > 0
