"""The ``measurement`` level's compiled kernel: steps 1-4 of :mod:`core.simulation.measurement`
for any number of frames in one call (:func:`measure_frames`).

The Python side (tables, constants, false-alarm pool, entry points) is
:mod:`core.simulation.measurement`; the argument tuples the kernel reads are defined there. The
draws (xoshiro256**: uniform, Box-Muller normal, Gamma, Poisson, integer) are
:mod:`core.simulation.rng_kernels`.
"""

from __future__ import annotations

import numba
import numpy as np

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)
from core.processing.points import angles_of
from core.simulation.rng_kernels import ss_gamma, ss_normal, ss_poisson, ss_randint, ss_uniform

__all__ = ["measure_frames"]


@numba.njit(cache=True, nogil=True)
def _lerp(table, x, x0, step):  # pragma: no cover
    """Linear interpolation in a table on the uniform grid ``x0 + i step`` (clamped)."""
    t = (x - x0) / step
    i = int(np.floor(t))
    i = min(max(i, 0), table.shape[0] - 2)
    w = min(max(t - i, 0.0), 1.0)
    return table[i] * (1.0 - w) + table[i + 1] * w


@numba.njit(cache=True, nogil=True)
def _training_sum(s, method, n_train, n_eff, L, leak_l, leak_r):  # pragma: no cover
    """CFAR noise estimate: each side ``(n / n_eff) Gamma(n_eff L)`` plus the own leakage."""
    z1 = ss_gamma(s, n_eff * L) * (n_train / n_eff) + leak_l
    z2 = ss_gamma(s, n_eff * L) * (n_train / n_eff) + leak_r
    if method == 0:
        # CA: (Z1 + Z2) / 2n
        return (z1 + z2) / (2 * n_train)
    if method == 1:
        # CASO: min(Z1, Z2) / n
        return min(z1, z2) / n_train
    # CAGO: max(Z1, Z2) / n
    return max(z1, z2) / n_train


@numba.njit(cache=True, nogil=True)
def _grow(f64, i64, need):  # pragma: no cover
    """The output buffers with room for at least ``need`` rows (doubling)."""
    if need <= f64.shape[0]:
        return f64, i64
    cap = max(need, 2 * f64.shape[0])
    f2 = np.empty((cap, f64.shape[1]))
    i2 = np.empty((cap, i64.shape[1]), dtype=np.int64)
    f2[: f64.shape[0]] = f64
    i2[: i64.shape[0]] = i64
    return f2, i2


