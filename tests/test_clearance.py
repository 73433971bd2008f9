"""Kinematic arm distance and ground clearance against brute force."""

import numpy as np
import pytest

from kinematics.clearance import (HousingCircle, arm_distance, ground_clearance,
                                  polyline_distance, segment_distances)
from kinematics.planting import CENTRE_LINE


def brute_segment_distance(p0, p1, q0, q1, samples=801):
    s = np.linspace(0, 1, samples)[:, None]
    a = p0 + s * (p1 - p0)
    b = q0 + s * (q1 - q0)
    return np.linalg.norm(a[:, None, :] - b[None, :, :], axis=-1).min()


def test_segment_distance_against_dense_points(rng):
    # sampled points are at most half a spacing (28 mm / 800 / 2 per segment) off the segments
    for _ in range(25):
        p0, p1, q0, q1 = rng.uniform(-10, 10, (4, 2))
        exact = segment_distances(p0, p1, q0, q1)
        brute = brute_segment_distance(p0, p1, q0, q1)
        assert exact <= brute + 1e-12
        assert exact == pytest.approx(brute, abs=0.036)


def test_crossing_and_touching_segments():
    assert segment_distances([0, -1], [0, 1], [-1, 0], [1, 0]) == 0.0
    assert segment_distances([0, 0], [1, 0], [1, 0], [2, 5]) == 0.0  # shared end
    assert segment_distances([0, 0], [1, 0], [2, 0], [3, 0]) == pytest.approx(1.0)  # collinear
    assert segment_distances([0, 0], [0, 0], [3, 4], [3, 4]) == pytest.approx(5.0)  # points


def test_arm_distance_against_dense_scan(paper_mechanism):
    m = paper_mechanism
    result = arm_distance(m, steps=360)
    phi = np.linspace(0, np.pi, 200_001)
    lines = [np.stack([m.positions(phi, arm=k, points=CENTRE_LINE)[p] for p in CENTRE_LINE], 1)
             for k in (0, 1)]
    dense = polyline_distance(*lines)
    assert result.value == pytest.approx(dense.min(), abs=1e-8)
    assert result.value <= dense.min() + 1e-12
    assert result.certified


def test_ground_clearance_against_dense_scan(paper_mechanism):
    m = paper_mechanism
    circles = [HousingCircle("gearbox1", "O", 50.0), HousingCircle("gearbox1", "C", 40.0),
               HousingCircle("gearbox2", "D", 55.0), HousingCircle("gearbox2", "E", 40.0)]
    soil = -500.0
    result, nearest = ground_clearance(m, circles, soil, steps=360)
    phi = np.linspace(0, 2 * np.pi, 400_001)
    lows = [np.zeros_like(phi) - 50.0] + [m.motion(phi, c.point).position[:, 1] - c.radius
                                          for c in circles[1:]]
    dense = np.min(lows, axis=0) - soil
    assert result.value == pytest.approx(dense.min(), abs=1e-8)
    # E is lowest at phi = 180 deg: closed form Rc + a + 2r
    expected = soil * -1 - (2 * 36.0 * 3.3 + m.centre_distance + 54.0) - 40.0
    assert result.value == pytest.approx(expected, abs=1e-9)
    assert nearest.point == "E"


# ------------------------------------------------------------------ arms that cross or touch
# An independent distance: shapely's (GEOS) distance between the two centre-line polylines,
# computed here from the mechanism's positions, not from kinematics.clearance.


def _shapely_distance(mechanism, phi):
    import shapely

    lines = [shapely.linestrings(np.stack(
        [mechanism.positions(phi, arm=k, points=CENTRE_LINE)[p] for p in CENTRE_LINE], axis=1))
        for k in (0, 1)]
    return shapely.distance(*lines)


