"""The ``fast`` level's closed-form model (see :mod:`core.simulation.fast`): the chain's range and
Doppler responses of a point scatterer, the per-cell noise power, and the compiled kernels that
draw a frame's noise map and its patches (cells where some scatterer's energy matters).
"""

from __future__ import annotations

import functools

import numba
import numpy as np
import scipy.fft

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)
from core.config import SPEED_OF_LIGHT_MPS, ProcessingSettings, RadarConfig
from core.processing import window
from core.simulation.link import noise_power_v2
from core.simulation.rng_kernels import FI, KI, WI, gamma_f32_l, gamma_l, normal_l
from core.simulation.scatterers import Scatterers

#: Per-channel signal power, relative to the cell's noise power, above which a cell gets
#: per-channel noise and the coherent signal (-30 dB: the signal changes the cell's mean power
#: by less than 0.1 % elsewhere).
PATCH_THRESHOLD = 1e-3

#: Per-channel power of one scatterer in a patch cell, relative to the cell's noise power, below
#: which it is left out of the cell's coherent sum (-50 dB: each one left out moves a channel of
#: signal power ``P`` by at most ``2 sqrt(SUM_FLOOR P s2) + SUM_FLOOR s2``, 2 % of the noise
#: power and 0.2 % of ``P`` at 10 dB over the noise; see docs/decisions/scene-06-walking-body.md).
SUM_FLOOR = 1e-5


@functools.lru_cache(maxsize=32)
def _doppler_window_shifted(name: str, n: int) -> np.ndarray:
    """Doppler window with the fftshift folded in (``w[m] (-1)^m`` for even ``n``), complex128."""
    w = window(name, n).astype(np.float64)
    if n % 2 == 0:
        w = w * np.where(np.arange(n) % 2 == 0, 1.0, -1.0)
    return w


@functools.lru_cache(maxsize=32)
def cell_noise_power_v2(radar: RadarConfig, settings: ProcessingSettings) -> np.ndarray:
    """Noise power per virtual channel and range-Doppler cell after both FFTs, ``(n_loops,)`` V².

    ``s2[d] = sigma^2 sum w_r^2 (sum w_d^2 - |W_d(d)|^2 / Nc)`` with static clutter removal,
    ``sigma^2 sum w_r^2 sum w_d^2`` without; index ``d`` is zero-velocity centred. The same for
    every range bin.
    """
    wr = window(settings.range_window, radar.n_samples).astype(np.float64)
    wd = window(settings.doppler_window, radar.n_loops).astype(np.float64)
    n = radar.n_loops
    gain_d = np.full(n, np.sum(wd**2))
    if settings.static_clutter_removal:
        # W_d(d) = sum_m w_m exp(-j 2 pi (d - n/2) m / n)
        big_w = (
            np.fft.fftshift(np.fft.fft(wd))
            if n % 2
            else np.fft.fft(_doppler_window_shifted(settings.doppler_window, n))
        )
        # s2[d] / (sigma^2 sum w_r^2) = sum w_d^2 - |W_d(d)|^2 / Nc
        gain_d = gain_d - np.abs(big_w) ** 2 / n
    out = noise_power_v2(radar) * np.sum(wr**2) * gain_d
    out.flags.writeable = False
    return out


def range_responses(radar: RadarConfig, range_m: np.ndarray, settings: ProcessingSettings):
    """Range window's response to each scatterer's beat tone, ``(N, n_samples)`` complex128.

    ``R[k] = sum_n w_r[n] exp(j theta n) exp(-j 2 pi k n / Nadc)``,
    ``theta = 2 pi (2 S R / c) / Fs``.
    """
    n = np.arange(radar.n_samples)
    # theta = 2 pi (2 S R / c) / Fs   (rad per sample)
    theta = (
        2
        * np.pi
        * 2
        * radar.slope_hz_per_s
        * np.asarray(range_m)
        / (SPEED_OF_LIGHT_MPS * radar.sample_rate_hz)
    )
    wr = window(settings.range_window, radar.n_samples).astype(np.float64)
    tone = wr[None, :] * np.exp(1j * ((theta[:, None] * n[None, :]) % (2 * np.pi)))
    return scipy.fft.fft(tone, axis=-1)


