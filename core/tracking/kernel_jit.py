"""The IPDA tracker's compiled kernel: :func:`track_kernel` and the steps it takes per frame.

:func:`track_kernel` tracks every selected trajectory of a data set in one call. Per frame it
takes the steps of the readable tracker (:func:`core.tracking.tracker.run_tracker`), one
function each: :func:`_predict_and_gate` (pass 1: predict every track, gate the points, keep
each track's validated measurements), :func:`_associate_and_update` (pass 2: each track alone,
IPDA, or with ``joint`` the clusters of tracks sharing a validated measurement jointly, JIPDA,
:mod:`core.tracking.jipda`; a cluster of one, or one above ``max_joint_events``, takes IPDA),
:func:`_initiate`, :func:`_confirm_and_delete`, :func:`_merge`, :func:`_cap` and
:func:`_write_outputs`. The EKF and PDA arithmetic they call is :mod:`core.tracking.kernel_maths`.

Its arguments are four groups of arrays, :class:`KernelFrames`, :class:`KernelConstants`,
:class:`KernelOutputs` and :class:`~core.tracking.results.TrackRecord`; the Python side that
fills them and calls it is :mod:`core.tracking.kernel`. Its work arrays, allocated once per call
(:func:`_allocate`), are grouped the same way: :class:`TrackBank` (the tracks),
:class:`TrackSlotRecord` (what the record keeps per track), :class:`Predictions` (pass 1 to
pass 2), :class:`Clusters` (JIPDA) and :class:`Scratch`.

The steps are compiled without numba's reference counting (``_nrt=False``; they allocate
nothing, so arrays are copied element by element, :func:`_copy_vector`): with it, every array
taken from a group and every call would count references, and the kernel ran 2.4-3 times slower
(measured: 30 against 11 ms of CPU for a 4 228-frame pass). Numba compiles what they call with
the same flag.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)
from core.tracking.ipda import LOG_2PI
from core.tracking.kernel_maths import (
    cholesky3,
    forward3,
    gate_xy,
    healthy,
    innovation_covariance,
    measure,
    nis,
    pda_update,
    predict,
    wrap_angle,
)
from core.tracking.management import VELOCITY_MERGE_D2
from core.tracking.results import TrackRecord

__all__ = ["KernelConstants", "KernelFrames", "KernelOutputs", "track_kernel"]


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
def _copy_vector(dst, src):
    """``dst[:] = src`` element by element (no temporary: the steps run without NRT)."""
    for i in range(src.shape[0]):
        dst[i] = src[i]


@njit(cache=True)
def _copy_matrix(dst, src):
    """``dst[:, :] = src`` element by element."""
    for i in range(src.shape[0]):
        for j in range(src.shape[1]):
            dst[i, j] = src[i, j]


@njit(cache=True)
def _compact(keep, nt, X, P, psi, conf, ids):
    j = 0
    for i in range(nt):
        if keep[i]:
            if j != i:
                _copy_vector(X[j], X[i])
                _copy_matrix(P[j], P[i])
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
                _copy_vector(gc[j], gc[i])
                _copy_matrix(gs[j], gs[i])
                na[j] = na[i]
                ns[j] = ns[i]
            j += 1


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


class TrackBank(NamedTuple):
    """The tracks of the trajectory being tracked: slots ``0 .. nt-1`` are live, the rest take
    the frame's newborns (``max_tracks + max points + 1`` slots)."""

    state: np.ndarray  # (cap, d) x
    covariance: np.ndarray  # (cap, d, d) P
    psi: np.ndarray  # (cap,) ψ, probability of existence
    confirmed: np.ndarray  # (cap,) bool
    ids: np.ndarray  # (cap,) int64, in order of birth
    keep: np.ndarray  # (cap,) bool, work: the slots a management step keeps
    order: np.ndarray  # (cap,) int64, work: slots ranked by ψ (ties: older)


class TrackSlotRecord(NamedTuple):
    """Per slot of :class:`TrackBank`, what the record keeps (length 0 when not recording)."""

    birth_frame: np.ndarray  # (cap,) int64, frame of birth within the trajectory
    gate_center_xy: np.ndarray  # (cap, 2)
    gate_shape_xy: np.ndarray  # (cap, 2, 2) G = γ J S_ra Jᵀ
    n_associated: np.ndarray  # (cap,) int64, measurements gated at the last update
    nis: np.ndarray  # (cap,) ε of the last update, NaN without a measurement


