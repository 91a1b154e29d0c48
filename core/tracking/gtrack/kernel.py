"""gtrack compiled: the readable tracker (:mod:`core.tracking.gtrack.tracker`) step for step in
one ``@njit`` kernel over all frames, tested equal to it (tests/core/tracking/test_gtrack.py).

The kernel keeps the tracks in arrays of ``max_tracks`` slots in the readable form's order
(survivors in order, then the frame's new tracks) and records every frame's tracks. The
helpers live in this file for numba's cache (it checks only the cached function's own file).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)
from core.tracking.ekf import MIN_RANGE_M

# indices into the float parameter vector
(G_GAIN, G_WX, G_WY, G_WZ, G_V, A_SNR, A_SNR_OBS, A_VEL, A_DIST, A_VSPREAD, VRES, H_SENSOR,
 DISP_W, VMAX, U_ALPHA, U_CONF, U_LOCK, V_INIT, T_FRAME, V_STATIC, V_HALF) = range(21)  # fmt: skip
# indices into the integer parameter vector
(DIMS, MAX_TRACKS, DET2ACT, DET2FREE, ACT2FREE, STAT2FREE, EXIT2FREE, SLEEP2FREE,
 ALLOC_POINTS) = range(9)  # fmt: skip
DETECT, ACTIVE = 1, 2
RATE_FILTER, TRACKING, LOCKED = 1, 2, 3


@njit(cache=True)
def _wrap(a):
    w = ((a + math.pi) % (2.0 * math.pi)) - math.pi
    if w == -math.pi:
        w = math.pi
    return w


@njit(cache=True)
def _unroll(v, ref, vmax):
    span = 2.0 * vmax
    return v + span * math.floor((ref - v + vmax) / span)


@njit(cache=True)
def _velocity_stage(r_sum, v_bar, cnt, vr_pred, k, i, vst, rate, r_alloc, fp):
    """The readable form's ``_velocity_stage`` for track slot i: r_sum the moving points' range
    sum, v_bar their pilot-unrolled mean vr, k frames since allocation."""
    if vst[i] == LOCKED:
        return _unroll(v_bar, vr_pred, fp[VMAX])
    inst = (r_sum / cnt - r_alloc[i]) / (k * fp[T_FRAME])
    rate[i] = fp[U_ALPHA] * rate[i] + (1.0 - fp[U_ALPHA]) * inst
    v = _unroll(v_bar, rate[i], fp[VMAX])
    if vst[i] == RATE_FILTER:
        if abs(inst - rate[i]) < fp[U_CONF] * abs(rate[i]):
            vst[i] = TRACKING
    elif abs(vr_pred - v) < fp[U_LOCK] * abs(v):
        vst[i] = LOCKED
    return v


@njit(cache=True)
def _sensor_state(x, d, M, h):
    p = np.zeros(3)
    v = np.zeros(3)
    if d == 2:
        pw = (x[0], x[1], 0.0)
        vw = (x[2], x[3], 0.0)
    else:
        pw = (x[0], x[1], x[2] - h)
        vw = (x[3], x[4], x[5])
    for i in range(3):
        p[i] = M[0, i] * pw[0] + M[1, i] * pw[1] + M[2, i] * pw[2]
        v[i] = M[0, i] * vw[0] + M[1, i] * vw[1] + M[2, i] * vw[2]
    return p, v


@njit(cache=True)
def _safe(p, d):
    """Position moved out to MIN_RANGE_M (2-D: in x–y) along its bearing; returns its range."""
    if d == 2:
        r = math.hypot(p[0], p[1])
        if r >= MIN_RANGE_M:
            return r
        if r == 0.0:
            p[0], p[1] = 0.0, MIN_RANGE_M
        else:
            p[0], p[1] = p[0] * MIN_RANGE_M / r, p[1] * MIN_RANGE_M / r
        return MIN_RANGE_M
    r = math.sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2])
    if r >= MIN_RANGE_M:
        return r
    if r > 0:
        s = MIN_RANGE_M / r
        p[0], p[1], p[2] = p[0] * s, p[1] * s, p[2] * s
    else:
        p[0], p[1], p[2] = 0.0, MIN_RANGE_M, 0.0
    return MIN_RANGE_M


@njit(cache=True)
def _measure_jac(x, d, M, h, zp, H):
    """zp = h(x) and H = ∂h/∂x (filled in place)."""
    p, v = _sensor_state(x, d, M, h)
    r = _safe(p, d)
    H[:, :] = 0.0
    if d == 2:
        zp[0] = r
        zp[1] = math.atan2(p[0], p[1])
        zp[2] = (p[0] * v[0] + p[1] * v[1]) / r
        r2 = r * r
        r3 = r2 * r
        cross = v[0] * p[1] - v[1] * p[0]
        Js = np.zeros((3, 4))
        Js[0, 0], Js[0, 1] = p[0] / r, p[1] / r
        Js[1, 0], Js[1, 1] = p[1] / r2, -p[0] / r2
        Js[2, 0], Js[2, 1] = p[1] * cross / r3, -p[0] * cross / r3
        Js[2, 2], Js[2, 3] = p[0] / r, p[1] / r
        for i in range(3):
            for k in range(2):
                for j in range(2):
                    H[i, k] += Js[i, j] * M[k, j]
                    H[i, 2 + k] += Js[i, 2 + j] * M[k, j]
        return
    rho2 = p[0] * p[0] + p[1] * p[1]
    rho = math.sqrt(rho2)
    pv = p[0] * v[0] + p[1] * v[1] + p[2] * v[2]
    zp[0] = r
    zp[1] = math.atan2(p[0], p[1])
    zp[2] = math.atan2(p[2], rho)
    zp[3] = pv / r
    rho2 = max(rho2, 1e-12)
    rho = math.sqrt(rho2)
    Jp = np.zeros((4, 3))
    Jv = np.zeros((4, 3))
    for k in range(3):
        Jp[0, k] = p[k] / r
        Jp[3, k] = v[k] / r - pv * p[k] / r**3
        Jv[3, k] = p[k] / r
    Jp[1, 0], Jp[1, 1] = p[1] / rho2, -p[0] / rho2
    den = r * r * rho
    Jp[2, 0], Jp[2, 1], Jp[2, 2] = -p[0] * p[2] / den, -p[1] * p[2] / den, rho2 / den
    for i in range(4):
        for k in range(3):
            for j in range(3):
                H[i, k] += Jp[i, j] * M[k, j]
                H[i, 3 + k] += Jv[i, j] * M[k, j]


@njit(cache=True)
def _chol_inv(A, Ai):
    """Ai = A⁻¹ of a symmetric positive-definite A (Cholesky A = L Lᵀ); returns ln det A."""
    m = A.shape[0]
    L = np.zeros((m, m))
    logdet = 0.0
    for i in range(m):
        for j in range(i + 1):
            acc = A[i, j]
            for k in range(j):
                acc -= L[i, k] * L[j, k]
            if i == j:
                L[i, i] = math.sqrt(acc)
                logdet += 2.0 * math.log(L[i, i])
            else:
                L[i, j] = acc / L[j, j]
    # L⁻¹ (lower), then A⁻¹ = L⁻ᵀ L⁻¹
    Li = np.zeros((m, m))
    for i in range(m):
        Li[i, i] = 1.0 / L[i, i]
        for j in range(i):
            acc = 0.0
            for k in range(j, i):
                acc -= L[i, k] * Li[k, j]
            Li[i, j] = acc / L[i, i]
    for i in range(m):
        for j in range(i + 1):
            acc = 0.0
            for k in range(i, m):
                acc += Li[k, i] * Li[k, j]
            Ai[i, j] = acc
            Ai[j, i] = acc
    return logdet


@njit(cache=True)
def _sym(A):
    return 0.5 * (A + A.T)


@njit(cache=True)
def _in_box(x, box, d):
    ok = box[0] <= x[0] <= box[1] and box[2] <= x[1] <= box[3]
    if d == 3:
        ok = ok and box[4] <= x[2] <= box[5]
    return ok


@njit(cache=True)
def _gate_xy(zp, C, d, gain, az_tilt, out):
    r, az = zp[0], zp[1]
    ce = math.cos(zp[2]) if d == 3 else 1.0
    c, s = math.cos(az), math.sin(az)
    J = np.array([[s * ce, r * ce * c], [c * ce, -r * ce * s]])
    rot = np.array(
        [[math.cos(az_tilt), math.sin(az_tilt)], [-math.sin(az_tilt), math.cos(az_tilt)]]
    )
    J = rot @ J
    C2 = np.ascontiguousarray(C[:2, :2])
    out[:, :] = gain * gain * (J @ C2 @ J.T)


@njit(cache=True)
def _points(pts, a, k_pts, d, m, M, h, fp, boundary, static_box):
    """The frame's points: measurements z, world positions, static and usable flags."""
    z = np.zeros((k_pts, m))
    pw = np.zeros((k_pts, 3))
    usable = np.zeros(k_pts, np.bool_)
    static = np.zeros(k_pts, np.bool_)
    for j in range(k_pts):
        r, az, el, vr = pts[a + j, 0], pts[a + j, 1], pts[a + j, 2], pts[a + j, 3]
        z[j, 0], z[j, 1] = r, az
        if d == 3:
            z[j, 2] = el
        z[j, m - 1] = vr
        e = el if d == 3 else 0.0
        ps = (r * math.cos(e) * math.sin(az), r * math.cos(e) * math.cos(az), r * math.sin(e))
        for k in range(3):
            pw[j, k] = M[k, 0] * ps[0] + M[k, 1] * ps[1] + M[k, 2] * ps[2]
        if d == 3:
            pw[j, 2] += h
        static[j] = abs(vr) < 0.5 * fp[VRES]
        usable[j] = _in_box(pw[j], boundary, d) and (not static[j] or _in_box(pw[j], static_box, d))
    return z, pw, usable, static


