"""The CV (and CA) IPDA step of the compiled tracker against numbers derived by hand.

Written for the CV-vs-CA investigation (docs/report/cv-vs-ca.md): initiation (state from
z = [r, az, vr], P0 in the state order [x, y, vx, vy(, ax, ay)]), Q0 = ΓΓᵀ per axis placed in the
state order, the Jacobian of eq. (11) and one IPDA update with one validated measurement, all
recomputed here with plain numpy and closed forms, independent of core.tracking.ekf/models.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import chi2

from core.tracking import TrackerParams
from core.tracking.kernel import run_tracker_compiled

T = 0.08


def _hand_F_Q(model: str, q: float) -> tuple[np.ndarray, np.ndarray]:
    """F and Q written out element by element for the state [x, y, vx, vy(, ax, ay)]."""
    n = 4 if model == "cv" else 6
    F = np.eye(n)
    F[0, 2] = F[1, 3] = T
    g = [T * T / 2, T] if model == "cv" else [T * T / 2, T, 1.0]
    if model == "ca":
        F[0, 4] = F[1, 5] = T * T / 2
        F[2, 4] = F[3, 5] = T
    Q = np.zeros((n, n))
    # per axis a ∈ {x, y}: the derivative-i entry of axis a sits at state index 2·i + a
    for a in range(2):
        for i in range(len(g)):
            for j in range(len(g)):
                Q[2 * i + a, 2 * j + a] = q * g[i] * g[j]
    return F, Q


def _hand_H(s: np.ndarray) -> np.ndarray:
    x, y, vx, vy = s[:4]
    r = math.hypot(x, y)
    H = np.zeros((3, len(s)))
    H[0, :2] = x / r, y / r
    H[1, :2] = y / r**2, -x / r**2
    # vr = (x vx + y vy)/r: ∂/∂x = vx/r − x (x vx + y vy)/r³, likewise y
    H[2, 0] = vx / r - x * (x * vx + y * vy) / r**3
    H[2, 1] = vy / r - y * (x * vx + y * vy) / r**3
    H[2, 2:4] = x / r, y / r
    return H


@pytest.mark.parametrize("model", ["cv", "ca"])
def test_initiation_and_one_ipda_update_by_hand(model: str) -> None:
    p0 = (0.3, 0.5, 0.7, 1.1) + ((0.13, 0.17) if model == "ca" else ())
    params = TrackerParams(
        model=model,
        q_coeff=2.5,
        r11=0.05,
        r22=0.02,
        r33=0.25,
        p0=p0,
        p_d=0.9,
        p_te=0.4,
        p11=0.95,
        p21=0.01,
        clutter_density=0.0073,
    )
    z0 = np.array([5.0, 0.3, -1.2])
    z1 = np.array([4.93, 0.305, -1.15])
    res = run_tracker_compiled([z0[None, :], z1[None, :]], params, T)
    # ---- frame 0: one tentative track at the measurement, velocity vr along the line of sight
    f0 = res.frames[0]
    assert len(f0.ids) == 1
    s0 = np.zeros(len(p0))
    s0[:4] = (5 * math.sin(0.3), 5 * math.cos(0.3), -1.2 * math.sin(0.3), -1.2 * math.cos(0.3))
    np.testing.assert_allclose(f0.state[0], s0, atol=1e-12)
    np.testing.assert_allclose(f0.covariance[0], np.diag(np.square(p0)), atol=1e-15)
    assert f0.psi[0] == pytest.approx(0.4)
    # ---- frame 1: prediction and one IPDA update with the single validated measurement
    F, Q = _hand_F_Q(model, 2.5)
    xp = F @ s0
    Pp = F @ np.diag(np.square(p0)) @ F.T + Q
    r = math.hypot(xp[0], xp[1])
    zp = np.array([r, math.atan2(xp[0], xp[1]), (xp[0] * xp[2] + xp[1] * xp[3]) / r])
    H = _hand_H(xp)
    R = np.diag([0.05**2, 0.02**2, 0.25**2])
    S = H @ Pp @ H.T + R
    nu = z1 - zp
    d2 = nu @ np.linalg.solve(S, nu)
    assert d2 <= chi2.ppf(0.99, 3)  # validated
    # Λ = N(ν; 0, S)/(P_G ρ); δ = P_D P_G (1 − Λ); β₁ = P_D P_G Λ/(1 − δ), β₀ = 1 − β₁
    lam = math.exp(-0.5 * d2) / math.sqrt(np.linalg.det(2 * math.pi * S)) / (0.99 * 0.0073)
    pdpg = 0.9 * 0.99
    delta = pdpg * (1 - lam)
    b1 = pdpg * lam / (1 - delta)
    b0 = (1 - pdpg) / (1 - delta)
    assert b0 + b1 == pytest.approx(1.0)
    K = Pp @ H.T @ np.linalg.inv(S)
    x1 = xp + K @ (b1 * nu)
    Pc = (np.eye(len(p0)) - K @ H) @ Pp  # = the Joseph form at the optimal gain
    P1 = b0 * Pp + (1 - b0) * Pc + K @ (b1 * np.outer(nu, nu) - np.outer(b1 * nu, b1 * nu)) @ K.T
    # ψ⁻ = p11 ψ + p21 (1 − ψ); ψ = (1 − δ) ψ⁻ / (1 − δ ψ⁻)
    pm = 0.95 * 0.4 + 0.01 * 0.6
    psi1 = (1 - delta) * pm / (1 - delta * pm)
    f1 = res.frames[1]
    assert len(f1.ids) == 1 and f1.ids[0] == f0.ids[0]  # gated: no new track
    np.testing.assert_allclose(f1.state[0], x1, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(f1.covariance[0], P1, rtol=1e-8, atol=1e-14)
    assert f1.psi[0] == pytest.approx(psi1, rel=1e-10)
    assert bool(f1.confirmed[0]) == (psi1 >= 0.9)


def test_cv_converges_to_a_constant_velocity_truth() -> None:
    """Exact measurements of a constant-velocity walk: the CV estimate converges to the truth
    (no bias from the model, the initiation or the Jacobian), to 1 mm and 1 cm/s in 60 frames."""
    v = np.array([0.6, -1.1])
    p = np.array([-2.0, 8.0]) + np.arange(60)[:, None] * T * v
    r = np.hypot(p[:, 0], p[:, 1])
    z = np.stack([r, np.arctan2(p[:, 0], p[:, 1]), (p @ v) / r], axis=1)
    params = TrackerParams(model="cv", q_coeff=0.5, r11=0.02, r22=0.005, r33=0.1, p_te=0.5)
    res = run_tracker_compiled([zi[None, :] for zi in z], params, T)
    assert res.has_estimate[-1]
    np.testing.assert_allclose(res.estimate_state[-1, :2], p[-1], atol=1e-3)
    np.testing.assert_allclose(res.estimate_state[-1, 2:4], v, atol=1e-2)
