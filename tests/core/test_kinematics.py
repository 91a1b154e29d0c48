"""Eq. (6), the walk the scenes and the synthetic tracker scenes integrate."""

from __future__ import annotations

import numpy as np

from core.kinematics import integrate_eq6

DT = 0.08


def test_integrate_eq6_hand_computed() -> None:
    # p0 = 0, v0 = (1, 0), a = (0, 1): v(1) = (1, 0.08), p(1) = (0.08, 0.0064),
    # v(2) = (1, 0.16), p(2) = (0.16, 0.0064 + 0.0128)
    p, v = integrate_eq6(np.zeros(2), np.array([1.0, 0.0]), np.tile([0.0, 1.0], (3, 1)), DT)
    np.testing.assert_allclose(v, [[1, 0], [1, 0.08], [1, 0.16]], atol=1e-15)
    np.testing.assert_allclose(p, [[0, 0], [0.08, 0.0064], [0.16, 0.0192]], atol=1e-15)


def test_the_synthetic_walk_and_the_scene_walk_are_one_integration() -> None:
    """A synthetic class-b walk obeys eq. (6) of its own accelerations to the last bit."""
    from core.tracking.synthetic import synthetic_trajectory

    pos, vel = synthetic_trajectory("b", np.random.default_rng(4))
    # a(t-1) = (v(t) - v(t-1)) / Δt recovered, then integrated again: the same positions
    a = np.zeros_like(vel)
    a[:-1] = (vel[1:] - vel[:-1]) / DT
    p, v = integrate_eq6(pos[0], vel[0], a, DT)
    np.testing.assert_allclose(p, pos, atol=1e-9)
    np.testing.assert_allclose(v, vel, atol=1e-12)
