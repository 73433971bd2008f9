"""`cadgen build`: scenes run exactly the stages their effects need; outputs atomic, deterministic."""

import json
import subprocess
import sys

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import cadgen.pipeline.build
from cadgen.pipeline.build import build, plan
from cadgen.cli import EXIT_CHECKS_FAILED, EXIT_OK, main
from cadgen.params import load_params
from cadgen.params.scene import EFFECTS
from kinematics.errors import DesignError, Problem

from helpers import REFERENCE, edited, with_keys

KERNEL_A = REFERENCE.parent / "kernel-a.toml"


@pytest.fixture(scope="module")
def params():
    return load_params(REFERENCE)


# the planting drivetrain is sized from its dynamics, which read the soil (metrics) and the
# cam's spring: a scene that designs it runs them too
@pytest.mark.parametrize("effects, stages", [
    (["metrics"], ["kinematics", "metrics"]),
    (["curves"], ["kinematics"]),
    (["teeth"], ["kinematics", "metrics", "cam", "drivetrain", "teeth"]),
    (["cam"], ["kinematics", "metrics", "cam"]),
    (["dxf"], ["kinematics", "metrics", "cam", "drivetrain", "teeth"]),
    (["arm_interference"], ["kinematics", "metrics", "cam", "drivetrain", "parts",
                            "arm_interference"]),
    (["ground_clearance"], ["kinematics", "metrics", "cam", "drivetrain", "parts",
                            "ground_clearance"]),
    (["plots"], ["kinematics", "metrics", "plots"]),
    (["report"], ["kinematics", "metrics"]),
])
def test_each_effect_needs_exactly_its_stages(effects, stages):
    assert plan(effects)[0] == stages


#: What the README's scene table promises each effect runs, besides the stages' own needs
#: (README, "Scenes"): written here from the table, not from EFFECT_STAGES.
PROMISED = {"metrics": {"metrics"}, "curves": {"kinematics"}, "teeth": {"teeth"},
            "meshing": {"teeth"}, "cam": {"metrics", "cam"}, "solids": {"metrics", "parts"},
            "stl": {"metrics", "parts"}, "arm_interference": {"parts", "arm_interference"},
            "ground_clearance": {"metrics", "parts", "ground_clearance"}, "dxf": set(),
            "plots": {"metrics", "plots"}, "report": {"metrics"}}
NEEDS = {"metrics": {"kinematics"}, "cam": {"metrics"}, "drivetrain": {"kinematics"},
         "teeth": {"kinematics", "drivetrain"}, "parts": {"metrics", "drivetrain"},
         "arm_interference": {"parts"}, "ground_clearance": {"parts"}, "plots": {"kinematics"}}


@settings(max_examples=300, deadline=None)
@given(effects=st.lists(st.sampled_from(sorted(PROMISED)), unique=True, max_size=12),
       mechanism=st.sampled_from(["planting", "pricking"]),
       case=st.sampled_from(["field", "bench"]))
def test_every_scene_runs_what_its_effects_promise_or_is_refused(effects, mechanism, case):
    """Any set of effects, either mechanism, either case: each applicable effect gets the
    stages the README promises it, the stages are closed under their needs and in run order,
    nothing is set aside but what has no meaning, and a scene with nothing left is refused
    (never a build of no stage that says PASSED)."""
    from cadgen.params import ParameterError
    from cadgen.pipeline.plan import STAGE_ORDER, _nothing_to_build

    meaningless = {("pricking", "cam"), ("pricking", "arm_interference"),
                   ("bench", "ground_clearance")}
    applicable = [e for e in effects if (mechanism, e) not in meaningless
                  and (case, e) not in meaningless]
    stages, aside = plan(effects, mechanism, case)
    assert set(aside) == set(effects) - set(applicable)
    for effect in applicable:
        promised = set(PROMISED[effect])
        if mechanism == "pricking":
            promised -= {"cam"}            # the pricking mechanism has none
        assert promised <= set(stages), effect
    if "dxf" in applicable and not {"teeth", "meshing", "cam", "solids", "stl"} & set(applicable):
        assert "teeth" in stages and ("cam" in stages or mechanism == "pricking")
    for stage in stages:
        assert NEEDS.get(stage, set()) <= set(stages), stage
    assert stages == sorted(stages, key=STAGE_ORDER.index)
    assert bool(stages) == bool(applicable)
    if not stages:
        with pytest.raises(ParameterError):
            _nothing_to_build(aside)


