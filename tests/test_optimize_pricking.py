"""PrickingProblem: the moved type-value points through the exact inverse design.

Every figure is checked against an independent source: ``certify`` reads report.json's
sections of the validated file (``cadgen.validate_data`` + ``cadgen.evaluate``), the base
designs against ``cadgen.evaluate`` of the bundled files, and the kernel-a result against
``cadgen.build`` of the written file.
"""

import math
import pickle

import numpy as np
import pytest

import cadgen
from cadgen.optimize.pricking import GEAR_NAMES, INVALID, PrickingProblem

EVERY_OBJECTIVE = [("convexity", "max"), ("ratio_margin", "max"), ("min_margin", "max"),
                   ("displacement", "min")]


@pytest.fixture(scope="module")
def base():
    return {name: cadgen.load_params(f"params/{name}.toml") for name in ("kernel-a", "kernel-b")}


def problem_for(params, box=3.0, points=None, objectives=EVERY_OBJECTIVE):
    free = {"box": box} if points is None else {"box": box, "points": points}
    return PrickingProblem(params, free, objectives)


def label(gear):
    return gear.replace(" ", "_")


@pytest.mark.parametrize("name", ["kernel-a", "kernel-b"])
def test_evaluate_gives_the_exact_paths_figures(base, name):
    problem = problem_for(base[name])
    rng = np.random.default_rng(17)
    X = np.vstack([np.zeros(24), rng.uniform(-3.0, 3.0, (2, 24))])
    screened = problem.evaluate(X)
    assert screened["valid"].all()
    for n, x in enumerate(X):
        certified = problem.certify(x)
        assert not certified["problems"]
        gears = {g["name"]: g for g in certified["metrics"]["gears"]["pitch_curves"]}
        # the figures from the report's own numbers, as a reader of report.json would
        normalised = [gears[g]["curvature_min_per_mm"] * gears[g]["perimeter_mm"] / (2 * math.pi)
                      for g in GEAR_NAMES]
        assert screened["values"]["convexity"][n] == pytest.approx(min(normalised), rel=1e-12)
        for gear in GEAR_NAMES:
            assert screened["values"][f"curvature_min@{label(gear)}"][n] == pytest.approx(
                gears[gear]["curvature_min_per_mm"], rel=1e-12)
        ratio_min = certified["metrics"]["gears"]["total_ratio_min"]
        assert screened["values"]["ratio_min"][n] == pytest.approx(ratio_min, rel=1e-12)
        assert screened["values"]["forward_deviation"][n] == pytest.approx(
            certified["metrics"]["verification"]["forward_deviation_mm"], rel=1e-9)
        moved = np.asarray(problem.tables_at(x)["trajectory"]["points"])
        start = np.asarray(base[name].trajectory.points)
        assert screened["values"]["displacement"][n] == pytest.approx(
            np.linalg.norm(moved - start, axis=1).max(), abs=1e-12)
        # F minimises: maximised objectives negated; G is minus each certified margin
        for k, (key, sense) in enumerate(problem.objectives):
            sign = 1.0 if sense == "min" else -1.0
            assert screened["F"][n, k] == pytest.approx(sign * certified["objectives"][key])
        np.testing.assert_allclose(
            screened["G"][n], [-certified["margins"][c] for c in problem.constraint_labels],
            rtol=1e-9)


def test_no_displacement_is_the_base_design(base):
    for name, convex in (("kernel-a", False), ("kernel-b", True)):
        problem = problem_for(base[name])
        design = cadgen.evaluate(base[name])
        result = problem.evaluate(np.zeros((1, 24)))
        for gear in design.gears:
            assert result["values"][f"curvature_min@{label(gear.name)}"][0] == \
                gear.curvature_min
            assert gear.convex is convex       # the spec: kernel-a all four concave, b convex
        concave = {f.path for f in design.findings if f.code == "concave_pitch_curve"}
        assert len(concave) == (0 if convex else 4)
        convex_constraints = result["G"][0, :4]
        assert (convex_constraints <= 0).all() if convex else (convex_constraints > 0).all()
        assert bool(result["values"]["convexity"][0] > 0) is convex
        assert result["values"]["displacement"][0] == 0.0
        assert problem.certify(np.zeros(24))["passed"] is convex


