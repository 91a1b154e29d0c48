"""Motion models, the measurement function, its Jacobian and the r → 0 guard."""

import math

import numpy as np
import pytest

from core.tracking import ekf
from core.tracking.models import process_noise, transition_matrix


def test_cv_matrices_by_hand():
    T = 0.08
    F = transition_matrix("cv", T)
    np.testing.assert_array_equal(F[0], [1, 0, T, 0])
    np.testing.assert_array_equal(F[3], [0, 0, 0, 1])
    Q = process_noise("cv", T, 2.0)
    # Q0 = [[T⁴/4, T³/2], [T³/2, T²]] per axis
    assert Q[0, 0] == pytest.approx(2 * T**4 / 4) and Q[0, 2] == pytest.approx(2 * T**3 / 2)
    assert Q[2, 2] == pytest.approx(2 * T**2) and Q[0, 1] == 0.0 and Q[1, 3] == Q[0, 2]


def test_ca_matrices_by_hand():
    T = 0.5
    F = transition_matrix("ca", T)
    x = np.array([1.0, 2.0, 0.5, -1.0, 0.2, 0.4])
    y = F @ x
    assert y[0] == pytest.approx(1 + 0.5 * T + 0.2 * T**2 / 2)
    assert y[3] == pytest.approx(-1 + 0.4 * T) and y[5] == 0.4
    Q = process_noise("ca", T, 1.0)
    assert Q[4, 4] == 1.0 and Q[0, 4] == pytest.approx(T**2 / 2) and Q[2, 4] == pytest.approx(T)
    assert np.all(np.linalg.eigvalsh(Q) >= -1e-15)


def test_measurement_and_jacobian_against_finite_differences():
    x = np.array([1.3, 3.7, -0.6, 0.9, 0.1, 0.0])
    z = ekf.measure(x)
    r = math.hypot(1.3, 3.7)
    np.testing.assert_allclose(z, [r, math.atan2(1.3, 3.7), (1.3 * -0.6 + 3.7 * 0.9) / r])
    H = ekf.jacobian(x)
    eps = 1e-6
    for j in range(6):
        d = np.zeros(6)
        d[j] = eps
        num = (ekf.measure(x + d) - ekf.measure(x - d)) / (2 * eps)
        np.testing.assert_allclose(H[:, j], num, atol=1e-8)


def test_range_zero_gives_finite_values():
    for state in ([0.0, 0.0, 1.0, 0.0], [1e-12, -1e-12, 0.3, 0.3], [0.0, -1e-9, 0.0, 0.0]):
        x = np.array(state)
        assert np.all(np.isfinite(ekf.measure(x))) and np.all(np.isfinite(ekf.jacobian(x)))
        assert ekf.measure(x)[0] == ekf.MIN_RANGE_M


def test_wrap_angle():
    a = ekf.wrap_angle(np.array([math.pi, -math.pi, 3 * math.pi, 0.1 - 2 * math.pi, 7.0]))
    np.testing.assert_allclose(a, [math.pi, math.pi, math.pi, 0.1, 7.0 - 2 * math.pi])
    nu = ekf.innovation(np.array([[1.0, 3.1, 0.0]]), np.array([1.0, -3.1, 0.0]))
    assert nu[0, 1] == pytest.approx(6.2 - 2 * math.pi)
