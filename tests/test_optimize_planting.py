"""PlantingProblem: the screen's F and G against the exact path's, the housing radii, pickling."""

import math
import pickle

import numpy as np
import pytest

import cadgen
from cadgen.design import build_mechanism
from cadgen.optimize.planting import CAM_LABELS, INVALID, PlantingProblem, supported_paths
from cadgen.solids.housings import housing_circles
from kinematics.evaluation import Targets
from kinematics.margins import bounds_of, margins
from kinematics.population import TOLERANCES
from tests.helpers import REFERENCE

FREE = [("planter.L2", 150.0, 230.0), ("pitch_curve.b1", 24.0, 31.0), ("train.R", 32.0, 40.0),
        ("train.phic_deg", 80.0, 100.0), ("field.depth", 20.0, 60.0),
        ("housing.wall", 3.0, 9.0), ("targets.hole_width_max", 20.0, 40.0),
        ("housing.gearbox2.D", 55.0, 75.0)]
OBJECTIVES = [("min_margin", "max"), ("hole_width@185", "min")]


@pytest.fixture(scope="module")
def base():
    return cadgen.load_params(REFERENCE)


@pytest.fixture(scope="module")
def problem(base):
    return PlantingProblem(base, FREE, OBJECTIVES)


def random_x(problem, count, seed):
    rng = np.random.default_rng(seed)
    return problem.lower + (problem.upper - problem.lower) * rng.random((count, len(FREE)))


def scale_of(label, targets):
    _, scale = margins(1.0, *bounds_of(label, targets))
    return scale if math.isfinite(scale) else 1.0


def test_screen_against_certify(problem):
    X = random_x(problem, 10, seed=11)
    screened = problem.evaluate(X)
    assert screened["F"].shape == (10, 2) and screened["G"].shape == (10, 12 + len(CAM_LABELS))
    certified = 0
    for row, x in enumerate(X):
        exact = problem.certify(x)
        if exact["problems"]:
            # a design the loader refuses (too deep for its path, a pointed curve) is invalid
            assert not screened["valid"][row]
            assert screened["errors"][row] in {p["code"] for p in exact["problems"]}
            assert (screened["G"][row] == INVALID).all()
            continue
        certified += 1
        assert screened["valid"][row]
        params = cadgen.validate_data(problem.tables_at(x))
        targets = Targets(**params.targets.model_dump())
        for j, label in enumerate(problem.constraint_labels[:12]):
            tolerance = TOLERANCES[label.split("@")[0]]
            assert abs(screened["values"][label][row] - exact["values"][label]) <= tolerance
            # G is minus the normalised margin: within the tolerance over the bound's size
            assert abs(screened["G"][row, j] + exact["margins"][label]) <= \
                tolerance / scale_of(label, targets) + 1e-12
        # the duckbill's checks: the linkage in closed form, the timing from the events
        for j, label in enumerate(problem.constraint_labels[12:], start=12):
            assert abs(screened["G"][row, j] + exact["margins"][label]) <= 1e-6, label
        worst = max(TOLERANCES[k.split("@")[0]] / scale_of(k, targets)
                    for k in problem.constraint_labels[:12])
        assert abs(screened["values"]["min_margin"][row] - exact["values"]["min_margin"]) <= worst
        assert screened["F"][row, 0] == pytest.approx(-exact["objectives"]["min_margin"], abs=worst)
        assert screened["F"][row, 1] == pytest.approx(exact["objectives"]["hole_width@185"],
                                                      abs=TOLERANCES["hole_width"])
        clear = np.abs(screened["G"][row]) > worst
        if clear.all():
            assert exact["passed"] == bool((screened["G"][row] <= 0).all())
        assert [m["key"] for m in exact["metrics"]] == [k.split("@")[0] for k in
                                                         problem.constraint_labels[:12]]
    assert certified >= 5


def test_the_targets_and_housing_of_the_file_are_applied(problem):
    x = np.array([190.0, 27.5, 36.0, 90.0, 35.0, 6.0, 25.0, 70.0])
    tables = problem.tables_at(x)
    assert tables["housing"]["gearbox2"] == {"D": 70.0}
    assert tables["targets"]["hole_width_max"] == 25.0
    params = cadgen.validate_data(tables)
    radii = [c.radius for c in housing_circles(params, build_mechanism(params))]
    np.testing.assert_allclose(problem.envelope_radii(x[None])[0], radii, rtol=0, atol=1e-9)


def _housing_case(base_tables, rng):
    tables = {k: dict(v) if isinstance(v, dict) else v for k, v in base_tables.items()}
    tables["train"].update(R=float(rng.choice([36.0, 30.0, 32.5, rng.uniform(30, 40)])),
                           i12=float(rng.choice([1.2, 1.0, rng.uniform(1, 1.5)])),
                           i13=float(rng.choice([1.1, 1.0, rng.uniform(1, 1.4)])),
                           r=float(rng.choice([27.0, 25.0, rng.uniform(24, 30)])))
    tables["pitch_curve"]["teeth"] = int(rng.choice([22, 18, 26, 14]))
    housing = tables.setdefault("housing", {})
    if rng.random() < 0.5:
        housing["wall"] = float(rng.choice([2.0, 3.9, 4.0, 5.5, 6.0, 7.99, 8.0, 10.0]))
    if rng.random() < 0.4:
        housing["clearance"] = float(rng.uniform(0, 5))
    if rng.random() < 0.3:
        housing["gearbox1"] = {"B": 65.0}
    if rng.random() < 0.3:
        housing["bolt_size"] = "M5"
    if rng.random() < 0.3:
        tables.setdefault("gears", {})["circular_module"] = float(rng.choice([1.0, 1.5]))
    if rng.random() < 0.3:
        tables.setdefault("manufacturing", {})["process"] = str(rng.choice(["printed", "laser"]))
    return tables