def test_displacements_outside_the_box_are_refused(base):
    problem = problem_for(base["kernel-a"], box=3.0, points=[3, 5])
    assert problem.variables == ["Q3.x", "Q3.y", "Q5.x", "Q5.y"]
    np.testing.assert_array_equal(problem.lower, -3.0)
    for bad in (3.01, -3.5, np.nan):
        x = np.array([0.0, 0.0, 0.0, bad])
        with pytest.raises(ValueError, match="Q5.y"):
            problem.evaluate(x[None])
        with pytest.raises(ValueError, match="Q5.y"):
            problem.certify(x)
    with pytest.raises(ValueError, match="shape"):
        problem.evaluate(np.zeros((2, 3)))
    with pytest.raises(ValueError, match="points"):
        problem_for(base["kernel-a"], points=[0, 13])
    with pytest.raises(ValueError, match="objective"):
        problem_for(base["kernel-a"], objectives=[("hole_width@185", "min")])


def test_the_problem_pickles_and_evaluates_the_same(base):
    problem = problem_for(base["kernel-b"], points=[4, 6])
    copy = pickle.loads(pickle.dumps(problem))
    X = np.array([[1.0, -2.0, 0.5, 2.5]])
    first, second = problem.evaluate(X), copy.evaluate(X)
    np.testing.assert_array_equal(first["F"], second["F"])
    np.testing.assert_array_equal(first["G"], second["G"])


def test_a_design_the_exact_path_refuses_is_flagged_never_a_number(base):
    params = base["kernel-a"]
    q4, q5 = np.asarray(params.trajectory.points)[[3, 4]]
    problem = problem_for(params, box=60.0, points=[5])
    onto_q4 = q4 - q5 + 1e-6          # Q5 moved onto Q4: a repeated point
    result = problem.evaluate(np.array([onto_q4, [0.0, 0.0]]))
    assert result["valid"].tolist() == [False, True]
    assert result["errors"][0] == "coincident_points"
    assert (result["F"][0] == INVALID).all() and (result["G"][0] == INVALID).all()
    assert all(np.isnan(column[0]) for column in result["values"].values())
    certified = problem.certify(onto_q4)
    assert certified["passed"] is False
    assert [p["code"] for p in certified["problems"]] == ["coincident_points"]
    with pytest.raises(cadgen.ParameterError):
        cadgen.validate_data(problem.tables_at(onto_q4))


def test_a_ratio_under_the_files_bound_is_a_violated_constraint(base):
    """The screen grades a ratio between 0 and gears.min_ratio; the file refuses it."""
    params = base["kernel-a"]
    points = np.asarray(params.trajectory.points)
    problem = problem_for(params, box=60.0, points=[4, 6])
    # Q4 and Q6 drawn towards Q5 (the hard case keeps 0.2 of their distance in x: the ratio
    # falls below zero); keeping 0.25 leaves it between 0 and min_ratio = 0.05
    def squeeze(keep):
        return np.concatenate([[(keep - 1) * (points[k, 0] - points[4, 0]), 0.0] for k in (3, 5)])

    x = squeeze(0.25)
    result = problem.evaluate(np.array([x, squeeze(0.2)]))
    assert result["valid"].tolist() == [True, False]
    assert result["errors"][1] == "ratio_not_positive"
    assert 0 < result["values"]["ratio_min"][0] < problem.min_ratio
    ratio_constraint = result["G"][0, problem.constraint_labels.index("ratio_min")]
    assert ratio_constraint == pytest.approx(
        (problem.min_ratio - result["values"]["ratio_min"][0]) / problem.min_ratio)
    assert ratio_constraint > 0
    certified = problem.certify(x)
    assert [p["code"] for p in certified["problems"]] == ["ratio_not_positive"]


# ------------------------------------------------------------------ kernel-a within 3 mm
STUDY = "params/studies/kernel-a-convex.toml"


