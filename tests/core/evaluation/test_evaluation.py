"""The paper's loss (eqs. 12–14), Table I layout and the extra metrics, on hand-computed cases."""

import math

import numpy as np
import pytest

from core.evaluation import evaluate, ospa, trajectory_loss, trajectory_losses
from core.tracking.batch import DatasetEstimates
from core.tracking.synthetic import SyntheticScene, synthetic_dataset


def test_trajectory_loss_hand_computed():
    truth = np.zeros((4, 2))
    est = np.array([[0.3, 0.4], [0.0, 0.0], [9.0, 9.0], [0.0, 0.1]])
    has = np.array([True, True, False, True])
    L, mse, n_c = trajectory_loss(est, has, truth)
    # errors² = 0.25, 0, 0.01 over N_c = 3 frames
    assert n_c == 3
    assert mse == pytest.approx(0.26 / 3, abs=1e-15)
    assert L == pytest.approx(0.26 / 9, abs=1e-15)


def test_no_confirmation_scores_one():
    L, mse, n_c = trajectory_loss(np.zeros((5, 2)), np.zeros(5, bool), np.ones((5, 2)))
    assert (L, n_c) == (1.0, 0) and math.isnan(mse)


def test_ospa_cases():
    assert ospa(np.zeros((0, 2)), np.zeros((0, 2))) == 0.0
    assert ospa(np.zeros((0, 2)), np.zeros((1, 2))) == 1.0  # a missed person costs c
    assert ospa(np.array([[0.3, 0.4]]), np.zeros((1, 2))) == pytest.approx(0.5)
    assert ospa(np.array([[3.0, 0.0]]), np.zeros((1, 2))) == pytest.approx(1.0)  # cut at c
    # one good track (0.5 m off) and one false track: sqrt((0.25 + 1)/2)
    two = np.array([[0.3, 0.4], [5.0, 5.0]])
    assert ospa(two, np.zeros((1, 2))) == pytest.approx(math.sqrt(1.25 / 2))
    # optimal assignment between two tracks and two persons
    tr = np.array([[0.0, 0.0], [2.0, 0.0]])
    gt = np.array([[2.1, 0.0], [0.0, 0.2]])
    assert ospa(tr, gt) == pytest.approx(math.sqrt((0.01 + 0.04) / 2))


def _estimates(ds, xy_err, has, conf_extra=None):
    f = ds.n_frames
    truth = ds.truth_xy_m[:, 0, :]
    est = truth + xy_err
    est[~has] = np.nan
    conf = np.full((f, 20, 2), np.nan)
    conf[has, 0] = est[has]
    if conf_extra is not None:
        conf[:, 1] = conf_extra
    t_off = ds.trajectory_offsets
    return DatasetEstimates(
        trajectories=np.arange(ds.n_trajectories),
        frame_index=np.arange(f),
        offsets=t_off,
        estimate_xy=est,
        has_estimate=has,
        estimate_psi=np.where(has, 0.95, np.nan),
        confirmed_xy=conf,
        n_confirmed=np.isfinite(conf[..., 0]).sum(1),
        n_tracks=np.isfinite(conf[..., 0]).sum(1),
    )


def test_evaluate_table_and_metrics_on_constructed_estimates():
    ds = synthetic_dataset(3, n_per_class=2, scene=SyntheticScene(clutter_per_frame=0.0))
    f = ds.n_frames
    t_off = ds.trajectory_offsets
    has = np.ones(f, dtype=bool)
    has[t_off[:-1]] = False  # first frame of every trajectory unconfirmed
    traj0 = slice(t_off[0], t_off[1])
    has[traj0] = False  # trajectory 0 (class a) never confirmed
    err = np.zeros((f, 2))
    err[:, 0] = 0.1  # 0.1 m everywhere → MSE = 0.01
    extra = np.full((f, 2), np.nan)
    extra[5] = ds.truth_xy_m[5, 0] + [3.0, 0.0]  # one far confirmed track in frame 5
    est = _estimates(ds, err, has, extra)
    ev = evaluate(ds, est)
    n = t_off[1:] - t_off[:-1]
    expect = np.where(np.arange(10) == 0, 1.0, 0.01 / (n - 1))
    np.testing.assert_allclose(ev.loss, expect, rtol=1e-12)
    assert ev.loss_total == pytest.approx(expect.mean(), rel=1e-12)
    np.testing.assert_allclose(trajectory_losses(ds, est), expect, rtol=1e-12)
    rows = {r.name: r for r in ev.table}
    assert list(rows) == ["A", "B", "C", "D", "E", "total"]
    assert rows["A"].loss == pytest.approx((1.0 + expect[5]) / 2)
    assert rows["A"].n_unconfirmed == 1 and rows["A"].mse == pytest.approx(0.01)
    assert rows["total"].n_trajectories == 10
    assert ev.rmse_m == pytest.approx(0.1)
    assert ev.confirmed_fraction == pytest.approx(has.mean())
    assert ev.far_frames_total == 1
    assert math.isnan(ev.first_confirmation_s[0])
    np.testing.assert_allclose(ev.first_confirmation_s[1:], 0.08, rtol=1e-12)
    # OSPA: 0.1 m error where confirmed, c = 1 where not; frame 5 has a false track
    assert 0.1 < ev.ospa_mean_m < 1.0
    text = ev.format_table()
    assert "total" in text and "A" in text
    d = ev.to_dict()
    assert d["table"][0]["class"] == "A" and d["trajectories"][0]["mse"] is None
