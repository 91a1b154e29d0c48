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
computed once, then per frame the noise map and one compiled kernel for patches, CFAR, detected
channels, points and labels). The first is the second with one frame, so both give the same
frames for the same per-frame generators.

Known approximations (measured in ``docs/fidelity.md``): neighbouring cells of the exact chain's
noise are correlated through the windows (range |rho|^2 = 0.44 for Hann), here they are
independent; the beat tone's drift over the frame (<= 0.2 range bins at 1.8 m/s) is reduced to
its phase term.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numba
import numpy as np
import scipy.fft
from scipy.optimize import brentq

from core.config import (
    DEFAULT_PROCESSING,
    SPEED_OF_LIGHT_MPS,
    CfarSettings,
    ProcessingSettings,
    RadarConfig,
)
from core.errors import InputError
from core.pointcloud import POINT_FIELDS, SOURCE_OTHER, PointCloud
from core.processing import (
    Detections,
    estimate_angles,
    label_sources,
    make_cfar,
    refine_bins,
    window,
)
from core.processing.angle import azimuth_row, elevation_pairs
from core.processing.cfar import cfar_level, two_stage_pfa
from core.processing.spectrum import clutter_removal_noise_profile, effective_cells
from core.simulation.antenna import AntennaGain
from core.simulation.baseband import steering_vectors
from core.simulation.frame import FrameOutput, needs_elevation
from core.simulation.link import noise_power_v2, received_power_w, signal_amplitude_v
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
def _signal_kernel(
    rng, rd, amp, theta, slow, slow1, wd, b, s2, steer, slot, threshold, tw_r, tw_d, noise, k_max
):  # pragma: no cover
    """Patch cells, their noise-free channel values and their noisy channel sums.

    amp (N,), theta (N,) beat tone rad/sample, slow (N, n_tx, M) slow-time sequences (after
    clutter removal), wd (M,) Doppler window, b (2J+1,) range
    window coefficients, s2 (M,) cell noise power, steer (N, L), slot (L,) TX slot of each
    channel, tw_r (N,) = exp(-j 2 pi k / N), tw_d (M, M) = exp(-j 2 pi (d - M/2) m / M). Writes the
    patch cells' power into ``rd``; only range bins below ``k_max`` are looked at.
    """
    n_samples = tw_r.shape[0]
    n_s = amp.shape[0]
    n_tx, m = slow.shape[1], slow.shape[2]
    n_v = steer.shape[1]
    half = (b.shape[0] - 1) // 2
    nn = n_samples
    # range response R_i[k] = sum_j b_j G(theta - 2 pi (k - j) / N),
    # G(phi) = (1 - exp(j phi N)) / (1 - exp(j phi)), exp(j phi N) = exp(j theta N);
    # its centred derivative R1_i[k] = dR/dtheta - j (N - 1)/2 R = sum_n w_n j (n - (N-1)/2) ...
    rr = np.empty((n_s, nn), dtype=np.complex128)
    rr1 = np.empty((n_s, nn), dtype=np.complex128)
    pr = np.empty((n_s, nn))
    pr1 = np.empty((n_s, nn))
    centre = (nn - 1) / 2
    for i in range(n_s):
        e_n = np.exp(1j * theta[i] * nn)
        num = 1.0 - e_n
        e = np.exp(1j * theta[i])
        for k in range(k_max):
            acc = 0.0 + 0.0j
            acc1 = 0.0 + 0.0j
            for jj in range(-half, half + 1):
                q = e * tw_r[(k - jj) % nn]  # exp(j phi)
                den = 1.0 - q
                if abs(den) < 1e-9:
                    g = nn + 0.0j
                    g1 = 1j * nn * (nn - 1) / 2
                else:
                    inv = 1.0 / den
                    g = num * inv
                    # dG/dtheta = (-j N e^{j N theta} (1 - q) + (1 - e^{j N theta}) j q) / (1 - q)^2
                    g1 = (-1j * nn * e_n * den + num * 1j * q) * (inv * inv)
                acc += b[jj + half] * g
                acc1 += b[jj + half] * g1
            rr[i, k] = amp[i] * acc
            rr1[i, k] = amp[i] * (acc1 - 1j * centre * acc)
            pr[i, k] = rr[i, k].real ** 2 + rr[i, k].imag ** 2
            pr1[i, k] = rr1[i, k].real ** 2 + rr1[i, k].imag ** 2
    # Doppler responses D_i[s, d] = sum_m wd[m] y[m] exp(-j 2 pi (d - M/2) m / M), D1 of delta y
    dd = np.empty((n_s, n_tx, m), dtype=np.complex128)
    dd1 = np.empty((n_s, n_tx, m), dtype=np.complex128)
    pd = np.zeros((n_s, m))
    pd1 = np.zeros((n_s, m))
    ws = np.empty(m, dtype=np.complex128)
    ws1 = np.empty(m, dtype=np.complex128)
    for i in range(n_s):
        for s in range(n_tx):
            for t in range(m):
                ws[t] = wd[t] * slow[i, s, t]
                ws1[t] = wd[t] * slow1[i, s, t]
            for d in range(m):
                acc = 0.0 + 0.0j
                acc1 = 0.0 + 0.0j
                for t in range(m):
                    acc += ws[t] * tw_d[d, t]
                    acc1 += ws1[t] * tw_d[d, t]
                dd[i, s, d] = acc
                dd1[i, s, d] = acc1
                pd[i, d] = max(pd[i, d], acc.real**2 + acc.imag**2)
                pd1[i, d] = max(pd1[i, d], acc1.real**2 + acc1.imag**2)
    cells_k = np.empty(nn * m, dtype=np.int64)
    cells_d = np.empty(nn * m, dtype=np.int64)
    n_c = 0
    for k in range(k_max):
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
    for c in range(n_c):
        k = cells_k[c]
        d = cells_d[c]
        for i in range(n_s):
            if pr[i, k] * pd[i, d] + pr1[i, k] * pd1[i, d] < 1e-6 * s2[d]:
                continue  # below -60 dB of the noise: nothing to add
            for s in range(n_tx):
                # first order in the beat tone's drift: R D + R1 D1
                g[s] = rr[i, k] * dd[i, s, d] + rr1[i, k] * dd1[i, s, d]
            for v in range(n_v):
                # X[c, v] = sum_i A_i R_i[k] D_i[slot(v), d] a_i[v]
                x[c, v] += g[slot[v]] * steer[i, v]
        norm2 = 0.0
        for v in range(n_v):
            norm2 += x[c, v].real ** 2 + x[c, v].imag ** 2
        if noise:
            sd = np.sqrt(s2[d] / 2)
            along[c] = sd * (rng.standard_normal() + 1j * rng.standard_normal())
            ortho[c] = s2[d] * rng.standard_gamma(n_v - 1.0)
        # P = |(|s| + n_1)|^2 + |n_perp|^2
        z = np.sqrt(norm2) + along[c]
        rd[k, d] = z.real**2 + z.imag**2 + ortho[c]
    return cells_k[:n_c], cells_d[:n_c], x, along, ortho


