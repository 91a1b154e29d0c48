"""Doppler at a person's range: the rows taken are those around round(R / dR)."""

from __future__ import annotations

import numpy as np

from core.config import RadarConfig
from core.processing.range_gate import doppler_at_range

RADAR = RadarConfig()


def test_picks_the_rows_around_the_range_bin() -> None:
    n_r, n_d = RADAR.n_samples, RADAR.n_loops
    rd = np.zeros((n_r, n_d), dtype=np.float32)
    rd[71, 20] = 30.0  # 4.00 m lands in bin 71 (SPEC §1)
    rd[72, 3] = 20.0
    rd[74, 9] = 50.0  # outside the +-1 window around 71
    out = doppler_at_range(rd, np.array([4.00, np.nan, 0.0]), RADAR)
    assert out.shape == (3, n_d)
    assert out[0, 20] == 30.0 and out[0, 3] == 20.0 and out[0, 9] == 0.0
    assert np.isnan(out[1]).all()
    assert out[2].max() == 0.0  # range 0 clips to rows 0..1
    wide = doppler_at_range(rd, np.array([4.00]), RADAR, half_width_bins=3)
    assert wide[0, 9] == 50.0
