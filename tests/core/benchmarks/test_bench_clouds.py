"""bench clouds: the report from a stored result, the spectrogram's reach, the real-data folder."""

from __future__ import annotations

import numpy as np
import pytest

from core.benchmarks import clouds


def _band(points: float, truth: bool = True) -> dict:
    return {
        "low_m": 1.0, "high_m": 3.0, "person_frames": 10, "points_mean": points,
        "points_median": points, "empty_fraction": 0.0, "spread_x_m": 0.1, "spread_y_m": 0.2,
        "rms_x_ref_m": 0.1 if truth else None, "rms_y_ref_m": 0.2 if truth else None,
        "centroid_error_m": 0.05, "doppler_std_mps": 0.5, "snr_median_db": 30.0,
        "reference_is_truth": truth,
    }  # fmt: skip


def test_doppler_extent_of_a_constructed_spectrogram() -> None:
    v = np.arange(-4, 4) * 0.5
    p = np.full((3, 8), -50.0)
    p[:, 6] = 0.0  # peak at +1.0 m/s
    p[0, 7] = -10.0  # within 15 dB: reach 1.5 m/s
    p[1, 0] = -20.0  # 20 dB down: not counted
    e = clouds.doppler_extent(p, v)
    assert e["peak_abs_velocity_median_mps"] == 1.0
    assert e["reach_abs_velocity_median_mps"] == 1.0
    assert e["reach_abs_velocity_p95_mps"] == pytest.approx(1.0 + 0.5 * 0.9)


def test_render_writes_the_tables_and_plots(tmp_path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    md = {
        "frame_period_s": 0.08, "range_resolution_m": 0.05, "velocity_mps": [-0.5, 0.0, 0.5],
        "spectrogram_db": [[0.0, 1.0, 2.0]] * 4, "torso_radial_velocity_mps": 0.5,
        "rd_frame": 2, "rd_first_bin": 10, "rd_crop_db": [[0.0, 1.0, 2.0]] * 29,
        "doppler_extent": {"below_peak_db": 15.0, "peak_abs_velocity_median_mps": 0.5,
                           "reach_abs_velocity_median_mps": 0.5, "reach_abs_velocity_p95_mps": 0.5},
    }  # fmt: skip
    level = {"frames": 10, "bands": [_band(1.0)]}
    result = {
        "dataset": "test",
        "range_bands_m": [[1.0, 3.0]],
        "models": {"point": {"exact": level, "fast": level, "measurement": level}},
        "real": {
            "file": "walk.txt", "frames": 5, "rule": "the rule", "snr_is": "intensity",
            "velocity_step_mps": 0.61, "bands": [_band(5.0, truth=False)],
        },
        "micro_doppler": {"point": md},
        "merge_fit": {
            "exact_points": {"point": [1.0]}, "best": [3, 2, 1], "chosen": [3, 2, 1],
            "grid": [{"cells": [3, 2, 1], "rms_log_ratio": 0.1, "points": {"point": [1.0]}}],
        },
    }  # fmt: skip
    written = clouds.render(result, quick=True)
    assert [p.name for p in written] == ["clouds.md", "micro_doppler.png", "rd_map.png"]
    text = written[0].read_text()
    assert "| 1–3 | point | 1.00 (1) | 0% | 0.10, 0.20 | 0.10, 0.20 | 0.50 | 30 |" in text
    assert "| 1–3 | RadHAR walk (real, IWR1443) | 5.00 (5) |" in text and "– (no truth)" in text
    assert all(p.stat().st_size > 0 for p in written)


def test_real_data_dir_follows_the_environment(monkeypatch, tmp_path) -> None:
    monkeypatch.setenv("RADARTUNE_REAL_DATA", str(tmp_path))
    assert clouds.real_data_dir() == tmp_path