def _brute_minimum(mechanism, poses):
    """Least distance over ``poses`` carrier angles in [0, pi], polished by Brent round the
    best pose (shapely's distance again): the scan alone can sit above a smooth minimum."""
    from scipy.optimize import minimize_scalar

    phi = np.linspace(0.0, np.pi, poses)
    dense = _shapely_distance(mechanism, phi)
    k = int(dense.argmin())
    if dense[k] == 0.0:
        return 0.0, dense
    step = phi[1] - phi[0]
    polished = minimize_scalar(lambda s: float(_shapely_distance(mechanism, np.array([s]))[0]),
                               bounds=(max(phi[k] - step, 0.0), min(phi[k] + step, np.pi)),
                               method="bounded", options={"xatol": 1e-12})
    return min(float(dense[k]), float(polished.fun)), dense


def _planter(paper_curve, **changes):
    from kinematics.planting import PlantingMechanism

    values = dict(i12=1.2, i13=1.1, R=36.0, r=27.0, L1=130.0, L2=190.0, phi0=np.pi / 2,
                  phic=np.pi / 2, n=3.0)
    return PlantingMechanism(paper_curve, **{**values, **changes})


# L1 = 250 mm: the planter plates E-P1 of the two arms are long enough to cross each other
# over a range of carrier angles (the paper's arms clear by 242.64 - L1 mm, see below).
@pytest.mark.parametrize("L1, crossing", [(250.0, True), (242.64, False), (242.6408, False)],
                         ids=["crossing", "0.8-um-apart", "35-nm-apart"])
def test_arms_that_cross_or_nearly_touch_are_certified_quickly(paper_curve, L1, crossing):
    mechanism = _planter(paper_curve, L1=L1)
    result = arm_distance(mechanism)
    # (i) a small budget: the search stopped on its own, well inside it (its speed is the
    # benchmark's to measure; the evaluations count does not depend on a busy machine)
    assert result.certified and not result.budget_spent
    assert result.evaluations < 100_000
    # (ii) agrees with 200,000 poses of an independent distance within its stated gap
    brute, dense = _brute_minimum(mechanism, 200_001)
    assert result.bound <= brute + 1e-12
    assert result.value <= brute + 1e-9
    assert (brute == 0.0) == crossing == (result.value == 0.0)
    if crossing:   # a crossing is a distance of exactly 0, certified: bound 0 = value 0
        assert result.bound == result.value == 0.0 and (dense == 0.0).sum() > 1000


def test_arms_touching_closer_than_the_budget_reaches_report_their_gap(paper_curve):
    # 0.14 nm apart at the closest: the kink of the distance at touching leaves only
    # bounds that close slowly; the budget stops the search, which says what it reached
    mechanism = _planter(paper_curve, L1=242.640835)
    result = arm_distance(mechanism, max_evaluations=20_000)
    assert result.budget_spent and not result.certified
    assert result.evaluations <= 20_000
    brute, _ = _brute_minimum(mechanism, 200_001)
    assert result.bound <= brute + 1e-12 and result.bound >= 0.0
    assert result.value <= brute + 1e-9
    assert result.gap == result.value - result.bound > result.atol
    assert result.verdict_above(10.0) == "fail"        # the value is below: certain
    assert result.verdict_above(-1.0) == "pass"        # the bound is above: certain
    assert result.verdict_above(0.5 * (result.bound + result.value)) == "undecided"


def test_arm_distance_bound_holds_over_the_parameter_space(paper_curve):
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st

    @settings(max_examples=25, deadline=None, derandomize=True, database=None,
              suppress_health_check=[HealthCheck.too_slow])
    @given(L1=st.floats(100.0, 320.0), L2=st.floats(120.0, 400.0), R=st.floats(30.0, 40.0),
           r=st.floats(20.0, 32.0), phic=st.floats(np.pi / 3, 2 * np.pi / 3))
    def check(L1, L2, R, r, phic):
        mechanism = _planter(paper_curve, L1=L1, L2=L2, R=R, r=r, phic=phic)
        result = arm_distance(mechanism, steps=720)
        brute, _ = _brute_minimum(mechanism, 20_001)
        assert result.bound <= brute + 1e-9
        assert brute <= result.value + 1e-6
        assert 0.0 <= result.bound <= result.value
        seen.add(("crossing" if brute == 0.0 else "clear", result.certified))

    seen = set()
    check()
    assert {("crossing", True), ("clear", True)} <= seen   # both kinds were drawn