@njit(cache=True)
def _predict(nt, X, P, D, F, Q, R, M, h, d, m, xp, Pp, Hs, zps, Cs, Cis, logdet):
    """Predict every live track; its measurement, Jacobian and gate covariance."""
    for i in range(nt):
        xp[i] = F @ X[i]
        Pp[i] = _sym(F @ P[i] @ F.T + Q)
        _measure_jac(xp[i], d, M, h, zps[i], Hs[i])
        C = Hs[i] @ Pp[i] @ Hs[i].T + R
        for k in range(m):
            C[k, k] += D[i, k]
        Cs[i] = _sym(C)
        logdet[i] = _chol_inv(Cs[i], Cis[i])


@njit(cache=True)
def _associate(nt, k_pts, usable, pw, z, xp, zps, Cis, logdet, fp, d, m):
    """Gate and associate: each point's track (−1 none)."""
    gain2 = fp[G_GAIN] * fp[G_GAIN]
    half = np.array([fp[G_WX], fp[G_WY], fp[G_WZ]]) / 2.0
    owner = np.full(k_pts, -1, np.int64)
    best = np.full(k_pts, np.inf)
    nu = np.zeros(m)
    for i in range(nt):
        for j in range(k_pts):
            if not usable[j]:
                continue
            # the limits first (cheap; most pairs fail them), then the distance
            inside = True
            for k in range(d):
                if abs(pw[j, k] - xp[i, k]) > half[k]:
                    inside = False
            if not inside:
                continue
            for k in range(m):
                nu[k] = z[j, k] - zps[i, k]
            nu[1] = _wrap(nu[1])
            if d == 3:
                nu[2] = _wrap(nu[2])
            nu[m - 1] = _unroll(z[j, m - 1], zps[i, m - 1], fp[VMAX]) - zps[i, m - 1]
            d2 = 0.0
            d2p = 0.0  # the gate's partial distance: position rows only
            for k in range(m):
                for l in range(m):
                    e = nu[k] * Cis[i, k, l] * nu[l]
                    d2 += e
                    if k < m - 1 and l < m - 1:
                        d2p += e
            if not d2p <= gain2:
                continue
            if fp[G_V] > 0 and abs(nu[m - 1]) > fp[G_V] / 2.0:
                continue
            score = d2 + logdet[i]
            if score < best[j]:
                best[j] = score
                owner[j] = i
    return owner


