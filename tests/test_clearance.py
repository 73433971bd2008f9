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
