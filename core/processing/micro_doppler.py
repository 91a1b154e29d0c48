"""Micro-Doppler spectrogram: Doppler against time at a person's range, from range-Doppler maps.

Each frame's range-Doppler map (``core.pipeline.simulate_scene(..., keep_rd_maps=True)``) is
cut at the person's range: the power of the range bins within ``half_width_bins`` of the
person's bin is summed (non-coherently) per Doppler bin. Stacking the cuts over the frames gives
the spectrogram: a walking body shows its torso line with the limbs' periodic smear around it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from core.config import RadarConfig


@dataclass(frozen=True, slots=True, kw_only=True)
class MicroDoppler:
    """A spectrogram.

    Attributes
    ----------
    velocity_mps
        Shape (D,): radial velocity of each Doppler bin (m/s), zero velocity at ``D // 2``.
    power_db
        Shape (F, D): ``10 log10`` of the summed power per frame and Doppler bin; a row is NaN
        when the person's range is unknown (absent) or outside the map.
    range_bin
        Shape (F,), int: the person's range bin per frame (-1 when absent).
    """

    velocity_mps: np.ndarray
    power_db: np.ndarray
    range_bin: np.ndarray


def micro_doppler(
    rd_maps_db: np.ndarray,
    range_m: np.ndarray,
    radar: RadarConfig,
    *,
    half_width_bins: int = 2,
) -> MicroDoppler:
    """Doppler spectrum at the person's range in each frame.

    Parameters
    ----------
    rd_maps_db
        Shape (F, R, D): range-Doppler maps in dB, zero velocity centred (as the chain keeps
        them).
    range_m
        Shape (F,): the person's range per frame (m); NaN when absent.
    radar
        Gives the range and velocity resolution of the bins.
    half_width_bins
        Range bins either side of the person's bin that are summed (a body is ~0.3 m deep).

    Returns
    -------
    MicroDoppler
    """
    maps = np.asarray(rd_maps_db, dtype=np.float64)
    if maps.ndim != 3:
        raise ValueError(f"rd_maps_db must have shape (F, R, D), got {maps.shape}")
    n_f, n_r, n_d = maps.shape
    rng = np.asarray(range_m, dtype=np.float64)
    if rng.shape != (n_f,):
        raise ValueError(f"range_m must have shape ({n_f},), got {rng.shape}")
    if half_width_bins < 0:
        raise ValueError(f"half_width_bins must be >= 0, got {half_width_bins}")
    known = np.isfinite(rng)
    # bin k holds range k Δr (the chain's refinement: r = k Δr)
    centre = np.full(n_f, -1, dtype=np.int64)
    centre[known] = np.rint(rng[known] / radar.range_resolution_m).astype(np.int64)
    centre[(centre < 0) | (centre >= n_r)] = -1
    power = np.full((n_f, n_d), np.nan)
    for f in np.flatnonzero(centre >= 0):
        lo = max(centre[f] - half_width_bins, 0)
        hi = min(centre[f] + half_width_bins + 1, n_r)
        # non-coherent sum of the cells: P = Σ_k 10^(L_k / 10)
        power[f] = 10 * np.log10(np.sum(10 ** (maps[f, lo:hi] / 10), axis=0))
    # v_d = (d − D/2) Δv, as the chain's points (core.processing.points.refine_bins)
    velocity = (np.arange(n_d) - n_d // 2) * radar.velocity_resolution_mps
    return MicroDoppler(velocity_mps=velocity, power_db=power, range_bin=centre)
