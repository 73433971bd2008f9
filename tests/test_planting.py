"""Planting mechanism kinematics: identities, periodicity, derivatives against finite differences."""

import numpy as np
import pytest

from kinematics.metrics import vertical_extremes
from kinematics.planting import ARM_POINTS
from kinematics.sweep import certified_minimum


def test_E_path_height_identity(paper_mechanism):
    m = paper_mechanism
    common = dict(steps=720, lipschitz=m.speed_bound("E"), curvature=m.acceleration_bound("E"))
    height = lambda p: m.motion(p, "E").position[:, 1]
    low = certified_minimum(height, 0, 2 * np.pi, **common)
    high = certified_minimum(lambda p: -height(p), 0, 2 * np.pi, **common)
    Rc = 2 * 36.0 * (1 + 1.2 + 1.1)
    expected = 2 * (Rc + m.centre_distance + 2 * 27.0)
    assert -high.value - low.value == pytest.approx(expected, abs=1e-9)
    assert expected == pytest.approx(703.1, abs=0.05)  # spec figure


def test_catching_pose(paper_mechanism):
    m = paper_mechanism
    pose = m.positions(np.array([0.0]))
    top = 2 * 36.0 * 3.3 + m.centre_distance + 54.0
    np.testing.assert_allclose(pose["E"][0], [0.0, top], atol=1e-12)
    np.testing.assert_allclose(pose["P1"][0], [-130.0, top], atol=1e-9)
    np.testing.assert_allclose(pose["N"][0], [-130.0, top - 190.0], atol=1e-9)
    assert m.attitude(np.array([0.0]))[0] == pytest.approx(0.0, abs=1e-14)


@pytest.mark.parametrize("point", ARM_POINTS)
def test_second_arm_is_first_shifted_half_a_turn(paper_mechanism, point, rng):
    phi = rng.uniform(-10, 10, 64)
    second = paper_mechanism.motion(phi, point, arm=1)
    first = paper_mechanism.motion(phi + np.pi, point, arm=0)
    np.testing.assert_allclose(second.position, first.position, atol=1e-10)
    np.testing.assert_allclose(second.velocity, first.velocity, atol=1e-10)


def test_periodic_over_a_thousand_revolutions(paper_mechanism, rng):
    # hard case: no drift in F or Psi after 1000 revolutions
    m = paper_mechanism
    phi = rng.uniform(0, 2 * np.pi, 200)
    later = phi + 2 * np.pi * 1000
    np.testing.assert_allclose(m.attitude(later), m.attitude(phi), atol=1e-9)
    np.testing.assert_allclose(m.intermediate_rotation(later) - m.intermediate_rotation(phi),
                               2 * np.pi * 1000, atol=1e-9)
    np.testing.assert_allclose(m.motion(later, "N").position, m.motion(phi, "N").position,
                               atol=1e-7)


def test_attitude_is_phi_minus_integral_of_ratio(paper_mechanism):
    # Psi(phi) = phi - integral_0^phi r1/(a - r1): against adaptive quadrature
    from scipy.integrate import quad

    m = paper_mechanism
    a = m.centre_distance
    r1 = m.pitch_curve.radius
    for phi in (0.7, 2.0, 3.9, 5.5):
        integral, _ = quad(lambda t: r1(t) / (a - r1(t)), 0, phi, epsabs=1e-13, epsrel=1e-13)
        assert m.attitude(np.array([phi]))[0] == pytest.approx(phi - integral, abs=1e-11)


# 8th-order central differences: truncation ~ h^8, far below the tolerances used
FIRST = np.array([1 / 280, -4 / 105, 1 / 5, -4 / 5, 0, 4 / 5, -1 / 5, 4 / 105, -1 / 280])
SECOND = np.array([-1 / 560, 8 / 315, -1 / 5, 8 / 5, -205 / 72, 8 / 5, -1 / 5, 8 / 315, -1 / 560])


@pytest.mark.parametrize("point", ARM_POINTS)
def test_velocity_and_acceleration_against_finite_differences(paper_mechanism, point):
    m = paper_mechanism
    phi = np.linspace(0.05, 2 * np.pi, 29)
    h = 2e-3
    samples = np.array([m.motion(phi + k * h, point).position for k in range(-4, 5)])
    motion = m.motion(phi, point)
    scale = m.speed_bound(point)
    np.testing.assert_allclose(np.tensordot(FIRST, samples, 1) / h, motion.velocity,
                               atol=1e-8 * scale)
    np.testing.assert_allclose(np.tensordot(SECOND, samples, 1) / h**2, motion.acceleration,
                               atol=1e-5 * scale)


@pytest.mark.parametrize("point", ARM_POINTS)
def test_speed_and_acceleration_bounds_hold(paper_mechanism, point):
    m = paper_mechanism
    phi = np.linspace(0, 2 * np.pi, 20001)
    motion = m.motion(phi, point)
    assert np.linalg.norm(motion.velocity, axis=1).max() <= m.speed_bound(point)
    assert np.linalg.norm(motion.acceleration, axis=1).max() <= m.acceleration_bound(point)


def test_converted_ratios_of_the_built_train(paper_mechanism):
    assert paper_mechanism.converted_ratios == pytest.approx((-1.0, -0.5))


def test_tip_path_extremes_against_dense_scan(paper_mechanism):
    tip = paper_mechanism.tip_path()
    low, high = vertical_extremes(tip, steps=360)
    phi = np.linspace(0, 2 * np.pi, 2_000_001)
    y = tip.height(phi)
    assert low.value == pytest.approx(y.min(), abs=1e-9)
    assert -high.value == pytest.approx(y.max(), abs=1e-9)
    assert low.value <= y.min() and -high.value >= y.max()  # refined beats the dense scan


def test_absolute_motion_adds_the_forward_drift(paper_mechanism, rng):
    phi = rng.uniform(0, 2 * np.pi, 20)
    spacing = 185.0
    absolute = paper_mechanism.absolute_motion(phi, spacing)
    relative = paper_mechanism.motion(phi, "N")
    np.testing.assert_allclose(absolute.position[:, 0], relative.position[:, 0] + spacing / np.pi * phi)
    # derivatives of X(phi) by 8th-order finite differences
    h = 2e-3
    samples = np.array([paper_mechanism.absolute_motion(phi + k * h, spacing).position
                        for k in range(-4, 5)])
    np.testing.assert_allclose(np.tensordot(FIRST, samples, 1) / h, absolute.velocity, atol=1e-6)
    np.testing.assert_allclose(np.tensordot(SECOND, samples, 1) / h**2, absolute.acceleration,
                               atol=5e-3)