class Predictions(NamedTuple):
    """Per track alive at the start of a frame: its prediction and gate (pass 1 → pass 2)."""

    state: np.ndarray  # (max_tracks, d) x⁻
    covariance: np.ndarray  # (max_tracks, d, d) P⁻
    jacobian: np.ndarray  # (max_tracks, 3, d) H
    hp: np.ndarray  # (max_tracks, 3, d) H P⁻
    chol_s: np.ndarray  # (max_tracks, 3, 3) L, S = H P⁻ Hᵀ + R = L Lᵀ
    psi: np.ndarray  # (max_tracks,) ψ⁻
    n_valid: np.ndarray  # (max_tracks,) int64, validated measurements
    innovations: np.ndarray  # (max_tracks, M, 3) ν of the validated measurements
    log_weights: np.ndarray  # (max_tracks, M) a = log(P_D P_G Λ) (first d², then a)
    point: np.ndarray  # (max_tracks, M) int64, the validated measurements' indices in the frame


class Clusters(NamedTuple):
    """Clusters of tracks sharing a validated measurement and the JIPDA marginals."""

    label: np.ndarray  # (max_tracks,) int64, union-find forest over the tracks
    owner: np.ndarray  # (M,) int64, first track that gated each measurement
    members: np.ndarray  # (max_tracks,) int64, the tracks of the cluster at hand
    used: np.ndarray  # (M,) bool, measurements taken by the joint event being built
    option: np.ndarray  # (max_tracks,) int64, each member's choice in that event (0: missed)
    log_w0: np.ndarray  # (max_tracks,) log(1 − P_D P_G ψ⁻)
    log_psi: np.ndarray  # (max_tracks,) log ψ⁻
    marginal: np.ndarray  # (max_tracks, M) β'_τi
    marginal0: np.ndarray  # (max_tracks,) β'_τ0


class Scratch(NamedTuple):
    """Work arrays of one track's prediction, gate and update."""

    gated_any: np.ndarray  # (M,) bool, the measurement lies in some gate
    beta: np.ndarray  # (M,) association probabilities of the update at hand
    fp: np.ndarray  # (d, d) F P
    b: np.ndarray  # (d, d) (I − K H) P⁻
    gain: np.ndarray  # (d, 3) K
    c: np.ndarray  # (d, 3) (I − K H) P⁻ Hᵀ
    kt: np.ndarray  # (d, 3) K T₂
    h: np.ndarray  # (3, d) H of a newborn
    hp: np.ndarray  # (3, d) H P₀ of a newborn
    s: np.ndarray  # (3, 3) S
    t2: np.ndarray  # (3, 3) (1 − β₀) R + spread
    z_pred: np.ndarray  # (3,) h(x⁻)
    w: np.ndarray  # (3,)
    v: np.ndarray  # (3,)
    chol: np.ndarray  # (d, d) Cholesky factor of the health check


@njit(cache=True)
def _allocate(n, max_tracks, max_m, record):
    """The work arrays of one kernel call (``max_m`` points at most in a frame)."""
    cap = max_tracks + max_m + 1
    bank = TrackBank(
        np.zeros((cap, n)),
        np.zeros((cap, n, n)),
        np.zeros(cap),
        np.zeros(cap, dtype=np.bool_),
        np.zeros(cap, dtype=np.int64),
        np.zeros(cap, dtype=np.bool_),
        np.zeros(cap, dtype=np.int64),
    )
    n_rec = cap if record else 0
    slots = TrackSlotRecord(
        np.zeros(n_rec, dtype=np.int64),
        np.zeros((n_rec, 2)),
        np.zeros((n_rec, 2, 2)),
        np.zeros(n_rec, dtype=np.int64),
        np.zeros(n_rec),
    )
    pred = Predictions(
        np.zeros((max_tracks, n)),
        np.zeros((max_tracks, n, n)),
        np.zeros((max_tracks, 3, n)),
        np.zeros((max_tracks, 3, n)),
        np.zeros((max_tracks, 3, 3)),
        np.zeros(max_tracks),
        np.zeros(max_tracks, dtype=np.int64),
        np.zeros((max_tracks, max_m + 1, 3)),
        np.zeros((max_tracks, max_m + 1)),
        np.zeros((max_tracks, max_m + 1), dtype=np.int64),
    )
    cl = Clusters(
        np.zeros(max_tracks, dtype=np.int64),
        np.zeros(max_m + 1, dtype=np.int64),
        np.zeros(max_tracks, dtype=np.int64),
        np.zeros(max_m + 1, dtype=np.bool_),
        np.zeros(max_tracks, dtype=np.int64),
        np.zeros(max_tracks),
        np.zeros(max_tracks),
        np.zeros((max_tracks, max_m + 1)),
        np.zeros(max_tracks),
    )
    s = Scratch(
        np.zeros(max_m + 1, dtype=np.bool_),
        np.zeros(max_m + 1),
        np.zeros((n, n)),
        np.zeros((n, n)),
        np.zeros((n, 3)),
        np.zeros((n, 3)),
        np.zeros((n, 3)),
        np.zeros((3, n)),
        np.zeros((3, n)),
        np.zeros((3, 3)),
        np.zeros((3, 3)),
        np.zeros(3),
        np.zeros(3),
        np.zeros(3),
        np.zeros((n, n)),
    )
    return bank, slots, pred, cl, s


