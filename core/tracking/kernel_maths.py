"""The EKF and PDA arithmetic of the compiled tracker, on preallocated arrays.

The compiled counterparts of :mod:`core.tracking.ekf` (prediction, measurement function and
Jacobian), :mod:`core.tracking.gating` (innovation covariance, its Cholesky factor, the gate)
and :func:`core.tracking.ipda.pda_update` (the PDA update with the spread of means, Joseph
form), written out for the 3-D measurement ``[r, az, vr]`` so that :mod:`core.tracking.kernel_jit`
allocates nothing per frame. Each writes into the arrays it is given.
"""

from __future__ import annotations

import math

from numba import njit

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)
from core.tracking.ekf import MIN_RANGE_M

__all__ = [
    "back3",
    "cholesky3",
    "forward3",
    "gate_xy",
    "healthy",
    "innovation_covariance",
    "measure",
    "nis",
    "pda_update",
    "predict",
    "safe_xy",
    "wrap_angle",
]


@njit(cache=True)
def wrap_angle(a):
    w = ((a + math.pi) % (2.0 * math.pi)) - math.pi
    if w == -math.pi:
        w = math.pi
    return w


@njit(cache=True)
def safe_xy(x, y):
    r = math.hypot(x, y)
    if r >= MIN_RANGE_M:
        return x, y, r
    if r == 0.0:
        return 0.0, MIN_RANGE_M, MIN_RANGE_M
    s = MIN_RANGE_M / r
    return x * s, y * s, MIN_RANGE_M


@njit(cache=True)
def predict(x, P, F, f_cols, f_nnz, Q, xo, Po, tmp):
    """x⁻ = F x, P⁻ = F P Fᵀ + Q using the sparsity of F (row i: columns f_cols[i, :f_nnz[i]])."""
    n = x.shape[0]
    # x⁻ = F x
    for i in range(n):
        s = 0.0
        for q in range(f_nnz[i]):
            k = f_cols[i, q]
            s += F[i, k] * x[k]
        xo[i] = s
    # tmp = F P
    for i in range(n):
        for j in range(n):
            s = 0.0
            for q in range(f_nnz[i]):
                k = f_cols[i, q]
                s += F[i, k] * P[k, j]
            tmp[i, j] = s
    # P⁻ = (F P) Fᵀ + Q, upper triangle mirrored (symmetric by construction)
    for i in range(n):
        for j in range(i, n):
            s = 0.0
            for q in range(f_nnz[j]):
                k = f_cols[j, q]
                s += tmp[i, k] * F[j, k]
            s += Q[i, j]
            Po[i, j] = s
            Po[j, i] = s


@njit(cache=True)
def measure(x, zp, H):
    """h(x) into zp (3,), Jacobian into H (3, n)."""
    px, py, r = safe_xy(x[0], x[1])
    vx, vy = x[2], x[3]
    r2 = r * r
    r3 = r2 * r
    zp[0] = r
    zp[1] = math.atan2(px, py)
    zp[2] = (px * vx + py * vy) / r
    H[:, :] = 0.0
    H[0, 0] = px / r
    H[0, 1] = py / r
    H[1, 0] = py / r2
    H[1, 1] = -px / r2
    cross = vx * py - vy * px
    H[2, 0] = py * cross / r3
    H[2, 1] = -px * cross / r3
    H[2, 2] = px / r
    H[2, 3] = py / r


@njit(cache=True)
def innovation_covariance(H, P, R, S, HP):
    n = P.shape[0]
    # HP = H P⁻ (H is zero beyond the first 4 columns)
    for i in range(3):
        for j in range(n):
            s = 0.0
            for k in range(4):
                s += H[i, k] * P[k, j]
            HP[i, j] = s
    # S = H P⁻ Hᵀ + R, upper triangle mirrored
    for i in range(3):
        for j in range(i, 3):
            s = 0.0
            for k in range(4):
                s += HP[i, k] * H[j, k]
            s += R[i, j]
            S[i, j] = s
            S[j, i] = s


@njit(cache=True)
def cholesky3(S, L):
    L[:, :] = 0.0
    for j in range(3):
        s = S[j, j]
        for k in range(j):
            s -= L[j, k] * L[j, k]
        d = math.sqrt(s) if s > 0.0 else 1e-300
        L[j, j] = d
        for i in range(j + 1, 3):
            t = S[i, j]
            for k in range(j):
                t -= L[i, k] * L[j, k]
            L[i, j] = t / d


@njit(cache=True)
def forward3(L, b, w):
    for i in range(3):
        s = b[i]
        for k in range(i):
            s -= L[i, k] * w[k]
        w[i] = s / L[i, i]


@njit(cache=True)
def back3(L, b, w):
    for i in range(2, -1, -1):
        s = b[i]
        for k in range(i + 1, 3):
            s -= L[k, i] * w[k]
        w[i] = s / L[i, i]


