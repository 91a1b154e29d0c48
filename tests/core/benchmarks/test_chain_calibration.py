"""The calibration statistics of the chains' point clouds (the estimator on hand-made frames)."""

from __future__ import annotations

import numpy as np
import pytest

from core.benchmarks.chain_calibration import frame_stats


def test_frame_stats_person_spread_and_zero_doppler_by_band():
    rng = np.random.default_rng(0)
    frames = []
    for _ in range(50):
        # a person of 6 moving points around (1, 3) with sigma 0.1 m, 0.2 m/s; 4 static points
        # at 5 m; one moving ghost 2.5 m away (outside the 1 m disc)
        x = np.concatenate([1 + 0.1 * rng.standard_normal(6), [0, 1, -1, 2], [1.0]])
        y = np.concatenate([3 + 0.1 * rng.standard_normal(6), [5, 5, 5, 4.6], [5.5]])
        z = np.concatenate([0.05 * rng.standard_normal(6), np.zeros(4), [0.0]])
        v = np.concatenate([-1 + 0.2 * rng.standard_normal(6), np.zeros(4), [-1.0]])
        frames.append({"x": x, "y": y, "z": z, "v": v, "snr": np.full(11, 12.0)})
    s = frame_stats(frames)
    assert s["person_points_per_frame"]["median"] == 6
    assert s["points_per_frame"]["median"] == 11
    # the standard deviation of 6 draws of sigma 0.1 has its median a little below 0.1
    assert s["spread_x_m"]["median"] == pytest.approx(0.09, abs=0.02)
    assert s["doppler_spread_mps"]["median"] == pytest.approx(0.18, abs=0.04)
    assert s["person_snr_db"]["median"] == 12.0
    zero = s["zero_doppler_fraction"]
    assert zero["2-4 m"] == 0.0 and zero["4-6 m"] == pytest.approx(4 / 5)
    # the person at range sqrt(1 + 9) = 3.16 m: its z spread (sigma 0.05 m) is an elevation
    # spread of 0.05 / 3.16 rad = 0.91 deg (median of 6 draws a little below), all in 2-4 m
    assert s["person_range_m"]["median"] == pytest.approx(np.sqrt(10.0), abs=0.05)
    assert s["spread_elevation_deg"]["median"] == pytest.approx(0.82, abs=0.15)
    band = s["spread_z_by_range_m"]
    assert band["2-4 m"]["n"] == 50 and band["0-2 m"]["n"] == 0 and band["4-6 m"]["n"] == 0
    assert band["2-4 m"]["median"] == s["spread_z_m"]["median"]
    # no point near 18 deg (z ~ 1 m at 3.16 m would be 20 sigma away)
    assert s["elevation_edge_share"] == {"top": 0.0, "bottom": 0.0}
    # a frame whose person's points all sit at +19 deg: all at the top edge
    el = np.radians(19.0)
    top = {k: np.full(3, val) for k, val in (("x", 0.0), ("v", 1.0), ("snr", 10.0))}
    top["y"], top["z"] = np.full(3, np.cos(el)), np.full(3, np.sin(el))
    assert frame_stats([top])["elevation_edge_share"] == {"top": 1.0, "bottom": 0.0}


def test_static_recurrence_tells_furniture_from_scattered_false_alarms():
    from core.benchmarks.chain_calibration import static_recurrence

    rng = np.random.default_rng(1)
    frames = []
    for _ in range(40):
        # two static points that stay (a desk), two drawn anywhere in 8 x 8 m, one moving point
        x = np.concatenate([[1.0, -2.0], rng.uniform(-4, 4, 2), [0.0]])
        y = np.concatenate([[3.0, 5.0], rng.uniform(0, 8, 2), [2.0]])
        v = np.array([0.0, 0.0, 0.0, 0.0, 1.0])
        frames.append({"x": x, "y": y, "v": v})
    r = static_recurrence(frames)
    # the desk's two recur; a random point meets a static one within 0.2 m with probability
    # about 4 * pi * 0.2^2 / 64 = 0.008
    assert r == pytest.approx(0.5, abs=0.03)
    assert static_recurrence(frames[:1]) is None