def test_envelope_radii_as_housing_circles(base):
    """Random trains, teeth, walls, bolts, processes and given radii: the vectorised rule gives
    every circle of cadgen.solids.housings.housing_circles."""
    rng = np.random.default_rng(4)
    base_tables = base.model_dump(mode="json", exclude_none=True)
    checked = 0
    for _ in range(30):
        try:
            params = cadgen.validate_data(_housing_case(base_tables, rng))
        except cadgen.ParameterError:
            continue
        free = [("train.R", 20.0, 50.0), ("train.i12", 0.5, 2.0), ("train.i13", 0.5, 2.0),
                ("train.r", 10.0, 40.0)]
        problem = PlantingProblem(params, free, [("min_margin", "max")])
        x = np.array([[params.train.R, params.train.i12, params.train.i13, params.train.r]])
        expected = [c.radius for c in housing_circles(params, build_mechanism(params))]
        np.testing.assert_allclose(problem.envelope_radii(x)[0], expected, rtol=0, atol=1e-9)
        checked += 1
    assert checked >= 20


def test_rows_are_independent_and_the_problem_pickles(problem):
    X = random_x(problem, 40, seed=5)
    whole = problem.evaluate(X)
    copy = pickle.loads(pickle.dumps(problem))
    again = copy.evaluate(X)
    for key in ("F", "G", "valid"):
        np.testing.assert_array_equal(again[key], whole[key])
    for row in (0, 13, 39):
        alone = copy.evaluate(X[row:row + 1])
        np.testing.assert_array_equal(alone["F"][0], whole["F"][row])
        np.testing.assert_array_equal(alone["G"][0], whole["G"][row])
        for key, values in alone["values"].items():
            np.testing.assert_array_equal(values[0], whole["values"][key][row])


def test_names_and_refusals(base):
    keys = PlantingProblem.objective_keys(base)
    assert keys[:3] == ["min_margin", "trajectory_height", "hole_width@150"]
    assert "hole_width@185" in keys and "ground_clearance" in keys
    assert "planter.L2" in supported_paths(base) and "train.n" not in supported_paths(base)
    with pytest.raises(ValueError, match="train.n") as caught:
        PlantingProblem(base, [("train.n", 2.0, 4.0), ("planter.L1", 100.0, 150.0)], OBJECTIVES)
    assert "planter.L1" not in str(caught.value).split("searches")[0]
    with pytest.raises(ValueError, match="pitch_curve.e2"):
        PlantingProblem(base, [("pitch_curve.e2", 0.5, 2.0)], OBJECTIVES)
    with pytest.raises(ValueError, match="objectives"):
        PlantingProblem(base, FREE, [("hole_width@170", "min")])
    problem = PlantingProblem(base, FREE, OBJECTIVES)
    assert problem.kind == "planting" and problem.variables == [p for p, _, _ in FREE]
    assert problem.constraint_labels == keys[1:] + list(CAM_LABELS)


def test_a_design_the_loader_refuses(problem):
    x = np.array([190.0, 27.5, 36.0, 90.0, 35.0, 6.0, 25.0, 70.0])
    refused = x.copy()
    refused[1] = 24.0           # the screen and the loader agree on it either way
    exact = problem.certify(refused)
    screened = problem.evaluate(refused[None])
    assert bool(exact["problems"]) == (not screened["valid"][0])
    deep = PlantingProblem(problem.base_params, [("field.depth", 100.0, 900.0)], OBJECTIVES)
    exact = deep.certify(np.array([850.0]))
    assert exact["passed"] is False and exact["values"] == {}
    assert {p["code"] for p in exact["problems"]} == {"no_soil_crossing"}
    screened = deep.evaluate(np.array([[850.0]]))
    assert not screened["valid"][0] and screened["errors"][0] == "no_soil_crossing"
    assert (screened["F"][0] == INVALID).all()


def test_the_duckbill_checks_are_constraints(base):
    """Short planter links break the duckbill's linkage (the push rod's end rises above the
    lever's pin) or its timing: cadgen build refuses those designs (stage "cam"), and the
    screen's cam constraints say so, with the exact path's margins."""
    problem = PlantingProblem(base, [("planter.L1", 100.0, 160.0), ("planter.L2", 60.0, 230.0),
                                     ("pitch_curve.b1", 24.0, 31.0)], [("min_margin", "max")])
    X = np.array([[116.0, 130.0, 31.0], [130.0, 190.0, 27.5], [150.0, 100.0, 26.0],
                  [105.0, 215.0, 30.0]])
    screened = problem.evaluate(X)
    cam = slice(12, 12 + len(CAM_LABELS))
    for row, x in enumerate(X):
        exact = problem.certify(x)
        assert not exact["problems"]
        staged = {p["code"] for p in exact["stage_problems"]}
        for j, label in enumerate(problem.constraint_labels[cam], start=12):
            assert abs(screened["G"][row, j] + exact["margins"][label]) <= 1e-6, label
        failing = screened["G"][row, cam] > 0
        assert bool(staged) == bool(failing.any()), (x, staged)
        if "push_rod_inverted" in staged:
            assert screened["G"][row, problem.constraint_labels.index("cam:push_rod")] > 0
        if not staged and exact["passed"] is False:
            assert (screened["G"][row, :12] > 0).any()
    assert (screened["G"][0, cam] > 0).any()          # the short-L2 optimum E's study found
    assert not (screened["G"][1, cam] > 0).any()      # the paper's design
