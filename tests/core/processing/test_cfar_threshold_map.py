"""The per-cell CFAR thresholds the range profile draws are the detector's own: a cell is
detected by ``two_stage_cfar`` exactly when its power exceeds both stages' thresholds (and it is
a local maximum), on noise maps with targets, for every estimator and with or without the
dead zero-Doppler bin of a rectangular window."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from core.config import DEFAULT_PROCESSING, CfarSettings, RadarConfig
from core.processing import two_stage_cfar, two_stage_thresholds
from core.processing.spectrum import clutter_removal_noise_profile

RADAR = RadarConfig()


def _noise_map(settings, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    n_r, n_d = RADAR.n_samples, RADAR.n_loops
    # sum of L = 12 exponential looks per cell, shaped by clutter removal's Doppler profile
    rd = rng.gamma(RADAR.n_virtual, 1.0, size=(n_r, n_d))
    if settings.static_clutter_removal:
        rd = rd * clutter_removal_noise_profile(settings.doppler_window, n_d)[None, :]
    for r, d, snr in ((40, 20, 300.0), (71, 5, 80.0), (150, 28, 40.0), (100, 12, 60.0)):
        rd[r, d] += snr * RADAR.n_virtual
    return rd


def _local_max(rd: np.ndarray) -> np.ndarray:
    n_r, _ = rd.shape
    keep = np.ones(rd.shape, dtype=bool)
    for dr in (-1, 0, 1):
        for dd in (-1, 0, 1):
            if dr == 0 and dd == 0:
                continue
            shifted = np.roll(rd, (-dr, -dd), axis=(0, 1))
            bigger = shifted > rd
            if dr == 1:
                bigger[n_r - 1] = False  # range edges are open
            if dr == -1:
                bigger[0] = False
            keep &= ~bigger
    return keep


@pytest.mark.parametrize("method", ["ca", "caso", "cago"])
@pytest.mark.parametrize("doppler_window", ["hann", "rect"])
def test_detections_are_the_cells_above_both_thresholds(method: str, doppler_window: str) -> None:
    s = DEFAULT_PROCESSING
    s = dataclasses.replace(
        s,
        doppler_window=doppler_window,
        range_cfar=dataclasses.replace(s.range_cfar, method=method),
        doppler_cfar=dataclasses.replace(s.doppler_cfar, method=method),
    )
    for seed in range(4):
        rd = _noise_map(s, seed)
        det = two_stage_cfar(rd, RADAR, s)
        th = two_stage_thresholds(rd, RADAR, s)
        with np.errstate(invalid="ignore"):
            mask = (rd > th.combined) & _local_max(rd)
        r, d = np.nonzero(mask)
        got = sorted(zip(det.range_bin.tolist(), det.doppler_index.tolist()))
        assert got == sorted(zip(r.tolist(), d.tolist()))
        assert len(got) >= 4  # the four targets at least


def test_thresholds_are_nan_outside_the_range_limits_and_on_dead_bins() -> None:
    s = dataclasses.replace(DEFAULT_PROCESSING, doppler_window="rect")
    rd = _noise_map(s, 0)
    th = two_stage_thresholds(rd, RADAR, s)
    k = np.arange(RADAR.n_samples) * RADAR.range_resolution_m
    inside = (k >= s.min_range_m) & (k <= s.max_range_m)
    assert np.isnan(th.combined[~inside]).all()
    assert np.isnan(th.combined[:, RADAR.n_loops // 2]).all()  # zero Doppler emptied
    others = np.delete(th.combined[inside], RADAR.n_loops // 2, axis=1)
    assert np.isfinite(others).all()


def test_ca_threshold_on_flat_noise_is_alpha_times_the_mean() -> None:
    # a flat map of mean mu: every interior range-stage threshold is alpha * mu
    s = dataclasses.replace(
        DEFAULT_PROCESSING,
        static_clutter_removal=False,
        cfar_noise_model=False,
        range_cfar=CfarSettings(method="ca", n_train=8, n_guard=4, pfa=1e-3, cyclic=False),
    )
    rd = np.full((RADAR.n_samples, RADAR.n_loops), 7.0)
    th = two_stage_thresholds(rd, RADAR, s)
    from core.processing import CaCfar

    alpha = CaCfar(n_train=8, n_guard=4, pfa=1e-3, n_channels=RADAR.n_virtual).alpha()
    np.testing.assert_allclose(th.range_stage[20:170], 7.0 * alpha, rtol=1e-12)
