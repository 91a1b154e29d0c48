"""Micro-Doppler cut: the right range bins, the non-coherent sum, the velocity axis."""

from __future__ import annotations

import math

import numpy as np
import pytest

from core.config import PAPER_RADAR
from core.processing.micro_doppler import micro_doppler


def test_cut_sums_the_person_bins_and_labels_velocity() -> None:
    radar = PAPER_RADAR
    n_f, n_r, n_d = 3, 40, 16
    maps = np.full((n_f, n_r, n_d), -100.0)
    dr = radar.range_resolution_m
    # frame 0: person at bin 10, energy 0 dB at Doppler bins 9 and 11 in range bins 9 and 11
    maps[0, 9, 9] = 0.0
    maps[0, 11, 9] = 0.0
    maps[0, 20, 9] = 30.0  # another range: not in the cut
    # frame 1: person at bin 30, one cell 10 dB at Doppler bin 8 (zero velocity)
    maps[1, 30, 8] = 10.0
    md = micro_doppler(maps, np.array([10 * dr, 30.2 * dr, np.nan]), radar, half_width_bins=1)
    np.testing.assert_array_equal(md.range_bin, [10, 30, -1])
    # two 0 dB cells summed: 10 log10(2) (+ the -100 dB floor, negligible)
    assert md.power_db[0, 9] == pytest.approx(10 * math.log10(2), abs=1e-6)
    assert md.power_db[1, 8] == pytest.approx(10.0, abs=1e-6)
    assert np.all(np.isnan(md.power_db[2]))
    assert md.velocity_mps[8] == 0.0
    assert md.velocity_mps[9] == pytest.approx(radar.velocity_resolution_mps)


def test_range_outside_the_map_is_absent_and_shapes_are_checked() -> None:
    maps = np.zeros((1, 4, 8))
    md = micro_doppler(maps, np.array([100.0]), PAPER_RADAR)
    assert md.range_bin[0] == -1 and np.all(np.isnan(md.power_db))
    with pytest.raises(ValueError, match="range_m"):
        micro_doppler(maps, np.zeros(2), PAPER_RADAR)
    with pytest.raises(ValueError, match="F, R, D"):
        micro_doppler(np.zeros((4, 8)), np.zeros(1), PAPER_RADAR)
