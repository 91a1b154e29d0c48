"""The room-levels benchmark's figures on hand-made frames (numbers derived by hand)."""

from __future__ import annotations

import numpy as np
import pytest

from core.benchmarks import room_levels as rl
from core.pointcloud import PointCloud


def _row(x, y, v, source, order):
    return {
        "x": np.asarray(x, dtype=float),
        "y": np.asarray(y, dtype=float),
        "v": np.asarray(v, dtype=float),
        "source": np.asarray(source),
        "order": np.asarray(order),
    }


def test_counts_by_path_order_shares_and_spread():
    # frame 1: person 0 direct at x = -0.1, 0, 0.1 (y 3, v 1), one first-order ghost far behind
    # at the same bearing, one noise point; frame 2: person 0 direct twice, a second-order ghost
    f1 = _row(
        [-0.1, 0.0, 0.1, 0.0, 2.0],
        [3.0, 3.0, 3.0, 6.0, 1.0],
        [1.0, 1.0, 1.0, 1.0, 0.0],
        [0, 0, 0, 0, -2],
        [0, 0, 0, 1, -1],
    )
    f2 = _row([0.0, 0.0, 0.0], [3.0, 3.2, 7.0], [1.0, 1.0, 1.0], [0, 0, 0], [0, 0, 2])
    m = rl.metrics([f1, f2], n_persons=1)
    assert m["frames"] == 2
    assert m["points_by_order_per_frame"] == {
        "direct": 2.5,
        "1 bounce": 0.5,
        "2 bounces": 0.5,
        "clutter / noise": 0.5,
    }
    assert m["points_per_frame"] == 4.0
    assert m["direct_points_per_person_frame"] == 2.5
    # 2 bounce points of 7 person points
    assert m["ghost_share"] == pytest.approx(2 / 7)
    # wall_loss's statistic: frame 1 has 4 moving points, median at (0, 3): the one at (0, 6)
    # is 3 m behind on its bearing; frame 2 has 3 moving points, median (0, 3.2): (0, 7) is a
    # ghost. 2 of 7 moving points.
    assert m["ghost_fraction"] == pytest.approx(2 / 7)
    # direct deviations from the frame's median: x -0.1, 0, 0.1, 0, 0 -> MAD 0; y: 0, 0, 0,
    # -0.1, 0.1 -> MAD 0; all v equal -> 0
    assert m["spread_x_m"] == pytest.approx(0.0)
    assert m["spread_v_mps"] == pytest.approx(0.0)


def test_robust_spread_of_a_known_sample():
    # deviations -2, -1, 0, 1, 2 about the median: MAD 1, robust sd 1.4826
    f = _row([-2, -1, 0, 1, 2], [4.0] * 5, [1.0] * 5, [0] * 5, [0] * 5)
    assert rl.metrics([f], 1)["spread_x_m"] == pytest.approx(rl.MAD_TO_SD)


def test_no_person_points_give_undefined_shares():
    f = _row([1.0], [2.0], [0.0], [-1], [-1])
    m = rl.metrics([f], 2)
    assert m["ghost_share"] is None
    assert m["ghost_fraction"] is None
    assert m["spread_x_m"] is None
    assert m["points_by_order_per_frame"]["clutter / noise"] == 1.0


def test_frame_rows_without_path_order_label_direct_and_clutter():
    pc = PointCloud(
        range_m=np.array([2.0, 3.0]),
        azimuth_rad=np.zeros(2),
        elevation_rad=np.zeros(2),
        radial_velocity_mps=np.array([0.5, -0.5]),
        snr_db=np.array([20.0, 15.0]),
        x_m=np.zeros(2),
        y_m=np.array([2.0, 3.0]),
        z_m=np.zeros(2),
        source=np.array([0, -1], dtype=np.int32),
    )
    (row,) = rl.frame_rows([pc])
    assert row["order"].tolist() == [0, -1]


def test_shared_cells_counts_bounces_within_one_merge_cell_of_a_direct_scatterer():
    from core.config import RadarConfig
    from core.simulation import Scatterers
    from core.simulation.body_cells import MERGE_CELLS
    from core.simulation.multipath import path_labels

    radar = RadarConfig()
    dr = MERGE_CELLS[0] * radar.range_resolution_m
    # person 0 direct at (0, 4) still; bounce A half a merge cell further along the same
    # bearing (shares the cell); bounce B two merge cells further (does not); bounce C of
    # person 1 at A's place (another person's: not counted as sharing); a clutter point
    pos = np.array(
        [[0.0, 4.0, 0.0], [0.0, 4.0 + 0.5 * dr, 0.0], [0.0, 4.0 + 2 * dr, 0.0],
         [0.0, 4.0 + 0.5 * dr, 0.0], [1.0, 2.0, 0.0]]
    )  # fmt: skip
    labels = path_labels(
        np.array([0, 0, 0, 1, -1]),
        np.array([0, 1, 1, 1, 0]),
        np.array([False, False, False, False, True]),
    )
    frame = Scatterers(
        position_m=pos, velocity_mps=np.zeros((5, 3)), rcs_dbsm=np.zeros(5), source=labels
    )
    out = rl.shared_cells([frame, frame], radar)
    assert out["first_order_scatterers_per_frame"] == 3.0
    assert out["share_in_a_direct_cell"] == pytest.approx(1 / 3)
    assert rl.shared_cells([], radar)["share_in_a_direct_cell"] is None
