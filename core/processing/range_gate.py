"""Doppler at a person's range: one column of the micro-Doppler spectrogram per frame.

Stacked over frames, the Doppler content of the range bins around a person's range is the
micro-Doppler spectrogram the GUI draws (Doppler against time at that person's range; the
Doppler resolution is the frame's, ``velocity_resolution_mps``, and the time step the frame
period).
"""

from __future__ import annotations

import numpy as np

from core.config import RadarConfig

__all__ = ["doppler_at_range"]


def doppler_at_range(
    rd_map_db: np.ndarray, range_m: np.ndarray, radar: RadarConfig, *, half_width_bins: int = 1
) -> np.ndarray:
    """The Doppler spectrum of a range-Doppler map at given ranges.

    For each range ``R`` the map's rows ``k0 - w .. k0 + w`` around ``k0 = round(R / dR)``
    (``dR`` the range resolution, ``w = half_width_bins``; clipped to the map) are combined by
    their maximum per Doppler bin, so a person whose range falls between bins, or whose body
    spans two, keeps its full Doppler content.

    Parameters
    ----------
    rd_map_db
        ``[range bin, Doppler bin]`` map in dB, zero velocity centred.
    range_m
        ``(n,)`` ranges in m (NaN: no person; its row is NaN).
    radar
        Range resolution.
    half_width_bins
        Range bins taken on each side of the nearest bin.

    Returns
    -------
    numpy.ndarray
        ``(n, n_doppler_bins)`` dB, the same dtype as the map's float values.
    """
    rd = np.asarray(rd_map_db)
    r = np.atleast_1d(np.asarray(range_m, dtype=np.float64))
    n_r, n_d = rd.shape
    out = np.full((len(r), n_d), np.nan, dtype=np.result_type(rd.dtype, np.float32))
    for i, rng_m in enumerate(r):
        if not np.isfinite(rng_m):
            continue
        # k0 = round(R / dR)
        k0 = int(np.round(rng_m / radar.range_resolution_m))
        lo, hi = max(0, k0 - half_width_bins), min(n_r, k0 + half_width_bins + 1)
        if lo < hi:
            out[i] = rd[lo:hi].max(axis=0)
    return out
