"""``fast`` fidelity level: the exact chain's range-Doppler spectrum in closed form.

The exact level synthesises every ADC sample of every chirp and channel, draws noise for every
sample and runs two FFTs over the whole cube. After the range and Doppler FFTs, a point scatterer
``i`` is separable (for the frame's few centimetres of range migration, see below)::

    X_i[v, k, d] = A_i a_i[v] R_i[k] D_i[slot(v), d]

- ``A_i = Vspp / (2 sqrt 2)``: the complex baseband amplitude (link budget, eqs. 2-4);
- ``a_i[v] = exp(j pi (p_v sin(az) cos(el) + e_v sin(el)))``: the virtual-array phase;
- ``R_i[k] = sum_n w_r[n] exp(j theta_i n) exp(-j 2 pi k n / Nadc)``: the range window's response
  to the beat tone ``theta_i = 2 pi (2 S R_i / c) / Fs`` rad/sample (one 256-point FFT);
- ``D_i[s, d] = sum_m w_d[m] (y_m - mean_m y) exp(-j 2 pi (d - Nc/2) m / Nc)`` with the slow-time
  phase of the chirp of slot ``s`` in loop ``m`` at time ``t_c = (m Ntx + s) Tchirp``::

      y_m = exp(j (4 pi R_i(t_c) / lambda + theta_i' (R_i(t_c) - R_i(t_mid)) (Nadc - 1) / 2))

  (static clutter removal subtracts the loop mean; the second term is the beat tone's phase at the
  middle of the ADC window moving with the range, the exact chain's "carrier at mid-ramp"). The
  slot's delay carries the TDM-MIMO Doppler coupling exactly.

Noise. Per virtual channel and cell, the exact chain's noise after the two windowed FFTs is
circular complex Gaussian with variance (``sigma^2`` per ADC sample)::

    s2[d] = sigma^2 sum_n w_r[n]^2 (sum_m w_d[m]^2 - |W_d(d)|^2 / Nc)        (with clutter removal)

(``W_d(d)`` the Doppler window's DFT at bin ``d``: clutter removal lowers the noise at and next to
zero Doppler). Every cell of the range-Doppler map is the non-coherent
sum of 12 such exponentials, drawn directly as ``s2[d] Gamma(12)``, except in the patches where
some scatterer's energy matters (per-channel signal power above ``-30 dB`` of ``s2``): there the
coherent sum ``s`` of the scatterers (12 channel values) meets the noise, and by the rotation
invariance of circular Gaussian noise the channel sum ``sum_v |s_v + n_v|^2`` is drawn as
``|(|s| + n_1)|^2 + s2 Gamma(11)``. Only the detected cells get their 12 channel values, drawn
from the exact conditional law given those draws (:func:`detected_channels`). The same CFAR,
angle, SNR and labelling stages as the
exact chain then run unchanged.

Entry points: :func:`simulate_frame_fast` (one frame, the GUI's) and
:func:`simulate_frames_fast` (all frames of a trajectory, the data-set path: per-scatterer inputs
computed once, then one compiled call for every frame's noise map, patches, CFAR, detected
channels, points and labels). The first is the second with one frame, so both give the same
frames for the same per-frame generators. The draws come from a compiled generator
(:mod:`core.simulation.rng_kernels`) seeded per frame with four raw words of that frame's
generator; the noise map's Gamma(12) is NumPy's float32 algorithm on those words
(``docs/decisions/fidelity-07``).

CFAR thresholds. Neighbouring cells of the exact chain's noise are correlated through the
windows (|rho|^2 = 4/9 for Hann), here they are independent. The exact chain's thresholds on
independent cells would give other noise false alarms, both through the two stages (which share
the cell under test) and through peak grouping (a noise peak among correlated neighbours is
less often a local maximum: 12 % of the exact chain's noise detections go, 3 % of independent
cells'). :func:`core.simulation.fast_cfar.independent_cell_stages` scales both stages'
``pfa`` by one factor so that the expected noise detections per frame after both stages and
peak grouping (:func:`core.processing.false_alarms.noise_detections_per_frame`) are the exact
chain's (``docs/decisions/fidelity-08``). ``rect`` windows leave independent cells: the
thresholds are then the chain's own.

Layout: the thresholds live in :mod:`core.simulation.fast_cfar`; this module (about 1 100 lines)
holds the closed-form model with its compiled kernels (slow-time sequences, noise map, patches)
and the two entry points, whose compiled batch path (:func:`_frames_kernel` →
:func:`_frame_kernel`) calls those kernels and must draw in the same order as the per-frame
reference functions (:func:`fast_spectrum`, :func:`detected_channels`) next to it. Splitting the
model's kernels (up to :func:`fast_spectrum`) from the entry points is the next step (issue 12).

Known approximations (measured in ``docs/fidelity.md``): the noise cells' correlation is
modelled only through the thresholds (above); the beat tone's drift over the frame (<= 0.2
range bins at 1.8 m/s) is reduced to its phase term.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numba
import numpy as np
import scipy.fft

from core.config import (
    DEFAULT_PROCESSING,
    SPEED_OF_LIGHT_MPS,
    ProcessingSettings,
    RadarConfig,
)
from core.errors import InputError
from core.pointcloud import POINT_FIELDS, SOURCE_OTHER, PointCloud
from core.processing import (
    Detections,
    estimate_angles,
    label_sources,
    refine_bins,
    window,
)
from core.processing.cfar import (
    CfarStageArgs,
    TwoStageCfarArgs,
    two_stage_kernel,
)
from core.processing.points import (  # noqa: F401  (angles_of: re-exported for measurement)
    angle_twiddles,
    angles_of,
    array_rows,
    cloud_from_rows,
    detection_rows,
    point_rows,
    points_kernel,
)
from core.simulation.antenna import AntennaGain
from core.simulation.baseband import steering_vectors
from core.simulation.fast_cfar import cfar_arguments, cfar_range_bins
from core.simulation.frame import FrameOutput, needs_elevation
from core.simulation.gaussian import FI, KI, WI
from core.simulation.link import noise_power_v2, received_power_w, signal_amplitude_v
from core.simulation.rng_kernels import (
    fill_normal,
    gamma_f32_l,
    gamma_l,
    normal_l,
    state6,
    state_from,
)
from core.simulation.scatterers import Scatterers

#: Per-channel signal power, relative to the cell's noise power, above which a cell gets
#: per-channel noise and the coherent signal (-30 dB: the signal changes the cell's mean power
#: by less than 0.1 % elsewhere).
PATCH_THRESHOLD = 1e-3


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
        _beat_rad_per_sample_per_m(radar),
        radar.n_samples,
        settings.static_clutter_removal,
    )


def _beat_rad_per_sample_per_m(radar: RadarConfig) -> float:
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
def _cosine_sum_coefficients(name: str, n: int) -> np.ndarray:
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


@numba.njit(cache=True, nogil=True)
def _slow_time_kernel(
    pos, vel, n_tx, n_loops, t_chirp, k_phase, k_beat, n_samples, clutter_removal
):  # pragma: no cover
    """Slow-time sequences ``y`` and ``delta y``, each ``(N, n_tx, n_loops)``.

    See :func:`slow_time_sequences`.
    """
    n_s = pos.shape[0]
    n_ch = n_tx * n_loops
    y = np.empty((n_s, n_tx, n_loops), dtype=np.complex128)
    y1 = np.empty((n_s, n_tx, n_loops), dtype=np.complex128)
    centre = (n_samples - 1) / 2
    for i in range(n_s):
        t_mid = (n_ch // 2) * t_chirp
        r_mid = np.sqrt(
            (pos[i, 0] + vel[i, 0] * t_mid) ** 2
            + (pos[i, 1] + vel[i, 1] * t_mid) ** 2
            + (pos[i, 2] + vel[i, 2] * t_mid) ** 2
        )
        for c in range(n_ch):
            t = c * t_chirp
            # R(t_c) = |p + v t_c|
            r = np.sqrt(
                (pos[i, 0] + vel[i, 0] * t) ** 2
                + (pos[i, 1] + vel[i, 1] * t) ** 2
                + (pos[i, 2] + vel[i, 2] * t) ** 2
            )
            # delta_c = theta' (R(t_c) - R(t_mid));  phi_c = 4 pi R(t_c) / lambda + delta_c (N-1)/2
            delta = k_beat * (r - r_mid)
            phi = (k_phase * r) % (2 * np.pi) + delta * centre
            z = np.cos(phi) + 1j * np.sin(phi)
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
def _noise_map(s, rd, s2, n_use, n_v):  # pragma: no cover
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
def _fft_pow2(a, tw):  # pragma: no cover
    """In-place radix-2 FFT of ``a`` (length a power of 2); ``tw[k] = exp(-j 2 pi k / n)``."""
    n = a.shape[0]
    j = 0
    for i in range(1, n):
        bit = n >> 1
        while j & bit:
            j ^= bit
            bit >>= 1
        j |= bit
        if i < j:
            a[i], a[j] = a[j], a[i]
    size = 2
    while size <= n:
        half = size // 2
        step = n // size
        for first in range(0, n, size):
            for k in range(half):
                # butterfly: (u, v w) -> (u + v w, u - v w)
                v = a[first + k + half] * tw[k * step]
                u = a[first + k]
                a[first + k] = u + v
                a[first + k + half] = u - v
        size *= 2


@numba.njit(cache=True, nogil=True)
def _patches_kernel(
    s, rd, amp, theta, slow, slow1, wd, b, s2, steer, slot, threshold, tw_r, tw_d, noise, k_max
):  # pragma: no cover
    """Patch cells, their noise-free channel values and their noisy channel sums.

    amp (N,), theta (N,) beat tone rad/sample, slow/slow1 (N, n_tx, M) slow-time sequences
    (after clutter removal), wd (M,) Doppler window (times ``(-1)^m`` when ``tw_d`` is the
    radix-2 FFT's twiddles), b (2J+1,) range window coefficients, s2 (M,) cell noise power,
    steer (N, L), slot (L,) TX slot of each channel, tw_r (N,) = exp(-j 2 pi k / N); tw_d either
    (M, M) = exp(-j 2 pi (d - M/2) m / M) (direct DFT) or (1, M/2) = exp(-j 2 pi k / M) (M a
    power of two: radix-2 FFT of the window-shifted sequence, the same transform). Adds the
    patch cells' noisy power into ``rd`` (draws from the generator state ``s``); only range
    bins below ``k_max`` are looked at.
    """
    n_samples = tw_r.shape[0]
    n_s = amp.shape[0]
    n_tx, m = slow.shape[1], slow.shape[2]
    n_v = steer.shape[1]
    half = (b.shape[0] - 1) // 2
    nn = n_samples
    centre = (nn - 1) / 2
    # range response R_i[k] = sum_j b_j G(theta - 2 pi (k - j) / N),
    # G(phi) = (1 - exp(j phi N)) / (1 - exp(j phi)), exp(j phi N) = exp(j theta N);
    # its centred derivative R1_i[k] = dR/dtheta - j (N - 1)/2 R = sum_n w_n j (n - (N-1)/2) ...
    # G and dG/dtheta are evaluated once per index k - j (shared by the 2J+1 terms of R)
    n_g = k_max + 2 * half
    gg = np.empty(n_g, dtype=np.complex128)
    gg1 = np.empty(n_g, dtype=np.complex128)
    rr = np.empty((n_s, k_max), dtype=np.complex128)
    rr1 = np.empty((n_s, k_max), dtype=np.complex128)
    pr = np.empty((n_s, k_max))
    pr1 = np.empty((n_s, k_max))
    for i in range(n_s):
        e_n = np.exp(1j * theta[i] * nn)
        num = 1.0 - e_n
        e = np.exp(1j * theta[i])
        for t in range(n_g):
            q = e * tw_r[(t - half) % nn]  # exp(j phi), phi = theta - 2 pi (t - J) / N
            den = 1.0 - q
            den2 = den.real * den.real + den.imag * den.imag
            if den2 < 1e-18:
                gg[t] = nn + 0.0j
                gg1[t] = 1j * nn * (nn - 1) / 2
            else:
                inv = den.conjugate() * (1.0 / den2)  # 1 / (1 - q)
                gg[t] = num * inv
                # dG/dtheta = (-j N e^{j N theta} (1 - q) + (1 - e^{j N theta}) j q) / (1 - q)^2
                gg1[t] = (-1j * nn * e_n * den + num * 1j * q) * (inv * inv)
        for k in range(k_max):
            acc = 0.0 + 0.0j
            acc1 = 0.0 + 0.0j
            for jj in range(-half, half + 1):
                # G at phi = theta - 2 pi (k - jj) / N is gg[k - jj + J]
                acc += b[jj + half] * gg[k - jj + half]
                acc1 += b[jj + half] * gg1[k - jj + half]
            rr[i, k] = amp[i] * acc
            rr1[i, k] = amp[i] * (acc1 - 1j * centre * acc)
            pr[i, k] = rr[i, k].real ** 2 + rr[i, k].imag ** 2
            pr1[i, k] = rr1[i, k].real ** 2 + rr1[i, k].imag ** 2
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
    for i in range(n_s):
        for sl in range(n_tx):
            for t in range(m):
                ws[t] = wd[t] * slow[i, sl, t]
                ws1[t] = wd[t] * slow1[i, sl, t]
            if radix2:
                _fft_pow2(ws, tw_d[0])
                _fft_pow2(ws1, tw_d[0])
                for d in range(m):
                    dd[i, sl, d] = ws[d]
                    dd1[i, sl, d] = ws1[d]
            else:
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
    lim_min = threshold * s2_min
    cells_k = np.empty(k_max * m, dtype=np.int64)
    cells_d = np.empty(k_max * m, dtype=np.int64)
    n_c = 0
    for k in range(k_max):
        # skip the range bin when no scatterer can reach the smallest limit in any Doppler bin
        # (pr pd[d] + pr1 pd1[d] <= pr max pd + pr1 max pd1, and lim[d] >= lim_min)
        maybe = False
        for i in range(n_s):
            if pr[i, k] * pd_max[i] + pr1[i, k] * pd1_max[i] > lim_min:
                maybe = True
                break
        if not maybe:
            continue
        for d in range(m):
            lim = threshold * s2[d]
            for i in range(n_s):
                if pr[i, k] * pd[i, d] + pr1[i, k] * pd1[i, d] > lim:
                    cells_k[n_c] = k
                    cells_d[n_c] = d
                    n_c += 1
                    break
    x = np.zeros((n_c, n_v), dtype=np.complex128)
    along = np.zeros(n_c, dtype=np.complex128)
    ortho = np.zeros(n_c)
    g = np.empty(n_tx, dtype=np.complex128)
    # Marsaglia-Tsang constants of Gamma(L - 1)
    dk = n_v - 1.0 - 1.0 / 3.0
    ck = 1.0 / np.sqrt(9.0 * dk)
    s0, s1, s2_, s3 = s[0], s[1], s[2], s[3]  # the generator state in registers
    for c in range(n_c):
        k = cells_k[c]
        d = cells_d[c]
        for i in range(n_s):
            if pr[i, k] * pd[i, d] + pr1[i, k] * pd1[i, d] < 1e-6 * s2[d]:
                continue  # below -60 dB of the noise: nothing to add
            for sl in range(n_tx):
                # first order in the beat tone's drift: R D + R1 D1
                g[sl] = rr[i, k] * dd[i, sl, d] + rr1[i, k] * dd1[i, sl, d]
            for v in range(n_v):
                # X[c, v] = sum_i A_i R_i[k] D_i[slot(v), d] a_i[v]
                x[c, v] += g[slot[v]] * steer[i, v]
        norm2 = 0.0
        for v in range(n_v):
            norm2 += x[c, v].real ** 2 + x[c, v].imag ** 2
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
def _twiddles(n_r: int, n_d: int) -> tuple[np.ndarray, np.ndarray]:
    """``exp(-j 2 pi k / Nr)`` ``(Nr,)`` and the Doppler transform's twiddles.

    Doppler index ``d`` is zero-velocity centred (bin ``d - Nd // 2``), as in the exact chain.
    ``Nd`` a power of two: ``(1, Nd/2)`` ``exp(-j 2 pi k / Nd)`` for the radix-2 FFT of the
    window-shifted sequence (:func:`_doppler_weights`); otherwise ``(Nd, Nd)``
    ``exp(-j 2 pi (d - Nd/2) m / Nd)`` for the direct DFT.
    """
    k = np.arange(n_r)
    m = np.arange(n_d)
    if _is_pow2(n_d):
        tw_d = np.exp(-2j * np.pi * np.arange(n_d // 2) / n_d)[None, :]
    else:
        tw_d = np.exp(-2j * np.pi * np.outer(m - n_d // 2, m) / n_d)
    return np.exp(-2j * np.pi * k / n_r), tw_d


def _is_pow2(n: int) -> bool:
    return n >= 2 and n & (n - 1) == 0


def _doppler_weights(name: str, n: int) -> np.ndarray:
    """The Doppler window as :func:`_patches_kernel` wants it (see :func:`_twiddles`)."""
    if _is_pow2(n):
        return _doppler_window_shifted(name, n)
    return window(name, n).astype(np.float64)


class Spectrum(NamedTuple):
    """The ``fast`` level's range-Doppler map and what it needs to rebuild detected cells.

    Attributes
    ----------
    rd_map
        ``[range bin, Doppler bin]`` float32 power (V²) summed over channels, zero velocity
        centred.
    patch
        ``(n_cells, 2)`` int: range bin and Doppler index of the cells where a scatterer's
        energy matters.
    signal
        ``(n_cells, n_virtual)`` complex128 noise-free Doppler-cube values of those cells.
    along
        ``(n_cells,)`` complex128: the noise component along ``signal / |signal|``.
    ortho
        ``(n_cells,)`` float64: noise power orthogonal to the signal (V²).
    state
        ``(4,)`` uint64: the compiled generator's state after these draws
        (:mod:`core.simulation.rng_kernels`); :func:`detected_channels` continues from it.
    """

    rd_map: np.ndarray
    patch: np.ndarray
    signal: np.ndarray
    along: np.ndarray
    ortho: np.ndarray
    state: np.ndarray


def fast_spectrum(
    radar: RadarConfig,
    scatterers: Scatterers,
    rng: np.random.Generator | None,
    *,
    antenna: AntennaGain,
    settings: ProcessingSettings = DEFAULT_PROCESSING,
    noise: bool = True,
    n_range_bins: int | None = None,
) -> Spectrum:
    """Range-Doppler map in closed form (see the module docstring).

    ``n_range_bins``: only the first range bins are drawn (the CFAR never looks beyond its
    range limit plus its training window, :func:`cfar_range_bins`); the rest of the map holds
    the mean noise power. None: the whole map (for display).

    The draws come from the compiled generator seeded with four raw draws of ``rng``
    (:func:`core.simulation.rng_kernels.state_from`): first the noise map row by row, then per
    patch cell the noise along the signal (real, imaginary) and the orthogonal power.

    Circular complex Gaussian noise is invariant under rotations of ``C^L``: in a patch cell
    with signal vector ``s`` the channel sum ``sum_v |s_v + n_v|^2`` has the law of
    ``|(|s| + n_1)|^2 + s2 Gamma(L - 1)`` (``n_1`` the noise along ``s``), so a cell costs one
    complex normal and one Gamma draw instead of ``L`` complex normals; the channel values of
    detected cells are rebuilt from the same draws by :func:`detected_channels`.
    """
    n_r, n_d, n_v = radar.n_samples, radar.n_loops, radar.n_virtual
    s2 = cell_noise_power_v2(radar, settings)  # (n_d,)
    n_use = n_r if n_range_bins is None else max(0, min(n_r, int(n_range_bins)))
    state = state6(state_from(rng if noise else None))
    rd = np.zeros((n_r, n_d), dtype=np.float32)
    if noise:
        _noise_map(state, rd, s2, n_use, n_v)
    if len(scatterers) == 0:
        e = np.zeros(0)
        return Spectrum(
            rd, np.zeros((0, 2), dtype=np.int64), np.zeros((0, n_v), complex), e, e, state
        )
    power = received_power_w(
        radar, scatterers.range_m, scatterers.azimuth_rad, scatterers.rcs_dbsm, antenna
    )
    amp = signal_amplitude_v(radar, power)  # (N,)
    r_mid = np.linalg.norm(
        scatterers.position_m
        + scatterers.velocity_mps * (0.5 * radar.n_loops * radar.n_tx * radar.chirp_period_s),
        axis=1,
    )
    # theta = 2 pi (2 S R / c) / Fs   (rad per sample)
    theta = _beat_rad_per_sample_per_m(radar) * r_mid
    k_idx, d_idx, x, along, ortho = _patches_kernel(
        state,
        rd,
        amp,
        theta,
        *slow_time_sequences(radar, scatterers, settings),
        _doppler_weights(settings.doppler_window, n_d),
        _cosine_sum_coefficients(settings.range_window, n_r),
        s2,
        steering_vectors(radar, scatterers),
        np.arange(n_v) // radar.n_rx,
        PATCH_THRESHOLD,
        *_twiddles(n_r, n_d),
        noise,
        n_use,
    )
    return Spectrum(rd, np.column_stack((k_idx, d_idx)).astype(np.int64), x, along, ortho, state)


def simulate_frame_fast(
    radar: RadarConfig,
    scatterers: Scatterers,
    rng: np.random.Generator,
    *,
    antenna: AntennaGain,
    settings: ProcessingSettings = DEFAULT_PROCESSING,
    keep_rd_map: bool = False,
    elevation: bool | None = None,
    noise: bool = True,
) -> FrameOutput:
    """One frame at the ``fast`` level: closed-form spectrum, then the exact chain's detection.

    Same signature and output as :func:`core.simulation.simulate_frame`; see the module
    docstring for the model. ``rng`` seeds the noise (a different stream from the exact
    level's, so the same seed gives statistically equivalent, not identical, frames).
    """
    out, maps = _frames_fast(
        radar, [scatterers], [rng], antenna, settings, elevation, noise, keep_rd_map
    )
    rd_db = None
    if keep_rd_map:
        rd = maps[0]
        rd_db = (10 * np.log10(np.maximum(rd, np.finfo(np.float32).tiny))).astype(np.float32)
    return FrameOutput(point_cloud=out.point_cloud, rd_map_db=rd_db, detections=out.detections)


def detected_channels(radar: RadarConfig, spec: Spectrum, det: Detections) -> np.ndarray:
    """Per-channel values ``(n_det, n_virtual)`` complex128 of the detected cells.

    Patch cell: ``x = s + n_1 u + w`` with ``u = s / |s|`` and ``w`` a uniformly random vector
    orthogonal to ``u`` with ``|w|^2`` the drawn orthogonal power. Noise-only cell: ``P^(1/2)``
    times a uniformly random unit vector of ``C^L`` (``P`` the cell's summed power). Both are the
    exact conditional laws of i.i.d. circular Gaussian channels given the drawn map. The normal
    draws (all real parts, then all imaginary parts) continue ``spec.state`` (advanced).
    """
    rd = spec.rd_map
    n_v = radar.n_virtual
    n_det = len(det)
    # patch cells are sorted by (range bin, Doppler index): look detections up by linear index
    n_d = rd.shape[1]
    lin = spec.patch[:, 0] * n_d + spec.patch[:, 1]
    want = det.range_bin * n_d + det.doppler_index
    j = np.full(n_det, -1, dtype=np.int64)
    if len(lin):
        pos = np.minimum(np.searchsorted(lin, want), len(lin) - 1)
        j = np.where(lin[pos] == want, pos, -1)
    zr = fill_normal(spec.state, n_det * n_v).reshape(n_det, n_v)
    z = zr + 1j * fill_normal(spec.state, n_det * n_v).reshape(n_det, n_v)
    out = np.empty((n_det, n_v), dtype=np.complex128)
    inside = j >= 0
    if np.any(inside):
        s = spec.signal[j[inside]]
        norm = np.linalg.norm(s, axis=1, keepdims=True)
        u = np.where(norm > 0, s / np.where(norm > 0, norm, 1.0), np.eye(1, n_v))
        w = z[inside]
        w -= u * np.sum(np.conj(u) * w, axis=1, keepdims=True)  # project out u
        w *= np.sqrt(spec.ortho[j[inside]] / np.sum(np.abs(w) ** 2, axis=1))[:, None]
        out[inside] = s + spec.along[j[inside], None] * u + w
    if not np.all(inside):
        p = rd[det.range_bin[~inside], det.doppler_index[~inside]].astype(np.float64)
        zo = z[~inside]
        out[~inside] = zo * np.sqrt(p / np.sum(np.abs(zo) ** 2, axis=1))[:, None]
    return out


def points_from_channels(
    radar: RadarConfig,
    settings: ProcessingSettings,
    rd: np.ndarray,
    det: Detections,
    channels: np.ndarray,
    elevation: bool,
) -> PointCloud:
    """Point cloud from detections and their channel values: the exact chain's steps 6-7.

    The same refinement (:func:`core.processing.refine_bins`) and angle estimation
    (:func:`core.processing.estimate_angles`) as :func:`core.processing.build_point_cloud`,
    without building the Doppler cube. ``source`` is left at ``SOURCE_OTHER``.
    """
    r_bin, d_bin = refine_bins(rd, det)
    az, el = estimate_angles(
        channels, d_bin, radar, fft_size=settings.angle_fft_size, elevation=elevation
    )
    rng_m = r_bin * radar.range_resolution_m
    horiz = rng_m * np.cos(el)
    return PointCloud(
        range_m=rng_m,
        azimuth_rad=az,
        elevation_rad=el,
        radial_velocity_mps=d_bin * radar.velocity_resolution_mps,
        snr_db=det.snr_db,
        x_m=horiz * np.sin(az),
        y_m=horiz * np.cos(az),
        z_m=rng_m * np.sin(el),
        source=np.full(len(det), SOURCE_OTHER, dtype=np.int32),
    )


def label_points(radar: RadarConfig, pc: PointCloud, scatterers: Scatterers) -> PointCloud:
    """Ground-truth labels as the exact chain sets them: nearest reflector at mid-frame."""
    if not len(pc) or not len(scatterers):
        return pc
    t_mid = 0.5 * radar.n_loops * radar.n_tx * radar.chirp_period_s
    pos = scatterers.position_m + scatterers.velocity_mps * t_mid
    r_mid = np.linalg.norm(pos, axis=1)
    vr = np.einsum("ij,ij->i", pos, scatterers.velocity_mps) / r_mid
    src = label_sources(pc.range_m, pc.radial_velocity_mps, r_mid, vr, scatterers.source, radar)
    return PointCloud(
        range_m=pc.range_m,
        azimuth_rad=pc.azimuth_rad,
        elevation_rad=pc.elevation_rad,
        radial_velocity_mps=pc.radial_velocity_mps,
        snr_db=pc.snr_db,
        x_m=pc.x_m,
        y_m=pc.y_m,
        z_m=pc.z_m,
        source=src,
    )


def points_compiled(
    radar: RadarConfig,
    settings: ProcessingSettings,
    rd: np.ndarray,
    det: Detections,
    channels: np.ndarray,
    elevation: bool,
) -> PointCloud:
    """:func:`points_from_channels`, compiled: the same point cloud (``source`` = -2)."""
    r_bin, d_bin, az, el = points_kernel(
        rd,
        det.range_bin,
        det.doppler_index,
        np.ascontiguousarray(channels, dtype=np.complex128),
        radar.n_tx,
        radar.n_rx,
        *array_rows(radar),
        angle_twiddles(radar, settings.angle_fft_size),
        bool(elevation),
    )
    rng_m = r_bin * radar.range_resolution_m
    horiz = rng_m * np.cos(el)
    return PointCloud(
        range_m=rng_m,
        azimuth_rad=az,
        elevation_rad=el,
        radial_velocity_mps=d_bin * radar.velocity_resolution_mps,
        snr_db=det.snr_db,
        x_m=horiz * np.sin(az),
        y_m=horiz * np.cos(az),
        z_m=rng_m * np.sin(el),
        source=np.full(len(det), SOURCE_OTHER, dtype=np.int32),
    )


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class FramesOutput:
    """Points of many frames, concatenated (the batch simulators' result).

    Attributes
    ----------
    point_cloud
        Points of every frame in frame order, ``(n_points,)`` per field.
    counts
        ``(F,)`` int64: points per frame.
    detections
        ``(n_points, 2)`` int64: range bin, Doppler index (as :class:`FrameOutput`).
    """

    point_cloud: PointCloud
    counts: np.ndarray
    detections: np.ndarray

    def clouds(self) -> list[PointCloud]:
        """The per-frame point clouds (views into the concatenated arrays)."""
        edges = np.concatenate(([0], np.cumsum(self.counts)))
        pc = self.point_cloud
        names = (*POINT_FIELDS, "source")
        return [
            PointCloud(**{k: getattr(pc, k)[a:b] for k in names})
            for a, b in zip(edges[:-1].tolist(), edges[1:].tolist())
        ]


# ---- all frames of a trajectory: the batch path -------------------------------------------------
# Everything after the noise map in one compiled call per frame (patches, CFAR, detected
# channels, points, labels); the per-scatterer inputs (link budget, slow-time sequences,
# steering) are computed once for all frames. simulate_frame_fast is this path with one frame,
# so the per-frame (GUI) and batch (data set) entry points give the same frames.


@numba.njit(cache=True, nogil=True)
def _detected_channels_kernel(s, rd, r, d, cells_k, cells_d, x, along, ortho):  # pragma: no cover
    """:func:`detected_channels` compiled (same conditional laws, same draw order)."""
    n_det = r.shape[0]
    n_v = x.shape[1]
    n_d = rd.shape[1]
    # z = N(0, 1) + j N(0, 1): all real parts first, then all imaginary parts
    zr = np.empty((n_det, n_v))
    zi = np.empty((n_det, n_v))
    s0, s1, s2, s3 = s[0], s[1], s[2], s[3]  # the generator state in registers
    for i in range(n_det):
        for v in range(n_v):
            zr[i, v], s0, s1, s2, s3 = normal_l(s0, s1, s2, s3)
    for i in range(n_det):
        for v in range(n_v):
            zi[i, v], s0, s1, s2, s3 = normal_l(s0, s1, s2, s3)
    s[0], s[1], s[2], s[3] = s0, s1, s2, s3
    out = np.empty((n_det, n_v), dtype=np.complex128)
    n_c = cells_k.shape[0]
    u = np.empty(n_v, dtype=np.complex128)
    w = np.empty(n_v, dtype=np.complex128)
    for i in range(n_det):
        want = r[i] * n_d + d[i]
        # patch cells are sorted by linear index (range bin, then Doppler index)
        lo, hi = 0, n_c
        while lo < hi:
            mid = (lo + hi) // 2
            if cells_k[mid] * n_d + cells_d[mid] < want:
                lo = mid + 1
            else:
                hi = mid
        j = lo if lo < n_c and cells_k[lo] * n_d + cells_d[lo] == want else -1
        for v in range(n_v):
            w[v] = zr[i, v] + 1j * zi[i, v]
        if j >= 0:
            norm2 = 0.0
            for v in range(n_v):
                norm2 += x[j, v].real ** 2 + x[j, v].imag ** 2
            norm = np.sqrt(norm2)
            for v in range(n_v):
                # u = s / |s| (first unit vector when s = 0)
                u[v] = x[j, v] / norm if norm > 0 else (1.0 + 0j if v == 0 else 0j)
            proj = 0j
            for v in range(n_v):
                proj += np.conj(u[v]) * w[v]
            p2 = 0.0
            for v in range(n_v):
                w[v] -= u[v] * proj  # w orthogonal to u
                p2 += w[v].real ** 2 + w[v].imag ** 2
            scale = np.sqrt(ortho[j] / p2)
            for v in range(n_v):
                # x = s + n_1 u + w,  |w|^2 = drawn orthogonal power
                out[i, v] = x[j, v] + along[j] * u[v] + w[v] * scale
        else:
            p2 = 0.0
            for v in range(n_v):
                p2 += w[v].real ** 2 + w[v].imag ** 2
            # x = P^(1/2) z / |z|
            scale = np.sqrt(np.float64(rd[r[i], d[i]]) / p2)
            for v in range(n_v):
                out[i, v] = w[v] * scale
    return out


class SpectrumTables(NamedTuple):
    """What the compiled frame kernel draws a frame's noise map and patches with."""

    n_use: int  # range bins drawn (the CFAR's reach; all of them when the map is kept)
    n_v: int  # virtual channels L
    wd: np.ndarray  # (n_d,) Doppler window as _patches_kernel wants it (_doppler_weights)
    b: np.ndarray  # (2J+1,) range window's cosine-sum coefficients
    s2: np.ndarray  # (n_d,) per-channel cell noise power, V²
    slot: np.ndarray  # (L,) TX slot of each virtual channel
    threshold: float  # patch threshold relative to s2 (PATCH_THRESHOLD)
    tw_r: np.ndarray  # (n_r,) range twiddles
    tw_d: np.ndarray  # Doppler twiddles (see _twiddles)


class PointTables(NamedTuple):
    """What the compiled frame kernel turns detections into labelled points with."""

    n_tx: int
    n_rx: int
    row_ch: np.ndarray  # azimuth row: channels
    row_pos: np.ndarray  # azimuth row: positions (half wavelengths)
    upper: np.ndarray  # elevation pairs: upper channels (empty without elevation)
    lower: np.ndarray  # elevation pairs: lower channels
    tw_a: np.ndarray  # angle FFT twiddles
    res_r: float  # range resolution, m
    res_v: float  # velocity resolution, m/s
    t_mid: float  # the frame's middle, s (labels)
    span: float  # unambiguous velocity span 2 v_max, m/s (labels)


def spectrum_tables(
    radar: RadarConfig, settings: ProcessingSettings, keep_rd_map: bool
) -> SpectrumTables:
    """The :class:`SpectrumTables` of a radar and settings."""
    n_r, n_d, n_v = radar.n_samples, radar.n_loops, radar.n_virtual
    tw_r, tw_d = _twiddles(n_r, n_d)
    return SpectrumTables(
        n_use=n_r if keep_rd_map else max(0, min(n_r, cfar_range_bins(radar, settings))),
        n_v=n_v,
        wd=_doppler_weights(settings.doppler_window, n_d),
        b=_cosine_sum_coefficients(settings.range_window, n_r),
        s2=cell_noise_power_v2(radar, settings),
        slot=np.arange(n_v) // radar.n_rx,
        threshold=PATCH_THRESHOLD,
        tw_r=tw_r,
        tw_d=tw_d,
    )


def point_tables(
    radar: RadarConfig, settings: ProcessingSettings, elevation: bool, t_mid: float
) -> PointTables:
    """The :class:`PointTables` of a radar and settings (elevation pairs only if asked)."""
    row_ch, row_pos, upper, lower = detection_rows(radar, elevation)
    return PointTables(
        n_tx=radar.n_tx,
        n_rx=radar.n_rx,
        row_ch=row_ch,
        row_pos=row_pos,
        upper=upper,
        lower=lower,
        tw_a=angle_twiddles(radar, settings.angle_fft_size),
        res_r=radar.range_resolution_m,
        res_v=radar.velocity_resolution_mps,
        t_mid=t_mid,
        span=2 * radar.max_velocity_mps,
    )


#: Stand-in CFAR arguments when no range bin lies inside the limits (``has_cfar`` False).
_NO_CFAR = TwoStageCfarArgs(
    profile=np.ones(1),
    lo=0,
    hi=0,
    a=0,
    b=0,
    range_stage=CfarStageArgs(1, 0, False, 0, 1.0, 1.0),
    doppler_stage=CfarStageArgs(1, 0, False, 0, 1.0, 1.0),
    peak_grouping=False,
)


@numba.njit(cache=True, nogil=True)
def _frame_kernel(
    s, rd, amp, theta, slow, slow1, steer, pos, vel, source, elevation, noise, spec, has_cfar,
    cfar, pts,
):  # fmt: skip  # pragma: no cover
    """One frame after its noise map: patches, CFAR, detected channels, points, labels.

    ``amp`` … ``source``: the frame's reflectors (see :func:`_patches_kernel`); ``spec``:
    :class:`SpectrumTables`; ``cfar``: :class:`~core.processing.cfar.TwoStageCfarArgs` (used
    when ``has_cfar``); ``pts``: :class:`PointTables`. Returns ``(det_r, det_d, f64 (n, 8),
    source)`` with ``f64`` columns range, azimuth, elevation, radial velocity, SNR, x, y, z.
    """
    cells_k, cells_d, x, along, ortho = _patches_kernel(
        s, rd, amp, theta, slow, slow1, spec.wd, spec.b, spec.s2, steer, spec.slot,
        spec.threshold, spec.tw_r, spec.tw_d, noise, spec.n_use,
    )  # fmt: skip
    if has_cfar:
        r, d, nz = two_stage_kernel(rd, cfar)
    else:
        r = np.zeros(0, dtype=np.int64)
        d = np.zeros(0, dtype=np.int64)
        nz = np.zeros(0)
    n_det = r.shape[0]
    if n_det == 0:
        return r, d, np.empty((0, 8)), np.full(0, -2, dtype=np.int32)
    ch = _detected_channels_kernel(s, rd, r, d, cells_k, cells_d, x, along, ortho)
    f64, src = point_rows(
        rd, r, d, nz, ch, pts.n_tx, pts.n_rx, pts.row_ch, pts.row_pos, pts.upper, pts.lower,
        pts.tw_a, elevation, pos, vel, source, pts.t_mid, pts.res_r, pts.res_v, pts.span,
    )  # fmt: skip
    return r, d, f64, src  # fmt: skip


@numba.njit(cache=True, nogil=True)
def _grow(f64, i64, i32, need):  # pragma: no cover
    """The output buffers with room for at least ``need`` rows (doubling)."""
    if need <= f64.shape[0]:
        return f64, i64, i32
    cap = max(need, 2 * f64.shape[0])
    f2 = np.empty((cap, f64.shape[1]))
    i2 = np.empty((cap, i64.shape[1]), dtype=np.int64)
    j2 = np.empty(cap, dtype=np.int32)
    f2[: f64.shape[0]] = f64
    i2[: i64.shape[0]] = i64
    j2[: i32.shape[0]] = i32
    return f2, i2, j2


@numba.njit(cache=True, nogil=True)
def _frames_kernel(
    states, start, elev, maps, keep, amp, theta, slow, slow1, steer, pos, vel, source, noise,
    spec, has_cfar, cfar, pts,
):  # fmt: skip  # pragma: no cover
    """Every frame: noise map, then :func:`_frame_kernel`; frame ``f`` draws from ``states[f]``
    and has the reflectors ``start[f]:start[f+1]`` (arguments as there).

    Returns ``(det (n, 2), f64 (n, 8), source (n,), counts (F,))`` concatenated in frame order.
    """
    n_f = start.shape[0] - 1
    counts = np.zeros(n_f, dtype=np.int64)
    cap = 8 * n_f + 16
    f64_all = np.empty((cap, 8))
    det_all = np.empty((cap, 2), dtype=np.int64)
    src_all = np.empty(cap, dtype=np.int32)
    n_out = 0
    for f in range(n_f):
        s = states[f].copy()
        rd = maps[f] if keep else maps[0]
        if noise:
            _noise_map(s, rd, spec.s2, spec.n_use, spec.n_v)
        else:
            rd[:] = 0.0
        i0, i1 = start[f], start[f + 1]
        r, d, f64, src = _frame_kernel(
            s, rd, amp[i0:i1], theta[i0:i1], slow[i0:i1], slow1[i0:i1], steer[i0:i1],
            pos[i0:i1], vel[i0:i1], source[i0:i1], elev[f], noise, spec, has_cfar, cfar, pts,
        )  # fmt: skip
        n = r.shape[0]
        f64_all, det_all, src_all = _grow(f64_all, det_all, src_all, n_out + n)
        for i in range(n):
            det_all[n_out + i, 0] = r[i]
            det_all[n_out + i, 1] = d[i]
            src_all[n_out + i] = src[i]
            for j in range(8):
                f64_all[n_out + i, j] = f64[i, j]
        n_out += n
        counts[f] = n
    return det_all[:n_out], f64_all[:n_out], src_all[:n_out], counts


def _frames_fast(
    radar: RadarConfig,
    frames: Sequence[Scatterers],
    rngs: Sequence[np.random.Generator | None],
    antenna: AntennaGain,
    settings: ProcessingSettings,
    elevation: bool | None,
    noise: bool,
    keep_rd_map: bool,
):
    """Shared body of :func:`simulate_frames_fast` and :func:`simulate_frame_fast`.

    Returns ``(FramesOutput, rd maps (F, n_r, n_d) float32 or None)``.
    """
    if len(frames) != len(rngs):
        raise InputError(f"rngs: {len(rngs)} generators for {len(frames)} frames")
    n_f = len(frames)
    n_r, n_d, n_v = radar.n_samples, radar.n_loops, radar.n_virtual
    counts = np.fromiter((len(s) for s in frames), dtype=np.int64, count=n_f)
    start = np.zeros(n_f + 1, dtype=np.int64)
    np.cumsum(counts, out=start[1:])
    every = Scatterers.concatenate(list(frames)) if start[-1] else Scatterers.empty()
    # per scatterer, all frames at once: link budget, beat tone, slow time, steering
    power = received_power_w(radar, every.range_m, every.azimuth_rad, every.rcs_dbsm, antenna)
    amp = signal_amplitude_v(radar, power)  # (N,)
    t_mid = 0.5 * radar.n_loops * radar.n_tx * radar.chirp_period_s
    r_mid = np.linalg.norm(every.position_m + every.velocity_mps * t_mid, axis=1)
    # theta = 2 pi (2 S R / c) / Fs   (rad per sample)
    theta = _beat_rad_per_sample_per_m(radar) * r_mid
    slow, slow1 = slow_time_sequences(radar, every, settings)
    steer = np.ascontiguousarray(steering_vectors(radar, every))
    pos = np.ascontiguousarray(every.position_m, dtype=np.float64)
    vel = np.ascontiguousarray(every.velocity_mps, dtype=np.float64)
    source = np.ascontiguousarray(every.source, dtype=np.int32)
    if elevation is not None:
        elev = np.full(n_f, bool(elevation))
    elif not radar.has_elevation:
        elev = np.zeros(n_f, dtype=bool)
    else:
        elev = np.fromiter((needs_elevation(radar, s) for s in frames), dtype=bool, count=n_f)
    cfar = cfar_arguments(radar, settings, n_v, n_r, n_d, True)
    has_cfar = cfar is not None  # None: no range bin inside the limits, nothing is tested
    states = np.zeros((n_f, 6), dtype=np.uint64)  # core.simulation.gaussian's six words
    for f in range(n_f):
        states[f, :4] = state_from(rngs[f] if noise else None)
    maps = np.empty((n_f if keep_rd_map else 1, n_r, n_d), dtype=np.float32)
    det, f64, src, n_out = _frames_kernel(
        states, start, elev, maps, bool(keep_rd_map), amp, theta, slow, slow1, steer, pos, vel,
        source, bool(noise), spectrum_tables(radar, settings, bool(keep_rd_map)), has_cfar,
        cfar if has_cfar else _NO_CFAR, point_tables(radar, settings, bool(elev.any()), t_mid),
    )  # fmt: skip
    pc = cloud_from_rows(f64, src)
    out = FramesOutput(point_cloud=pc, counts=n_out, detections=det)
    return out, (maps if keep_rd_map else None)


def simulate_frames_fast(
    radar: RadarConfig,
    frames: Sequence[Scatterers],
    rngs: Sequence[np.random.Generator | None],
    *,
    antenna: AntennaGain,
    settings: ProcessingSettings = DEFAULT_PROCESSING,
    elevation: bool | None = None,
    noise: bool = True,
) -> FramesOutput:
    """Many frames at the ``fast`` level (the data-set path).

    Frame ``f`` draws only from ``rngs[f]``, in the order :func:`simulate_frame_fast` draws,
    so the result equals the per-frame entry point's frames bit for bit (tested).

    Parameters
    ----------
    frames
        ``F`` frames' reflectors.
    rngs
        ``F`` generators, one per frame (the pipeline's ``stage_rng(seed, "noise", f)``).
    elevation
        Estimate elevation; ``None``: per frame, when the radar can and the frame is not planar.
    """
    return _frames_fast(radar, frames, rngs, antenna, settings, elevation, noise, False)[0]