@njit(cache=True)
def _update(a, f, nt, k_pts, owner, static, z, ids, birth, X, P, D, xp, Pp, Hs, zps, Cs, R,
            fp, d, m, cap, az_tilt, vst, rate, r_alloc, still, point_track):  # fmt: skip
    """Update every live track with its points (or TI's handling of a frame without moving
    points); returns the points counts, NIS and the gates."""
    eye = np.eye(3 * d)
    nas = np.zeros(cap + 0, np.int64)
    nis = np.full(cap, np.nan)
    gc = np.zeros((cap, 2))
    gs = np.zeros((cap, 2, 2))
    for i in range(nt):
        gc[i, 0], gc[i, 1] = xp[i, 0], xp[i, 1]
        _gate_xy(zps[i], Cs[i], d, fp[G_GAIN], az_tilt, gs[i])
        cnt = 0
        n_mov = 0
        for j in range(k_pts):
            if owner[j] == i:
                cnt += 1
                point_track[a + j] = ids[i]
                if not static[j]:
                    n_mov += 1
        nas[i] = cnt
        if n_mov == 0:
            # no moving point: no update; the track slows down or stops (TI's erasure)
            X[i] = xp[i]
            P[i] = Pp[i]
            if not still[i]:
                speed = 0.0
                for k in range(d):
                    speed += X[i, d + k] ** 2
                if math.sqrt(speed) < fp[V_STATIC]:
                    fac = 0.0
                    still[i] = cnt == 0 or cnt > 3
                else:
                    fac = fp[V_HALF]
                for k in range(d):
                    X[i, d + k] *= fac
                    X[i, 2 * d + k] = 0.0
            continue
        still[i] = False
        nus = np.zeros((cnt, m))
        c = 0
        for j in range(k_pts):
            if owner[j] == i:
                for k in range(m):
                    nus[c, k] = z[j, k] - zps[i, k]
                nus[c, 1] = _wrap(nus[c, 1])
                if d == 3:
                    nus[c, 2] = _wrap(nus[c, 2])
                nus[c, m - 1] = _unroll(z[j, m - 1], zps[i, m - 1], fp[VMAX]) - zps[i, m - 1]
                c += 1
        nu_bar = np.zeros(m)
        for k in range(m):
            nu_bar[k] = np.mean(nus[:, k])
        # the radial-velocity row: the moving points' centroid, unrolled by stage
        n_mov = 0
        r_sum = 0.0
        v_sum = 0.0
        pilot = 0.0
        for j in range(k_pts):
            if owner[j] == i and not static[j]:
                if n_mov == 0:
                    pilot = z[j, m - 1]
                n_mov += 1
                r_sum += z[j, 0]
                v_sum += _unroll(z[j, m - 1], pilot, fp[VMAX])
        vr_c = _velocity_stage(r_sum, v_sum / n_mov, n_mov, zps[i, m - 1], f - birth[i], i,
                               vst, rate, r_alloc, fp)  # fmt: skip
        nu_bar[m - 1] = vr_c - zps[i, m - 1]
        Rc = R.copy()
        for k in range(m):
            Rc[k, k] += D[i, k]
        Rc = Rc / cnt
        H = Hs[i]
        S = _sym(H @ Pp[i] @ H.T + Rc)
        Si = np.zeros((m, m))
        _chol_inv(S, Si)
        K = Pp[i] @ H.T @ Si
        X[i] = xp[i] + K @ nu_bar
        IKH = eye - K @ H
        P[i] = _sym(IKH @ Pp[i] @ IKH.T + K @ Rc @ K.T)
        nis[i] = nu_bar @ Si @ nu_bar
        if cnt > 1:
            for k in range(m):
                sp = np.mean((nus[:, k] - nu_bar[k]) ** 2)
                D[i, k] = (1.0 - fp[DISP_W]) * D[i, k] + fp[DISP_W] * sp
    return nas, nis, gc, gs


