"""The IPDA tracker's compiled kernel: every ``@njit`` function of the tracker, in one file.

:func:`track_kernel` tracks every selected trajectory of a data set in one call, with the
helpers it calls (prediction, PDA update, Cholesky solves, gating, track health, compaction, the
JIPDA clusters and joint-event enumeration). Per frame it predicts and gates every track first
(pass 1, kept per track), then associates and updates (pass 2): each track alone (IPDA), or with
``joint`` the clusters of tracks sharing a validated measurement jointly (JIPDA,
:mod:`core.tracking.jipda`; a cluster of one, or one above ``max_joint_events``, takes IPDA).
Its arguments are four groups of arrays, :class:`KernelFrames`, :class:`KernelConstants`,
:class:`KernelOutputs` and :class:`~core.tracking.results.TrackRecord`; the Python side that
fills them and calls it is :mod:`core.tracking.kernel`.

Why one module (over the house's ~600 lines): it was kept whole because numba's on-disk cache
(``cache=True``) once checked only the source file of the function it caches, so a helper moved
to another file could change without the cached kernel being recompiled; :mod:`core.jit_guard`
now stamps every kernel with the hash of every numba module under ``core/``, so that reason is
gone. The argument types stay with the kernel because it names its tuples with them.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)
from core.tracking.ekf import MIN_RANGE_M
from core.tracking.ipda import LOG_2PI
from core.tracking.management import VELOCITY_MERGE_D2
from core.tracking.results import TrackRecord

__all__ = ["KernelConstants", "KernelFrames", "KernelOutputs", "track_kernel"]


@njit(cache=True)
def _wrap(a):
    w = ((a + math.pi) % (2.0 * math.pi)) - math.pi
    if w == -math.pi:
        w = math.pi
    return w


@njit(cache=True)
def _safe_xy(x, y):
    r = math.hypot(x, y)
    if r >= MIN_RANGE_M:
        return x, y, r
    if r == 0.0:
        return 0.0, MIN_RANGE_M, MIN_RANGE_M
    s = MIN_RANGE_M / r
    return x * s, y * s, MIN_RANGE_M


@njit(cache=True)
def _predict(x, P, F, f_cols, f_nnz, Q, xo, Po, tmp):
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
def _measure(x, zp, H):
    """h(x) into zp (3,), Jacobian into H (3, n)."""
    px, py, r = _safe_xy(x[0], x[1])
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
def _innov_cov(H, P, R, S, HP):
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
def _chol3(S, L):
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
def _fwd3(L, b, w):
    for i in range(3):
        s = b[i]
        for k in range(i):
            s -= L[i, k] * w[k]
        w[i] = s / L[i, i]


@njit(cache=True)
def _back3(L, b, w):
    for i in range(2, -1, -1):
        s = b[i]
        for k in range(i + 1, 3):
            s -= L[k, i] * w[k]
        w[i] = s / L[i, i]


@njit(cache=True)
def _pda_update(x, P, xp, Pp, H, HP, R, L, nu, beta, beta0, mval, K, B, C, KT, T2, w, v):
    """PDA update with the spread of means and the Joseph form into x, P."""
    n = xp.shape[0]
    # K = P⁻ Hᵀ S⁻¹: row i of K solves S kᵢ = (H P⁻)[:, i]
    for i in range(n):
        for r in range(3):
            v[r] = HP[r, i]
        _fwd3(L, v, w)
        _back3(L, w, v)
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
def _healthy(x, P, psi, Lw):
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
def _better(psi_a, id_a, psi_b, id_b):
    """True when track a ranks before track b (higher ψ, ties: older)."""
    return psi_a > psi_b or (psi_a == psi_b and id_a < id_b)


@njit(cache=True)
def _pair_d2(X, P, a, b, i):
    """Squared Mahalanobis distance of tracks ``a`` and ``b`` in state components ``i, i+1``
    (position: 0, velocity: 2): Δᵀ (P_a + P_b)⁻¹ Δ with the 2 × 2 inverse written out."""
    dx = X[a, i] - X[b, i]
    dy = X[a, i + 1] - X[b, i + 1]
    c00 = P[a, i, i] + P[b, i, i]
    c01 = P[a, i, i + 1] + P[b, i, i + 1]
    c11 = P[a, i + 1, i + 1] + P[b, i + 1, i + 1]
    return (c11 * dx * dx - 2.0 * c01 * dx * dy + c00 * dy * dy) / (c00 * c11 - c01 * c01)


@njit(cache=True)
def _compact(keep, nt, X, P, psi, conf, ids):
    j = 0
    for i in range(nt):
        if keep[i]:
            if j != i:
                X[j] = X[i]
                P[j] = P[i]
                psi[j] = psi[i]
                conf[j] = conf[i]
                ids[j] = ids[i]
            j += 1
    return j


@njit(cache=True)
def _compact_rec(keep, nt, birth, gc, gs, na, ns):
    """Compact the per-slot recording arrays (birth frame, gate, gated count, NIS) like
    :func:`_compact`."""
    j = 0
    for i in range(nt):
        if keep[i]:
            if j != i:
                birth[j] = birth[i]
                gc[j] = gc[i]
                gs[j] = gs[i]
                na[j] = na[i]
                ns[j] = ns[i]
            j += 1


@njit(cache=True)
def _nis(L, nu, beta, mval, v, w):
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
    _fwd3(L, v, w)
    return w[0] * w[0] + w[1] * w[1] + w[2] * w[2]


@njit(cache=True)
def _gate_xy(x, S, gamma, gc, gs):
    """Gate of a track in x–y: centre (2,) and G = γ J S_ra Jᵀ (2, 2) into gc, gs."""
    px, py, r = _safe_xy(x[0], x[1])
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


@njit(cache=True)
def _rank(nt, psi, ids, order):
    for i in range(nt):
        order[i] = i
    for i in range(1, nt):  # insertion sort, stable, few tracks
        t = order[i]
        k = i - 1
        while k >= 0 and _better(psi[t], ids[t], psi[order[k]], ids[order[k]]):
            order[k + 1] = order[k]
            k -= 1
        order[k + 1] = t


@njit(cache=True)
def _find(lab, a):
    """Root of track a in the union–find forest ``lab`` (the smallest index of its cluster)."""
    while lab[a] != a:
        a = lab[a]
    return a


@njit(cache=True)
def _union(lab, a, b):
    """Join the clusters of tracks a and b; the smaller root becomes the root."""
    ra = _find(lab, a)
    rb = _find(lab, b)
    if ra < rb:
        lab[rb] = ra
    elif rb < ra:
        lab[ra] = rb


@njit(cache=True)
def _joint_cluster(members, nk, MV, AW, IDX, PSP, pdpg, used, opt, LW0, LPS, MG, MG0):
    """JIPDA marginals of the cluster's tracks ``members[:nk]`` into MG0[q] = β'_τ0 and
    MG[q, i] = β'_τi (normalised), enumerating every joint event depth first, twice: first the
    largest log p(ε), then the sums of p(ε)/max p. ``AW[τ, i]`` = log(P_D P_G Λ_τi)."""
    for q in range(nk):
        t = members[q]
        pq = PSP[t]
        # log w_τ0 = log(1 − P_D P_G ψ⁻_τ); log w_τi = log ψ⁻_τ + log(P_D P_G Λ_τi)
        LW0[q] = math.log1p(-pdpg * pq)
        LPS[q] = math.log(pq) if pq > 0.0 else -math.inf
        MG0[q] = 0.0
        for j in range(MV[t]):
            MG[q, j] = 0.0
    for j in range(used.shape[0]):
        used[j] = False
    top = -math.inf
    total = 0.0
    for sweep in range(2):
        lvl = 0
        opt[0] = -1
        while lvl >= 0:
            t = members[lvl]
            k = opt[lvl]
            if k >= 1:
                used[IDX[t, k - 1]] = False
            k += 1
            while k >= 1 and k <= MV[t] and used[IDX[t, k - 1]]:
                k += 1
            if k > MV[t]:
                opt[lvl] = -1
                lvl -= 1
                continue
            opt[lvl] = k
            if k >= 1:
                used[IDX[t, k - 1]] = True
            if lvl < nk - 1:
                lvl += 1
                opt[lvl] = -1
                continue
            # one joint event: log p(ε) = Σ_τ log w_τ,ε(τ)
            lp = 0.0
            for q in range(nk):
                if opt[q] == 0:
                    lp += LW0[q]
                else:
                    lp += LPS[q] + AW[members[q], opt[q] - 1]
            if sweep == 0:
                if lp > top:
                    top = lp
            else:
                pe = math.exp(lp - top)
                total += pe
                for q in range(nk):
                    if opt[q] == 0:
                        MG0[q] += pe
                    else:
                        MG[q, opt[q] - 1] += pe
    for q in range(nk):
        MG0[q] /= total
        for j in range(MV[members[q]]):
            MG[q, j] /= total


@njit(cache=True)
def track_kernel(frames_, c_, out_, check, record, rec_):
    """Track the frames (:class:`KernelFrames`) with the constants (:class:`KernelConstants`)
    into the outputs (:class:`KernelOutputs`); with ``check`` count unhealthy tracks, with
    ``record`` write every live track into the record
    (:class:`~core.tracking.results.TrackRecord`).

    The four groups arrive as plain tuples and are named again here: numba types a NamedTuple
    argument about 1 µs slower per call than a plain tuple.
    """
    frames, c, out = KernelFrames(*frames_), KernelConstants(*c_), KernelOutputs(*out_)
    rec = TrackRecord(*rec_)
    # local names for the hot loops (the maths below reads like the readable tracker)
    z, f_off, t_off = frames.z, frames.frame_offsets, frames.trajectory_offsets
    sel, out_offsets = frames.trajectories, frames.output_offsets
    F, f_cols, f_nnz, Q, R, P0 = c.F, c.f_cols, c.f_nnz, c.Q, c.R, c.P0
    gamma, gamma2, p_g, pdpg = c.gamma, c.gamma2, c.p_g, c.pdpg
    p_te, p11, p21 = c.p_te, c.p11, c.p21
    rho_given, nonparam = c.clutter_density, c.nonparametric
    confirm_th, delete_th, max_tracks = c.confirm_threshold, c.delete_threshold, c.max_tracks
    joint, max_events = c.joint, c.max_joint_events
    est_xy, has, est_psi = out.estimate_xy, out.has_estimate, out.estimate_psi
    est_x, est_P, conf_xy = out.estimate_state, out.estimate_covariance, out.confirmed_xy
    n_conf, n_tr, n_bad = out.n_confirmed, out.n_tracks, out.n_unhealthy
    n = F.shape[0]
    chol = np.zeros((n, n))
    log_pg = math.log(p_g)
    log_pdpg = math.log(pdpg)
    a0 = math.log1p(-pdpg) if pdpg < 1.0 else -math.inf
    # gate volume constant c₃ γ^{3/2}, c₃ = 4π/3
    vol_c = 4.0 * math.pi / 3.0 * gamma**1.5
    max_m = 0
    for f in range(len(f_off) - 1):
        max_m = max(max_m, f_off[f + 1] - f_off[f])
    cap = max_tracks + max_m + 1
    X = np.zeros((cap, n))
    P = np.zeros((cap, n, n))
    psi = np.zeros(cap)
    conf = np.zeros(cap, dtype=np.bool_)
    ids = np.zeros(cap, dtype=np.int64)
    keep = np.zeros(cap, dtype=np.bool_)
    order = np.zeros(cap, dtype=np.int64)
    # recording slots (birth frame, gate, gated count, NIS), allocated only when recording
    n_rec = cap if record else 0
    birth = np.zeros(n_rec, dtype=np.int64)
    gc = np.zeros((n_rec, 2))
    gs = np.zeros((n_rec, 2, 2))
    na = np.zeros(n_rec, dtype=np.int64)
    ns = np.zeros(n_rec)
    gated_any = np.zeros(max_m + 1, dtype=np.bool_)
    beta = np.zeros(max_m + 1)
    # per track of a frame: prediction, gate and validated measurements (pass 1 → pass 2);
    # a frame starts with at most max_tracks tracks (the cap ends every frame)
    XP = np.zeros((max_tracks, n))
    PPm = np.zeros((max_tracks, n, n))
    HH = np.zeros((max_tracks, 3, n))
    HPs = np.zeros((max_tracks, 3, n))
    LL = np.zeros((max_tracks, 3, 3))
    PSP = np.zeros(max_tracks)
    MV = np.zeros(max_tracks, dtype=np.int64)
    NU = np.zeros((max_tracks, max_m + 1, 3))
    AW = np.zeros((max_tracks, max_m + 1))
    IDX = np.zeros((max_tracks, max_m + 1), dtype=np.int64)
    # clusters and joint events (JIPDA)
    lab = np.zeros(max_tracks, dtype=np.int64)
    owner = np.zeros(max_m + 1, dtype=np.int64)
    members = np.zeros(max_tracks, dtype=np.int64)
    used = np.zeros(max_m + 1, dtype=np.bool_)
    opt = np.zeros(max_tracks, dtype=np.int64)
    LW0 = np.zeros(max_tracks)
    LPS = np.zeros(max_tracks)
    MG = np.zeros((max_tracks, max_m + 1))
    MG0 = np.zeros(max_tracks)
    tmp = np.zeros((n, n))
    A = np.zeros((n, n))
    K = np.zeros((n, 3))
    C3 = np.zeros((n, 3))
    KT = np.zeros((n, 3))
    H = np.zeros((3, n))
    HP = np.zeros((3, n))
    S = np.zeros((3, 3))
    tmp2 = np.zeros((3, 3))
    zp = np.zeros(3)
    w = np.zeros(3)
    v = np.zeros(3)
    for si in range(len(sel)):
        k_traj = sel[si]
        fa = t_off[k_traj]
        fb = t_off[k_traj + 1]
        o = out_offsets[si]
        nt = 0
        next_id = 0
        for f in range(fa, fb):
            za = f_off[f]
            m = f_off[f + 1] - za
            for j in range(m):
                gated_any[j] = False
            n_old = nt
            # pass 1: predict and gate every track; keep its prediction and its validated
            # measurements (innovations, a = log(P_D P_G Λ), frame indices)
            for t in range(n_old):
                xp = XP[t]
                Pp = PPm[t]
                Ht = HH[t]
                HPt = HPs[t]
                L = LL[t]
                _predict(X[t], P[t], F, f_cols, f_nnz, Q, xp, Pp, tmp)
                # ψ⁻ = p11 ψ + p21 (1 − ψ)
                pp = p11 * psi[t] + p21 * (1.0 - psi[t])
                pp = min(1.0, max(0.0, pp))
                PSP[t] = pp
                _measure(xp, zp, Ht)
                _innov_cov(Ht, Pp, R, S, HPt)
                if record:
                    _gate_xy(xp, S, gamma, gc[t], gs[t])
                _chol3(S, L)
                lab[t] = t
                mval = 0
                for j in range(m):
                    v[0] = z[za + j, 0] - zp[0]
                    v[1] = _wrap(z[za + j, 1] - zp[1])
                    v[2] = z[za + j, 2] - zp[2]
                    _fwd3(L, v, w)
                    dd = w[0] * w[0] + w[1] * w[1] + w[2] * w[2]
                    if dd <= gamma:
                        if joint and gated_any[j]:
                            # union with the cluster of the measurement's first track
                            _union(lab, owner[j], t)
                        elif joint:
                            owner[j] = t
                        gated_any[j] = True
                        NU[t, mval, 0] = v[0]
                        NU[t, mval, 1] = v[1]
                        NU[t, mval, 2] = v[2]
                        AW[t, mval] = dd
                        IDX[t, mval] = j
                        mval += 1
                MV[t] = mval
                if mval == 0:
                    continue
                logdet = 2.0 * (math.log(L[0, 0]) + math.log(L[1, 1]) + math.log(L[2, 2]))
                if nonparam:
                    m_hat = mval - pdpg * pp
                    if m_hat <= 0.0:
                        m_hat = float(mval)
                    # ρ̂ = m̂ / V, V = c₃ γ^{3/2} √det S
                    rho = m_hat / (vol_c * L[0, 0] * L[1, 1] * L[2, 2])
                else:
                    rho = rho_given
                # log Λᵢ = −½dᵢ² − ½ log det S − (3/2) log 2π − log(P_G ρ)
                # aᵢ = log(P_D P_G) + log Λᵢ
                c0 = -0.5 * logdet - 1.5 * LOG_2PI - (log_pg + math.log(rho)) + log_pdpg
                for j in range(mval):
                    AW[t, j] = -0.5 * AW[t, j] + c0
            # pass 2: association and update, per track (IPDA) or per cluster (JIPDA)
            for t in range(n_old):
                lab[t] = _find(lab, t)
            for r0 in range(n_old):
                if lab[r0] != r0:
                    continue
                nk = 0
                bound = 1.0
                for t in range(r0, n_old):
                    if lab[t] == r0:
                        members[nk] = t
                        nk += 1
                        bound *= 1.0 + MV[t]
                if nk > 1 and bound <= max_events:
                    _joint_cluster(
                        members, nk, MV, AW, IDX, PSP, pdpg, used, opt, LW0, LPS, MG, MG0
                    )
                for q in range(nk):
                    t = members[q]
                    mval = MV[t]
                    pp = PSP[t]
                    if record:
                        # gated measurements of this update; ε set below when there is one
                        na[t] = mval
                        ns[t] = math.nan
                    if mval == 0 and nk == 1 or mval == 0 and bound > max_events:
                        # ψ = (1 − P_D P_G) ψ⁻ / (1 − P_D P_G ψ⁻); state unchanged
                        if pp <= 0.0:
                            psi[t] = 0.0
                        elif pp >= 1.0:
                            psi[t] = 1.0
                        else:
                            psi[t] = (1.0 - pdpg) * pp / (1.0 - pdpg * pp)
                        X[t, :] = XP[t]
                        P[t, :, :] = PPm[t]
                        continue
                    if nk == 1 or bound > max_events:
                        # IPDA: 1 − δ = e^{a₀} + Σ e^{aᵢ} by log-sum-exp
                        top = a0
                        for j in range(mval):
                            if AW[t, j] > top:
                                top = AW[t, j]
                        ssum = math.exp(a0 - top)
                        for j in range(mval):
                            ssum += math.exp(AW[t, j] - top)
                        lse = top + math.log(ssum)
                        b0 = math.exp(a0 - lse)
                        for j in range(mval):
                            beta[j] = math.exp(AW[t, j] - lse)
                        omd = math.exp(lse)  # 1 − δ
                        if pp <= 0.0:
                            psi[t] = 0.0
                        elif pp >= 1.0:
                            psi[t] = 1.0
                        else:
                            # ψ = (1 − δ) ψ⁻ / ((1 − ψ⁻) + (1 − δ) ψ⁻)
                            ps = omd * pp / ((1.0 - pp) + omd * pp)
                            psi[t] = min(1.0, max(0.0, ps))
                    else:
                        # JIPDA: ψ_τ = Σ_i β'_τi + β'_τ0 q_τ
                        # q_τ = (1 − P_D P_G) ψ⁻ / (1 − P_D P_G ψ⁻)
                        qq = (1.0 - pdpg) * pp / (1.0 - pdpg * pp)
                        ps = MG0[q] * qq
                        for j in range(mval):
                            ps += MG[q, j]
                        if ps > 0.0:
                            psi[t] = min(1.0, ps)
                            # β_τ0 = β'_τ0 q_τ / ψ_τ, β_τi = β'_τi / ψ_τ
                            b0 = MG0[q] * qq / ps
                            for j in range(mval):
                                beta[j] = MG[q, j] / ps
                        else:
                            psi[t] = 0.0
                            b0 = 1.0
                            for j in range(mval):
                                beta[j] = 0.0
                        if mval == 0:
                            X[t, :] = XP[t]
                            P[t, :, :] = PPm[t]
                            continue
                    _pda_update(
                        X[t],
                        P[t],
                        XP[t],
                        PPm[t],
                        HH[t],
                        HPs[t],
                        R,
                        LL[t],
                        NU[t],
                        beta,
                        b0,
                        mval,
                        K,
                        A,
                        C3,
                        KT,
                        tmp2,
                        w,
                        v,
                    )
                    if record:
                        ns[t] = _nis(LL[t], NU[t], beta, mval, v, w)
            # initiation: measurements outside every gate start tentative tracks
            for j in range(m):
                if not gated_any[j]:
                    r = z[za + j, 0]
                    az = z[za + j, 1]
                    vr = z[za + j, 2]
                    sa = math.sin(az)
                    ca = math.cos(az)
                    X[nt, :] = 0.0
                    X[nt, 0] = r * sa
                    X[nt, 1] = r * ca
                    X[nt, 2] = vr * sa
                    X[nt, 3] = vr * ca
                    P[nt, :, :] = P0
                    psi[nt] = p_te
                    conf[nt] = False
                    ids[nt] = next_id
                    if record:
                        birth[nt] = f - fa
                        na[nt] = 0
                        ns[nt] = math.nan
                        # gate of a newborn track: S₀ = H(x₀) P₀ H(x₀)ᵀ + R around x₀
                        _measure(X[nt], zp, H)
                        _innov_cov(H, P0, R, S, HP)
                        _gate_xy(X[nt], S, gamma, gc[nt], gs[nt])
                    next_id += 1
                    nt += 1
            # confirmation (tracks updated this frame only), deletion
            for t in range(nt):
                if t < n_old and psi[t] >= confirm_th:
                    conf[t] = True
                keep[t] = psi[t] >= delete_th
            if record:
                _compact_rec(keep, nt, birth, gc, gs, na, ns)
            nt = _compact(keep, nt, X, P, psi, conf, ids)
            # merging: greedy in ψ order, within the 2-D gate of the combined position covariance
            if nt > 1:
                _rank(nt, psi, ids, order)
                for t in range(nt):
                    keep[t] = True
                for ia in range(nt):
                    a = order[ia]
                    if not keep[a]:
                        continue
                    for ib in range(ia + 1, nt):
                        b = order[ib]
                        if not keep[b]:
                            continue
                        # d² = Δpᵀ (P_a + P_b)⁻¹ Δp
                        if _pair_d2(X, P, a, b, 0) > gamma2:
                            continue
                        if joint and conf[a] and conf[b]:
                            # confirmed pairs (JIPDA): also Δvᵀ (P_v,a + P_v,b)⁻¹ Δv ≤ 2 ln 10
                            if _pair_d2(X, P, a, b, 2) > VELOCITY_MERGE_D2:
                                continue
                        keep[b] = False
                if record:
                    _compact_rec(keep, nt, birth, gc, gs, na, ns)
                nt = _compact(keep, nt, X, P, psi, conf, ids)
            # cap: the lowest ψ go (ties: the youngest)
            if nt > max_tracks:
                _rank(nt, psi, ids, order)
                for t in range(nt):
                    keep[t] = False
                for ia in range(max_tracks):
                    keep[order[ia]] = True
                if record:
                    _compact_rec(keep, nt, birth, gc, gs, na, ns)
                nt = _compact(keep, nt, X, P, psi, conf, ids)
            # outputs: the estimate is the confirmed track with the highest ψ (ties: older)
            best = -1
            nc = 0
            for t in range(nt):
                if conf[t]:
                    conf_xy[o, nc, 0] = X[t, 0]
                    conf_xy[o, nc, 1] = X[t, 1]
                    nc += 1
                    if best < 0 or _better(psi[t], ids[t], psi[best], ids[best]):
                        best = t
            n_conf[o] = nc
            n_tr[o] = nt
            if check:
                for t in range(nt):
                    if not _healthy(X[t], P[t], psi[t], chol):
                        n_bad[o] += 1
            if best >= 0:
                has[o] = True
                est_xy[o, 0] = X[best, 0]
                est_xy[o, 1] = X[best, 1]
                est_psi[o] = psi[best]
                est_x[o, :] = X[best]
                est_P[o, :, :] = P[best]
            if record:
                # every live track of this frame (nt <= max_tracks after the cap)
                rec.estimate[o] = best
                for t in range(nt):
                    rec.ids[o, t] = ids[t]
                    rec.state[o, t, :] = X[t]
                    rec.covariance[o, t, :, :] = P[t]
                    rec.psi[o, t] = psi[t]
                    rec.confirmed[o, t] = conf[t]
                    rec.birth_frame[o, t] = birth[t]
                    rec.gate_center_xy[o, t, :] = gc[t]
                    rec.gate_shape_xy[o, t, :, :] = gs[t]
                    rec.n_associated[o, t] = na[t]
                    rec.nis[o, t] = ns[t]
            o += 1


class KernelFrames(NamedTuple):
    """The measurements of one kernel call and which trajectories to track."""

    z: np.ndarray  # (P, 3) float64 [r (m), az (rad), vr (m/s)], sorted by frame
    frame_offsets: np.ndarray  # (F + 1,) int64 point ranges per global frame
    trajectory_offsets: np.ndarray  # (K + 1,) int64 frame ranges per trajectory
    trajectories: np.ndarray  # (K_sel,) int64 the trajectories to track, in order
    output_offsets: np.ndarray  # (K_sel + 1,) int64 output-frame ranges per tracked trajectory


class KernelConstants(NamedTuple):
    """Everything the kernel reads from the parameters and the frame period."""

    F: np.ndarray  # (d, d) transition matrix
    f_cols: np.ndarray  # (d, k) int64: row i of F is non-zero in columns f_cols[i, :f_nnz[i]]
    f_nnz: np.ndarray  # (d,) int64 non-zeros per row of F
    Q: np.ndarray  # (d, d) process noise
    R: np.ndarray  # (3, 3) measurement noise
    P0: np.ndarray  # (d, d) initial covariance
    gamma: float  # gate threshold χ²⁻¹₃(P_G)
    gamma2: float  # merge threshold χ²⁻¹₂(P_G)
    p_g: float  # P_G
    pdpg: float  # P_D·P_G
    p_te: float  # ψ of a new track
    p11: float  # Markov chain 1: P(exists | existed)
    p21: float  # Markov chain 1: P(exists | did not exist)
    clutter_density: float  # ρ (given; 1.0 and unused when non-parametric)
    nonparametric: bool  # ρ̂ = m̂/V per gate instead of ρ
    confirm_threshold: float
    delete_threshold: float
    max_tracks: int
    joint: bool  # JIPDA over clusters of tracks sharing measurements (else IPDA per track)
    max_joint_events: float  # clusters with a larger event bound Π(1 + m_τ) take IPDA


class KernelOutputs(NamedTuple):
    """What the kernel writes per output frame (F_sel frames, NaN where no estimate)."""

    estimate_xy: np.ndarray  # (F_sel, 2)
    has_estimate: np.ndarray  # (F_sel,) bool
    estimate_psi: np.ndarray  # (F_sel,)
    estimate_state: np.ndarray  # (F_sel, d)
    estimate_covariance: np.ndarray  # (F_sel, d, d)
    confirmed_xy: np.ndarray  # (F_sel, max_tracks, 2), NaN-padded
    n_confirmed: np.ndarray  # (F_sel,) int64
    n_tracks: np.ndarray  # (F_sel,) int64
    n_unhealthy: np.ndarray  # (F_sel,) int64, counted only when checking

    @classmethod
    def allocate(cls, n_out: int, d: int, max_tracks: int) -> KernelOutputs:
        return cls(
            estimate_xy=np.full((n_out, 2), np.nan),
            has_estimate=np.zeros(n_out, dtype=np.bool_),
            estimate_psi=np.full(n_out, np.nan),
            estimate_state=np.full((n_out, d), np.nan),
            estimate_covariance=np.full((n_out, d, d), np.nan),
            confirmed_xy=np.full((n_out, max_tracks, 2), np.nan),
            n_confirmed=np.zeros(n_out, dtype=np.int64),
            n_tracks=np.zeros(n_out, dtype=np.int64),
            n_unhealthy=np.zeros(n_out, dtype=np.int64),
        )