@njit(cache=True, _nrt=False)
def _predict_and_gate(z, za, m, n_old, bank, pred, cl, s, c, record, slots):
    """Pass 1: predict every track, gate the frame's ``m`` points (rows ``za:za+m`` of ``z``)
    and keep each track's validated measurements (innovations, a = log(P_D P_G Λ), indices);
    with JIPDA, join the tracks that share a measurement into clusters."""
    X, P, psi = bank.state, bank.covariance, bank.psi
    gated_any, zp, v, w = s.gated_any, s.z_pred, s.v, s.w
    S = s.s
    NU, AW, IDX = pred.innovations, pred.log_weights, pred.point
    lab, owner = cl.label, cl.owner
    gamma, pdpg, joint = c.gamma, c.pdpg, c.joint
    log_pg = math.log(c.p_g)
    log_pdpg = math.log(pdpg)
    # gate volume constant c₃ γ^{3/2}, c₃ = 4π/3
    vol_c = 4.0 * math.pi / 3.0 * gamma**1.5
    for j in range(m):
        gated_any[j] = False
    for t in range(n_old):
        xp = pred.state[t]
        Pp = pred.covariance[t]
        Ht = pred.jacobian[t]
        HPt = pred.hp[t]
        L = pred.chol_s[t]
        predict(X[t], P[t], c.F, c.f_cols, c.f_nnz, c.Q, xp, Pp, s.fp)
        # ψ⁻ = p11 ψ + p21 (1 − ψ)
        pp = c.p11 * psi[t] + c.p21 * (1.0 - psi[t])
        pp = min(1.0, max(0.0, pp))
        pred.psi[t] = pp
        measure(xp, zp, Ht)
        innovation_covariance(Ht, Pp, c.R, S, HPt)
        if record:
            gate_xy(xp, S, gamma, slots.gate_center_xy[t], slots.gate_shape_xy[t])
        cholesky3(S, L)
        lab[t] = t
        mval = 0
        for j in range(m):
            v[0] = z[za + j, 0] - zp[0]
            v[1] = wrap_angle(z[za + j, 1] - zp[1])
            v[2] = z[za + j, 2] - zp[2]
            forward3(L, v, w)
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
        pred.n_valid[t] = mval
        if mval == 0:
            continue
        logdet = 2.0 * (math.log(L[0, 0]) + math.log(L[1, 1]) + math.log(L[2, 2]))
        if c.nonparametric:
            m_hat = mval - pdpg * pp
            if m_hat <= 0.0:
                m_hat = float(mval)
            # ρ̂ = m̂ / V, V = c₃ γ^{3/2} √det S
            rho = m_hat / (vol_c * L[0, 0] * L[1, 1] * L[2, 2])
        else:
            rho = c.clutter_density
        # log Λᵢ = −½dᵢ² − ½ log det S − (3/2) log 2π − log(P_G ρ)
        # aᵢ = log(P_D P_G) + log Λᵢ
        c0 = -0.5 * logdet - 1.5 * LOG_2PI - (log_pg + math.log(rho)) + log_pdpg
        for j in range(mval):
            AW[t, j] = -0.5 * AW[t, j] + c0