@njit(cache=True)
def _transition(nt, k_pts, owner, static, nas, X, st, hits, misses, sleeps, still,
                static_box, ip, d, cap):  # fmt: skip
    """Count each track's hit or miss; which tracks are kept."""
    keep = np.zeros(cap, np.bool_)
    for i in range(nt):
        if st[i] == DETECT:
            moving = False
            for j in range(k_pts):
                if owner[j] == i and not static[j]:
                    moving = True
            if moving:
                hits[i] += 1
                misses[i] = 0
                if hits[i] >= ip[DET2ACT]:
                    st[i] = ACTIVE
                keep[i] = True
            else:
                hits[i] = 0
                misses[i] += 1
                keep[i] = misses[i] < ip[DET2FREE]
            continue
        in_static = _in_box(X[i], static_box, d)
        if nas[i] > 0:
            misses[i] = 0
            all_static = True
            for j in range(k_pts):
                if owner[j] == i and not static[j]:
                    all_static = False
            if in_static and all_static:
                sleeps[i] += 1
                keep[i] = sleeps[i] < ip[SLEEP2FREE]
            else:
                sleeps[i] = 0
                keep[i] = True
            continue
        misses[i] += 1
        if not in_static:
            limit = ip[EXIT2FREE]
        elif still[i]:
            limit = ip[STAT2FREE]
        else:
            limit = ip[ACT2FREE]
        keep[i] = misses[i] < limit
    return keep


