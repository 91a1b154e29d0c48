"""IPDA maths: hand-computed δ, ψ, β; Σβ = 1; the no-measurement recursion; the 0/0 cases; and
equality of the state update with an independently written parametric PDAF."""

import math

import numpy as np
import pytest
from scipy.stats import chi2

from core.tracking import ekf, gating, ipda
from core.tracking.kernel import track_frames
from core.tracking.params import TrackerParams

PDPG = 0.9 * 0.99


def test_hand_computed_single_measurement():
    a = ipda.associate(np.array([math.log(2.0)]), PDPG)
    # δ = P_D P_G (1 − Λ) = −0.891, 1 − δ = 1.891
    assert a.delta == pytest.approx(-0.891, abs=1e-14)
    assert a.one_minus_delta == pytest.approx(1.891, abs=1e-14)
    assert a.beta0 == pytest.approx(0.109 / 1.891, abs=1e-14)
    assert a.beta[0] == pytest.approx(1.782 / 1.891, abs=1e-14)
    psi = ipda.update_existence(0.5, a, PDPG, 1)
    # ψ = 1.891·0.5 / (1 + 0.891·0.5)
    assert psi == pytest.approx(0.9455 / 1.4455, abs=1e-14)


def test_hand_computed_two_measurements():
    a = ipda.associate(np.log([0.5, 1.5]), PDPG)
    assert a.delta == pytest.approx(PDPG * (1 - 2.0), abs=1e-14)
    np.testing.assert_allclose(a.beta, [PDPG * 0.5 / 1.891, PDPG * 1.5 / 1.891], atol=1e-14)
    assert a.beta0 + a.beta.sum() == pytest.approx(1.0, abs=1e-15)
    # ψ⁻ = p11 ψ + p21 (1 − ψ)
    assert ipda.predict_existence(0.6, 0.98, 0.1) == pytest.approx(0.98 * 0.6 + 0.1 * 0.4)


def test_betas_sum_to_one_over_extreme_ratios():
    rng = np.random.default_rng(0)
    for _ in range(200):
        m = int(rng.integers(1, 8))
        log_lr = rng.uniform(-700, 700, m)
        pdpg = float(rng.choice([0.5, 0.8, 0.98, 1.0]))
        a = ipda.associate(log_lr, pdpg)
        assert np.all(np.isfinite(a.beta)) and 0.0 <= a.beta0 <= 1.0
        assert a.beta0 + a.beta.sum() == pytest.approx(1.0, abs=1e-12)
        psi = ipda.update_existence(0.3, a, pdpg, m)
        assert 0.0 <= psi <= 1.0


def test_no_measurement_existence_is_the_closed_form_exactly():
    for pp in (0.0, 1e-300, 0.2, 0.5, 0.97, 1.0 - 1e-16):
        for pdpg in (0.792, 0.891, 0.9801):
            a = ipda.associate(np.zeros(0), pdpg)
            assert a.beta0 == 1.0 and a.delta == pdpg
            assert ipda.update_existence(pp, a, pdpg, 0) == (1 - pdpg) * pp / (1 - pdpg * pp)


def test_no_measurement_recursion_in_the_kernel_is_exact():
    # one detection at frame 0 (birth, ψ = P_te), then nine empty frames
    p = TrackerParams(p_te=0.8, p11=0.95, p21=0.05, confirm_threshold=0.0, delete_threshold=0.0)
    z = np.array([[4.0, 0.1, 0.5]])
    f_off = np.array([0] + [1] * 10)
    out = track_frames(z, f_off, np.array([0, 10]), np.array([0]), p, 0.08)
    psi, expect = 0.8, []
    pdpg = p.p_d * p.p_g
    for _ in range(9):
        pp = p.p11 * psi + p.p21 * (1 - psi)
        psi = (1 - pdpg) * pp / (1 - pdpg * pp)
        expect.append(psi)
    np.testing.assert_allclose(out[2][1:], expect, rtol=1e-15, atol=0)


def test_zero_over_zero_cases():
    # P_D P_G = 1 and no measurement: 1 − δ = 0, β₀ = 1
    a = ipda.associate(np.zeros(0), 1.0)
    assert a.one_minus_delta == 0.0 and a.beta0 == 1.0
    assert ipda.update_existence(0.4, a, 1.0, 0) == 0.0
    assert ipda.update_existence(1.0, a, 1.0, 0) == 1.0  # certain existence is kept
    assert ipda.update_existence(0.0, a, 1.0, 0) == 0.0
    # P_D P_G = 1 with a measurement: β₀ = 0, the measurement is the target's
    b = ipda.associate(np.array([-3.0]), 1.0)
    assert b.beta0 == 0.0 and b.beta[0] == 1.0
    assert ipda.update_existence(0.4, b, 1.0, 1) == pytest.approx(
        math.exp(-3) * 0.4 / (0.6 + math.exp(-3) * 0.4)
    )
    # ψ⁻ exactly 0 and 1 with measurements
    assert ipda.update_existence(0.0, b, 0.9, 1) == 0.0
    assert ipda.update_existence(1.0, b, 0.9, 1) == 1.0