@njit(cache=True, _nrt=False)
def _missed_existence(pp, pdpg):
    """ψ after a frame with no validated measurement: (1 − P_D P_G) ψ⁻ / (1 − P_D P_G ψ⁻)."""
    if pp <= 0.0:
        return 0.0
    if pp >= 1.0:
        return 1.0
    return (1.0 - pdpg) * pp / (1.0 - pdpg * pp)


@njit(cache=True, _nrt=False)
def _ipda_association(aw, mval, pp, a0, beta):
    """IPDA: the association probabilities into ``beta[:mval]``; returns ``(β₀, ψ)``."""
    # 1 − δ = e^{a₀} + Σ e^{aᵢ} by log-sum-exp
    top = a0
    for j in range(mval):
        if aw[j] > top:
            top = aw[j]
    ssum = math.exp(a0 - top)
    for j in range(mval):
        ssum += math.exp(aw[j] - top)
    lse = top + math.log(ssum)
    b0 = math.exp(a0 - lse)
    for j in range(mval):
        beta[j] = math.exp(aw[j] - lse)
    omd = math.exp(lse)  # 1 − δ
    if pp <= 0.0:
        return b0, 0.0
    if pp >= 1.0:
        return b0, 1.0
    # ψ = (1 − δ) ψ⁻ / ((1 − ψ⁻) + (1 − δ) ψ⁻)
    ps = omd * pp / ((1.0 - pp) + omd * pp)
    return b0, min(1.0, max(0.0, ps))


@njit(cache=True, _nrt=False)
def _jipda_association(mg, mg0, mval, pp, pdpg, beta):
    """JIPDA: a member's association probabilities from its marginals ``mg[:mval]``, ``mg0``
    into ``beta[:mval]``; returns ``(β₀, ψ)``."""
    # ψ_τ = Σ_i β'_τi + β'_τ0 q_τ, q_τ = (1 − P_D P_G) ψ⁻ / (1 − P_D P_G ψ⁻)
    qq = (1.0 - pdpg) * pp / (1.0 - pdpg * pp)
    ps = mg0 * qq
    for j in range(mval):
        ps += mg[j]
    if ps > 0.0:
        # β_τ0 = β'_τ0 q_τ / ψ_τ, β_τi = β'_τi / ψ_τ
        b0 = mg0 * qq / ps
        for j in range(mval):
            beta[j] = mg[j] / ps
        return b0, min(1.0, ps)
    for j in range(mval):
        beta[j] = 0.0
    return 1.0, 0.0


@njit(cache=True, _nrt=False)
def _associate_and_update(n_old, bank, pred, cl, s, c, a0, record, slots):
    """Pass 2: association and update, each track alone (IPDA) or jointly within a cluster of
    tracks sharing measurements (JIPDA; a cluster of one, or one above ``max_joint_events``,
    takes IPDA)."""
    X, P, psi = bank.state, bank.covariance, bank.psi
    lab, members = cl.label, cl.members
    MV, beta = pred.n_valid, s.beta
    pdpg, max_events = c.pdpg, c.max_joint_events
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
                members,
                nk,
                MV,
                pred.log_weights,
                pred.point,
                pred.psi,
                pdpg,
                cl.used,
                cl.option,
                cl.log_w0,
                cl.log_psi,
                cl.marginal,
                cl.marginal0,
            )
        for q in range(nk):
            t = members[q]
            mval = MV[t]
            pp = pred.psi[t]
            if record:
                # gated measurements of this update; ε set below when there is one
                slots.n_associated[t] = mval
                slots.nis[t] = math.nan
            alone = nk == 1 or bound > max_events
            if mval == 0 and alone:
                # ψ = (1 − P_D P_G) ψ⁻ / (1 − P_D P_G ψ⁻); state unchanged
                psi[t] = _missed_existence(pp, pdpg)
                _copy_vector(X[t], pred.state[t])
                _copy_matrix(P[t], pred.covariance[t])
                continue
            if alone:
                b0, ps = _ipda_association(pred.log_weights[t], mval, pp, a0, beta)
                psi[t] = ps
            else:
                b0, ps = _jipda_association(cl.marginal[q], cl.marginal0[q], mval, pp, pdpg, beta)
                psi[t] = ps
                if mval == 0:
                    _copy_vector(X[t], pred.state[t])
                    _copy_matrix(P[t], pred.covariance[t])
                    continue
            pda_update(
                X[t],
                P[t],
                pred.state[t],
                pred.covariance[t],
                pred.jacobian[t],
                pred.hp[t],
                c.R,
                pred.chol_s[t],
                pred.innovations[t],
                beta,
                b0,
                mval,
                s.gain,
                s.b,
                s.c,
                s.kt,
                s.t2,
                s.w,
                s.v,
            )
            if record:
                slots.nis[t] = nis(pred.chol_s[t], pred.innovations[t], beta, mval, s.v, s.w)