def slow_time_sequences(
    radar: RadarConfig, scatterers: Scatterers, settings: ProcessingSettings
) -> tuple[np.ndarray, np.ndarray]:
    """Slow-time sequences ``y`` and ``delta y`` per scatterer and TX slot, ``(N, n_tx, n_loops)``.

    ``y_c = exp(j (4 pi R(t_c) / lambda + delta_c (Nadc - 1) / 2))`` and ``delta_c y_c`` with
    ``delta_c = theta' (R(t_c) - R(t_mid))`` the beat tone's drift (rad/sample) at chirp ``c``;
    both after static clutter removal when the settings ask for it.
    """
    return _slow_time_kernel(
        np.ascontiguousarray(scatterers.position_m, dtype=np.float64),
        np.ascontiguousarray(scatterers.velocity_mps, dtype=np.float64),
        radar.n_tx,
        radar.n_loops,
        radar.chirp_period_s,
        4 * np.pi / radar.wavelength_m,
        beat_rad_per_sample_per_m(radar),
        radar.n_samples,
        settings.static_clutter_removal,
    )


def beat_rad_per_sample_per_m(radar: RadarConfig) -> float:
    """``theta' = 2 pi (2 S / c) / Fs``: beat tone phase per ADC sample per metre of range."""
    return 2 * np.pi * 2 * radar.slope_hz_per_s / (SPEED_OF_LIGHT_MPS * radar.sample_rate_hz)


def doppler_responses(
    radar: RadarConfig, scatterers: Scatterers, settings: ProcessingSettings
) -> np.ndarray:
    """Slow-time response of each scatterer per TX slot, ``(N, n_tx, n_loops)`` complex128.

    Index ``d`` is zero-velocity centred. Includes the TDM slot delay, static clutter removal
    and the beat tone's phase drift with the range (see the module docstring).
    """
    y = slow_time_sequences(radar, scatterers, settings)[0]
    w = _doppler_window_shifted(settings.doppler_window, radar.n_loops)
    out = scipy.fft.fft(y * w, axis=-1)
    if radar.n_loops % 2:
        out = np.fft.fftshift(out, axes=-1)
    return out


