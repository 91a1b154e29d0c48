"""Merging a person's scatterers per cell for the measurement level."""

from __future__ import annotations

import numpy as np
import pytest

from core.config import PAPER_RADAR
from core.simulation.body_cells import merge_person_cells

RADAR = PAPER_RADAR
DR = RADAR.range_resolution_m
DV = RADAR.velocity_resolution_mps


def _frame(pos, vel, rcs, src):
    return (
        np.array([0, len(rcs)]),
        np.array(pos, dtype=float),
        np.array(vel, dtype=float),
        np.array(rcs, dtype=float),
        np.array(src, dtype=np.int32),
    )


def test_a_weaker_scatterer_in_the_stronger_ones_cell_is_absorbed() -> None:
    # person 0: 0 dBsm at 5 m, and -3 dBsm 0.5 bin further at the same velocity: merged;
    # a third 10 bins away: kept. Clutter (-1) next to them: kept. Person 1 alone: kept.
    r2 = 5.0 + 0.5 * DR
    start, pos, vel, rcs, src = _frame(
        [[0, 5.0, 0], [0, r2, 0], [0, 5.0 + 10 * DR, 0], [0, 5.0, 0], [1, 7, 0]],
        [[0, 1.0, 0]] * 5,
        [0.0, -3.0, 0.0, 5.0, 1.0],
        [0, 0, 0, -1, 1],
    )
    out = merge_person_cells(RADAR, start, pos, vel, rcs, src, (1.0, 1.0, 1.0))
    np.testing.assert_array_equal(out.start, [0, 4])
    np.testing.assert_array_equal(out.source, [0, 0, -1, 1])
    # P = 1 + 10^-0.3; position at the power-weighted mean
    p2 = 10**-0.3
    assert out.rcs_dbsm[0] == pytest.approx(10 * np.log10(1 + p2))
    assert out.position_m[0, 1] == pytest.approx((5.0 + p2 * r2) / (1 + p2))
    # the others keep their values bit for bit
    np.testing.assert_array_equal(out.position_m[1:], pos[2:])
    np.testing.assert_array_equal(out.rcs_dbsm[1:], rcs[2:])


def test_velocity_or_angle_apart_is_not_merged_and_nothing_merged_returns_the_input() -> None:
    start, pos, vel, rcs, src = _frame(
        [[0, 5.0, 0], [0, 5.0, 0], [2.0, 5.0, 0]],
        [[0, 1.0, 0], [0, 1.0 + 3 * DV, 0], [0, 0, 0]],
        [0.0, 0.0, 0.0],
        [0, 0, 0],
    )
    out = merge_person_cells(RADAR, start, pos, vel, rcs, src, (1.0, 1.0, 1.0))
    assert out.position_m is pos and out.rcs_dbsm is rcs and out.start is start


def test_frames_stay_apart() -> None:
    pos = np.array([[0, 5.0, 0], [0, 5.0, 0]])
    out = merge_person_cells(
        RADAR,
        np.array([0, 1, 2]),
        pos,
        np.zeros((2, 3)),
        np.zeros(2),
        np.zeros(2, dtype=np.int32),
    )
    assert out.position_m is pos
