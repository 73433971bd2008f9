"""The population screen against the exact evaluator, design by design.

The exact path is the one ``cadgen build`` uses: ``cadgen.validate_data`` (which refuses
what :mod:`cadgen.params.feasibility` finds) and ``cadgen.evaluate`` (certified minima,
Brent roots, the closure doubled to 1e-13). Every screened metric must be within its
stated tolerance (:data:`kinematics.population.TOLERANCES`) of the exact value, and every
design the exact path refuses must be invalid in the screen, with the same reason.
"""

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings, strategies as st

import cadgen
from cadgen.design import build_mechanism
from cadgen.solids.housings import housing_circles
from kinematics.clearance import HousingCircle
from kinematics.evaluation import Targets, evaluate_planting
from kinematics.margins import is_equality, margins, metric_bounds, min_margin
from kinematics.pitch_curves import LimaconPitchCurve, polar_perimeter, solve_closure
from kinematics.planting import PlantingMechanism
from kinematics.population import (CIRCLE_AXES, DESIGN_FIELDS, TOLERANCES, metric_keys, screen,
                                   spacing_key)
from kinematics.population_closure import LIMACON_FIELDS, solve_pair
from tests.conftest import PAPER_LIMACON
from tests.helpers import REFERENCE

SPACINGS = (150.0, 185.0, 200.0)
PAPER_TRAIN = dict(i12=1.2, i13=1.1, R=36.0, r=27.0, L1=130.0, L2=190.0, phi0=math.pi / 2,
                   phic=math.pi / 2, n=3.0)
#: The problems the file loader refuses a design for that the screen must see too.
SCREENED_CODES = {"pointed_pitch_curve", "tiny_intermediate_radius", "closure_not_converged",
                  "no_soil_crossing"}


@pytest.fixture(scope="module")
def base_tables():
    return cadgen.load_params(REFERENCE).model_dump(mode="json", exclude_none=True)


def columns_of(tables, circles) -> dict:
    """The screen's columns of one parameter mapping (angles to rad), with given circles."""
    curve, train = tables["pitch_curve"], tables["train"]
    out = {k: curve[k] for k in ("a1", "b1", "c1", "d1", "e1", "e2", "g1", "g2", "teeth")}
    out.update(f1=curve["f1_rad"], f2=curve["f2_rad"], i12=train["i12"], i13=train["i13"],
               R=train["R"], r=train["r"], n=train["n"], phi0=math.radians(train["phi0_deg"]),
               phic=math.radians(train["phic_deg"]), L1=tables["planter"]["L1"],
               L2=tables["planter"]["L2"], depth=tables["field"]["depth"])
    return {**{k: np.array([float(v)]) for k, v in out.items()},
            "circles": np.asarray(circles, dtype=float).reshape(1, -1)}


def exact_values(evaluation) -> dict:
    return {(m.key if m.spacing is None else spacing_key(m.key, m.spacing)): m.value
            for m in evaluation.metrics}


def assert_within_tolerance(found: dict, exact: dict, row: int = 0):
    for key, value in exact.items():
        tolerance = TOLERANCES[key.split("@")[0]]
        assert abs(found[key][row] - value) <= tolerance, (key, found[key][row], value)


# ------------------------------------------------------------------------ random designs
@st.composite
def designs(draw):
    """Parameter files round the paper's design, inside the schema's ranges: about a third
    are refused by the loader (pointed curves, tiny intermediate radii, too deep). Hypothesis
    draws the spread and a seed; the values are uniform within the spread."""
    scale = draw(st.sampled_from([0.03, 0.08, 0.15, 0.25]))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))

    def near(value, spread):
        return float(value + rng.uniform(-1.0, 1.0) * spread * scale / 0.15)

    curve = {"a1": near(1.2, 1.5), "b1": near(27.5, 5.0), "c1": near(-5.5, 4.0),
             "d1": near(30.5, 5.0), "e1": near(2.66, 0.3), "f1_rad": near(8.55, 0.4),
             "f2_rad": near(4.24, 0.4), "g1": near(-6.95, 5.0), "g2": near(-4.0, 5.0),
             "e2": float(rng.choice([1.0, 1.0, 1.0, 0.5, 1.5, 2.0])),
             "teeth": int(rng.integers(12, 29))}
    train = {"i12": near(1.2, 0.3), "i13": near(1.1, 0.3), "R": near(36.0, 6.0),
             "r": near(27.0, 5.0), "phi0_deg": near(90.0, 30.0), "phic_deg": near(90.0, 30.0)}
    planter = {"L1": near(130.0, 30.0), "L2": near(190.0, 50.0)}
    depth = float(rng.choice([0.1, 35.0, near(35.0, 40.0), 120.0, near(700.0, 150.0)]))
    return curve, train, planter, max(0.1, depth)


