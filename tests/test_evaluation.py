"""The paper design's metrics, against identities and second methods."""

import numpy as np
import pytest
from scipy.optimize import brentq

from kinematics.evaluation import Targets, evaluate_planting

SPACINGS = (150.0, 185.0, 200.0)


def circles(mechanism):
    """Both gearboxes' envelopes: gear tips plus a 6-mm allowance (clearance and wall)."""
    from cadgen.solids.housings import envelope_circles

    return envelope_circles(mechanism, mechanism.module(22), 6.0)


@pytest.fixture(scope="module")
def evaluation(paper_mechanism):
    return evaluate_planting(paper_mechanism, teeth=22, depth=35.0, spacings=SPACINGS,
                             carrier_speed_rpm=30.0, housing_circles=circles(paper_mechanism))


def metric(evaluation, key, spacing=None):
    (found,) = [m for m in evaluation.metrics if m.key == key and m.spacing == spacing]
    return found


def test_module_from_the_spec_figures(evaluation):
    assert metric(evaluation, "module").value == pytest.approx(192.886 / (22 * np.pi), abs=1e-5)


def test_events_against_dense_scan_and_brent(evaluation, paper_mechanism):
    # second method: dense sampling, Brent on each bracket
    tip = paper_mechanism.tip_path()
    phi = np.linspace(0, 2 * np.pi, 1_000_001)
    y = tip.height(phi)
    assert evaluation.events.lowest_height == pytest.approx(y.min(), abs=1e-8)
    soil = y.min() + 35.0
    crossings = np.flatnonzero(np.diff(np.sign(y - soil)) != 0)
    roots = [brentq(lambda s: tip.height(np.array([s]))[0] - soil, phi[i], phi[i + 1], xtol=1e-14)
             for i in crossings]
    assert len(roots) == 2
    assert evaluation.events.entry == pytest.approx(roots[0], abs=1e-10)
    assert evaluation.events.exit == pytest.approx(roots[1], abs=1e-10)
    for hole in evaluation.holes:
        x = tip.position(np.array(roots))[:, 0] + hole.spacing / np.pi * np.array(roots)
        assert hole.width == pytest.approx(abs(x[1] - x[0]), abs=1e-8)


def test_trajectory_height_and_catch_to_plant(evaluation, paper_mechanism):
    tip = paper_mechanism.tip_path()
    top = tip.height(np.array([0.0]))[0]
    assert evaluation.catch_to_plant_height == pytest.approx(top - evaluation.events.lowest_height)
    assert metric(evaluation, "trajectory_height").value >= evaluation.catch_to_plant_height


def test_velocity_identities_at_the_lowest_point(evaluation):
    omega = 2 * np.pi * 30.0 / 60.0
    relative = np.array(evaluation.speeds["relative_lowest"])
    assert abs(relative[1]) < 1e-6 * np.linalg.norm(relative)  # dy/dt = 0 at a minimum of y
    for s in SPACINGS:
        absolute = np.array(evaluation.speeds["absolute_lowest"][s])
        np.testing.assert_allclose(absolute - relative, [s / np.pi * omega, 0.0], atol=1e-12)


def test_attitude_difference_is_exit_minus_entry(evaluation):
    att = evaluation.attitudes_deg
    assert metric(evaluation, "angle_difference").value == pytest.approx(abs(att["exit"] - att["entry"]))
    assert att["catching"] == pytest.approx(0.0, abs=1e-12)


def test_every_search_is_certified(evaluation):
    for name, search in evaluation.accuracy["minimum_searches"].items():
        assert search["certified"], name
        if search["maximum"]:   # the highest point: a height, bounded from above
            assert search["value"] <= search["certified_bound"]
        else:
            assert search["certified_bound"] <= search["value"]
    highest = evaluation.accuracy["minimum_searches"]["highest_point"]
    assert highest["value"] == pytest.approx(evaluation.events.highest_height, abs=1e-9)


def test_targets_decide_pass_and_fail(paper_mechanism):
    strict = Targets(trajectory_height_min=800.0, hole_width_max=5.0)
    result = evaluate_planting(paper_mechanism, teeth=22, depth=35.0, spacings=SPACINGS,
                               targets=strict, housing_circles=circles(paper_mechanism))
    assert not metric(result, "trajectory_height").passed
    widths = {m.spacing: m.passed for m in result.metrics if m.key == "hole_width"}
    assert widths == {150.0: True, 185.0: False, 200.0: False}
    assert not result.passed
