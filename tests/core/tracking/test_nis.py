"""Gated-measurement count and NIS recorded per track: a case derived by hand (one track, one
measurement in its gate, β known in closed form), on both engines."""

import math

import numpy as np
import pytest

from core.tracking.inputs import TrackerConstants
from core.tracking.params import TrackerParams
from core.tracking.tracker import run_tracker


@pytest.mark.parametrize("engine", ["numpy", "numba"])
def test_nis_of_one_track_with_one_gated_measurement(engine):
    # frame 0: a track is born at r = 5 m, az = 0, vr = 0, i.e. x₀ = (0, 5, 0, 0);
    # frame 1: one measurement near it, inside its gate
    p = TrackerParams(model="cv", association="ipda", clutter_density=5.0)
    T = 0.08
    z1 = np.array([5.1, 0.02, 0.1])
    res = run_tracker([np.array([[5.0, 0.0, 0.0]]), z1[None, :]], p, T, engine=engine)
    born, upd = res.frames
    assert born.n_associated.tolist() == [0] and np.isnan(born.nis[0])
    assert len(upd) == 1 and upd.ids[0] == born.ids[0]

    c = TrackerConstants.build(p, T)
    x0 = np.array([0.0, 5.0, 0.0, 0.0])
    # prediction: x⁻ = F x₀ = x₀ (no velocity), P⁻ = F P₀ Fᵀ + Q
    P_pred = c.F @ c.P0 @ c.F.T + c.Q
    # at (x, y) = (0, 5) at rest: r = y, az = atan2(x, y) (∂az/∂x = 1/r), ∂vr/∂vy = y/r = 1
    H = np.array([[0.0, 1.0, 0.0, 0.0], [1.0 / 5.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
    S = H @ P_pred @ H.T + c.R
    nu = z1 - np.array([5.0, 0.0, 0.0])
    d2 = float(nu @ np.linalg.solve(S, nu))
    assert d2 <= c.gamma  # the measurement is in the gate
    # Λ = N(ν; 0, S) / (P_G ρ), β₁ = P_D P_G Λ / (1 − P_D P_G + P_D P_G Λ)
    lam = math.exp(-0.5 * d2) / math.sqrt((2 * math.pi) ** 3 * np.linalg.det(S))
    lam /= p.p_g * p.clutter_density
    pdpg = p.p_d * p.p_g
    beta1 = pdpg * lam / (1.0 - pdpg + pdpg * lam)
    assert 0.05 < beta1 < 0.95  # β₁ weighs the innovation (ε ≠ d²)
    # ν̃ = β₁ ν, ε = ν̃ᵀ S⁻¹ ν̃ = β₁² d²
    nis = beta1**2 * d2
    assert upd.n_associated.tolist() == [1]
    np.testing.assert_allclose(upd.nis[0], nis, rtol=1e-9)
    # the state moved by K ν̃ with the same ν̃
    K = P_pred @ H.T @ np.linalg.inv(S)
    np.testing.assert_allclose(upd.state[0], x0 + K @ (beta1 * nu), rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("engine", ["numpy", "numba"])
def test_no_gated_measurement_gives_zero_count_and_nan_nis(engine):
    # frame 1's measurement is far outside the gate: the track coasts (and a new one is born)
    p = TrackerParams(model="cv", association="ipda", p_te=0.9)
    res = run_tracker([np.array([[5.0, 0.0, 0.0]]), np.array([[9.0, 1.0, 0.0]])], p, engine=engine)
    upd = res.frames[1]
    old = upd.ids == res.frames[0].ids[0]
    assert old.sum() == 1 and len(upd) == 2
    assert upd.n_associated.tolist() == [0, 0]
    assert np.all(np.isnan(upd.nis))