def tables_with(base, change):
    curve, train, planter, depth = change
    tables = {k: dict(v) if isinstance(v, dict) else v for k, v in base.items()}
    tables["pitch_curve"].update(curve)
    tables["train"].update(train)
    tables["planter"].update(planter)
    tables["field"]["depth"] = depth
    return tables


@settings(max_examples=80, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(change=designs())
def test_screen_matches_the_exact_evaluator(base_tables, change):
    tables = tables_with(base_tables, change)
    try:
        params = cadgen.validate_data(tables)
    except cadgen.ParameterError as error:
        codes = {p.code for p in error.problems if not p.stage}
        event(f"refused: {sorted(codes)}")
        found = screen(columns_of(tables, np.full(7, 40.0)), SPACINGS)
        assert not found.valid[0], codes
        assert found.reason[0] in SCREENED_CODES
        if codes <= {"pointed_pitch_curve", "tiny_intermediate_radius", "no_soil_crossing"}:
            assert found.reason[0] in codes, (found.reason[0], codes)
        return
    event("evaluated")
    mechanism = build_mechanism(params)
    circles = [c.radius for c in housing_circles(params, mechanism)]
    found = screen(columns_of(tables, circles), params.field.plant_spacings)
    assert found.valid[0], found.reason[0]
    assert_within_tolerance(found.values, exact_values(cadgen.evaluate(params)))


def _random_population(rng, count):
    """Designs round the paper's, as screen columns, with fixed envelope circles."""
    def near(value, spread):
        return value + spread * rng.uniform(-1.0, 1.0, count)

    columns = {"a1": near(1.2, 1.0), "b1": near(27.5, 3.0), "c1": near(-5.5, 3.0),
               "d1": near(30.5, 3.0), "e1": near(2.66, 0.2), "e2": np.ones(count),
               "f1": near(8.55, 0.25), "f2": near(4.24, 0.25), "g1": near(-6.95, 3.0),
               "g2": near(-4.0, 3.0), "teeth": rng.integers(18, 27, count).astype(float),
               "i12": near(1.2, 0.2), "i13": near(1.1, 0.2), "R": near(36.0, 5.0),
               "r": near(27.0, 4.0), "L1": near(130.0, 25.0), "L2": near(190.0, 45.0),
               "phi0": near(math.pi / 2, 0.3), "phic": near(math.pi / 2, 0.3),
               "n": np.full(count, 3.0), "depth": near(40.0, 30.0)}
    columns["circles"] = np.column_stack([near(45.0, 10.0) for _ in CIRCLE_AXES])
    return columns


def _exact(columns, row, targets=Targets()):
    curve = LimaconPitchCurve(**{k: float(columns[k][row]) for k in LIMACON_FIELDS})
    mechanism = PlantingMechanism(curve, *(float(columns[k][row]) for k in (
        "i12", "i13", "R", "r", "L1", "L2", "phi0", "phic", "n")))
    circles = [HousingCircle(box, axis, float(columns["circles"][row, j]))
               for j, (box, axis) in enumerate(CIRCLE_AXES)]
    return evaluate_planting(mechanism, teeth=int(columns["teeth"][row]),
                             depth=float(columns["depth"][row]), spacings=SPACINGS,
                             housing_circles=circles, targets=targets)


@settings(max_examples=4, deadline=None, derandomize=True)
@given(seed=st.integers(0, 2**31 - 1))
def test_screen_at_the_targets_limits(seed):
    """Designs whose metrics sit near a target's bound: the screen's values and verdicts.

    A thousand random designs are screened; for every metric the valid design nearest
    each of its bounds is taken to the exact evaluator (kinematics.evaluation, the one
    cadgen.evaluate runs), which must agree within the tolerance, and so on the verdict
    wherever the exact margin is larger than the tolerance.
    """
    rng = np.random.default_rng(seed)
    columns = _random_population(rng, 1000)
    found = screen(columns, SPACINGS)
    bounds = metric_bounds(Targets())
    chosen = set()
    for key in metric_keys(SPACINGS):
        low, high = bounds[key.split("@")[0]]
        if is_equality(key):
            continue
        for bound in (low, high):
            if bound is None:
                continue
            distance = np.where(found.valid, np.abs(found.values[key] - bound), np.inf)
            chosen.add(int(np.argmin(distance)))
    for row in sorted(chosen):
        evaluation = _exact(columns, row)
        exact = exact_values(evaluation)
        assert_within_tolerance(found.values, exact, row)
        for metric in evaluation.metrics:
            key = metric.key if metric.spacing is None else spacing_key(metric.key, metric.spacing)
            margin, _ = margins(metric.value, *bounds[metric.key])
            if abs(margin) > TOLERANCES[metric.key] and metric.verdict != "undecided":
                screened, _ = margins(found.values[key][row], *bounds[metric.key])
                assert (screened >= 0) == (margin >= 0), (key, screened, margin)


# ------------------------------------------------------------------------------ closure
def test_closure_against_kinematics_closure():
    rng = np.random.default_rng(7)
    count = 40
    coefficients = {k: PAPER_LIMACON[k] + rng.uniform(-1.0, 1.0, count) * spread
                    for k, spread in dict(a1=0.8, b1=2.0, c1=2.0, d1=2.0, e1=0.1, f1=0.2,
                                          f2=0.2, g1=2.0, g2=2.0).items()}
    coefficients["e2"] = np.ones(count)
    law = solve_pair(coefficients, np.full(count, 22.0), 256)
    assert (law.reason == "").all()
    phi = rng.uniform(-10.0, 30.0, (count, 5))
    attitude = law.attitude(phi)
    grid = np.arange(256) * (2 * np.pi / 256)
    for row in range(count):
        curve = LimaconPitchCurve(**{k: float(coefficients[k][row]) for k in LIMACON_FIELDS})
        closure = solve_closure(curve)
        assert law.centre_distance[row] == pytest.approx(closure.centre_distance, abs=1e-10)
        assert law.radius_min[row] == pytest.approx(closure.radius_min[1], abs=1e-10)
        assert law.radius_max[row] == pytest.approx(closure.radius_max[1], abs=1e-10)
        assert law.perimeter[row] == pytest.approx(polar_perimeter(curve), abs=1e-7)
        # the attitude Psi = phi - F: on the grid (FFT) and off it (Hermite), as the law's
        assert np.abs(law.attitude_grid[row] + closure.law.periodic_part(grid)).max() < 1e-11
        assert np.abs(attitude[row] + closure.law.periodic_part(phi[row])).max() < 1e-10


def test_paper_design_closure_and_module():
    """The spec's checks: a = 59.944 mm, perimeter 192.886 mm (module at z = 22)."""
    law = solve_pair({k: np.array([float(v)]) for k, v in PAPER_LIMACON.items()},
                     np.array([22.0]), 256)
    assert law.centre_distance[0] == pytest.approx(59.944, abs=5e-4)
    assert law.perimeter[0] == pytest.approx(192.886, abs=5e-4)


# ---------------------------------------------------------------------------- hard cases
def _paper(**changes):
    columns = {**{k: np.array([float(v)]) for k, v in {**PAPER_LIMACON, **PAPER_TRAIN}.items()},
               "teeth": np.array([22.0]), "depth": np.array([35.0]),
               "circles": np.full((1, 7), 45.0)}
    columns.update({k: np.array([float(v)]) for k, v in changes.items()})
    return columns


@pytest.mark.parametrize("changes, reason", [
    (dict(g2=-20.0), "pointed_pitch_curve"),          # swing 1:14.7, r1 under 3 modules
    (dict(teeth=7.0), "pointed_pitch_curve"),         # module 8.8 mm: both gears too small
    (dict(depth=800.0), "no_soil_crossing"),          # deeper than the tip path is high
], ids=["ratio-swing", "few-teeth", "too-deep"])
def test_designs_the_loader_refuses_are_invalid(changes, reason):
    found = screen(_paper(**changes), SPACINGS)
    assert not found.valid[0] and found.reason[0] == reason
    assert all(np.isnan(v[0]) for v in found.values.values())


def test_tiny_intermediate_radius_as_the_loader_finds_it(base_tables):
    lobed = {"a1": 3.761, "b1": 34.36, "c1": -6.648, "d1": 35.266, "e1": 2.859,
             "f1_rad": 9.161, "f2_rad": 3.896, "g1": -8.692, "g2": -4.891, "teeth": 10}
    tables = tables_with(base_tables, (lobed, {}, {}, 35.0))
    with pytest.raises(cadgen.ParameterError) as caught:
        cadgen.validate_data(tables)
    assert {p.code for p in caught.value.problems} == {"tiny_intermediate_radius"}
    found = screen(columns_of(tables, np.full(7, 40.0)), SPACINGS)
    assert found.reason[0] == "tiny_intermediate_radius"


def test_pitch_curve_through_its_centre_is_invalid():
    curve = LimaconPitchCurve(**PAPER_LIMACON)
    _, x, y = curve._xy(1.0)
    found = screen(_paper(g1=PAPER_LIMACON["g1"] - float(x), g2=PAPER_LIMACON["g2"] - float(y)),
                   SPACINGS)
    assert found.reason[0] == "pointed_pitch_curve"


@pytest.mark.parametrize("depth", [0.1, 35.0, 300.0], ids=["shallow", "paper", "deep"])
def test_depth_extremes_match_the_exact_path(depth):
    columns = _paper(depth=depth)
    found = screen(columns, SPACINGS)
    assert_within_tolerance(found.values, exact_values(_exact(columns, 0)))


def test_a_coarse_grid_hands_unresolved_laws_to_a_finer_one():
    columns = _paper()
    found = screen(columns, SPACINGS, samples=16, max_samples=1024)
    assert found.samples[0] > 16
    assert_within_tolerance(found.values, exact_values(_exact(columns, 0)))
    refused = screen(columns, SPACINGS, samples=16, max_samples=16)
    assert refused.reason[0] == "closure_unresolved"


def test_rows_do_not_depend_on_each_other():
    rng = np.random.default_rng(3)
    columns = _random_population(rng, 60)
    whole = screen(columns, SPACINGS)
    for row in (0, 17, 59):
        alone = screen({k: v[row:row + 1] for k, v in columns.items()}, SPACINGS)
        assert alone.reason[0] == whole.reason[row]
        for key, values in alone.values.items():
            np.testing.assert_array_equal(values[0], whole.values[key][row])


def test_every_input_is_checked():
    columns = _paper()
    del columns["L2"]
    with pytest.raises(ValueError, match="L2"):
        screen(columns, SPACINGS)
    with pytest.raises(ValueError, match="circles"):
        screen({**_paper(), "circles": np.ones((1, 3))}, SPACINGS)
    assert set(DESIGN_FIELDS) | {"circles"} == set(_paper())


# ------------------------------------------------------------------------------ margins
def test_margins_by_kind_of_bound():
    values = np.array([480.0, 500.0, 530.0])
    margin, scale = margins(values, 500.0, None)
    np.testing.assert_array_equal(margin, [-20.0, 0.0, 30.0])
    assert scale == 500.0
    margin, scale = margins(np.array([-1.0, 10.0, 28.0, 35.0]), 0.0, 30.0)
    np.testing.assert_array_equal(margin, [-1.0, 10.0, 2.0, -5.0])
    assert scale == 30.0
    margin, _ = margins(np.array([0.0, 1.0, 3.0]), 1.0, 1.0)
    np.testing.assert_array_equal(margin, [-1.0, 0.0, -2.0])
    # a bound per design (searched targets), and a bound of 0 has no scale
    margin, scale = margins(np.array([5.0, 5.0]), None, np.array([10.0, 4.0]))
    np.testing.assert_array_equal(margin / scale, [0.5, -0.25])
    assert math.isnan(margins(3.0, 0.0, None)[1])
    # a met equality target leaves min_margin to the others; a failed one counts
    normalised = np.array([[0.2, 0.1, 0.0], [0.2, 0.1, -1.0]])
    np.testing.assert_array_equal(min_margin(normalised, [False, False, True]), [0.1, -1.0])


# ---------------------------------------------------------------------------- cam events
def test_cam_events_as_cam_timing_finds_them():
    """Where the tip clears the seedling after its exit (kinematics.cam.cam_timing's
    ``seedling_cleared``), for seedlings it clears and ones it never does."""
    from kinematics.cam import cam_timing
    from kinematics.errors import DesignError

    rng = np.random.default_rng(9)
    columns = _random_population(rng, 40)
    columns["seedling_height"] = rng.choice([0.0, 100.0, 400.0, 650.0, 900.0], 40)
    found = screen(columns, SPACINGS)
    outcomes = set()
    for row in np.flatnonzero(found.valid):
        evaluation = _exact(columns, row)
        curve = LimaconPitchCurve(**{k: float(columns[k][row]) for k in LIMACON_FIELDS})
        mechanism = PlantingMechanism(curve, *(float(columns[k][row]) for k in (
            "i12", "i13", "R", "r", "L1", "L2", "phi0", "phic", "n")))
        assert found.events["lowest"][row] == pytest.approx(evaluation.events.lowest, abs=1e-9)
        assert found.events["exit"][row] == pytest.approx(evaluation.events.exit, abs=1e-9)
        try:
            cleared = cam_timing(mechanism, evaluation.events,
                                 seedling_height=float(columns["seedling_height"][row]),
                                 opening_offset=0.0, opening_duration=0.0, closing_delay=0.0,
                                 closing_duration=0.0, closed_before_catch=0.0
                                 ).events["seedling_cleared"]
        except DesignError:
            outcomes.add("never")
            assert np.isnan(found.events["cleared"][row])
            assert found.events["seedling_room"][row] < 0.0
            continue
        outcomes.add("cleared")
        assert found.events["cleared"][row] == pytest.approx(cleared, abs=1e-9)
        assert found.events["seedling_room"][row] >= 0.0
    assert outcomes == {"never", "cleared"}