@njit(cache=True, _nrt=False)
def _initiate(z, za, m, frame, nt, next_id, bank, s, c, record, slots):
    """Initiation: every measurement outside every gate starts a tentative track.
    Returns ``(nt, next_id)``."""
    X, P = bank.state, bank.covariance
    for j in range(m):
        if s.gated_any[j]:
            continue
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
        _copy_matrix(P[nt], c.P0)
        bank.psi[nt] = c.p_te
        bank.confirmed[nt] = False
        bank.ids[nt] = next_id
        if record:
            slots.birth_frame[nt] = frame
            slots.n_associated[nt] = 0
            slots.nis[nt] = math.nan
            # gate of a newborn track: S₀ = H(x₀) P₀ H(x₀)ᵀ + R around x₀
            measure(X[nt], s.z_pred, s.h)
            innovation_covariance(s.h, c.P0, c.R, s.s, s.hp)
            gate_xy(X[nt], s.s, c.gamma, slots.gate_center_xy[nt], slots.gate_shape_xy[nt])
        next_id += 1
        nt += 1
    return nt, next_id


@njit(cache=True, _nrt=False)
def _compact_kept(nt, bank, record, slots):
    """Keep the slots marked in ``bank.keep``, in order; returns the new count."""
    if record:
        _compact_rec(
            bank.keep,
            nt,
            slots.birth_frame,
            slots.gate_center_xy,
            slots.gate_shape_xy,
            slots.n_associated,
            slots.nis,
        )
    return _compact(bank.keep, nt, bank.state, bank.covariance, bank.psi, bank.confirmed, bank.ids)


@njit(cache=True, _nrt=False)
def _confirm_and_delete(nt, n_old, bank, c, record, slots):
    """Confirmation (tracks updated this frame only) and deletion; returns the new count."""
    psi, keep = bank.psi, bank.keep
    for t in range(nt):
        if t < n_old and psi[t] >= c.confirm_threshold:
            bank.confirmed[t] = True
        keep[t] = psi[t] >= c.delete_threshold
    return _compact_kept(nt, bank, record, slots)


@njit(cache=True, _nrt=False)
def _merge(nt, bank, c, record, slots):
    """Merging: greedy in ψ order, within the 2-D gate of the combined position covariance
    (confirmed pairs under JIPDA: also in velocity); returns the new count."""
    if nt <= 1:
        return nt
    X, P, conf, keep, order = bank.state, bank.covariance, bank.confirmed, bank.keep, bank.order
    _rank(nt, bank.psi, bank.ids, order)
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
            if _pair_d2(X, P, a, b, 0) > c.gamma2:
                continue
            if c.joint and conf[a] and conf[b]:
                # confirmed pairs (JIPDA): also Δvᵀ (P_v,a + P_v,b)⁻¹ Δv ≤ 2 ln 10
                if _pair_d2(X, P, a, b, 2) > VELOCITY_MERGE_D2:
                    continue
            keep[b] = False
    return _compact_kept(nt, bank, record, slots)


@njit(cache=True, _nrt=False)
def _cap(nt, bank, c, record, slots):
    """Cap: beyond ``max_tracks`` the lowest ψ go (ties: the youngest); returns the count."""
    if nt <= c.max_tracks:
        return nt
    _rank(nt, bank.psi, bank.ids, bank.order)
    for t in range(nt):
        bank.keep[t] = False
    for ia in range(c.max_tracks):
        bank.keep[bank.order[ia]] = True
    return _compact_kept(nt, bank, record, slots)