@numba.njit(cache=True, nogil=True)
def measure_frames(
    states, start, pos, vel, gain_db, rcs, elev, noise, const, tables, array, fa
):  # pragma: no cover
    """Steps 1-4 of the module docstring for every frame ``f`` (reflectors
    ``start[f]:start[f+1]``), frame ``f`` drawing from the generator state ``states[f]``.

    Returns ``counts`` ``(F,)``, ``f64`` ``(n, 8)`` (range, azimuth, elevation, radial velocity,
    SNR, x, y, z) and ``i64`` ``(n, 3)`` (reflector index or -1 for a false alarm, range bin,
    Doppler index). ``const``: :class:`ModelConstants`; ``tables``: :class:`KernelTables`;
    ``array``: :class:`ArrayLayout`; ``fa``: :class:`FalseAlarmPool`.
    """
    t_mid, range_res, vel_res, n_loops = const.t_mid, const.range_res, const.vel_res, const.n_loops
    doppler_scale, c_amp2, L = const.doppler_scale, const.c_amp2, const.L
    rmeth, rn, rne, ralpha = const.range_stage
    dmeth, dn, dne, dalpha = const.doppler_stage
    bin_lo, bin_hi = const.bin_lo, const.bin_hi  # (const.m_az: not read here)
    range_gain, range_est, range_leak = tables.range_gain, tables.range_est, tables.range_leak
    doppler_gain, doppler_index = tables.doppler_gain, tables.doppler_index
    doppler_est, doppler_leak, cell_noise = (
        tables.doppler_est,
        tables.doppler_leak,
        tables.cell_noise,
    )
    az_pos, el_pos, n_tx, n_rx = array.az_pos, array.el_pos, array.n_tx, array.n_rx
    row_ch, row_pos, upper, lower, tw_a = (
        array.row_ch, array.row_pos, array.upper, array.lower, array.tw_a
    )  # fmt: skip
    fa_rate, fa_doppler, fa_snr, fa_az, fa_frac = fa
    n_frames = states.shape[0]
    counts = np.zeros(n_frames, dtype=np.int64)
    cap = start[n_frames] + 4 * n_frames + 16
    f64 = np.empty((cap, 8))
    i64 = np.empty((cap, 3), dtype=np.int64)
    n_out = 0
    f_step = 1.0 / (range_gain.shape[0] - 1)
    half = n_loops / 2
    nu_step = n_loops / (doppler_gain.shape[0] - 1)
    n_v = az_pos.shape[0]
    xv = np.empty(n_v, dtype=np.complex128)
    spec = np.empty(tw_a.shape[0])
    s = np.empty(4, dtype=np.uint64)
    for fr in range(n_frames):
        s[:] = states[fr]
        first = n_out
        for i in range(start[fr], start[fr + 1]):
            px = pos[i, 0] + vel[i, 0] * t_mid
            py = pos[i, 1] + vel[i, 1] * t_mid
            pz = pos[i, 2] + vel[i, 2] * t_mid
            r = np.sqrt(px * px + py * py + pz * pz)
            vr = (px * vel[i, 0] + py * vel[i, 1] + pz * vel[i, 2]) / r
            r0 = np.sqrt(pos[i, 0] ** 2 + pos[i, 1] ** 2 + pos[i, 2] ** 2)
            # A^2 = Pt Gt Gr lambda^2 sigma / ((4 pi)^3 R^4) * R 10^(Ge/20)   (eqs. 2-4)
            amp2 = c_amp2 * 10.0 ** ((2.0 * gain_db[i] + rcs[i]) / 10.0) / r0**4
            rb = r / range_res
            k_int = np.floor(rb)
            f = rb - k_int
            nu_true = doppler_scale * vr / vel_res
            nu = (nu_true + half) % n_loops - half
            gr = _lerp(range_gain, f, 0.0, f_step)
            r_est = k_int + _lerp(range_est, f, 0.0, f_step)
            jd = int(np.rint((nu + half) / nu_step))
            jr = int(np.rint(f / f_step))
            dc = doppler_index[jd]
            d_est = _lerp(doppler_est, nu, -half, nu_step)
            # rho = A^2 |R|^2 |D|^2 / s2[d]  (per channel, peak cell)
            rho = max(amp2 * gr * doppler_gain[jd] / cell_noise[dc], 1e-30)
            # the array phase of the exact chain is that of the first chirp's direction
            u0 = pos[i, 0] / r0
            s0 = pos[i, 2] / r0
            if noise:
                # X = |sqrt(L rho) + n|^2 + Gamma(L - 1),  n ~ CN(0, 1)
                a = np.sqrt(L * rho) + ss_normal(s) / np.sqrt(2.0)
                b = ss_normal(s) / np.sqrt(2.0)
                x = a * a + b * b + ss_gamma(s, L - 1.0)
                # training cells: noise plus the reflector's own leakage (units of s2)
                leak = L * amp2 / cell_noise[dc]
                lr = leak * doppler_gain[jd]
                ld = leak * gr
                mu_r = _training_sum(
                    s, rmeth, rn, rne, L, lr * range_leak[jr, 0], lr * range_leak[jr, 1]
                )
                mu_d = _training_sum(
                    s, dmeth, dn, dne, L, ld * doppler_leak[jd, 0], ld * doppler_leak[jd, 1]
                )
                det = x > ralpha * mu_r and x > dalpha * mu_d
                snr = 10.0 * np.log10(x / mu_r)
                # Cramer-Rao: var(bin) = 6 / (4 pi^2 L rho)
                sd_bin = np.sqrt(6.0 / (4.0 * np.pi**2 * L * rho))
                r_est += sd_bin * ss_normal(s)
                d_est += sd_bin * ss_normal(s)
            else:
                det = True
                snr = 10.0 * np.log10(L * rho)
            # angles: the chain's estimator on the peak cell's channel values, units of noise:
            # x_v = rho^(1/2) exp(j pi (p_v u + e_v sin el)) exp(j 2 pi nu k(v) / (Nc Ntx)) + n_v
            amp = np.sqrt(rho)
            for v in range(n_v):
                ph = np.pi * (az_pos[v] * u0 + el_pos[v] * s0)
                ph += 2.0 * np.pi * nu_true * (v // n_rx) / (n_loops * n_tx)
                xv[v] = amp * (np.cos(ph) + 1j * np.sin(ph))
                if noise:
                    xv[v] += (ss_normal(s) + 1j * ss_normal(s)) / np.sqrt(2.0)
            a_i, e_i = angles_of(
                xv,
                d_est,
                n_tx,
                n_rx,
                n_loops,
                row_ch,
                row_pos,
                upper,
                lower,
                tw_a,
                elev[fr],
                spec,
            )
            if not (det and bin_lo - 0.5 <= r_est <= bin_hi + 0.5):
                continue
            u_est = np.sin(a_i) * np.cos(e_i)
            az = np.arcsin(min(max(u_est / np.cos(e_i), -1.0), 1.0))
            f64, i64 = _grow(f64, i64, n_out + 1)
            rng_m = r_est * range_res
            f64[n_out, 0] = rng_m
            f64[n_out, 1] = az
            f64[n_out, 2] = e_i
            f64[n_out, 3] = ((d_est + half) % n_loops - half) * vel_res
            f64[n_out, 4] = snr
            i64[n_out, 0] = i
            i64[n_out, 1] = int(np.rint(r_est))
            i64[n_out, 2] = dc
            n_out += 1
        if noise and fa_rate > 0.0 and fa_snr.shape[0] > 0:
            # the chain's own false alarms: Poisson count, resampled from the measured pool,
            # range uniform over the detectable bins, Doppler refinement uniform in the cell
            k = ss_poisson(s, fa_rate)
            f64, i64 = _grow(f64, i64, n_out + k)
            for _ in range(k):
                pick = ss_randint(s, fa_snr.shape[0])
                rb = bin_lo + ss_randint(s, bin_hi - bin_lo + 1) + fa_frac[pick]
                db = fa_doppler[pick] - n_loops // 2 + (ss_uniform(s) - 0.5)
                f64[n_out, 0] = rb * range_res
                f64[n_out, 1] = fa_az[pick]
                f64[n_out, 2] = 0.0
                f64[n_out, 3] = db * vel_res
                f64[n_out, 4] = fa_snr[pick]
                i64[n_out, 0] = -1
                i64[n_out, 1] = int(np.rint(rb))
                i64[n_out, 2] = fa_doppler[pick]
                n_out += 1
        for j in range(first, n_out):
            # x = r cos(el) sin(az), y = r cos(el) cos(az), z = r sin(el)
            horiz = f64[j, 0] * np.cos(f64[j, 2])
            f64[j, 5] = horiz * np.sin(f64[j, 1])
            f64[j, 6] = horiz * np.cos(f64[j, 1])
            f64[j, 7] = f64[j, 0] * np.sin(f64[j, 2])
        counts[fr] = n_out - first
    return counts, f64[:n_out], i64[:n_out]