def test_effects_without_meaning_are_set_aside_with_the_reason():
    stages, aside = plan(["cam", "arm_interference", "metrics"], mechanism="pricking")
    assert stages == ["kinematics", "metrics"] and set(aside) == {"cam", "arm_interference"}
    stages, aside = plan(["ground_clearance"], case="bench")
    assert stages == [] and "soil" in aside["ground_clearance"]


def test_a_metrics_scene_builds_no_teeth_no_solids_and_never_imports_fcl(tmp_path):
    """In a fresh interpreter: the heavy libraries of the later stages stay unimported."""
    script = (
        "import sys\n"
        "from cadgen.cli import main\n"
        f"code = main(['build', {str(REFERENCE)!r}, '--effects', 'metrics', '--output-dir', "
        f"{str(tmp_path)!r}])\n"
        # the tooth generator and its scipy.spatial (0.3 s of imports) belong to the teeth stage
        "heavy = [m for m in ('fcl', 'manifold3d', 'trimesh', 'matplotlib', 'ezdxf', "
        "'cadgen.gears.teeth', 'cadgen.gears.pairs', 'scipy.spatial') "
        "if m in sys.modules]\n"
        "print('HEAVY', heavy, 'CODE', code)\n")
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         check=True).stdout
    assert "HEAVY [] CODE 0" in out
    report = json.loads((tmp_path / "xin2024-planter" / "report.json").read_text())
    assert [s["stage"] for s in report["stages"]] == ["kinematics", "metrics"]
    assert "gear_train" not in report and "solids" not in report
    assert sorted(p.name for p in (tmp_path / "xin2024-planter").iterdir()) == ["report.json"]


def test_bench_run_reports_only_what_needs_no_soil(params):
    result = build(params, None, effects=["metrics"], case="bench")
    keys = {m["key"] for m in result.report["metrics"]}
    assert keys == {"trajectory_height", "arm_distance", "module"}
    assert result.report["scene"]["case"] == "bench" and result.report["passed"]
    # nor the search of a metric it leaves out (the housings over the soil surface)
    field = build(params, None, effects=["metrics"])
    searches = {case: set(report["accuracy"]["minimum_searches"])
                for case, report in (("field", field.report), ("bench", result.report))}
    assert "ground_clearance" in searches["field"]
    assert searches["bench"] == searches["field"] - {"ground_clearance"}


def test_a_failed_stage_is_reported_its_dependents_skipped_the_rest_written(
        params, tmp_path, monkeypatch):
    def broken(run):
        raise DesignError([Problem("cam.roller_radius", "synthetic", "the cam stage broke")])

    monkeypatch.setitem(cadgen.pipeline.build.STAGE_FUNCTIONS, "cam", broken)
    result = build(params, tmp_path, effects=["metrics", "teeth", "cam", "curves", "dxf"])
    stages = {s["stage"]: s for s in result.report["stages"]}
    assert stages["cam"]["status"] == "failed" and "the cam stage broke" in stages["cam"]["message"]
    assert stages["cam"]["problems"][0]["path"] == "cam.roller_radius"
    assert stages["teeth"]["status"] == "ok"
    assert not result.report["passed"] and result.exit_code == EXIT_CHECKS_FAILED
    folder = tmp_path / "xin2024-planter"
    assert (folder / "gears" / "central.dxf").is_file() and not (folder / "cam.dxf").exists()
    assert any("stage cam failed" in f for f in result.report["failures"])


def test_a_failure_while_writing_leaves_the_previous_outputs(params, tmp_path, monkeypatch):
    build(params, tmp_path, effects=["metrics"])
    before = (tmp_path / "xin2024-planter" / "report.json").read_bytes()
    import cadgen.pipeline.writers

    def failing(run):
        def write(staging):
            (staging / "half.txt").write_text("half")
            raise RuntimeError("disk full")
        return [write]

    monkeypatch.setattr(cadgen.pipeline.writers, "writers_for", failing)
    with pytest.raises(RuntimeError):
        build(params, tmp_path, effects=["metrics", "curves"])
    assert (tmp_path / "xin2024-planter" / "report.json").read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["xin2024-planter"]
    assert not (tmp_path / "xin2024-planter" / "half.txt").exists()


