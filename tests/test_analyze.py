"""`run_analysis`: the files it writes, and nothing partial when it fails."""

import json

import pytest

from cadgen.pipeline.build import run_analysis
from cadgen.params import load_params
from tests.helpers import REFERENCE


@pytest.fixture(scope="module")
def params():
    return load_params(REFERENCE)


def test_writes_report_and_plots(params, tmp_path):
    result = run_analysis(params, output_root=tmp_path)
    folder = tmp_path / "xin2024-planter"
    plots = sorted(p.name for p in (folder / "plots").iterdir())
    assert [p for p in plots if not p.startswith("gears-")] == [
        "absolute_paths.png", "assembly.png", "attitude.png", "cam-contour.png", "cam-follower.png",
        "housing-frame.png", "housing-gearbox1.png", "housing-gearbox2.png", "pitch_curves.png",
        "relative_path.png", "tip_velocity.png"]
    # one picture per pair: gearbox 2's two, train 1's two sets of three, the drive's two
    assert len([p for p in plots if p.startswith("gears-")]) == 2 + 3 + 3 + 2
    dxf = sorted(p.name for p in (folder / "gears").iterdir())
    new_gears = ("sun-I", "idler-1-I", "idler-2-I", "planet-I", "input-gear-1",
                 "central-shaft-gear", "input-gear-2", "transmission-driven-gear")
    assert dxf == sorted(["central.dxf", "gear-D.dxf", "idler-1.dxf", "idler-2.dxf",
                          "intermediate.dxf", "planet-gear-E.dxf", "sun.dxf", "train-1-planet.dxf",
                          *(f"{gear}.dxf" for gear in new_gears)])
    assert (folder / "cam.dxf").is_file()
    assert sorted(p.name for p in (folder / "drawings").iterdir()) == ["cam.dxf", "train.dxf"]
    solids = sorted(p.name for p in (folder / "solids").iterdir())
    assert solids == sorted(["assembly.glb", "blade-left.stl", "blade-right.stl", "cam.stl",
                             "central.stl", "gear-D.stl", "gearbox1-base.stl",
                             "gearbox1-cover.stl", "gearbox2-base.stl", "gearbox2-cover.stl",
                             *(f"shaft-{axis}.stl" for axis in ("O", "A", "B", "C", "C2", "D", "E",
                                                                "S", "input")),
                             # side 2's C2: its central-gear keyseat half a turn from side 1's
                             "shaft-C2-arm2.stl",
                             "ground.stl", "idler-1.stl", "idler-2.stl", "intermediate.stl",
                             "planet-gear-E.stl", "planter-shell.stl", "sun.stl",
                             "train-1-planet.stl", "frame-base.stl", "frame-cover.stl",
                             *(f"{gear}.stl" for gear in new_gears),
                             # the duckbill linkage
                             "lever.stl", "push-rod.stl", "blade-link-left.stl",
                             "blade-link-right.stl",
                             # a spacer in each gap of 0.5 mm or more between the parts on a
                             # shaft inside a cavity (2 mm gaps; one long one under E's gear;
                             # S and C hold only their gear and bearing pair)
                             *(f"spacer-{axis}-{k}.stl" for axis, count in (
                                 ("O", 3), ("S", 1), ("input", 3), ("A", 3), ("B", 3),
                                 ("C2", 2), ("C", 1), ("D", 3), ("E", 2))
                               for k in range(1, count + 1))])
    report = json.loads((folder / "report.json").read_text())
    assert report["cam"]["cuttable"] and report["cam"]["problems"] == []
    assert all(row["gears_enclosed"] for row in report["solids"]["enclosure"])
    assert {p["file"] for p in report["solids"]["parts"]} <= {f"solids/{n}" for n in solids}
    assert report["derived"]["centre_distance_a_mm"] == pytest.approx(59.944, abs=1e-3)
    assert report["passed"] is True
    assert {m["key"] for m in report["metrics"]} >= {
        "trajectory_height", "hole_width", "hole_verticality", "angle_difference",
        "arm_distance", "ground_clearance", "module"}
    assert len([m for m in report["metrics"] if m["key"] == "hole_width"]) == 3
    assert report["input_sha256"] == result.report["input_sha256"]
    for png in (folder / "plots").iterdir():
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "all targets met" in result.summary_text()
    assert "0 interfering poses" in result.summary_text()
    assert report["gear_train"]["failures"] == []


def test_failure_leaves_previous_outputs_untouched(params, tmp_path, monkeypatch):
    run_analysis(params, output_root=tmp_path, plots=False, gears=False)
    before = (tmp_path / "xin2024-planter" / "report.json").read_bytes()

    import cadgen.pipeline.figures

    def broken(*args, **kwargs):
        raise RuntimeError("plotting failed")

    monkeypatch.setattr(cadgen.pipeline.figures, "build_figures", broken)
    with pytest.raises(RuntimeError):
        run_analysis(params, output_root=tmp_path, gears=False)
    assert (tmp_path / "xin2024-planter" / "report.json").read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["xin2024-planter"]


def test_same_input_same_hash(params):
    first = run_analysis(params, output_root=None, gears=False)
    second = run_analysis(params, output_root=None, gears=False)
    assert first.report["input_sha256"] == second.report["input_sha256"]
    assert first.report["metrics"] == second.report["metrics"]


def test_pricking_report_says_where_the_gears_are_concave(tmp_path):
    params = load_params(REFERENCE.parent / "kernel-a.toml")
    result = run_analysis(params, output_root=tmp_path)
    folder = tmp_path / "kernel-a"
    assert sorted(p.name for p in (folder / "plots").iterdir()) == [
        "assembly.png", "field_paths.png", "housing-gear-case.png", "loop.png", "pitch_curves.png",
        "ratio.png"]
    # kernel-a's gears are too concave for any cutter: said, not drawn
    assert {f["code"] for f in json.loads((folder / "report.json").read_text())
            ["gear_train"]["failures"]} == {"gear_not_cuttable"}
    assert "NOT CUT" in result.summary_text()
    report = json.loads((folder / "report.json").read_text())
    assert report["verified"] is True
    assert {f["code"] for f in report["findings"]} >= {"concave_pitch_curve"}
    assert [g["convex"] for g in report["gears"]["pitch_curves"]] == [False] * 4
    assert len(report["field"]["per_inclination"]) == 3
    text = result.summary_text()
    assert "concave" in text and "near Q" in text


def test_same_input_same_files(params, tmp_path):
    """Every written file is byte-identical, but report.json's stage timings."""
    for root in ("first", "second"):
        run_analysis(params, output_root=tmp_path / root, plots=False)
    first, second = tmp_path / "first" / "xin2024-planter", tmp_path / "second" / "xin2024-planter"
    files = sorted(p.relative_to(first) for p in first.rglob("*") if p.is_file())
    assert files == sorted(p.relative_to(second) for p in second.rglob("*") if p.is_file())
    assert {f.suffix for f in files} == {".csv", ".dxf", ".stl", ".glb", ".json"}
    for name in files:
        if name.name != "report.json":
            assert (first / name).read_bytes() == (second / name).read_bytes(), name

    def untimed(folder):   # the report without its stage timings and gear-cache hits
        report = json.loads((folder / "report.json").read_text())
        for stage in report["stages"]:
            stage.pop("seconds")
        report.pop("gear_cache")
        return report

    assert untimed(first) == untimed(second)
