"""The worker forked beside the teeth (cadgen.pipeline.build): what it computes is what one
process computes, on every bundled example.

The worker sweeps a gearless assembly and draws the figures that show no gear while the
teeth are cut. That is only right where the swept parts do not depend on the gears: a
pricking gear case is drawn round the gears' outlines, so its sweep must wait for them (the
landed code once swept the larger gearless case and reported kernel-b's ground clearance as
40.84 mm instead of the written case's 62.61 mm). The reference here is the same build with
forking switched off: every stage in one process, in plan order, on the parts written.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import cadgen.pipeline.figures
from cadgen.params import load_params
from cadgen.pipeline.build import build

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "params").glob("*.toml"))
EFFECTS = ["metrics", "teeth", "solids", "arm_interference", "ground_clearance", "plots"]

pytestmark = pytest.mark.skipif(not cadgen.pipeline.figures._can_fork(),
                                reason="needs fork and a second core (the worker beside)")


def _files(folder: Path) -> dict:
    return {str(f.relative_to(folder)): f.read_bytes() for f in sorted(folder.rglob("*"))
            if f.is_file() and f.name != "report.json"}


def _without_timings(report: dict) -> dict:
    report = dict(report)
    report["stages"] = [(r["stage"], r["status"]) for r in report["stages"]]
    report.pop("gear_cache", None)   # the second build finds the first one's gears
    return report


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_a_build_with_the_worker_beside_equals_one_in_one_process(path, tmp_path):
    params = load_params(path)
    forked = build(params, tmp_path / "forked", effects=EFFECTS)
    assert any("second process" in r["message"] for r in forked.report["stages"])
    # a build told to keep to its process (a batch with a design on every core)
    alone = build(params, tmp_path / "alone", effects=EFFECTS, parallel=False)
    assert not any("second process" in r["message"] for r in alone.report["stages"])
    # the sweeps' minima, poses and certificates, every check: the same numbers
    assert _without_timings(forked.report) == _without_timings(alone.report)
    # every file (STLs, DXFs, every figure), byte for byte
    files = _files(forked.output_dir)
    assert any(name.startswith("plots/") for name in files)
    assert files == _files(alone.output_dir)


@pytest.mark.parametrize("effects", [None, ["teeth", "stl"]], ids=["every-effect", "solids-only"])
def test_the_building_process_takes_the_workers_meshes_of_the_gearless_parts(effects, tmp_path,
                                                                              monkeypatch):
    """The worker meshes the gearless parts for its sweeps and sends them back first: the
    building process (this one) must not mesh them again for the assembly view and the
    solids' files (a quarter of a second of the paper design's CPU, made twice before), even
    when the worker's sweeps are far from done (made slow here: the worker is forked from
    this process, so it runs the patched stage). A scene of solids without sweeps or figures
    meshes them beside the teeth too (it once left the second core idle and took longer than
    the scene with the sweeps), and writes the same files as one process."""
    import importlib
    import time

    import cadgen.pipeline.beside as beside
    import cadgen.pipeline.build

    extrude = importlib.import_module("cadgen.solids.extrude")  # the package's name is a function
    meshed_here, assemblies = [], []
    to_trimesh, take_meshes = extrude.to_trimesh, beside.take_meshes

    def counting(solid, name):
        meshed_here.append(name)     # in this process only: the worker's calls are its own
        return to_trimesh(solid, name)

    def taking(run, worker):
        assemblies.append(run.values["parts"].assembly)
        return take_meshes(run, worker)

    def slow(run, sweep=cadgen.pipeline.build.STAGE_FUNCTIONS["arm_interference"]):
        time.sleep(2.0)
        return sweep(run)

    monkeypatch.setattr(extrude, "to_trimesh", counting)
    monkeypatch.setattr(beside, "take_meshes", taking)
    monkeypatch.setitem(cadgen.pipeline.build.STAGE_FUNCTIONS, "arm_interference", slow)
    params = load_params(ROOT / "params" / "xin2024-planter.toml")
    # every effect: the STLs need every mesh too
    result = build(params, tmp_path / "forked", effects=effects)
    assert any("second process" in r["message"] for r in result.report["stages"]) \
        == (effects is None)
    kinds = beside.gearless_kinds(params.mechanism)
    parts = {p.name: p.kind for p in assemblies[0].parts}
    gearless = {name for name, kind in parts.items() if kind in kinds}
    assert gearless and len(gearless) < len(parts)     # both kinds are in the paper design
    assert not gearless & set(meshed_here)
    assert set(parts) - gearless <= set(meshed_here)   # the gears' parts are meshed here
    # every part has its mesh, and each its STL
    assert all(p._mesh is not None for p in assemblies[0].parts)
    assert {f.stem for f in (result.output_dir / "solids").glob("*.stl")} >= set(parts)
    if effects is not None:
        monkeypatch.setattr(cadgen.pipeline.figures, "_can_fork", lambda: False)
        alone = build(params, tmp_path / "alone", effects=effects)
        assert _files(result.output_dir) == _files(alone.output_dir)


def test_a_cutting_file_that_fails_ahead_is_said_by_the_writing_with_its_path(tmp_path,
                                                                              monkeypatch):
    """The building process makes the cam's file while the worker draws; a failure there is
    not kept: the writing makes it again and raises, naming the file in the staging folder,
    and no output folder is left (the build writes all or nothing)."""
    import cadgen.export.cam_dxf as cam_dxf
    from cadgen.export.dxf import DxfExportError

    asked = []

    def refused(*args, path, **kwargs):
        asked.append(str(path))
        raise DxfExportError(f"{path}: refused here")

    monkeypatch.setattr(cam_dxf, "cam_dxf_bytes", refused)
    params = load_params(ROOT / "params" / "xin2024-planter.toml")
    with pytest.raises(DxfExportError) as raised:
        build(params, tmp_path, cache=False)
    assert asked[0] == "cam.dxf"                        # made ahead, while the worker drew
    assert len(asked) == 2 and asked[1].endswith("/cam.dxf") and asked[1] != "cam.dxf"
    assert asked[1] in str(raised.value)                # the writing's own path, in the error
    assert not (tmp_path / params.name).exists()


@pytest.mark.parametrize("name", ["xin2024-planter", "kernel-b"])
def test_the_gearless_kinds_are_built_the_same_with_and_without_the_gears(name):
    """What GEARLESS_KINDS claims, checked part by part: the worker's meshes of these kinds are
    taken for the build's own. kernel-b's ground reaches past the largest gear disc, so it was
    longer without the gears, and a build of solids without sweeps wrote that one."""
    import numpy as np

    import cadgen.pipeline.build as pipeline
    from cadgen.pipeline.beside import gearless_kinds

    params = load_params(ROOT / "params" / f"{name}.toml")
    stages = ["kinematics", "metrics", "cam", "drivetrain", "teeth"]
    run = pipeline._Build(params, [s for s in stages if not (s == "cam" and
                                                              params.mechanism == "pricking")],
                          None)
    run.effects, run.case, run.cache = ["stl"], "field", False
    run.run(pipeline.STAGE_FUNCTIONS)
    assert all(r.status == "ok" for r in run.records)
    kinds = gearless_kinds(params.mechanism)
    made = {gears: {p.name: p for p in pipeline._parts(run, gears=gears).assembly.parts
                    if p.kind in kinds} for gears in (True, False)}
    assert made[True] and set(made[True]) == set(made[False])
    for part_name, part in made[True].items():
        other = made[False][part_name]
        assert np.array_equal(part.mesh.vertices, other.mesh.vertices), part_name
        assert np.array_equal(part.mesh.faces, other.mesh.faces), part_name


def test_parallel_takes_only_a_flag(tmp_path):
    with pytest.raises(TypeError, match="parallel must be True, False or None, not 'no'"):
        build(load_params(EXAMPLES[0]), tmp_path, effects=["metrics"], parallel="no")
    assert not any(tmp_path.iterdir())