@njit(cache=True, _nrt=False)
def _write_outputs(o, nt, bank, out, check, chol, record, slots, rec):
    """Output frame ``o``: the confirmed positions, the estimate (the confirmed track with the
    highest ψ, ties: older), the counts; with ``record`` every live track."""
    X, P, psi, conf, ids = bank.state, bank.covariance, bank.psi, bank.confirmed, bank.ids
    best = -1
    nc = 0
    for t in range(nt):
        if conf[t]:
            out.confirmed_xy[o, nc, 0] = X[t, 0]
            out.confirmed_xy[o, nc, 1] = X[t, 1]
            nc += 1
            if best < 0 or _better(psi[t], ids[t], psi[best], ids[best]):
                best = t
    out.n_confirmed[o] = nc
    out.n_tracks[o] = nt
    if check:
        for t in range(nt):
            if not healthy(X[t], P[t], psi[t], chol):
                out.n_unhealthy[o] += 1
    if best >= 0:
        out.has_estimate[o] = True
        out.estimate_xy[o, 0] = X[best, 0]
        out.estimate_xy[o, 1] = X[best, 1]
        out.estimate_psi[o] = psi[best]
        _copy_vector(out.estimate_state[o], X[best])
        _copy_matrix(out.estimate_covariance[o], P[best])
    if record:
        # every live track of this frame (nt <= max_tracks after the cap)
        rec.estimate[o] = best
        for t in range(nt):
            rec.ids[o, t] = ids[t]
            _copy_vector(rec.state[o, t], X[t])
            _copy_matrix(rec.covariance[o, t], P[t])
            rec.psi[o, t] = psi[t]
            rec.confirmed[o, t] = conf[t]
            rec.birth_frame[o, t] = slots.birth_frame[t]
            _copy_vector(rec.gate_center_xy[o, t], slots.gate_center_xy[t])
            _copy_matrix(rec.gate_shape_xy[o, t], slots.gate_shape_xy[t])
            rec.n_associated[o, t] = slots.n_associated[t]
            rec.nis[o, t] = slots.nis[t]


@njit(cache=True)
def track_kernel(frames_, c_, out_, check, record, rec_):
    """Track the frames (:class:`KernelFrames`) with the constants (:class:`KernelConstants`)
    into the outputs (:class:`KernelOutputs`); with ``check`` count unhealthy tracks, with
    ``record`` write every live track into the record
    (:class:`~core.tracking.results.TrackRecord`).

    The four groups arrive as plain tuples and are named again here: numba types a NamedTuple
    argument about 1 µs slower per call than a plain tuple. Per frame the steps are those of
    the readable tracker (:mod:`core.tracking.tracker`): prediction and gate, association and
    update, initiation, confirmation and deletion, merging, the cap, the outputs.
    """
    frames, c, out = KernelFrames(*frames_), KernelConstants(*c_), KernelOutputs(*out_)
    rec = TrackRecord(*rec_)
    z, f_off, t_off = frames.z, frames.frame_offsets, frames.trajectory_offsets
    max_m = 0
    for f in range(len(f_off) - 1):
        max_m = max(max_m, f_off[f + 1] - f_off[f])
    bank, slots, pred, cl, s = _allocate(c.F.shape[0], c.max_tracks, max_m, record)
    # log-weight of "no measurement is the track's" in IPDA: log(1 − P_D P_G)
    a0 = math.log1p(-c.pdpg) if c.pdpg < 1.0 else -math.inf
    for si in range(len(frames.trajectories)):
        k_traj = frames.trajectories[si]
        fa = t_off[k_traj]
        fb = t_off[k_traj + 1]
        o = frames.output_offsets[si]
        nt = 0
        next_id = 0
        for f in range(fa, fb):
            za = f_off[f]
            m = f_off[f + 1] - za
            # a frame starts with at most max_tracks tracks (the cap ends every frame)
            n_old = nt
            _predict_and_gate(z, za, m, n_old, bank, pred, cl, s, c, record, slots)
            _associate_and_update(n_old, bank, pred, cl, s, c, a0, record, slots)
            nt, next_id = _initiate(z, za, m, f - fa, nt, next_id, bank, s, c, record, slots)
            nt = _confirm_and_delete(nt, n_old, bank, c, record, slots)
            nt = _merge(nt, bank, c, record, slots)
            nt = _cap(nt, bank, c, record, slots)
            _write_outputs(o, nt, bank, out, check, s.chol, record, slots, rec)
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