def test_pitch_curve_tables_close_on_the_spec_perimeter(params, tmp_path):
    """curves/central.csv is the polar pitch curve: its perimeter is the spec's 192.886 mm."""
    import numpy as np

    build(params, tmp_path, effects=["curves"])
    table = np.loadtxt(tmp_path / "xin2024-planter" / "curves" / "central.csv", delimiter=",",
                       skiprows=1)
    angle, radius = np.radians(table[:, 0]), table[:, 1]
    points = np.column_stack([radius * np.cos(angle), radius * np.sin(angle)])
    perimeter = np.linalg.norm(np.diff(np.vstack([points, points[:1]]), axis=0), axis=1).sum()
    assert perimeter == pytest.approx(192.886, abs=2e-3)


def test_exit_codes_say_whether_the_design_passes(tmp_path, capsys):
    passing = main(["build", str(REFERENCE), "--effects", "metrics", "--output-dir",
                    str(tmp_path)])
    strict = tmp_path / "strict.toml"
    strict.write_text(edited(module_min="3.0"))
    failing = main(["build", str(strict), "--effects", "metrics", "--output-dir", str(tmp_path)])
    assert (passing, failing) == (EXIT_OK, EXIT_CHECKS_FAILED)
    assert "non-circular gear module" in capsys.readouterr().out


def test_pricking_build_runs_its_own_stages(tmp_path):
    result = build(load_params(KERNEL_A), tmp_path, effects=["metrics", "cam", "curves"])
    assert [s["stage"] for s in result.report["stages"]] == ["kinematics", "metrics"]
    assert result.report["scene"]["set_aside"] == {"cam": "the pricking mechanism has no cam"}
    curves = sorted(p.name for p in (tmp_path / "kernel-a" / "curves").iterdir())
    assert curves == ["intermediate-1.csv", "intermediate-2.csv", "planet.csv", "sun.csv"]
    # kernel-a's gears are concave: the design does not pass, and says why
    assert not result.report["passed"]
    assert any("concave" in f for f in result.report["failures"])


