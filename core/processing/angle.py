"""Angle of arrival at detected cells (SPEC §3, step 6).

TDM-MIMO: the chirp of TX slot ``k`` in loop ``m`` starts at ``(m Ntx + k) Tchirp``, so a target
with Doppler phase ``omega`` per loop (``omega = 2 pi d / Nc`` for Doppler bin ``d``) carries an
extra ``omega k / Ntx`` on the channels of slot ``k``; it is removed before the angle FFT:
``x_v <- x_v exp(-j omega k(v) / Ntx)``.

Azimuth: the channels of the azimuth row (elevation position 0) sit at azimuth positions
``p`` (units of lambda/2) with phase ``pi p u``, ``u = sin(az) cos(el)``. The row is zero-padded
to ``N_fft`` (64) and transformed; the peak at index ``k`` (centred) gives ``u = 2 k / N_fft``,
refined by a parabola through the log power of the peak and its neighbours.

Elevation (only when the scene needs it): an elevated channel and the row channel at the same
azimuth position differ by ``pi sin(el)`` in phase: ``sin(el) = arg(sum x_e conj(x_row)) / pi``.
"""

from __future__ import annotations

import functools

import numpy as np

from core.config import RadarConfig

_TINY = float(np.finfo(np.float64).tiny)


def _frozen(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


def _parabolic_offset(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Vertex offset in (-0.5, 0.5) of a parabola through (-1, a), (0, b), (1, c)."""
    # delta = (a - c) / (2 (a - 2b + c))
    den = a - 2.0 * b + c
    with np.errstate(divide="ignore", invalid="ignore"):
        delta = np.where(den < 0, 0.5 * (a - c) / den, 0.0)
    return np.clip(np.nan_to_num(delta), -0.5, 0.5)


def log_parabolic_offset(left: np.ndarray, peak: np.ndarray, right: np.ndarray) -> np.ndarray:
    """Sub-bin offset of a spectral peak from the log powers of the peak and its neighbours."""
    tiny = _TINY
    la, lb, lc = (
        np.log(np.maximum(np.asarray(v, dtype=np.float64), tiny)) for v in (left, peak, right)
    )
    return _parabolic_offset(la, lb, lc)


def azimuth_row(radar: RadarConfig) -> tuple[np.ndarray, np.ndarray]:
    """Channels of the azimuth row and their azimuth positions (units of lambda/2).

    The row is the set of channels at the lowest elevation position; where two channels share
    an azimuth position the first is used.
    """
    return _azimuth_row(radar.azimuth_positions, radar.elevation_positions)


@functools.lru_cache(maxsize=32)
def _azimuth_row(az_pos: tuple, el_pos: tuple) -> tuple[np.ndarray, np.ndarray]:
    el = np.asarray(el_pos)
    az = np.asarray(az_pos)
    base = el.min()
    channels, positions, seen = [], [], set()
    for v in np.flatnonzero(el == base):
        if int(az[v]) not in seen:
            seen.add(int(az[v]))
            channels.append(v)
            positions.append(int(az[v]))
    pos = np.asarray(positions)
    return _frozen(np.asarray(channels)), _frozen(pos - pos.min())


def elevation_pairs(radar: RadarConfig) -> tuple[np.ndarray, np.ndarray]:
    """Pairs ``(elevated channel, row channel)`` at the same azimuth position, one above."""
    return _elevation_pairs(radar.azimuth_positions, radar.elevation_positions)


@functools.lru_cache(maxsize=32)
def _elevation_pairs(az_pos: tuple, el_pos: tuple) -> tuple[np.ndarray, np.ndarray]:
    el = np.asarray(el_pos)
    az = np.asarray(az_pos)
    base = el.min()
    upper, lower = [], []
    for v in np.flatnonzero(el == base + 1):
        match = np.flatnonzero((el == base) & (az == az[v]))
        if match.size:
            upper.append(v)
            lower.append(match[0])
    return _frozen(np.asarray(upper, dtype=np.int64)), _frozen(np.asarray(lower, dtype=np.int64))


def tdm_compensate(channels: np.ndarray, doppler_bin: np.ndarray, radar: RadarConfig) -> np.ndarray:
    """Remove the TDM-MIMO Doppler phase: ``x_v exp(-j 2 pi d k(v) / (Nc Ntx))``.

    Parameters
    ----------
    channels
        ``(n_det, n_virtual)`` complex values of the detected cells.
    doppler_bin
        ``(n_det,)`` (fractional) Doppler bins, zero velocity = 0.
    """
    slot = np.arange(radar.n_virtual) // radar.n_rx
    # omega = 2 pi d / Nc per loop; slot k lags k/Ntx of a loop
    phase = -2 * np.pi * np.outer(doppler_bin, slot) / (radar.n_loops * radar.n_tx)
    return channels * np.exp(1j * phase)


def azimuth_power(channels: np.ndarray, radar: RadarConfig, fft_size: int = 64) -> np.ndarray:
    """Azimuth FFT power over the azimuth row of TDM-compensated channel values.

    Parameters
    ----------
    channels
        ``(n_det, n_virtual)`` complex128, the TDM-MIMO Doppler phase already removed.

    Returns
    -------
    numpy.ndarray
        ``(n_det, fft_size)`` float64; index ``k`` (``k < N/2``, else ``k - N``) is at
        ``u = sin(az) cos(el) = 2 k / N``.
    """
    x = np.asarray(channels)
    row_ch, row_pos = azimuth_row(radar)
    row = np.zeros((x.shape[0], fft_size), dtype=np.complex128)
    row[:, row_pos] = x[:, row_ch]
    # X_k = sum_p x_p exp(-j 2 pi k p / N): peaks at k = N u / 2
    spec = np.fft.fft(row, axis=1)  # index k <-> k (k < N/2) or k - N
    return spec.real**2 + spec.imag**2


def elevation_sines(channels: np.ndarray, radar: RadarConfig) -> np.ndarray:
    """``sin(el) = arg(sum x_upper conj(x_lower)) / pi`` over the elevation pairs, clipped to
    [-1, 1]; zeros when the array has no elevated channel. ``channels``: ``(n_det, n_virtual)``,
    TDM-compensated."""
    x = np.asarray(channels)
    upper, lower = elevation_pairs(radar)
    if not upper.size:
        return np.zeros(x.shape[0])
    z = np.sum(x[:, upper] * np.conj(x[:, lower]), axis=1)
    return np.clip(np.angle(z) / np.pi, -1.0, 1.0)


def estimate_angles(
    channels: np.ndarray,
    doppler_bin: np.ndarray,
    radar: RadarConfig,
    *,
    fft_size: int = 64,
    elevation: bool = False,
    compensate_tdm: bool = True,
) -> tuple[np.ndarray, np.ndarray]:
    """Azimuth (and optionally elevation) of detected cells.

    Parameters
    ----------
    channels
        ``(n_det, n_virtual)`` complex Doppler-cube values at the detected cells.
    doppler_bin
        ``(n_det,)`` Doppler bin of each detection (fractional allowed), zero velocity = 0.
    fft_size
        Zero-padded azimuth FFT length.
    elevation
        Estimate elevation from the elevated row; otherwise elevation is 0.
    compensate_tdm
        Apply the TDM-MIMO Doppler phase compensation (switch off only to show its effect).

    Returns
    -------
    azimuth_rad, elevation_rad : numpy.ndarray
        ``(n_det,)`` each, radians.
    """
    x = np.asarray(channels, dtype=np.complex128)
    n_det = x.shape[0]
    if n_det == 0:
        return np.zeros(0), np.zeros(0)
    if compensate_tdm:
        x = tdm_compensate(x, np.asarray(doppler_bin, dtype=np.float64), radar)
    power = azimuth_power(x, radar, fft_size)
    k = np.argmax(power, axis=1)
    i = np.arange(n_det)
    delta = log_parabolic_offset(
        power[i, (k - 1) % fft_size], power[i, k], power[i, (k + 1) % fft_size]
    )
    k_signed = np.where(k >= fft_size // 2, k - fft_size, k)
    # u = sin(az) cos(el) = 2 (k + delta) / N, k centred
    u = 2.0 * (k_signed + delta) / fft_size
    el = np.zeros(n_det)
    if elevation:
        if elevation_pairs(radar)[0].size:
            el = np.arcsin(elevation_sines(x, radar))
    az = np.arcsin(np.clip(u / np.cos(el), -1.0, 1.0))
    return az, el