def textbook_pdaf(x, P, z, R, p_d, p_g, rho):
    """Parametric PDAF (Bar-Shalom, Daum, Huang 2009, eqs. 33–46), written independently."""
    zp = np.array(
        [
            math.hypot(x[0], x[1]),
            math.atan2(x[0], x[1]),
            (x[0] * x[2] + x[1] * x[3]) / math.hypot(x[0], x[1]),
        ]
    )
    H = ekf.jacobian(x)  # the Jacobian is checked against finite differences elsewhere
    S = H @ P @ H.T + R
    Si = np.linalg.inv(S)
    W = P @ H.T @ Si
    nu = z - zp
    nu[:, 1] = (nu[:, 1] + np.pi) % (2 * np.pi) - np.pi
    d2 = np.einsum("ij,jk,ik->i", nu, Si, nu)
    gamma = chi2.ppf(p_g, 3)
    nu = nu[d2 <= gamma]
    d2 = d2[d2 <= gamma]
    # e_i = exp(−½ d²_i), b = ρ √det(2πS) (1 − P_D P_G)/P_D
    e = np.exp(-0.5 * d2)
    b = rho * math.sqrt(np.linalg.det(2 * np.pi * S)) * (1 - p_d * p_g) / p_d
    beta = e / (b + e.sum())
    beta0 = b / (b + e.sum())
    nu_c = beta @ nu
    x_new = x + W @ nu_c
    Pc = P - W @ S @ W.T
    P_tilde = W @ ((nu.T * beta) @ nu - np.outer(nu_c, nu_c)) @ W.T
    return x_new, beta0 * P + (1 - beta0) * Pc + P_tilde, beta0, beta


@pytest.mark.parametrize("rho", [1e-4, 0.0073, 0.5])
@pytest.mark.parametrize("psi_pred", [0.05, 0.5, 0.999])
def test_ipda_state_update_equals_parametric_pdaf(rho, psi_pred):
    rng = np.random.default_rng(int(rho * 1e4) + int(psi_pred * 100))
    x = np.array([1.5, 4.0, 0.8, -0.5])
    A = rng.normal(size=(4, 4))
    P = A @ A.T * 0.05 + np.diag([0.05, 0.05, 0.2, 0.2])
    R = np.diag([0.05**2, 0.02**2, 0.2**2])
    H = ekf.jacobian(x)
    S = gating.innovation_covariance(H, P, R)
    L = gating.cholesky(S)
    zp = ekf.measure(x)
    z = zp + rng.multivariate_normal(np.zeros(3), S, size=5) * 0.8
    nu_all = ekf.innovation(z, zp)
    d2 = gating.mahalanobis_squared(nu_all, L)
    inside = d2 <= gating.gate_threshold(0.99)
    assert inside.sum() >= 2
    nu = nu_all[inside]
    log_lr = ipda.log_likelihood_ratios(d2[inside], gating.log_det_from_cholesky(L), 0.99, rho)
    assoc = ipda.associate(log_lr, 0.9 * 0.99)
    x_new, P_new = ipda.pda_update(x, P, H, R, L, nu, assoc)
    x_ref, P_ref, beta0_ref, beta_ref = textbook_pdaf(x, P, z, R, 0.9, 0.99, rho)
    assert assoc.beta0 == pytest.approx(beta0_ref, abs=1e-12)
    np.testing.assert_allclose(assoc.beta, beta_ref, atol=1e-12)
    np.testing.assert_allclose(x_new, x_ref, rtol=0, atol=1e-10)
    np.testing.assert_allclose(P_new, P_ref, rtol=0, atol=1e-10)
    # the existence update depends on ψ⁻, the state update does not
    assert 0 < ipda.update_existence(psi_pred, assoc, 0.891, len(nu)) < 1


def test_nonparametric_density_and_guard():
    # ρ̂ = (m − P_D P_G ψ⁻)/V
    assert ipda.nonparametric_density(3, 0.5, 2.0) == pytest.approx(1.25)
    assert ipda.nonparametric_density(1, 1.0, 2.0) == pytest.approx(0.5)  # guard: m̂ = m
    # V = (4π/3) γ^{3/2} √det S for S = I: a ball of radius √γ
    assert gating.gate_volume(np.eye(3), 4.0) == pytest.approx(4 * math.pi / 3 * 8)