def recorded_best(box):
    """A long run's best design at ``box`` (mm), as the study file's comments record it.

    Lines ``#   3mm Q3  dx -2.980225  dy -2.519994`` (mm), and ``# 3mm curvature minima``
    followed by ``gear=value`` pairs in 1/mm, as certified at those rounded displacements.
    """
    tag = f"{box:g}mm"
    moves, minima = {}, {}
    for line in open(STUDY, encoding="utf-8"):
        words = line.lstrip("#").split()
        if len(words) == 6 and words[0] == tag and words[2] == "dx" and words[4] == "dy":
            moves[int(words[1][1:])] = (float(words[3]), float(words[5]))
        if line.startswith(f"# {tag} curvature minima"):
            minima.update(w.split("=") for w in words[3:])
    assert sorted(moves) == list(range(1, 13)) and len(minima) == 4
    return np.array([moves[k] for k in sorted(moves)]).ravel(), minima


def certified_as_recorded(params, box):
    x, minima = recorded_best(box)
    assert np.abs(x).max() <= box
    certified = problem_for(params, box=box).certify(x)
    assert not certified["problems"]
    for key, text in minima.items():
        decimals = len(text.split(".")[1])
        assert certified["values"][f"curvature_min@{key}"] == pytest.approx(
            float(text), abs=0.5 * 10.0**-decimals), key      # to the digits printed
    return x, certified


def test_the_best_found_within_3_mm_is_certified_concave(base):
    """The study's record of the long searches' best within 3 mm: the exact path agrees
    that three pitch curves stay concave, and the report names exactly those."""
    _, certified = certified_as_recorded(base["kernel-a"], 3.0)
    assert not certified["passed"] and certified["values"]["convexity"] < 0
    concave = {f["path"] for f in certified["findings"] if f["code"] == "concave_pitch_curve"}
    assert concave == {f"gears.{label(g)}" for g in GEAR_NAMES
                       if certified["values"][f"curvature_min@{label(g)}"] < 0}
    assert len(concave) == 3


def test_within_4_mm_kernel_a_has_four_convex_gears_and_builds_so(base, tmp_path):
    """What the 3-mm box lacks: the study's record of a 4-mm design with four convex pitch
    curves, certified, and built from a written file with no concave_pitch_curve."""
    import tomlkit

    x, certified = certified_as_recorded(base["kernel-a"], 4.0)
    assert certified["passed"] and certified["values"]["convexity"] > 0
    assert all(g["convex"] for g in certified["metrics"]["gears"]["pitch_curves"])
    path = tmp_path / "kernel-a-convex-4mm.toml"
    path.write_text(tomlkit.dumps(problem_for(base["kernel-a"], box=4.0).tables_at(x)),
                    encoding="utf-8")
    report = cadgen.build(cadgen.load_params(path), output_root=None,
                          effects=["metrics"]).report
    assert not [f for f in report["findings"] if f["code"] == "concave_pitch_curve"]
    assert report["verified"] and report["passed"]
    gears = {g["name"]: g for g in report["gears"]["pitch_curves"]}
    for gear in GEAR_NAMES:
        assert gears[gear]["curvature_min_per_mm"] == \
            certified["values"][f"curvature_min@{label(gear)}"]


def test_kernel_a_within_3_mm_the_optimiser_reports_no_cuttable_design(tmp_path):
    """A short seeded search of the study (2 workers) ends as the long ones did: no design
    with four convex pitch curves; the report says so, and a build of the file it wrote
    finds the same concave pitch curves."""
    import dataclasses

    study = dataclasses.replace(cadgen.load_study(STUDY), evaluations=128)
    result = cadgen.optimize_study(study, workers=2, max_certified=6)
    assert result.evaluations == 128
    assert not result.found and result.exit_code == 1
    chosen = result.least_violating
    assert chosen is not None and not chosen.passed
    assert np.abs(chosen.x).max() <= 3.0
    # better than the drawn loop, still concave
    assert result.base.exact["values"]["convexity"] < chosen.exact["values"]["convexity"] < 0
    folder = cadgen.write_optimize_outputs(result, tmp_path)
    page = (folder / "optimize.html").read_text(encoding="utf-8")
    assert "No design meeting every target was found" in page
    written = cadgen.load_params(folder / "least-violating.toml")
    report = cadgen.build(written, output_root=None, effects=["metrics"]).report
    built = {f["path"] for f in report["findings"] if f["code"] == "concave_pitch_curve"}
    expected = {f["path"] for f in chosen.exact["findings"] if f["code"] == "concave_pitch_curve"}
    assert built == expected and built
    assert not report["passed"]