@pytest.mark.parametrize("design, figures", [
    (REFERENCE, {"relative_path.png", "absolute_paths.png", "attitude.png", "tip_velocity.png",
                 "pitch_curves.png"}),
    (KERNEL_A, {"loop.png", "pitch_curves.png", "ratio.png", "field_paths.png"}),
])
def test_plots_asked_alone_draw_the_motion_figures(design, figures, tmp_path):
    # the motion figures are drawn from the metrics' events: "plots" alone once ran the
    # kinematics only, drew nothing and said "ok"
    result = build(load_params(design), tmp_path, effects=["plots"])
    stages = {s["stage"]: s["status"] for s in result.report["stages"]}
    assert stages == {"kinematics": "ok", "metrics": "ok", "plots": "ok"}
    written = {p.name for p in (tmp_path / design.stem / "plots").iterdir()}
    assert written == figures
    assert all((tmp_path / design.stem / "plots" / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
               for name in written)


def test_a_scene_none_of_whose_effects_applies_is_refused_and_writes_nothing(tmp_path, capsys):
    # it once ran no stage and said PASSED of nothing
    from cadgen.params import ParameterError

    with pytest.raises(ParameterError) as caught:
        build(load_params(KERNEL_A), tmp_path / "out", effects=["cam", "arm_interference"])
    [problem] = caught.value.problems
    assert (problem.path, problem.code) == ("scene.effects", "nothing_to_build")
    assert "the pricking mechanism has no cam" in problem.message
    assert "the pricking mechanism has a single arm" in problem.message
    assert main(["build", str(KERNEL_A), "--effects", "cam", "--output-dir",
                 str(tmp_path / "out")]) == 2
    assert "scene.effects" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("design", [REFERENCE, KERNEL_A], ids=["planting", "pricking"])
def test_a_bench_runs_animation_has_no_soil_line(design, tmp_path):
    # its report leaves out what needs soil; the animation drew the soil line all the same
    pages = {}
    for case in ("field", "bench"):
        build(load_params(design), tmp_path / case, effects=["report"], case=case)
        pages[case] = (tmp_path / case / design.stem / "report.html").read_text(encoding="utf-8")
    assert "soil surface" in pages["field"]
    assert "soil surface" not in pages["bench"]
    assert '"soil": null' in pages["bench"] or '"soil":null' in pages["bench"]


def test_dxf_asked_alone_writes_the_gears_as_the_teeth_effect_cuts_them(params, tmp_path):
    # it once cut them without the drivetrain, so with other bores than every other scene's
    alone = build(params, tmp_path / "alone", effects=["dxf"], cache=False)
    with_teeth = build(params, tmp_path / "teeth", effects=["teeth", "dxf"], cache=False)
    files = {p.name: p.read_bytes() for p in (alone.output_dir / "gears").iterdir()}
    assert len(files) == 16    # every gear's cutting file; the train sheet is a drawing
    assert files == {p.name: p.read_bytes() for p in (with_teeth.output_dir / "gears").iterdir()}
    assert (alone.output_dir / "cam.dxf").is_file()
    drawings = sorted(p.name for p in (alone.output_dir / "drawings").iterdir())
    assert drawings == ["cam.dxf", "train.dxf"]


def test_two_processes_write_the_same_bytes_whatever_their_string_hashing(tmp_path):
    # the cutting files once came out in one of two orders of their CLASSES section, as the
    # process's string hashing fell (seeds 0 and 4 gave the two); every file but report.json
    # must be the same bytes for the same input
    import os

    trees = []
    for seed in ("0", "4"):
        out = tmp_path / seed
        done = subprocess.run([sys.executable, "-m", "cadgen", "build", str(REFERENCE),
                               "--effects", "teeth,cam,dxf,stl,curves", "--no-cache",
                               "--output-dir", str(out)], capture_output=True, text=True,
                              env={**os.environ, "PYTHONHASHSEED": seed})
        assert done.returncode == 0, done.stderr[-2000:]
        folder = out / REFERENCE.stem
        trees.append({str(p.relative_to(folder)): p.read_bytes() for p in folder.rglob("*")
                      if p.is_file() and p.name != "report.json"})
    assert any(name.endswith(".dxf") for name in trees[0])
    assert any(name.endswith(".stl") for name in trees[0])
    assert trees[0] == trees[1]


@pytest.mark.parametrize("design", [REFERENCE, REFERENCE.parent / "kernel-b.toml"],
                         ids=["planting", "pricking"])
def test_a_file_is_the_same_bytes_whichever_scene_writes_it(design, tmp_path):
    """A scene runs only what its effects need, and the files it writes are those of the full
    build, byte for byte (scenes with the teeth: solids without them are gearless by design).
    Found wrong: dxf alone cut the gears with other bores; a scene of solids without sweeps
    wrote the pricking ground of the gearless assembly."""
    params = load_params(design)
    full = build(params, tmp_path / "full", effects=list(EFFECTS))
    reference = {str(p.relative_to(full.output_dir)): p.read_bytes()
                 for p in full.output_dir.rglob("*") if p.is_file()}
    for effects in (["dxf"], ["teeth", "stl"], ["plots"]):
        result = build(params, tmp_path / "-".join(effects), effects=effects)
        written = {str(p.relative_to(result.output_dir)): p.read_bytes()
                   for p in result.output_dir.rglob("*")
                   if p.is_file() and p.name not in ("report.json", "report.html")}
        assert written and set(written) <= set(reference), effects
        assert {name for name in written if written[name] != reference[name]} == set(), effects


def test_a_report_asked_alone_holds_the_metrics_it_judges(tmp_path):
    # it once ran no stage, wrote a report of nothing and said PASSED
    result = build(load_params(REFERENCE), tmp_path, effects=["report"])
    assert [s["stage"] for s in result.report["stages"]] == ["kinematics", "metrics"]
    metrics = {m["key"] for m in result.report["metrics"]}
    assert {"trajectory_height", "hole_width", "module"} <= metrics
    html = (tmp_path / REFERENCE.stem / "report.html").read_text(encoding="utf-8")
    assert "trajectory height" in html


def test_sweeps_replace_the_kinematic_estimates_and_keep_them_beside(params):
    result = build(params, None, effects=["metrics", "arm_interference", "ground_clearance"])
    report = result.report
    metrics = {m["key"]: m for m in report["metrics"]}
    for key, sweep_key in (("arm_distance", "arm_interference"),
                           ("ground_clearance", "ground_clearance")):
        sweep = report["sweep"][sweep_key]
        assert metrics[key]["value"] == sweep["minimum_mm"]
        assert metrics[key]["kinematic_estimate"] == sweep["kinematic_estimate_mm"]
        assert sweep["certified"] and sweep["certified_bound_mm"] <= sweep["minimum_mm"]
        assert sweep["minimum_mm"] - sweep["certified_bound_mm"] <= sweep["atol_mm"] * (1 + 1e-9)
        assert sweep["interference_ranges_deg"] == [] and sweep["passed"]
        gap = [b - a for a, b in zip(*sweep["nearest_points_mm"])]
        assert sum(g * g for g in gap) ** 0.5 == pytest.approx(sweep["minimum_mm"], abs=1e-9)
    # the solids' arms come closer than their centre lines: the cam of one passes the other's shell
    arms = report["sweep"]["arm_interference"]
    assert arms["minimum_mm"] < arms["kinematic_estimate_mm"]
    # the housings are the hull of the envelope circles: the same clearance, to the polygon sag
    ground = report["sweep"]["ground_clearance"]
    assert ground["kinematic_estimate_mm"] - 0.03 < ground["minimum_mm"] <= \
        ground["kinematic_estimate_mm"] + 1e-6
    assert [s["stage"] for s in report["stages"]] == [
        "kinematics", "metrics", "cam", "drivetrain", "parts", "arm_interference",
        "ground_clearance"]


def test_figures_drawn_in_a_forked_worker_are_the_same_bytes(params):
    from cadgen.pipeline.figures import _can_fork, build_figures

    if not _can_fork():
        pytest.skip("this platform cannot fork")
    result = cadgen.pipeline.build._Build(params, ["kinematics", "metrics", "cam"], None)
    result.effects, result.case = ["cam"], "field"
    result.run(cadgen.pipeline.build.STAGE_FUNCTIONS)
    together = build_figures(result, parallel=True)
    alone = build_figures(result, parallel=False)
    assert list(together) == list(alone) and len(together) == 7
    assert all(together[name] == alone[name] for name in alone)


def test_sweeps_run_beside_the_teeth_give_the_same_clearances(params):
    """With teeth to cut, the sweeps run in a forked worker on a gearless assembly."""
    from cadgen.pipeline.figures import _can_fork

    if not _can_fork():
        pytest.skip("this platform cannot fork")
    beside = build(params, None, effects=["teeth", "arm_interference", "ground_clearance"])
    alone = build(params, None, effects=["arm_interference", "ground_clearance"])
    stages = {s["stage"]: s for s in beside.report["stages"]}
    assert "second process" in stages["arm_interference"]["message"]
    for key in ("arm_interference", "ground_clearance"):
        assert beside.report["sweep"][key] == alone.report["sweep"][key]


def test_circular_gears_without_a_whole_tooth_module_fail_the_teeth_stage_only():
    """R = 37 mm: no module in 0.05-mm steps gives whole teeth to 37, 44.4, 40.7 and 27 mm."""
    params = load_params_text(edited(R="37.0"))
    report = build(params, None, effects=["metrics", "teeth"]).report
    stages = {s["stage"]: s for s in report["stages"]}
    assert stages["metrics"]["status"] == "ok"
    assert stages["teeth"]["status"] == "failed"
    assert stages["teeth"]["problems"][0]["path"] == "gears.circular_module"
    assert stages["teeth"]["problems"][0]["code"] == "fractional_teeth"
    assert not report["passed"]


def load_params_text(text):
    from cadgen.params import validate_text

    return validate_text(text)


# ------------------------------------------------------------------ checks of a stage not run
# planter.L2 = 150 mm: the duckbill linkage's push rod ends above the lever pin
# (push_rod_inverted), a check of the cam stage; the kinematics and metrics do not need it.


@pytest.fixture
def short_planter(tmp_path):
    path = tmp_path / "short-planter.toml"
    path.write_text(edited(L2="150.0", name='"short-planter"'), encoding="utf-8")
    return path


def test_a_metrics_build_keeps_a_cam_check_as_a_warning_with_its_stage(short_planter, tmp_path,
                                                                         capsys):
    out = tmp_path / "out"
    code = main(["build", str(short_planter), "--effects", "metrics", "--output-dir", str(out)])
    assert code == EXIT_OK
    report = json.loads((out / "short-planter" / "report.json").read_text(encoding="utf-8"))
    assert [(w["path"], w["code"], w["stage"]) for w in report["warnings"]] == [
        ("cam.lever.roller_arm", "push_rod_inverted", "cam")]
    assert report["passed"] and [s["stage"] for s in report["stages"]] == ["kinematics",
                                                                            "metrics"]
    printed = capsys.readouterr().out
    assert "warning: cam.lever.roller_arm:" in printed and "[push_rod_inverted] (stage cam" \
        in printed


def test_a_build_that_runs_the_cam_refuses_the_design_and_writes_nothing(short_planter,
                                                                         tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["build", str(short_planter), "--output-dir", str(out)]) == 2
    assert "push_rod_inverted" in capsys.readouterr().err
    assert not (out / "short-planter").exists()


def test_validate_says_what_the_files_own_scene_builds(short_planter, tmp_path, capsys):
    # its scene runs the cam: validate refuses it as build does, with the same line
    assert main(["validate", str(short_planter)]) == 2
    validated = capsys.readouterr().out.splitlines()
    assert main(["build", str(short_planter), "--output-dir", str(tmp_path / "out")]) == 2
    assert validated == capsys.readouterr().err.splitlines()
    assert len(validated) == 1 and "[push_rod_inverted] (stage cam)" in validated[0]
    # a scene without the cam: a warning in both, with its stage
    metrics_only = tmp_path / "metrics-only.toml"
    metrics_only.write_text(with_keys(short_planter.read_text(encoding="utf-8"), "scene",
                                      effects='["metrics"]'), encoding="utf-8")
    assert main(["validate", str(metrics_only)]) == EXIT_OK
    lines = capsys.readouterr().out.splitlines()
    assert lines == [f"{metrics_only}: warning: {validated[0].split(': ', 1)[1]}",
                     f"{metrics_only}: ok (1 warning)"]


def test_the_library_loads_such_a_design_for_a_metrics_only_evaluation():
    from cadgen.design import evaluate
    from cadgen.params import stage_problems, validate_text

    params = validate_text(edited(L2="150.0"))
    assert [(p.code, p.stage) for p in stage_problems(params)] == [("push_rod_inverted", "cam")]
    assert evaluate(params, steps=720).metrics   # the metrics evaluate
    with pytest.raises(DesignError) as caught:   # ParameterError: a DesignError too
        build(params, None, effects=["solids"])  # solids need the cam
    assert [p.code for p in caught.value.problems] == ["push_rod_inverted"]


# ------------------------------------------------------------------ "certified" is true


def test_crossing_arms_report_a_certified_distance_of_zero(tmp_path):
    report = build(load_params_text(edited(L1="250.0")), None, effects=["metrics"]).report
    search = report["accuracy"]["minimum_searches"]["arm_distance"]
    assert search["certified"] and search["value"] == search["certified_bound"] == 0.0
    assert search["evaluations"] < 5_000
    arm = next(m for m in report["metrics"] if m["key"] == "arm_distance")
    assert (arm["passed"], arm["verdict"]) == (False, "fail")
    (row,) = [r for r in report["accuracy_achieved"]
              if r["knob"] == "resolution.steps_per_revolution"]
    assert "NOT certified" not in row["achieved"] and "arm_distance" in row["achieved"]


@pytest.mark.parametrize("target, verdict", [(10.0, "fail"), (1e-7, "undecided")])
def test_a_search_that_did_not_certify_is_named_with_its_gap(monkeypatch, target, verdict):
    # arms 0.14 nm apart at the closest, and a budget too small to close the bound there
    from kinematics.clearance import KinematicClearance, arm_distance

    monkeypatch.setattr(KinematicClearance, "arm_distance",
                        lambda self, mechanism, steps: arm_distance(
                            mechanism, steps=steps, max_evaluations=20_000))
    params = load_params_text(edited(L1="242.640835", arm_distance_min=repr(target)))
    report = build(params, None, effects=["metrics"]).report
    search = report["accuracy"]["minimum_searches"]["arm_distance"]
    assert not search["certified"] and search["budget_spent"]
    assert search["certified_bound"] < target < search["value"] or verdict == "fail"
    (row,) = [r for r in report["accuracy_achieved"]
              if r["knob"] == "resolution.steps_per_revolution"]
    achieved = row["achieved"]
    assert "certified: lowest_point, highest_point, ground_clearance" in achieved
    assert (f"NOT certified: arm_distance (budget of {search['evaluations']} evaluations "
            f"spent), true minimum in [{search['certified_bound']:.9g}, {search['value']:.9g}]"
            in achieved)
    arm = next(m for m in report["metrics"] if m["key"] == "arm_distance")
    assert (arm["passed"], arm["verdict"]) == (False, verdict)
    assert not report["passed"]
    if verdict == "undecided":
        assert any("undecided" in f for f in report["failures"])