@njit(cache=True)
def _allocate(a, pts, nt, next_id, k_pts, usable, static, owner, pw, z, X, M, h, P0, R, fp,
              ip, d, m, cap, az_tilt, point_track):  # fmt: skip
    """New tracks from the points no track took (live count and the obscuring tracks: this
    frame's tracks before freeing)."""
    n = 3 * d
    free = np.zeros(k_pts, np.bool_)
    for j in range(k_pts):
        free[j] = usable[j] and not static[j] and owner[j] < 0
    bX = np.zeros((cap, n))
    bD = np.zeros((cap, m))
    bid = np.zeros(cap, np.int64)
    bgs = np.zeros((cap, 2, 2))
    brate = np.zeros(cap)
    bralloc = np.zeros(cap)
    nb = 0
    members = np.zeros(k_pts, np.int64)
    cvec = np.zeros(3)
    for i0 in range(k_pts):
        if not free[i0]:
            continue
        if nt + nb >= cap:
            break
        nm = 1
        members[0] = i0
        for k in range(d):
            cvec[k] = pw[i0, k]
        cv = pts[a + i0, 3]
        for j in range(i0 + 1, k_pts):
            if not free[j]:
                continue
            dist = 0.0
            for k in range(d):
                dist += (pw[j, k] - cvec[k]) ** 2
            vj = _unroll(pts[a + j, 3], cv, fp[VMAX])
            if abs(vj - cv) < fp[A_VSPREAD] and dist < fp[A_DIST]:
                members[nm] = j
                nm += 1
                for k in range(d):
                    cvec[k] += (pw[j, k] - cvec[k]) / nm
                cv += (vj - cv) / nm
        if nm <= ip[ALLOC_POINTS] or not abs(cv) > fp[A_VEL]:
            continue
        snr_sum = 0.0
        for q in range(nm):
            snr_sum += pts[a + members[q], 4]
        # obscured: a track of this frame nearer the sensor at about the set's bearing
        cs = np.zeros(3)
        c3 = (cvec[0], cvec[1], cvec[2] - h if d == 3 else 0.0)
        for k in range(3):
            cs[k] = M[0, k] * c3[0] + M[1, k] * c3[1] + M[2, k] * c3[2]
        r_c = math.sqrt(cs[0] ** 2 + cs[1] ** 2 + cs[2] ** 2)
        az_c = math.atan2(cs[0], cs[1])
        obscured = False
        for i in range(nt):
            t3 = (X[i, 0], X[i, 1], X[i, 2] - h if d == 3 else 0.0)
            pt0 = M[0, 0] * t3[0] + M[1, 0] * t3[1] + M[2, 0] * t3[2]
            pt1 = M[0, 1] * t3[0] + M[1, 1] * t3[1] + M[2, 1] * t3[2]
            pt2 = M[0, 2] * t3[0] + M[1, 2] * t3[1] + M[2, 2] * t3[2]
            r_t = math.sqrt(pt0 * pt0 + pt1 * pt1 + pt2 * pt2)
            if r_t >= r_c or r_t == 0.0:
                continue
            hw = math.atan2(fp[G_WX] / 2.0, r_t)
            if abs(_wrap(math.atan2(pt0, pt1) - az_c)) <= hw:
                obscured = True
                break
        thr = fp[A_SNR_OBS] if obscured else fp[A_SNR]
        if not snr_sum > thr:
            continue
        for q in range(nm):
            free[members[q]] = False
            point_track[a + members[q]] = next_id
        # the new track
        x = np.zeros(n)
        for k in range(d):
            x[k] = cvec[k]
        rn = max(r_c, MIN_RANGE_M)
        # TI's INIT stage: the set's vr unrolled to the initial radial velocity
        rr = _unroll(cv, fp[V_INIT], fp[VMAX])
        for k in range(d):
            x[d + k] = (M[k, 0] * cs[0] + M[k, 1] * cs[1] + M[k, 2] * cs[2]) * rr / rn
        brate[nb] = rr
        rsum = 0.0
        for q in range(nm):
            rsum += z[members[q], 0]
        bralloc[nb] = rsum / nm
        if nm > 1:
            for k in range(m):
                col = np.zeros(nm)
                for q in range(nm):
                    col[q] = z[members[q], k]
                bD[nb, k] = np.var(col)
        bX[nb] = x
        bid[nb] = next_id
        next_id += 1
        Hn = np.zeros((m, n))
        zn = np.zeros(m)
        _measure_jac(x, d, M, h, zn, Hn)
        Cn = Hn @ P0 @ Hn.T + R
        for k in range(m):
            Cn[k, k] += bD[nb, k]
        _gate_xy(zn, Cn, d, fp[G_GAIN], az_tilt, bgs[nb])
        nb += 1
    return nb, next_id, bX, bD, bid, bgs, brate, bralloc