@functools.lru_cache(maxsize=32)
def cosine_sum_coefficients(name: str, n: int) -> np.ndarray:
    """``b_j`` (j = -J..J) with ``w[n] = sum_j b_j exp(j 2 pi j n / N)``, complex128 ``(2J+1,)``.

    The library's windows are periodic cosine sums (rect, Hann, Hamming, Blackman), so the
    window's DFT ``W`` has only these few non-zero coefficients: ``b_j = W[j] / N``.
    """
    w = window(name, n).astype(np.float64)
    big_w = np.fft.fft(w) / n
    half = 0
    for j in range(1, n // 2):
        if abs(big_w[j]) > 1e-6 * abs(big_w[0]):
            half = j
    b = np.array([big_w[j % n] for j in range(-half, half + 1)])
    # the closed form below is exact only for cosine sums: check that nothing else is left
    rebuilt = np.real(
        np.sum(
            b[:, None]
            * np.exp(2j * np.pi * np.outer(np.arange(-half, half + 1), np.arange(n)) / n),
            axis=0,
        )
    )
    if half > 4 or np.max(np.abs(rebuilt - w)) > 1e-5:
        raise ValueError(f"window {name!r} is not a short cosine sum")
    return b


#: Samples per range bin of :func:`range_envelopes`.
ENVELOPE_PER_BIN = 8


@functools.lru_cache(maxsize=32)
def range_envelopes(name: str, n: int) -> np.ndarray:
    """Bounds of a unit scatterer's range responses away from its tone, ``(2, Q N/2 + 1)``.

    ``env[0, g] >= |R(Delta)|^2`` and ``env[1, g] >= |R1(Delta)|^2`` for every offset
    ``|Delta| >= g / Q`` range bins (circular, ``Q`` = :data:`ENVELOPE_PER_BIN`) between the
    beat tone and the bin, with ``R(Delta) = sum_m w_m exp(j 2 pi Delta m / N)`` the window's
    response (``w`` rebuilt from :func:`cosine_sum_coefficients`, as the patch kernel uses it)
    and ``R1`` that of ``w_m (m - (N - 1)/2)``; ``N = n``. Non-increasing in ``g``. Computed
    on a grid of 128 offsets per bin (zero-padded FFT), each sample's bound taken from one grid
    step nearer the tone, times 2 for the peaks between grid points (the response changes by a
    few per cent over 1/128 bin).
    """
    fine = 128
    b = cosine_sum_coefficients(name, n)
    half = (b.shape[0] - 1) // 2
    idx = np.arange(n)
    w = np.real(
        np.sum(b[:, None] * np.exp(2j * np.pi * np.outer(np.arange(-half, half + 1), idx) / n), 0)
    )
    out = np.empty((2, ENVELOPE_PER_BIN * (n // 2) + 1))
    for row, weights in enumerate((w, w * (idx - (n - 1) / 2))):
        p = np.abs(np.fft.fft(weights, n * fine)) ** 2  # |R(-u / fine)|^2, u = 0 .. n fine - 1
        # both signs of the offset: |R(u / fine)|^2 is p[n fine - u]
        mirror = np.concatenate(([p[0]], p[::-1][: n * fine // 2]))
        both = np.maximum(p[: n * fine // 2 + 1], mirror)
        beyond = np.maximum.accumulate(both[::-1])[::-1]  # max over offsets >= u / fine
        start = np.maximum(np.arange(out.shape[1]) * (fine // ENVELOPE_PER_BIN) - 1, 0)
        out[row] = 2.0 * beyond[start]
    out.flags.writeable = False
    return out


@numba.njit(cache=True, nogil=True)
def _slow_time_kernel(
    pos, vel, n_tx, n_loops, t_chirp, k_phase, k_beat, n_samples, clutter_removal
):  # pragma: no cover
    """Slow-time sequences ``y`` and ``delta y``, each ``(N, n_tx, n_loops)``.

    See :func:`slow_time_sequences`. The phasor of chirp 0 is ``cos + j sin`` of its phase, the
    next ones follow by rotation: the unwrapped phase is ``phi_c = K R_c + const`` with
    ``K = 4 pi / lambda + theta' (Nadc - 1) / 2``, so ``y_c = y_(c-1) exp(j K (R_c - R_(c-1)))``;
    the increment is ``Delta = K (R_last - R_0) / (n_ch - 1)`` (one ``cos``/``sin``) times
    ``exp(j eps_c)`` of the small rest ``eps_c`` (the range's curvature, <= 0.02 rad at 1 m and
    5 m/s across), a Taylor polynomial to ``eps^7`` (error below ``eps^8 / 8!``, 1e-15 for
    ``|eps| < 0.05``; ``cos``/``sin`` beyond). Measured against ``cos``/``sin`` per chirp: 4e-12
    (relative, 1 600 walking-body scatterers), at a fifth of the cost.
    """
    n_s = pos.shape[0]
    n_ch = n_tx * n_loops
    y = np.empty((n_s, n_tx, n_loops), dtype=np.complex128)
    y1 = np.empty((n_s, n_tx, n_loops), dtype=np.complex128)
    centre = (n_samples - 1) / 2
    r_c = np.empty(n_ch)
    # K = 4 pi / lambda + theta' (N - 1) / 2: the unwrapped phase per metre of range
    k_all = k_phase + k_beat * centre
    t_mid = (n_ch // 2) * t_chirp
    for i in range(n_s):
        r_mid = np.sqrt(
            (pos[i, 0] + vel[i, 0] * t_mid) ** 2
            + (pos[i, 1] + vel[i, 1] * t_mid) ** 2
            + (pos[i, 2] + vel[i, 2] * t_mid) ** 2
        )
        for c in range(n_ch):
            t = c * t_chirp
            # R(t_c) = |p + v t_c|
            r_c[c] = np.sqrt(
                (pos[i, 0] + vel[i, 0] * t) ** 2
                + (pos[i, 1] + vel[i, 1] * t) ** 2
                + (pos[i, 2] + vel[i, 2] * t) ** 2
            )
        # delta_c = theta' (R(t_c) - R(t_mid));  phi_c = 4 pi R(t_c) / lambda + delta_c (N-1)/2
        delta = k_beat * (r_c[0] - r_mid)
        phi = (k_phase * r_c[0]) % (2 * np.pi) + delta * centre
        z = np.cos(phi) + 1j * np.sin(phi)
        y[i, 0, 0] = z
        y1[i, 0, 0] = delta * z
        step = (r_c[n_ch - 1] - r_c[0]) / max(n_ch - 1, 1)  # one chirp: no step
        rot = np.cos(k_all * step) + 1j * np.sin(k_all * step)
        for c in range(1, n_ch):
            # phi_c - phi_(c-1) = K step + eps_c
            eps = k_all * ((r_c[c] - r_c[c - 1]) - step)
            if abs(eps) < 0.05:
                e2 = eps * eps
                co = 1.0 - e2 * (0.5 - e2 * (1.0 / 24 - e2 * (1.0 / 720)))
                si = eps * (1.0 - e2 * (1.0 / 6 - e2 * (1.0 / 120 - e2 * (1.0 / 5040))))
                z = z * (rot * (co + 1j * si))
            else:
                z = z * (rot * (np.cos(eps) + 1j * np.sin(eps)))
            delta = k_beat * (r_c[c] - r_mid)
            y[i, c % n_tx, c // n_tx] = z
            y1[i, c % n_tx, c // n_tx] = delta * z
        if clutter_removal:
            for s in range(n_tx):
                mean = y[i, s, :].sum() / n_loops
                mean1 = y1[i, s, :].sum() / n_loops
                for m in range(n_loops):
                    y[i, s, m] -= mean
                    y1[i, s, m] -= mean1
    return y, y1


@numba.njit(cache=True, nogil=True)
def noise_map(s, rd, s2, n_use, n_v):  # pragma: no cover
    """Noise-only map: ``rd[k, d] = s2[d] Gamma(L)`` (float32) for ``k < n_use`` (row by row),
    the mean ``L s2[d]`` beyond (never read by the CFAR). Draws from the six-word state ``s``
    (advanced): NumPy's float32 Gamma algorithm (:func:`~core.simulation.rng_kernels.gamma_f32`),
    as ``standard_gamma(L, dtype=float32)`` fed the same words."""
    n_r, n_d = rd.shape
    # Marsaglia-Tsang constants of Gamma(L) in float32: b = L - 1/3, c = 1 / sqrt(9 b)
    b = np.float32(n_v) - np.float32(1.0 / 3.0)
    c = np.float32(np.float32(1.0) / np.sqrt(np.float32(9.0) * b))
    s2_32 = s2.astype(np.float32)
    ki, wi, fi = KI, WI, FI
    # the generator state in registers
    s0, s1, s2_, s3, buf, has = s[0], s[1], s[2], s[3], s[4], s[5] != 0
    for k in range(n_use):
        for d in range(n_d):
            g, s0, s1, s2_, s3, buf, has = gamma_f32_l(s0, s1, s2_, s3, buf, has, b, c, ki, wi, fi)
            # noise-only cell: sum of L exponentials of mean s2[d] ~ s2[d] Gamma(L)
            rd[k, d] = g * s2_32[d]
    s[0], s[1], s[2], s[3], s[4], s[5] = s0, s1, s2_, s3, buf, np.uint64(has)
    for k in range(n_use, n_r):
        for d in range(n_d):
            rd[k, d] = np.float32(n_v * s2[d])


@numba.njit(cache=True, nogil=True)
def _bit_reversal(n):  # pragma: no cover
    """Bit-reversed index of ``0 .. n - 1`` (``n`` a power of 2): the radix-2 FFT's input order."""
    rev = np.zeros(n, dtype=np.int64)
    j = 0
    for i in range(1, n):
        bit = n >> 1
        while j & bit:
            j ^= bit
            bit >>= 1
        j |= bit
        rev[i] = j
    return rev


@numba.njit(cache=True, nogil=True)
def _fft2_pow2(x, x1, w, rev, tw, a, a1):  # pragma: no cover
    """Radix-2 FFTs of ``w x`` into ``a`` and of ``w x1`` into ``a1`` (length a power of 2, both
    at once: same order, same twiddles ``tw[k] = exp(-j 2 pi k / n)``)."""
    n = a.shape[0]
    for t in range(n):
        a[rev[t]] = w[t] * x[t]
        a1[rev[t]] = w[t] * x1[t]
    size = 2
    while size <= n:
        half = size // 2
        step = n // size
        for first in range(0, n, size):
            for k in range(half):
                tk = tw[k * step]
                # butterfly: (u, v w) -> (u + v w, u - v w)
                v = a[first + k + half] * tk
                u = a[first + k]
                a[first + k] = u + v
                a[first + k + half] = u - v
                v1 = a1[first + k + half] * tk
                u1 = a1[first + k]
                a1[first + k] = u1 + v1
                a1[first + k + half] = u1 - v1
        size *= 2


@numba.njit(cache=True, nogil=True)
def patches_kernel(
    s, rd, amp, theta, slow, slow1, wd, b, s2, steer, slot, threshold, half_r, tw_d, env, noise,
    k_max,
):  # fmt: skip  # pragma: no cover
    """Patch cells, their noise-free channel values and their noisy channel sums.

    amp (N,), theta (N,) beat tone rad/sample, slow/slow1 (N, n_tx, M) slow-time sequences
    (after clutter removal), wd (M,) Doppler window (times ``(-1)^m`` when ``tw_d`` is the
    radix-2 FFT's twiddles), b (2J+1,) range window coefficients, s2 (M,) cell noise power,
    steer (N, L), slot (L,) TX slot of each channel (``v // n_rx``), half_r (2 Nadc,) =
    exp(j pi u / Nadc); tw_d either
    (M, M) = exp(-j 2 pi (d - M/2) m / M) (direct DFT) or (1, M/2) = exp(-j 2 pi k / M) (M a
    power of two: radix-2 FFT of the window-shifted sequence, the same transform); env
    (2, Q Nadc / 2 + 1) :func:`range_envelopes`. Adds the patch cells' noisy power into ``rd``
    (draws from the generator state ``s``); only range bins below ``k_max`` are looked at.

    A scatterer's range responses are computed only in the range bins its envelope bound
    (``env``, the range window's far response) cannot rule out: beyond them its power is below
    :data:`SUM_FLOOR` in every cell, where the patch test and the sums ignore it anyway, so
    the result is the same as computing every bin (tested bit for bit).
    """
    n_samples = half_r.shape[0] // 2
    n_s = amp.shape[0]
    n_tx, m = slow.shape[1], slow.shape[2]
    n_v = steer.shape[1]
    n_rx = n_v // n_tx
    half = (b.shape[0] - 1) // 2
    nn = n_samples
    centre = (nn - 1) / 2
    # range response R_i[k] = sum_j b_j G(theta - 2 pi (k - j) / N),
    # G(phi) = (1 - exp(j phi N)) / (1 - exp(j phi)), exp(j phi N) = exp(j theta N);
    # its centred derivative R1_i[k] = dR/dtheta - j (N - 1)/2 R = sum_n w_n j (n - (N-1)/2) ...
    # G and dG/dtheta are evaluated once per index t = k - j + J (shared by the 2J+1 terms of R)
    # in closed form: 1 / (1 - exp(j phi)) = (1 + j cot(phi / 2)) / 2, phi_t / 2 = theta / 2 - b_t,
    # b_t = pi (t - J) / N from the table half_r (the b_j of a periodic cosine sum are real)
    n_g = k_max + 2 * half
    bj = np.empty(b.shape[0])
    for j in range(b.shape[0]):
        bj[j] = b[j].real
    cos_b = np.empty(n_g)
    sin_b = np.empty(n_g)
    for t in range(n_g):
        u = (t - half) % (2 * nn)
        cos_b[t] = half_r[u].real
        sin_b[t] = half_r[u].imag
    # Doppler responses D_i[s, d] = sum_m wd[m] y[m] exp(-j 2 pi (d - M/2) m / M), D1 of delta y
    dd = np.empty((n_s, n_tx, m), dtype=np.complex128)
    dd1 = np.empty((n_s, n_tx, m), dtype=np.complex128)
    pd = np.zeros((n_s, m))
    pd1 = np.zeros((n_s, m))
    pd_max = np.zeros(n_s)
    pd1_max = np.zeros(n_s)
    ws = np.empty(m, dtype=np.complex128)
    ws1 = np.empty(m, dtype=np.complex128)
    radix2 = tw_d.shape[0] == 1
    rev = _bit_reversal(m) if radix2 else np.zeros(0, dtype=np.int64)
    for i in range(n_s):
        for sl in range(n_tx):
            if radix2:
                _fft2_pow2(slow[i, sl], slow1[i, sl], wd, rev, tw_d[0], dd[i, sl], dd1[i, sl])
            else:
                for t in range(m):
                    ws[t] = wd[t] * slow[i, sl, t]
                    ws1[t] = wd[t] * slow1[i, sl, t]
                for d in range(m):
                    acc = 0.0 + 0.0j
                    acc1 = 0.0 + 0.0j
                    for t in range(m):
                        acc += ws[t] * tw_d[d, t]
                        acc1 += ws1[t] * tw_d[d, t]
                    dd[i, sl, d] = acc
                    dd1[i, sl, d] = acc1
            for d in range(m):
                a0 = dd[i, sl, d]
                a1 = dd1[i, sl, d]
                pd[i, d] = max(pd[i, d], a0.real**2 + a0.imag**2)
                pd1[i, d] = max(pd1[i, d], a1.real**2 + a1.imag**2)
        for d in range(m):
            pd_max[i] = max(pd_max[i], pd[i, d])
            pd1_max[i] = max(pd1_max[i], pd1[i, d])
    s2_min = s2[0]
    for d in range(m):
        s2_min = min(s2_min, s2[d])
    floor_min = SUM_FLOOR * s2_min
    cut = min(floor_min, threshold * s2_min)  # what neither the patch test nor the sums use
    # each scatterer's range bins: those closer to its beat tone than the envelope's reach
    # (at most two runs k_run[i, 0]:k_run[i, 1] and k_run[i, 2]:k_run[i, 3] after wrapping)
    n_env = env.shape[1]
    q_env = (n_env - 1) / (nn / 2)  # envelope samples per range bin
    k_run = np.zeros((n_s, 4), dtype=np.int64)
    for i in range(n_s):
        a2 = amp[i] * amp[i]
        # smallest g with a2 (env0[g] pd_max + env1[g] pd1_max) < cut (env non-increasing)
        lo = 0
        hi = n_env
        while lo < hi:
            mid = (lo + hi) // 2
            if a2 * (env[0, mid] * pd_max[i] + env[1, mid] * pd1_max[i]) < cut:
                hi = mid
            else:
                lo = mid + 1
        reach = lo / q_env  # bins; beyond it (circularly) the scatterer is below the floor
        kappa = (theta[i] * nn / (2 * np.pi)) % nn
        t_lo = int(np.floor(kappa - reach)) - 1
        t_hi = int(np.ceil(kappa + reach)) + 1
        if lo == n_env or t_hi - t_lo + 1 >= nn:
            k_run[i, 1] = k_max
            continue
        k0 = t_lo % nn
        k1 = k0 + t_hi - t_lo + 1
        k_run[i, 0] = min(k0, k_max)
        k_run[i, 1] = min(k1, k_max)
        if k1 > nn:  # wraps past the last bin
            k_run[i, 3] = min(k1 - nn, k_max)
    g_re = np.empty(n_g)
    g_im = np.empty(n_g)
    g1_re = np.empty(n_g)
    g1_im = np.empty(n_g)
    rr = np.empty((n_s, k_max), dtype=np.complex128)
    rr1 = np.empty((n_s, k_max), dtype=np.complex128)
    pr = np.empty((n_s, k_max))
    pr1 = np.empty((n_s, k_max))
    for i in range(n_s):
        if k_run[i, 1] == k_run[i, 0] and k_run[i, 3] == k_run[i, 2]:
            continue
        e_n = np.exp(1j * theta[i] * nn)
        num_re = 1.0 - e_n.real  # 1 - exp(j N theta)
        num_im = -e_n.imag
        a_re = nn * e_n.imag  # -j N exp(j N theta)
        a_im = -nn * e_n.real
        sin_a = np.sin(0.5 * theta[i])
        cos_a = np.cos(0.5 * theta[i])
        for run in range(2):
            ka = k_run[i, 2 * run]
            kb = k_run[i, 2 * run + 1]
            if kb <= ka:
                continue
            for t in range(ka, kb + 2 * half):
                # sin and cos of phi_t / 2 = theta / 2 - b_t
                sn = sin_a * cos_b[t] - cos_a * sin_b[t]
                cs = cos_a * cos_b[t] + sin_a * sin_b[t]
                # |1 - exp(j phi)|^2 < 1e-18: G = N, dG/dtheta = j N (N-1)/2
                sing = abs(sn) < 5e-10
                # w = 1 / (1 - exp(j phi)) = 1/2 + j cot(phi / 2) / 2
                w_im = 0.5 * cs / (1.0 if sing else sn)
                # G = num w
                gr = 0.5 * num_re - num_im * w_im
                gi = num_re * w_im + 0.5 * num_im
                # dG/dtheta = -j N exp(j N theta) w + j num (w^2 - w)  (q/(1-q)^2 = w^2 - w)
                q_re = -0.25 - w_im * w_im
                q_im = 0.0
                h_re = -(num_re * q_im + num_im * q_re)
                h_im = num_re * q_re - num_im * q_im
                g_re[t] = nn if sing else gr
                g_im[t] = 0.0 if sing else gi
                g1_re[t] = 0.0 if sing else 0.5 * a_re - a_im * w_im + h_re
                g1_im[t] = nn * (nn - 1) / 2 if sing else a_re * w_im + 0.5 * a_im + h_im
            for k in range(ka, kb):
                acc_re = 0.0
                acc_im = 0.0
                acc1_re = 0.0
                acc1_im = 0.0
                for jj in range(-half, half + 1):
                    # G at phi = theta - 2 pi (k - jj) / N is g[k - jj + J]
                    acc_re += bj[jj + half] * g_re[k - jj + half]
                    acc_im += bj[jj + half] * g_im[k - jj + half]
                    acc1_re += bj[jj + half] * g1_re[k - jj + half]
                    acc1_im += bj[jj + half] * g1_im[k - jj + half]
                x_re = amp[i] * acc_re
                x_im = amp[i] * acc_im
                # R1 = A (acc1 - j centre acc)
                y_re = amp[i] * (acc1_re + centre * acc_im)
                y_im = amp[i] * (acc1_im - centre * acc_re)
                rr[i, k] = complex(x_re, x_im)
                rr1[i, k] = complex(y_re, y_im)
                pr[i, k] = x_re * x_re + x_im * x_im
                pr1[i, k] = y_re * y_re + y_im * y_im
    lim_min = threshold * s2_min
    lim = np.empty(m)
    for d in range(m):
        lim[d] = threshold * s2[d]
    # patch cells: (k, d) where some scatterer's pr pd[d] + pr1 pd1[d] > lim[d]; a scatterer is
    # looked at in the range bins where its bound over Doppler (pr max pd + pr1 max pd1) is above
    # the smallest limit
    mask = np.zeros((k_max, m), dtype=np.bool_)
    row = np.zeros(k_max, dtype=np.bool_)
    for i in range(n_s):
        for run in range(2):
            for k in range(k_run[i, 2 * run], k_run[i, 2 * run + 1]):
                if pr[i, k] * pd_max[i] + pr1[i, k] * pd1_max[i] <= lim_min:
                    continue
                a0 = pr[i, k]
                a1 = pr1[i, k]
                hit = False
                for d in range(m):
                    h = a0 * pd[i, d] + a1 * pd1[i, d] > lim[d]
                    mask[k, d] |= h
                    hit |= h
                row[k] |= hit
    cells_k = np.empty(k_max * m, dtype=np.int64)
    cells_d = np.empty(k_max * m, dtype=np.int64)
    n_c = 0
    for k in range(k_max):
        if not row[k]:
            continue
        for d in range(m):
            if mask[k, d]:
                cells_k[n_c] = k
                cells_d[n_c] = d
                n_c += 1
    x = np.empty((n_c, n_v), dtype=np.complex128)
    along = np.zeros(n_c, dtype=np.complex128)
    ortho = np.zeros(n_c)
    # the patch cells of range bin k are cells row_at[k]:row_at[k + 1] (sorted by range bin)
    row_at = np.zeros(k_max + 1, dtype=np.int64)
    for c in range(n_c):
        row_at[cells_k[c] + 1] += 1
    for k in range(k_max):
        row_at[k + 1] += row_at[k]
    # the sums, scatterer by scatterer (each cell still adds its scatterers in index order), over
    # its range bins where its bound reaches SUM_FLOOR; x_re[c n_v + v]
    x_re = np.zeros(n_c * n_v)
    x_im = np.zeros(n_c * n_v)
    a_re = np.empty(n_v)
    a_im = np.empty(n_v)
    for i in range(n_s):
        for v in range(n_v):
            a_re[v] = steer[i, v].real
            a_im[v] = steer[i, v].imag
        for run in range(2):
            for k in range(k_run[i, 2 * run], k_run[i, 2 * run + 1]):
                c_lo = row_at[k]
                c_hi = row_at[k + 1]
                if c_lo == c_hi:
                    continue
                p0 = pr[i, k]
                p1 = pr1[i, k]
                if p0 * pd_max[i] + p1 * pd1_max[i] < floor_min:
                    continue
                r0r = rr[i, k].real
                r0i = rr[i, k].imag
                r1r = rr1[i, k].real
                r1i = rr1[i, k].imag
                for c in range(c_lo, c_hi):
                    d = cells_d[c]
                    if p0 * pd[i, d] + p1 * pd1[i, d] < SUM_FLOOR * s2[d]:
                        continue  # below SUM_FLOOR: left out
                    base = c * n_v
                    for sl in range(n_tx):
                        # first order in the beat tone's drift: g = R D + R1 D1
                        u0 = dd[i, sl, d]
                        u1 = dd1[i, sl, d]
                        gr = (r0r * u0.real - r0i * u0.imag) + (r1r * u1.real - r1i * u1.imag)
                        gi = (r0r * u0.imag + r0i * u0.real) + (r1r * u1.imag + r1i * u1.real)
                        v0 = sl * n_rx
                        for r in range(n_rx):
                            # X[c, v] = sum_i A_i R_i[k] D_i[slot(v), d] a_i[v],  v = slot n_rx + rx
                            x_re[base + v0 + r] += gr * a_re[v0 + r] - gi * a_im[v0 + r]
                            x_im[base + v0 + r] += gr * a_im[v0 + r] + gi * a_re[v0 + r]
    # Marsaglia-Tsang constants of Gamma(L - 1)
    dk = n_v - 1.0 - 1.0 / 3.0
    ck = 1.0 / np.sqrt(9.0 * dk)
    s0, s1, s2_, s3 = s[0], s[1], s[2], s[3]  # the generator state in registers
    for c in range(n_c):
        k = cells_k[c]
        d = cells_d[c]
        norm2 = 0.0
        for v in range(n_v):
            x[c, v] = complex(x_re[c * n_v + v], x_im[c * n_v + v])
            norm2 += x_re[c * n_v + v] ** 2 + x_im[c * n_v + v] ** 2
        if noise:
            sd = np.sqrt(s2[d] / 2)
            re, s0, s1, s2_, s3 = normal_l(s0, s1, s2_, s3)
            im, s0, s1, s2_, s3 = normal_l(s0, s1, s2_, s3)
            along[c] = sd * (re + 1j * im)
            g_o, s0, s1, s2_, s3 = gamma_l(s0, s1, s2_, s3, dk, ck)
            ortho[c] = s2[d] * g_o
        # P = |(|s| + n_1)|^2 + |n_perp|^2
        z = np.sqrt(norm2) + along[c]
        rd[k, d] = z.real**2 + z.imag**2 + ortho[c]
    s[0], s[1], s[2], s[3] = s0, s1, s2_, s3
    return cells_k[:n_c], cells_d[:n_c], x, along, ortho


@functools.lru_cache(maxsize=8)
def twiddles(n_r: int, n_d: int) -> tuple[np.ndarray, np.ndarray]:
    """``exp(j pi u / Nr)`` ``(2 Nr,)`` (the range response's half angles) and the Doppler
    transform's twiddles.

    Doppler index ``d`` is zero-velocity centred (bin ``d - Nd // 2``), as in the exact chain.
    ``Nd`` a power of two: ``(1, Nd/2)`` ``exp(-j 2 pi k / Nd)`` for the radix-2 FFT of the
    window-shifted sequence (:func:`doppler_weights`); otherwise ``(Nd, Nd)``
    ``exp(-j 2 pi (d - Nd/2) m / Nd)`` for the direct DFT.
    """
    u = np.arange(2 * n_r)
    m = np.arange(n_d)
    if _is_pow2(n_d):
        tw_d = np.exp(-2j * np.pi * np.arange(n_d // 2) / n_d)[None, :]
    else:
        tw_d = np.exp(-2j * np.pi * np.outer(m - n_d // 2, m) / n_d)
    return np.exp(1j * np.pi * u / n_r), tw_d


def _is_pow2(n: int) -> bool:
    return n >= 2 and n & (n - 1) == 0


def doppler_weights(name: str, n: int) -> np.ndarray:
    """The Doppler window as :func:`patches_kernel` wants it (see :func:`twiddles`)."""
    if _is_pow2(n):
        return _doppler_window_shifted(name, n)
    return window(name, n).astype(np.float64)