@njit(cache=True)
def pda_update(x, P, xp, Pp, H, HP, R, L, nu, beta, beta0, mval, K, B, C, KT, T2, w, v):
    """PDA update with the spread of means and the Joseph form into x, P."""
    n = xp.shape[0]
    # K = P⁻ Hᵀ S⁻¹: row i of K solves S kᵢ = (H P⁻)[:, i]
    for i in range(n):
        for r in range(3):
            v[r] = HP[r, i]
        forward3(L, v, w)
        back3(L, w, v)
        for r in range(3):
            K[i, r] = v[r]
    # ν̄ = Σ βᵢ νᵢ
    nb0 = 0.0
    nb1 = 0.0
    nb2 = 0.0
    for j in range(mval):
        nb0 += beta[j] * nu[j, 0]
        nb1 += beta[j] * nu[j, 1]
        nb2 += beta[j] * nu[j, 2]
    # x = x⁻ + K ν̄
    for i in range(n):
        x[i] = xp[i] + K[i, 0] * nb0 + K[i, 1] * nb1 + K[i, 2] * nb2
    # B = (I − K H) P⁻ = P⁻ − K (H P⁻)
    for i in range(n):
        for j in range(n):
            B[i, j] = Pp[i, j] - (K[i, 0] * HP[0, j] + K[i, 1] * HP[1, j] + K[i, 2] * HP[2, j])
    # C = B Hᵀ, so that (I − K H) P⁻ (I − K H)ᵀ = B − C Kᵀ
    for i in range(n):
        for r in range(3):
            C[i, r] = B[i, 0] * H[r, 0] + B[i, 1] * H[r, 1] + B[i, 2] * H[r, 2] + B[i, 3] * H[r, 3]
    # T2 = (1 − β₀) R + spread, spread = Σβᵢ(νᵢ − ν̄)(νᵢ − ν̄)ᵀ + β₀ ν̄ν̄ᵀ (= Σβνν' − ν̄ν̄')
    c = 1.0 - beta0
    nbar = (nb0, nb1, nb2)
    for a in range(3):
        for b in range(3):
            s = beta0 * nbar[a] * nbar[b]
            for j in range(mval):
                s += beta[j] * (nu[j, a] - nbar[a]) * (nu[j, b] - nbar[b])
            T2[a, b] = c * R[a, b] + s
    # KT = K T2
    for i in range(n):
        for b in range(3):
            KT[i, b] = K[i, 0] * T2[0, b] + K[i, 1] * T2[1, b] + K[i, 2] * T2[2, b]
    # P = β₀ P⁻ + (1 − β₀) [(I − KH) P⁻ (I − KH)ᵀ] + K [(1 − β₀) R + spread] Kᵀ
    #   = β₀ P⁻ + (1 − β₀) P_c + K (Σβνν' − ν̄ν̄') Kᵀ, P_c in the Joseph form
    for i in range(n):
        for j in range(i, n):
            joseph = B[i, j] - (C[i, 0] * K[j, 0] + C[i, 1] * K[j, 1] + C[i, 2] * K[j, 2])
            kt = KT[i, 0] * K[j, 0] + KT[i, 1] * K[j, 1] + KT[i, 2] * K[j, 2]
            val = beta0 * Pp[i, j] + c * joseph + kt
            P[i, j] = val
            P[j, i] = val


@njit(cache=True)
def healthy(x, P, psi, Lw):
    """True when x, P, ψ are finite, ψ ∈ [0, 1] and P is symmetric positive definite."""
    n = x.shape[0]
    if not (0.0 <= psi <= 1.0):
        return False
    for i in range(n):
        if not math.isfinite(x[i]):
            return False
        for j in range(n):
            if not math.isfinite(P[i, j]) or P[i, j] != P[j, i]:
                return False
    # Cholesky: every pivot must be > 0
    for j in range(n):
        s = P[j, j]
        for k in range(j):
            s -= Lw[j, k] * Lw[j, k]
        if not s > 0.0:
            return False
        d = math.sqrt(s)
        Lw[j, j] = d
        for i in range(j + 1, n):
            t = P[i, j]
            for k in range(j):
                t -= Lw[i, k] * Lw[j, k]
            Lw[i, j] = t / d
    return True


@njit(cache=True)
def nis(L, nu, beta, mval, v, w):
    """ε = ν̃ᵀ S⁻¹ ν̃ of the combined innovation ν̃ = Σ βᵢ νᵢ (m ≥ 1), S = L Lᵀ."""
    # ν̃ = Σ βᵢ νᵢ
    nb0 = 0.0
    nb1 = 0.0
    nb2 = 0.0
    for j in range(mval):
        nb0 += beta[j] * nu[j, 0]
        nb1 += beta[j] * nu[j, 1]
        nb2 += beta[j] * nu[j, 2]
    v[0] = nb0
    v[1] = nb1
    v[2] = nb2
    # ε = ‖L⁻¹ ν̃‖²
    forward3(L, v, w)
    return w[0] * w[0] + w[1] * w[1] + w[2] * w[2]


@njit(cache=True)
def gate_xy(x, S, gamma, gc, gs):
    """Gate of a track in x–y: centre (2,) and G = γ J S_ra Jᵀ (2, 2) into gc, gs."""
    px, py, r = safe_xy(x[0], x[1])
    az = math.atan2(px, py)
    sa = math.sin(az)
    ca = math.cos(az)
    # J = ∂(x, y)/∂(r, az) for x = r sin az, y = r cos az
    j00 = sa
    j01 = r * ca
    j10 = ca
    j11 = -r * sa
    # M = J S_ra
    m00 = j00 * S[0, 0] + j01 * S[1, 0]
    m01 = j00 * S[0, 1] + j01 * S[1, 1]
    m10 = j10 * S[0, 0] + j11 * S[1, 0]
    m11 = j10 * S[0, 1] + j11 * S[1, 1]
    gc[0] = px
    gc[1] = py
    # G = γ M Jᵀ
    gs[0, 0] = gamma * (m00 * j00 + m01 * j01)
    gs[0, 1] = gamma * (m00 * j10 + m01 * j11)
    gs[1, 0] = gamma * (m10 * j00 + m11 * j01)
    gs[1, 1] = gamma * (m10 * j10 + m11 * j11)