@njit(cache=True)
def _compact(f, nt, nb, keep, X, P, D, st, hits, misses, sleeps, ids, birth, vst, rate,
             r_alloc, still, gc, gs, nas, nis, bX, bD, bid, bgs, brate, bralloc, P0,
             ip):  # fmt: skip
    """Survivors in order, then the new tracks; returns the live count."""
    w = 0
    for i in range(nt):
        if keep[i]:
            X[w], P[w], D[w] = X[i], P[i], D[i]
            st[w], hits[w], misses[w], sleeps[w] = st[i], hits[i], misses[i], sleeps[i]
            ids[w], birth[w] = ids[i], birth[i]
            vst[w], rate[w], r_alloc[w], still[w] = vst[i], rate[i], r_alloc[i], still[i]
            gc[w], gs[w], nas[w], nis[w] = gc[i], gs[i], nas[i], nis[i]
            w += 1
    for q in range(nb):
        X[w], P[w], D[w] = bX[q], P0, bD[q]
        st[w] = ACTIVE if 1 >= ip[DET2ACT] else DETECT
        hits[w], misses[w], sleeps[w] = 1, 0, 0
        ids[w], birth[w] = bid[q], f
        vst[w], rate[w], r_alloc[w], still[w] = RATE_FILTER, brate[q], bralloc[q], False
        gc[w, 0], gc[w, 1] = bX[q, 0], bX[q, 1]
        gs[w], nas[w], nis[w] = bgs[q], 0, np.nan
        w += 1
    return w


@njit(cache=True)
def _record(f, nt, ids, X, P, st, gc, gs, birth, nas, nis, presence_box, d, rec_n, rec_ids,
            rec_x, rec_P, rec_conf, rec_gc, rec_gs, rec_birth, rec_nas, rec_nis, rec_est,
            presence):  # fmt: skip
    """The frame's tracks into the rec_* arrays, the estimate and the presence flag."""
    rec_n[f] = nt
    est, est_n, est_id = -1, -1, 0
    pres = False
    for i in range(nt):
        rec_ids[f, i] = ids[i]
        rec_x[f, i] = X[i]
        rec_P[f, i] = P[i]
        rec_conf[f, i] = st[i] == ACTIVE
        rec_gc[f, i] = gc[i]
        rec_gs[f, i] = gs[i]
        rec_birth[f, i] = birth[i]
        rec_nas[f, i] = nas[i]
        rec_nis[f, i] = nis[i]
        if st[i] == ACTIVE:
            if nas[i] > est_n or (nas[i] == est_n and ids[i] < est_id):
                est, est_n, est_id = i, nas[i], ids[i]
            if _in_box(X[i], presence_box, d):
                pres = True
    rec_est[f] = est
    presence[f] = pres


