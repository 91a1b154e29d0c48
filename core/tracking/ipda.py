"""Integrated probabilistic data association (Mušicki, Evans, Stanković 1994), SPEC §4.

One cycle per track and frame, ψ the probability of track existence:

- existence prediction (eq. 9): ψ⁻ = p11·ψ + p21·(1 − ψ)
- likelihood ratios: Λᵢ = N(νᵢ; 0, S) / (P_G·ρ), computed in the log domain
- δ = P_D·P_G·(1 − ΣΛᵢ)  (δ = P_D·P_G when no measurement is validated)
- ψ = (1 − δ)·ψ⁻ / (1 − δ·ψ⁻)
- β₀ = (1 − P_D·P_G)/(1 − δ), βᵢ = P_D·P_G·Λᵢ/(1 − δ)
- x = x⁻ + K·Σβᵢνᵢ, P = β₀·P⁻ + (1 − β₀)·P_c + K·(Σβᵢνᵢνᵢᵀ − ννᵀ)·Kᵀ, P_c by the Joseph form.

Clutter density ρ: given (parametric) or non-parametric ρ̂ = m̂/V, m̂ = m − P_D·P_G·ψ⁻.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba.extending import register_jitable
from scipy.linalg import cho_solve

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)
from core.tracking.ekf import joseph_update, symmetrize
from core.tracking.gating import mahalanobis_squared

__all__ = [
    "LOG_2PI",
    "predict_existence",
    "log_likelihood_ratios",
    "nonparametric_density",
    "Association",
    "associate",
    "update_existence",
    "pda_update",
    "combined_nis",
]

LOG_2PI = math.log(2.0 * math.pi)


@register_jitable
def predict_existence(psi: float, p11: float, p21: float) -> float:
    """ψ⁻ = p11·ψ + p21·(1 − ψ) (eq. 9), clipped to [0, 1]."""
    # ψ⁻ = p11 ψ + p21 (1 − ψ)
    return min(1.0, max(0.0, p11 * psi + p21 * (1.0 - psi)))


def nonparametric_density(m: int, pdpg_psi: float, volume: float) -> float:
    """Non-parametric clutter density ρ̂ = m̂/V with m̂ = m − P_D·P_G·ψ⁻ (per m·rad·m/s).

    Guard: when m̂ ≤ 0 (possible only for P_D·P_G·ψ⁻ = 1 with one measurement) m̂ = m, the
    plain non-parametric PDA estimate. Only meaningful for m ≥ 1.
    """
    m_hat = m - pdpg_psi
    if m_hat <= 0.0:
        m_hat = float(m)
    # ρ̂ = m̂ / V
    return m_hat / volume


def log_likelihood_ratios(d2: np.ndarray, log_det_S: float, p_g: float, rho: float) -> np.ndarray:
    """log Λᵢ = log N(νᵢ; 0, S) − log(P_G·ρ), d2 the squared Mahalanobis distances (m,)."""
    n = 3
    # log N(ν; 0, S) = −½ d² − ½ log det S − (n/2) log 2π
    log_n = -0.5 * d2 - 0.5 * log_det_S - 0.5 * n * LOG_2PI
    # Λ = N / (P_G ρ)
    return log_n - math.log(p_g * rho)


@dataclass(frozen=True, slots=True, kw_only=True)
class Association:
    """Result of the IPDA association step of one track.

    Attributes
    ----------
    delta
        δ = P_D·P_G·(1 − ΣΛᵢ) (may be very negative).
    one_minus_delta
        1 − δ = 1 − P_D·P_G + P_D·P_G·ΣΛᵢ ≥ 0.
    beta0
        Probability that no validated measurement is the target's.
    beta
        βᵢ of the m validated measurements, shape (m,); β₀ + Σβᵢ = 1.
    """

    delta: float
    one_minus_delta: float
    beta0: float
    beta: np.ndarray


def associate(log_lr: np.ndarray, pdpg: float) -> Association:
    """δ and the association probabilities β from log Λᵢ (m,), computed with log-sum-exp.

    ``P_D·P_G = 1`` with no measurement (1 − δ = 0) is the one 0/0 case: β₀ = 1 then.
    """
    m = len(log_lr)
    if m == 0:
        return Association(delta=pdpg, one_minus_delta=1.0 - pdpg, beta0=1.0, beta=np.zeros(0))
    # a₀ = log(1 − P_D P_G), aᵢ = log(P_D P_G Λᵢ); 1 − δ = e^{a₀} + Σ e^{aᵢ}
    a0 = math.log1p(-pdpg) if pdpg < 1.0 else -math.inf
    a = math.log(pdpg) + np.asarray(log_lr, dtype=np.float64)
    top = max(a0, float(np.max(a)))
    lse = top + math.log(math.exp(a0 - top) + float(np.sum(np.exp(a - top))))
    # β₀ = (1 − P_D P_G)/(1 − δ), βᵢ = P_D P_G Λᵢ/(1 − δ)
    beta0 = math.exp(a0 - lse)
    beta = np.exp(a - lse)
    one_minus_delta = math.exp(lse)
    return Association(
        delta=1.0 - one_minus_delta, one_minus_delta=one_minus_delta, beta0=beta0, beta=beta
    )


def update_existence(psi_pred: float, assoc: Association, pdpg: float, m: int) -> float:
    """ψ = (1 − δ)·ψ⁻ / (1 − δ·ψ⁻), in [0, 1], with the 0/0 cases explicit.

    ψ⁻ = 0 gives 0 and ψ⁻ = 1 gives 1 (certain existence is kept for every 1 − δ > 0, and by
    continuity also for P_D·P_G = 1 without measurements, the one 0/0 case).
    """
    if psi_pred <= 0.0:
        return 0.0
    if psi_pred >= 1.0:
        return 1.0
    if m == 0:
        # ψ = (1 − P_D P_G) ψ⁻ / (1 − P_D P_G ψ⁻)
        return (1.0 - pdpg) * psi_pred / (1.0 - pdpg * psi_pred)
    w = assoc.one_minus_delta
    # 1 − δ ψ⁻ = (1 − ψ⁻) + (1 − δ) ψ⁻, both terms ≥ 0 and the first > 0
    psi = w * psi_pred / ((1.0 - psi_pred) + w * psi_pred)
    return min(1.0, max(0.0, psi))


def pda_update(
    x_pred: np.ndarray,
    P_pred: np.ndarray,
    H: np.ndarray,
    R: np.ndarray,
    L: np.ndarray,
    nu: np.ndarray,
    assoc: Association,
) -> tuple[np.ndarray, np.ndarray]:
    """PDA state update with the spread of means.

    Parameters
    ----------
    x_pred, P_pred
        Predicted state (n,) and covariance (n, n).
    H, R
        Measurement Jacobian (3, n) and noise covariance (3, 3).
    L
        Lower Cholesky factor of S = H P⁻ Hᵀ + R, (3, 3).
    nu
        Innovations of the validated measurements (m, 3), azimuth wrapped.
    assoc
        δ and β from :func:`associate`.

    Returns
    -------
    x, P
        Updated state (n,) and symmetric covariance (n, n).
    """
    if len(nu) == 0:
        return x_pred.copy(), P_pred.copy()
    # K = P⁻ Hᵀ S⁻¹ (Cholesky solve)
    K = cho_solve((L, True), H @ P_pred).T
    beta = assoc.beta
    # ν̄ = Σ βᵢ νᵢ
    nu_bar = beta @ nu
    # x = x⁻ + K ν̄
    x = x_pred + K @ nu_bar
    # P_c = (I − K H) P⁻ (I − K H)ᵀ + K R Kᵀ (Joseph form)
    P_c = joseph_update(P_pred, K, H, R)
    d = nu - nu_bar
    # Σβᵢνᵢνᵢᵀ − ν̄ν̄ᵀ = Σβᵢ(νᵢ − ν̄)(νᵢ − ν̄)ᵀ + β₀ ν̄ν̄ᵀ (positive semi-definite form)
    spread = (d.T * beta) @ d + assoc.beta0 * np.outer(nu_bar, nu_bar)
    # P = β₀ P⁻ + (1 − β₀) P_c + K (Σβνν' − ν̄ν̄') Kᵀ
    P = assoc.beta0 * P_pred + (1.0 - assoc.beta0) * P_c + K @ spread @ K.T
    return x, symmetrize(P)


def combined_nis(nu: np.ndarray, beta: np.ndarray, L: np.ndarray) -> float:
    """Normalised innovation squared of the PDA update, ε = ν̃ᵀ S⁻¹ ν̃ (unitless).

    Parameters
    ----------
    nu
        Innovations of the validated measurements (m, 3), azimuth wrapped.
    beta
        Their association probabilities given existence βᵢ (m,), as in :func:`pda_update`.
    L
        Lower Cholesky factor of S = H P⁻ Hᵀ + R, (3, 3).

    Returns
    -------
    float
        ε with ν̃ = Σᵢ βᵢ νᵢ the combined innovation; NaN when m = 0 (no update).
    """
    if len(nu) == 0:
        return math.nan
    # ν̃ = Σ βᵢ νᵢ
    nu_bar = beta @ nu
    # ε = ν̃ᵀ S⁻¹ ν̃
    return float(mahalanobis_squared(nu_bar[None, :], L)[0])