@functools.lru_cache(maxsize=8)
def _twiddles(n_r: int, n_d: int) -> tuple[np.ndarray, np.ndarray]:
    """``exp(-j 2 pi k / Nr)`` ``(Nr,)`` and ``exp(-j 2 pi (d - Nd/2) m / Nd)`` ``(Nd, Nd)``.

    Doppler index ``d`` is zero-velocity centred (bin ``d - Nd // 2``), as in the exact chain.
    """
    k = np.arange(n_r)
    m = np.arange(n_d)
    return np.exp(-2j * np.pi * k / n_r), np.exp(-2j * np.pi * np.outer(m - n_d // 2, m) / n_d)


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
    """

    rd_map: np.ndarray
    patch: np.ndarray
    signal: np.ndarray
    along: np.ndarray
    ortho: np.ndarray


def fast_spectrum(
    radar: RadarConfig,
    scatterers: Scatterers,
    rng: np.random.Generator,
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

    Circular complex Gaussian noise is invariant under rotations of ``C^L``: in a patch cell
    with signal vector ``s`` the channel sum ``sum_v |s_v + n_v|^2`` has the law of
    ``|(|s| + n_1)|^2 + s2 Gamma(L - 1)`` (``n_1`` the noise along ``s``), so a cell costs one
    complex normal and one Gamma draw instead of ``L`` complex normals; the channel values of
    detected cells are rebuilt from the same draws by :func:`detected_channels`.
    """
    n_r, n_d, n_v = radar.n_samples, radar.n_loops, radar.n_virtual
    s2 = cell_noise_power_v2(radar, settings)  # (n_d,)
    n_use = n_r if n_range_bins is None else max(0, min(n_r, int(n_range_bins)))
    if noise:
        # noise-only cell: sum of L exponentials of mean s2[d] ~ s2[d] Gamma(L)
        rd = np.empty((n_r, n_d), dtype=np.float32)
        rd[:n_use] = rng.standard_gamma(float(n_v), (n_use, n_d), dtype=np.float32)
        rd[:n_use] *= s2.astype(np.float32)[None, :]
        rd[n_use:] = (n_v * s2).astype(np.float32)[None, :]
    else:
        rd = np.zeros((n_r, n_d), dtype=np.float32)
    if len(scatterers) == 0:
        e = np.zeros(0)
        return Spectrum(rd, np.zeros((0, 2), dtype=np.int64), np.zeros((0, n_v), complex), e, e)
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
    k_idx, d_idx, x, along, ortho = _signal_kernel(
        rng if noise else np.random.default_rng(0),
        rd,
        amp,
        theta,
        *slow_time_sequences(radar, scatterers, settings),
        window(settings.doppler_window, n_d).astype(np.float64),
        _cosine_sum_coefficients(settings.range_window, n_r),
        s2,
        steering_vectors(radar, scatterers),
        np.arange(n_v) // radar.n_rx,
        PATCH_THRESHOLD,
        *_twiddles(n_r, n_d),
        noise,
        n_use,
    )
    return Spectrum(rd, np.column_stack((k_idx, d_idx)).astype(np.int64), x, along, ortho)


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
    docstring for the model. ``rng`` draws the noise (a different stream from the exact level's,
    so the same seed gives statistically equivalent, not identical, frames).
    """
    out, maps = _frames_fast(
        radar, [scatterers], [rng], antenna, settings, elevation, noise, keep_rd_map
    )
    rd_db = None
    if keep_rd_map:
        rd = maps[0]
        rd_db = (10 * np.log10(np.maximum(rd, np.finfo(np.float32).tiny))).astype(np.float32)
    return FrameOutput(point_cloud=out.point_cloud, rd_map_db=rd_db, detections=out.detections)


def detected_channels(
    radar: RadarConfig, spec: Spectrum, det: Detections, rng: np.random.Generator
) -> np.ndarray:
    """Per-channel values ``(n_det, n_virtual)`` complex128 of the detected cells.

    Patch cell: ``x = s + n_1 u + w`` with ``u = s / |s|`` and ``w`` a uniformly random vector
    orthogonal to ``u`` with ``|w|^2`` the drawn orthogonal power. Noise-only cell: ``P^(1/2)``
    times a uniformly random unit vector of ``C^L`` (``P`` the cell's summed power). Both are the
    exact conditional laws of i.i.d. circular Gaussian channels given the drawn map.
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
    z = rng.standard_normal((n_det, n_v)) + 1j * rng.standard_normal((n_det, n_v))
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


# ---- the exact chain's two-stage CFAR, compiled ------------------------------------------------
# The same decisions as core.processing.two_stage_cfar (same thresholds from
# core.processing.make_cfar, same edge rules, same peak grouping, same output order); it only
# avoids numpy's per-call overhead on a 256 x 32 map. tests/core/fidelity checks the equality.
_METHOD_CODE = {"ca": 0, "caso": 1, "cago": 2}


@numba.njit(cache=True, nogil=True)
def _cfar_line(p, n, g, cyclic, method, alpha_both, alpha_one, mask, mu, cs):  # pragma: no cover
    size = p.shape[0]
    pad = n + g if cyclic else 0
    # prefix sums over the (cyclically padded) line: cs[j] = sum of the first j padded cells
    cs[0] = 0.0
    for j in range(size + 2 * pad):
        # p[(j - pad) mod size] without an integer division
        q = j - pad
        while q < 0:
            q += size
        while q >= size:
            q -= size
        cs[j + 1] = cs[j] + p[q]
    for i in range(size):
        c = i + pad
        if cyclic:
            ok_l = True
            ok_r = True
            left = cs[c - g] - cs[c - g - n]
            right = cs[c + g + 1 + n] - cs[c + g + 1]
        else:
            ok_l = i - g - n >= 0
            ok_r = i + g + n <= size - 1
            left = cs[max(0, i - g)] - cs[max(0, i - g - n)]
            right = cs[min(size, i + g + 1 + n)] - cs[min(size, i + g + 1)]
        m, a = cfar_level(left, right, ok_l, ok_r, n, method, alpha_both, alpha_one)
        mu[i] = m
        mask[i] = p[i] > a * m  # False when no training side exists (m is NaN)


@numba.njit(cache=True, nogil=True)
def _two_stage_kernel(
    rd,
    profile,
    lo,
    hi,
    a,
    b,
    rn,
    rg,
    rcyc,
    rmeth,
    ralpha,
    ralpha1,
    dn,
    dg,
    dcyc,
    dmeth,
    dalpha,
    dalpha1,
    peak,
):  # pragma: no cover
    n_r, n_d = rd.shape
    size = b - a
    # whitened map: rd / profile[d]; bins the clutter removal empties (profile 0) carry nothing
    sub = np.empty((size, n_d), dtype=np.float64)
    for i in range(size):
        for d in range(n_d):
            sub[i, d] = 0.0 if profile[d] < 0.01 else rd[a + i, d] / profile[d]
    mask_r = np.zeros((size, n_d), dtype=np.bool_)
    noise_r = np.empty((size, n_d), dtype=np.float64)
    col = np.empty(size, dtype=np.float64)
    mcol = np.empty(size, dtype=np.bool_)
    ncol = np.empty(size, dtype=np.float64)
    cs = np.empty(2 * (size + n_d) + 2 * (rn + rg + dn + dg) + 2, dtype=np.float64)
    for d in range(n_d):
        for i in range(size):
            col[i] = sub[i, d]
        _cfar_line(col, rn, rg, rcyc, rmeth, ralpha, ralpha1, mcol, ncol, cs)
        for i in range(size):
            mask_r[i, d] = mcol[i] and (lo <= a + i <= hi) and profile[d] >= 0.01
            noise_r[i, d] = ncol[i]
    out_r = np.empty(size * n_d, dtype=np.int64)
    out_d = np.empty(size * n_d, dtype=np.int64)
    out_n = np.empty(size * n_d, dtype=np.float64)
    n_out = 0
    row = np.empty(n_d, dtype=np.float64)
    mrow = np.empty(n_d, dtype=np.bool_)
    nrow = np.empty(n_d, dtype=np.float64)
    for i in range(size):
        any_r = False
        for d in range(n_d):
            any_r = any_r or mask_r[i, d]
        if not any_r:
            continue
        for d in range(n_d):
            row[d] = sub[i, d]
        _cfar_line(row, dn, dg, dcyc, dmeth, dalpha, dalpha1, mrow, nrow, cs)
        r = a + i
        for d in range(n_d):
            if not (mask_r[i, d] and mrow[d]):
                continue
            if peak:
                keep = True
                for dr in range(-1, 2):
                    rr = r + dr
                    if rr < 0 or rr >= n_r:
                        continue
                    for dd in range(-1, 2):
                        if (dr != 0 or dd != 0) and rd[r, d] < rd[rr, (d + dd) % n_d]:
                            keep = False
                if not keep:
                    continue
            out_r[n_out] = r
            out_d[n_out] = d
            # back to the map's units at the cell under test
            out_n[n_out] = noise_r[i, d] * profile[d]
            n_out += 1
    return out_r[:n_out], out_d[:n_out], out_n[:n_out]


def two_stage_cfar_compiled(
    rd_map: np.ndarray,
    radar: RadarConfig,
    settings: ProcessingSettings = DEFAULT_PROCESSING,
    *,
    n_channels: int | None = None,
    independent_cells: bool = False,
) -> Detections:
    """:func:`core.processing.two_stage_cfar`, compiled: the same detections, in the same order.

    Parameters and returns as there (``rd_map`` ``[range bin, Doppler bin]``, Doppler zero
    velocity centred). ``independent_cells=True`` sets the thresholds for independent cells
    (what the ``fast`` level's noise map has) instead of the window-correlated cells of the
    exact chain, with the exact chain's two-stage false-alarm rate
    (:func:`independent_cell_stages`).
    """
    rd = np.ascontiguousarray(rd_map)
    L = radar.n_virtual if n_channels is None else n_channels
    args = _cfar_arguments(radar, settings, L, rd.shape[0], rd.shape[1], independent_cells)
    if args is None:
        return _no_detections()
    r, d, noise = _two_stage_kernel(rd, *args)
    return Detections(
        range_bin=r, doppler_index=d, power=rd[r, d].astype(np.float64), noise_power=noise
    )


@functools.lru_cache(maxsize=64)
def _cfar_arguments(
    radar: RadarConfig,
    settings: ProcessingSettings,
    n_channels: int,
    n_r: int,
    n_d: int,
    independent_cells: bool,
):
    """Whitening profile, range limits, training windows and thresholds (cached)."""
    k = np.arange(n_r) * radar.range_resolution_m
    in_range = (k >= settings.min_range_m) & (k <= settings.max_range_m)
    if not in_range.any():
        return None
    lo, hi = (int(i) for i in np.flatnonzero(in_range)[[0, -1]])
    rc, dc = settings.range_cfar, settings.doppler_cfar
    margin = rc.n_train + rc.n_guard
    a, b = max(0, lo - margin), min(n_r, hi + 1 + margin)
    ne_r = ne_d = None
    profile = np.ones(n_d)
    if settings.cfar_noise_model:
        ne_r = effective_cells_or_none(settings.range_window, radar.n_samples, rc.n_train)
        ne_d = effective_cells_or_none(settings.doppler_window, n_d, dc.n_train)
        if settings.static_clutter_removal:
            profile = clutter_removal_noise_profile(settings.doppler_window, n_d)
    if independent_cells and (ne_r is not None or ne_d is not None):
        rc, dc = independent_cell_stages(settings, n_channels, radar.n_samples, n_d)
        ne_r = ne_d = None
    rcf, dcf = make_cfar(rc, n_channels, ne_r), make_cfar(dc, n_channels, ne_d)
    return (
        np.ascontiguousarray(profile, dtype=np.float64),
        lo, hi, a, b,
        rc.n_train, rc.n_guard, rc.cyclic, _METHOD_CODE[rc.method], rcf.alpha(),
        rcf.alpha_one_side(),
        dc.n_train, dc.n_guard, dc.cyclic, _METHOD_CODE[dc.method], dcf.alpha(),
        dcf.alpha_one_side(),
        settings.peak_grouping,
    )  # fmt: skip


@functools.lru_cache(maxsize=16)
def cfar_range_bins(radar: RadarConfig, settings: ProcessingSettings) -> int:
    """Range bins the two-stage CFAR reads: up to its range limit plus guard and training."""
    k = np.arange(radar.n_samples) * radar.range_resolution_m
    inside = np.flatnonzero((k >= settings.min_range_m) & (k <= settings.max_range_m))
    if inside.size == 0:
        return 0
    margin = settings.range_cfar.n_train + settings.range_cfar.n_guard
    return int(min(radar.n_samples, inside[-1] + 1 + margin))


@functools.lru_cache(maxsize=16)
def independent_cell_stages(
    settings: ProcessingSettings, n_channels: int, n_range_bins: int, n_doppler_bins: int
) -> tuple[CfarSettings, CfarSettings]:
    """CFAR stages for independent cells with the exact chain's two-stage false-alarm rate.

    The exact chain's cells are window-correlated and its thresholds account for it. With
    independent cells (the ``fast`` level's noise map) the same per-stage ``pfa`` gives a
    different two-stage rate (periodic Hann: 6.1e-5 per cell instead of 3.6e-5), because the
    stages share the cell under test. Both stages' ``pfa`` are scaled by one factor ``kappa``
    so that :func:`core.processing.cfar.two_stage_pfa` for independent cells equals the exact
    chain's.
    """
    target = two_stage_pfa(
        settings, n_channels, n_range_bins=n_range_bins, n_doppler_bins=n_doppler_bins
    )
    rc, dc = settings.range_cfar, settings.doppler_cfar

    def stages(log_kappa: float) -> tuple[CfarSettings, CfarSettings]:
        k = float(np.exp(log_kappa))
        return (
            dataclasses.replace(rc, pfa=min(rc.pfa * k, 0.5)),
            dataclasses.replace(dc, pfa=min(dc.pfa * k, 0.5)),
        )

    def err(log_kappa: float) -> float:
        r, d = stages(log_kappa)
        indep = dataclasses.replace(settings, range_cfar=r, doppler_cfar=d, cfar_noise_model=False)
        p = two_stage_pfa(
            indep, n_channels, n_range_bins=n_range_bins, n_doppler_bins=n_doppler_bins
        )
        return float(np.log(p) - np.log(target))

    return stages(brentq(err, -6.0, 3.0, xtol=1e-6))


def effective_cells_or_none(window_name: str, n_fft: int, n_train: int) -> float | None:
    """Effective independent cells of ``n_train`` window-correlated ones (None: independent)."""
    ne = effective_cells(window_name, n_fft, n_train)
    return None if abs(ne - n_train) < 1e-9 else ne


def _no_detections() -> Detections:
    e = np.zeros(0, dtype=np.int64)
    return Detections(range_bin=e, doppler_index=e, power=np.zeros(0), noise_power=np.zeros(0))


# ---- the exact chain's point extraction (steps 6-7), compiled ------------------------------------
# The same maths as core.processing.refine_bins and core.processing.estimate_angles (log-parabolic
# peak refinement, TDM-MIMO compensation, zero-padded azimuth DFT, elevation from the elevated
# row); tests/core/fidelity checks the equality.
@numba.njit(cache=True, nogil=True)
def _log_parabola(a, b, c):  # pragma: no cover
    tiny = 2.2250738585072014e-308
    la = np.log(max(a, tiny))
    lb = np.log(max(b, tiny))
    lc = np.log(max(c, tiny))
    # delta = (a - c) / (2 (a - 2b + c))
    den = la - 2.0 * lb + lc
    if den < 0:
        delta = 0.5 * (la - lc) / den
        if not np.isfinite(delta):
            delta = 0.0
    else:
        delta = 0.0
    return min(0.5, max(-0.5, delta))


@numba.njit(cache=True, nogil=True)
def angles_of(
    x, db, n_tx, n_rx, n_loops, row_ch, row_pos, upper, lower, tw_a, elevation, spec
):  # pragma: no cover
    """Azimuth and elevation of one cell's channel values ``x`` (L,), the chain's step 6.

    TDM-MIMO compensation with the (refined) Doppler bin ``db``, zero-padded DFT of the azimuth
    row, log-parabolic peak refinement, elevation from the elevated pairs. ``spec`` is a work
    array of ``fft_size``; ``tw_a`` ``(fft_size, n_row)`` the DFT's twiddles
    ``exp(-j 2 pi (j - N/2) p / N)`` (:func:`angle_twiddles`).
    """
    fft_size = tw_a.shape[0]
    n_v = x.shape[0]
    # x_v exp(-j 2 pi d k(v) / (Nc Ntx))
    xc = np.empty(n_v, dtype=np.complex128)
    for v in range(n_v):
        xc[v] = x[v] * np.exp(-2j * np.pi * db * (v // n_rx) / (n_loops * n_tx))
    # spec[j] = |sum_p x_p exp(-j 2 pi (j - N/2) p / N)|^2  (fftshifted)
    best = 0
    for j in range(fft_size):
        acc = 0.0 + 0.0j
        for q in range(row_ch.shape[0]):
            acc += xc[row_ch[q]] * tw_a[j, q]
        spec[j] = acc.real**2 + acc.imag**2
        if spec[j] > spec[best]:
            best = j
    delta = _log_parabola(spec[(best - 1) % fft_size], spec[best], spec[(best + 1) % fft_size])
    # u = sin(az) cos(el) = 2 (k - N/2 + delta) / N
    u = 2.0 * (best - fft_size // 2 + delta) / fft_size
    e = 0.0
    if elevation and upper.shape[0] > 0:
        z = 0.0 + 0.0j
        for q in range(upper.shape[0]):
            z += xc[upper[q]] * np.conj(xc[lower[q]])
        # sin(el) = arg(sum x_upper conj(x_lower)) / pi
        e = np.arcsin(min(1.0, max(-1.0, np.angle(z) / np.pi)))
    return np.arcsin(min(1.0, max(-1.0, u / np.cos(e)))), e


@numba.njit(cache=True, nogil=True)
def _points_kernel(
    rd, r, d, x, n_tx, n_rx, row_ch, row_pos, upper, lower, tw_a, elevation
):  # pragma: no cover
    n_r, n_d = rd.shape
    n_det = r.shape[0]
    r_bin = np.empty(n_det)
    d_bin = np.empty(n_det)
    az = np.empty(n_det)
    el = np.zeros(n_det)
    spec = np.empty(tw_a.shape[0])
    for i in range(n_det):
        ri, di = r[i], d[i]
        dr = 0.0
        if 0 < ri < n_r - 1:
            dr = _log_parabola(
                np.float64(rd[ri - 1, di]), np.float64(rd[ri, di]), np.float64(rd[ri + 1, di])
            )
        dd = _log_parabola(
            np.float64(rd[ri, (di - 1) % n_d]),
            np.float64(rd[ri, di]),
            np.float64(rd[ri, (di + 1) % n_d]),
        )
        r_bin[i] = ri + dr
        db = di - n_d // 2 + dd
        d_bin[i] = db
        az[i], el[i] = angles_of(
            x[i], db, n_tx, n_rx, n_d, row_ch, row_pos, upper, lower, tw_a, elevation, spec
        )
    return r_bin, d_bin, az, el


@functools.lru_cache(maxsize=16)
def angle_twiddles(radar: RadarConfig, fft_size: int) -> np.ndarray:
    """``exp(-j 2 pi (j - N/2) p / N)`` for the azimuth row, ``(fft_size, n_row)`` complex128."""
    _, row_pos, _, _ = array_rows(radar)
    j = np.arange(fft_size)[:, None] - fft_size // 2
    out = np.exp(-2j * np.pi * ((j * row_pos[None, :]) % fft_size) / fft_size)
    out.flags.writeable = False
    return out


@functools.lru_cache(maxsize=16)
def array_rows(radar: RadarConfig):
    row_ch, row_pos = azimuth_row(radar)
    upper, lower = elevation_pairs(radar)
    return (
        row_ch.astype(np.int64),
        row_pos.astype(np.int64),
        upper.astype(np.int64),
        lower.astype(np.int64),
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
    r_bin, d_bin, az, el = _points_kernel(
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
def _detected_channels_kernel(rng, rd, r, d, cells_k, cells_d, x, along, ortho):  # pragma: no cover
    """:func:`detected_channels` compiled (same conditional laws, same draw order)."""
    n_det = r.shape[0]
    n_v = x.shape[1]
    n_d = rd.shape[1]
    # z = N(0, 1) + j N(0, 1): all real parts first, then all imaginary parts
    zr = np.empty((n_det, n_v))
    zi = np.empty((n_det, n_v))
    for i in range(n_det):
        for v in range(n_v):
            zr[i, v] = rng.standard_normal()
    for i in range(n_det):
        for v in range(n_v):
            zi[i, v] = rng.standard_normal()
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


@numba.njit(cache=True, nogil=True)
def _label_kernel(range_m, vr_m, pos, vel, source, t_mid, res_r, res_v, span):  # pragma: no cover
    """:func:`core.processing.label_sources` with reflectors at mid-frame, compiled."""
    n = range_m.shape[0]
    n_s = pos.shape[0]
    out = np.full(n, -2, dtype=np.int32)
    r_ref = np.empty(n_s)
    v_ref = np.empty(n_s)
    for s in range(n_s):
        p0 = pos[s, 0] + vel[s, 0] * t_mid
        p1 = pos[s, 1] + vel[s, 1] * t_mid
        p2 = pos[s, 2] + vel[s, 2] * t_mid
        r_ref[s] = np.sqrt(p0 * p0 + p1 * p1 + p2 * p2)
        # v_r = p(t_mid) . v / |p(t_mid)|
        v_ref[s] = (p0 * vel[s, 0] + p1 * vel[s, 1] + p2 * vel[s, 2]) / r_ref[s]
    for i in range(n):
        best = np.inf
        for s in range(n_s):
            dr = (range_m[i] - r_ref[s]) / res_r
            # radial velocities compared modulo 2 v_max (Doppler aliasing)
            dv = ((vr_m[i] - v_ref[s]) + span / 2) % span - span / 2
            dv /= res_v
            if abs(dr) <= 1.0 and abs(dv) <= 1.0:
                dist = dr * dr + dv * dv
                if dist < best:
                    best = dist
                    out[i] = source[s]
    return out


@numba.njit(cache=True, nogil=True)
def _frame_kernel(
    rng,
    rd,
    amp,
    theta,
    slow,
    slow1,
    steer,
    pos,
    vel,
    source,
    elevation,
    noise,
    n_use,
    wd,
    b,
    s2,
    slot,
    threshold,
    tw_r,
    tw_d,
    has_cfar,
    profile,
    lo,
    hi,
    a,
    bb,
    rn,
    rg,
    rcyc,
    rmeth,
    ralpha,
    ralpha1,
    dn,
    dg,
    dcyc,
    dmeth,
    dalpha,
    dalpha1,
    peak,
    n_tx,
    n_rx,
    row_ch,
    row_pos,
    upper,
    lower,
    tw_a,
    res_r,
    res_v,
    t_mid,
    span,
):  # pragma: no cover
    """One frame after its noise map: patches, CFAR, detected channels, points, labels.

    Returns ``(det_r, det_d, f64 (n, 8), source)`` with ``f64`` columns range, azimuth,
    elevation, radial velocity, SNR, x, y, z.
    """
    cells_k, cells_d, x, along, ortho = _signal_kernel(
        rng,
        rd,
        amp,
        theta,
        slow,
        slow1,
        wd,
        b,
        s2,
        steer,
        slot,
        threshold,
        tw_r,
        tw_d,
        noise,
        n_use,
    )
    if has_cfar:
        r, d, nz = _two_stage_kernel(
            rd,
            profile,
            lo,
            hi,
            a,
            bb,
            rn,
            rg,
            rcyc,
            rmeth,
            ralpha,
            ralpha1,
            dn,
            dg,
            dcyc,
            dmeth,
            dalpha,
            dalpha1,
            peak,
        )
    else:
        r = np.zeros(0, dtype=np.int64)
        d = np.zeros(0, dtype=np.int64)
        nz = np.zeros(0)
    n_det = r.shape[0]
    f64 = np.empty((n_det, 8))
    src = np.full(n_det, -2, dtype=np.int32)
    if n_det == 0:
        return r, d, f64, src
    ch = _detected_channels_kernel(rng, rd, r, d, cells_k, cells_d, x, along, ortho)
    r_bin, d_bin, az, el = _points_kernel(
        rd, r, d, ch, n_tx, n_rx, row_ch, row_pos, upper, lower, tw_a, elevation
    )
    for i in range(n_det):
        rng_m = r_bin[i] * res_r
        horiz = rng_m * np.cos(el[i])
        f64[i, 0] = rng_m
        f64[i, 1] = az[i]
        f64[i, 2] = el[i]
        f64[i, 3] = d_bin[i] * res_v
        # SNR = 10 log10(P / noise estimate)
        f64[i, 4] = 10 * np.log10(np.float64(rd[r[i], d[i]]) / nz[i])
        f64[i, 5] = horiz * np.sin(az[i])
        f64[i, 6] = horiz * np.cos(az[i])
        f64[i, 7] = rng_m * np.sin(el[i])
    if pos.shape[0]:
        src = _label_kernel(f64[:, 0], f64[:, 3], pos, vel, source, t_mid, res_r, res_v, span)
    return r, d, f64, src  # fmt: skip


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

    Returns ``(FramesOutput, rd maps or None)``.
    """
    if len(frames) != len(rngs):
        raise InputError(f"rngs: {len(rngs)} generators for {len(frames)} frames")
    n_f = len(frames)
    n_r, n_d, n_v = radar.n_samples, radar.n_loops, radar.n_virtual
    s2 = cell_noise_power_v2(radar, settings)  # (n_d,)
    s2_32 = s2.astype(np.float32)
    n_use = n_r if keep_rd_map else max(0, min(n_r, cfar_range_bins(radar, settings)))
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
    cfar = _cfar_arguments(radar, settings, n_v, n_r, n_d, True)
    has_cfar = cfar is not None
    if cfar is None:  # no range bin inside the limits: nothing is tested
        e = np.ones(1)
        cfar = (e, 0, 0, 0, 0, 1, 0, False, 0, 1.0, 1.0, 1, 0, False, 0, 1.0, 1.0, False)
    consts = (
        window(settings.doppler_window, n_d).astype(np.float64),
        _cosine_sum_coefficients(settings.range_window, n_r),
        s2,
        np.arange(n_v) // radar.n_rx,
        PATCH_THRESHOLD,
        *_twiddles(n_r, n_d),
        has_cfar,
        *cfar,
        radar.n_tx,
        radar.n_rx,
        *array_rows(radar),
        angle_twiddles(radar, settings.angle_fft_size),
        radar.range_resolution_m,
        radar.velocity_resolution_mps,
        t_mid,
        2 * radar.max_velocity_mps,
    )
    quiet = np.random.default_rng(0)
    out_r, out_d, out_f, out_s, maps = [], [], [], [], []
    n_out = np.zeros(n_f, dtype=np.int64)
    for f in range(n_f):
        a, b = start[f], start[f + 1]
        rng = rngs[f] if noise else quiet
        if noise:
            # noise-only cell: sum of L exponentials of mean s2[d] ~ s2[d] Gamma(L)
            rd = np.empty((n_r, n_d), dtype=np.float32)
            rd[:n_use] = rng.standard_gamma(float(n_v), (n_use, n_d), dtype=np.float32)
            rd[:n_use] *= s2_32[None, :]
            rd[n_use:] = (n_v * s2).astype(np.float32)[None, :]
        else:
            rd = np.zeros((n_r, n_d), dtype=np.float32)
        elev = needs_elevation(radar, frames[f]) if elevation is None else bool(elevation)
        r, d, f64, src = _frame_kernel(
            rng, rd, amp[a:b], theta[a:b], slow[a:b], slow1[a:b], steer[a:b],
            pos[a:b], vel[a:b], source[a:b], elev, bool(noise), n_use, *consts,
        )  # fmt: skip
        out_r.append(r)
        out_d.append(d)
        out_f.append(f64)
        out_s.append(src)
        n_out[f] = len(r)
        if keep_rd_map:
            maps.append(rd)
    f64 = np.concatenate(out_f) if n_f else np.zeros((0, 8))
    pc = PointCloud(
        range_m=f64[:, 0].copy(),
        azimuth_rad=f64[:, 1].copy(),
        elevation_rad=f64[:, 2].copy(),
        radial_velocity_mps=f64[:, 3].copy(),
        snr_db=f64[:, 4].copy(),
        x_m=f64[:, 5].copy(),
        y_m=f64[:, 6].copy(),
        z_m=f64[:, 7].copy(),
        source=np.concatenate(out_s) if n_f else np.zeros(0, dtype=np.int32),
    )
    det = np.zeros((0, 2), dtype=np.int64)
    if n_f:
        det = np.column_stack((np.concatenate(out_r), np.concatenate(out_d))).astype(np.int64)
    return FramesOutput(point_cloud=pc, counts=n_out, detections=det), (maps or None)


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