@njit(cache=True)
def gtrack_kernel(pts, off, M, F, Q, R, P0, fp, ip, boundary, static_box, presence_box,
                  az_tilt, rec_n, rec_ids, rec_x, rec_P, rec_conf, rec_gc, rec_gs, rec_birth,
                  rec_nas, rec_nis, rec_est, point_track, presence):  # fmt: skip
    """Track all frames (see the module docstring); fills the ``rec_*`` arrays, the points'
    track ids and the presence flags. Per frame the steps of the readable tracker's ``step``:
    points, predict, gate and associate, update, states, allocation."""
    d = ip[DIMS]
    n = 3 * d
    m = 4 if d == 3 else 3
    cap = ip[MAX_TRACKS]
    h = fp[H_SENSOR]
    # live tracks (slots 0..nt−1 in order)
    X = np.zeros((cap, n))
    P = np.zeros((cap, n, n))
    D = np.zeros((cap, m))
    st = np.zeros(cap, np.int64)
    hits = np.zeros(cap, np.int64)
    misses = np.zeros(cap, np.int64)
    sleeps = np.zeros(cap, np.int64)
    ids = np.zeros(cap, np.int64)
    birth = np.zeros(cap, np.int64)
    vst = np.zeros(cap, np.int64)
    rate = np.zeros(cap)
    r_alloc = np.zeros(cap)
    still = np.zeros(cap, np.bool_)
    nt = 0
    next_id = 0
    xp = np.zeros((cap, n))
    Pp = np.zeros((cap, n, n))
    Hs = np.zeros((cap, m, n))
    zps = np.zeros((cap, m))
    Cs = np.zeros((cap, m, m))
    Cis = np.zeros((cap, m, m))
    logdet = np.zeros(cap)
    for f in range(len(off) - 1):
        a, b = off[f], off[f + 1]
        k_pts = b - a
        z, pw, usable, static = _points(pts, a, k_pts, d, m, M, h, fp, boundary, static_box)
        _predict(nt, X, P, D, F, Q, R, M, h, d, m, xp, Pp, Hs, zps, Cs, Cis, logdet)
        owner = _associate(nt, k_pts, usable, pw, z, xp, zps, Cis, logdet, fp, d, m)
        nas, nis, gc, gs = _update(a, f, nt, k_pts, owner, static, z, ids, birth, X, P, D, xp,
                                   Pp, Hs, zps, Cs, R, fp, d, m, cap, az_tilt, vst, rate,
                                   r_alloc, still, point_track)  # fmt: skip
        keep = _transition(nt, k_pts, owner, static, nas, X, st, hits, misses, sleeps, still,
                           static_box, ip, d, cap)  # fmt: skip
        nb, next_id, bX, bD, bid, bgs, brate, bralloc = _allocate(
            a, pts, nt, next_id, k_pts, usable, static, owner, pw, z, X, M, h, P0, R, fp, ip, d,
            m, cap, az_tilt, point_track)  # fmt: skip
        nt = _compact(f, nt, nb, keep, X, P, D, st, hits, misses, sleeps, ids, birth, vst, rate,
                      r_alloc, still, gc, gs, nas, nis, bX, bD, bid, bgs, brate, bralloc, P0,
                      ip)  # fmt: skip
        _record(f, nt, ids, X, P, st, gc, gs, birth, nas, nis, presence_box, d, rec_n, rec_ids,
                rec_x, rec_P, rec_conf, rec_gc, rec_gs, rec_birth, rec_nas, rec_nis, rec_est,
                presence)  # fmt: skip
