"""Loss breakdown and paired comparison (core.evaluation) against hand-built cases."""

from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest

from core.dataset import Dataset
from core.evaluation import loss_breakdown, paired_comparison

T = 0.08


def _dataset(truth_xy: np.ndarray, truth_v: np.ndarray) -> Dataset:
    """One trajectory of class 'c', no points (the breakdown needs only the truth)."""
    n = len(truth_xy)
    empty = np.zeros(0)
    return Dataset(
        frame=np.zeros(0, np.int64),
        range_m=empty,
        azimuth_rad=empty,
        elevation_rad=empty,
        radial_velocity_mps=empty,
        snr_db=empty,
        x_m=empty,
        y_m=empty,
        z_m=empty,
        source=np.zeros(0, np.int32),
        trajectory=np.zeros(n, np.int64),
        truth_t_s=np.arange(n) * T,
        truth_xy_m=truth_xy[:, None, :],
        truth_v_mps=truth_v[:, None, :],
        trajectory_class=np.array(["c"]),
        scene_json="{}",
        radar_json=json.dumps({"frame_period_s": T}),
    )


def _walk(n: int = 30, turn_at: int = 15) -> tuple[np.ndarray, np.ndarray]:
    """Eq. (6) walk along +x at 1 m/s, y = 5 m; at frame ``turn_at`` v gains 0.2 m/s along y."""
    v = np.tile([1.0, 0.0], (n, 1))
    v[turn_at:, 1] = 0.2
    p = np.zeros((n, 2))
    p[0] = (-1.0, 5.0)
    for t in range(1, n):
        p[t] = p[t - 1] + v[t] * T
    return p, v


def _estimates(est_xy: np.ndarray, has: np.ndarray) -> SimpleNamespace:
    n = len(has)
    return SimpleNamespace(
        trajectories=np.array([0]),
        frame_index=np.arange(n),
        offsets=np.array([0, n]),
        estimate_xy=est_xy,
        has_estimate=has,
    )


def test_breakdown_splits_the_loss_by_frame_kind() -> None:
    p, v = _walk()
    ds = _dataset(p, v)
    has = np.arange(30) >= 3
    est = np.where(has[:, None], p + [0.01, 0.0], np.nan)  # 1 cm ahead along x from frame 3
    bd = loss_breakdown(ds, _estimates(est, has), n_transient=10, manoeuvre_window=10)
    n_c = 27
    assert bd.n_c[0] == n_c and bd.first_confirmed_frame[0] == 3
    # L = SSE/N_c² with SSE = 27 · 1e-4 m²
    assert bd.sse[0] == pytest.approx(n_c * 1e-4)
    assert bd.loss[0] == pytest.approx(n_c * 1e-4 / n_c**2)
    # transient: frames 3–12 (10); manoeuvre: |Δv|/T = 2.5 m/s² at frame 15 → frames 15–24 (10);
    # steady: 13, 14, 25–29 (7)
    np.testing.assert_array_equal(bd.frames_by_category[0], [10, 10, 7])
    np.testing.assert_allclose(bd.loss_by_category[0], np.array([10, 10, 7]) * 1e-4 / n_c**2)
    assert bd.loss_by_category[0].sum() == pytest.approx(bd.loss[0])
    # 1 cm ahead along the heading before the turn, ~0.98 cm after it (heading 11.3° off x)
    heading = v[13:] / np.linalg.norm(v[13:], axis=1, keepdims=True)
    assert bd.along_track_mean_m[0] == pytest.approx(np.mean(0.01 * heading[:, 0]))
    # range and cross-range parts add up to the 1 cm error
    assert bd.range_rms_m[0] ** 2 + bd.cross_range_rms_m[0] ** 2 == pytest.approx(1e-4)
    table = bd.class_table()
    assert [r["class"] for r in table] == ["C", "total"]
    assert table[1]["loss"] == pytest.approx(bd.loss[0])


def test_breakdown_restarts_the_transient_on_a_track_change() -> None:
    p, v = _walk(turn_at=30)  # no manoeuvre
    ds = _dataset(p, v)
    has = np.ones(30, bool)
    ids = np.where(np.arange(30) < 20, 0, 4)  # the estimate switches to track 4 at frame 20
    bd = loss_breakdown(ds, _estimates(p.copy(), has), estimate_ids=ids, n_transient=5)
    # transient: 0–4 and 20–24
    np.testing.assert_array_equal(bd.frames_by_category[0], [10, 0, 20])
    bd2 = loss_breakdown(ds, _estimates(p.copy(), has), n_transient=5)
    np.testing.assert_array_equal(bd2.frames_by_category[0], [5, 0, 25])


def test_never_confirmed_scores_one() -> None:
    p, v = _walk()
    bd = loss_breakdown(_dataset(p, v), _estimates(np.full((30, 2), np.nan), np.zeros(30, bool)))
    assert bd.loss[0] == 1.0 and bd.n_c[0] == 0 and bd.first_confirmed_frame[0] == -1
    assert bd.loss_by_category.sum() == 0.0


def test_paired_comparison_exact_cases() -> None:
    rng = np.random.default_rng(3)
    b = rng.lognormal(-13, 1, 35)
    cls = np.repeat(list("abcde"), 7)
    # a = 2 b on every trajectory: every bootstrap ratio is 2
    c = paired_comparison(2 * b, b, cls, n_boot=2000)
    assert c.ratio == pytest.approx(2.0)
    assert c.ci_low == pytest.approx(2.0) and c.ci_high == pytest.approx(2.0)
    assert c.p_ratio_above == 1.0 and c.wins_b == 35 and c.wins_a == 0
    assert c.log_ratio_median == pytest.approx(np.log(2))
    assert c.wilcoxon_p < 1e-6
    # equal runs: ratio 1, no wins, no test
    e = paired_comparison(b, b, cls, n_boot=500)
    assert e.ratio == 1.0 and e.wins_a == e.wins_b == 0 and np.isnan(e.wilcoxon_p)
    assert e.p_ratio_above == 0.0


def test_paired_comparison_interval_is_the_bootstrap_of_the_ratio_of_means() -> None:
    rng = np.random.default_rng(5)
    a = rng.lognormal(-13, 1, 35)
    b = rng.lognormal(-13, 1, 35)
    c = paired_comparison(a, b, n_boot=4000, seed=1)
    assert c.ratio == pytest.approx(a.mean() / b.mean())
    assert c.ci_low < c.ratio < c.ci_high
    # the same resampling by hand (one stratum)
    idx = np.random.default_rng(1).choice(np.arange(35), size=(4000, 35))
    r = a[idx].mean(axis=1) / b[idx].mean(axis=1)
    assert c.ci_low == pytest.approx(np.quantile(r, 0.025))
    assert c.ci_high == pytest.approx(np.quantile(r, 0.975))
    assert c.p_ratio_above == pytest.approx(np.mean(r > 1.05))


def test_paired_comparison_rejects_bad_input() -> None:
    with pytest.raises(ValueError, match="equal-length"):
        paired_comparison(np.ones(3), np.ones(4))
    with pytest.raises(ValueError, match="positive"):
        paired_comparison(np.array([1.0, 0.0]), np.ones(2))


def test_track_with_ids_matches_track_dataset() -> None:
    from core.evaluation import track_with_ids
    from core.tracking import TrackerParams, track_dataset
    from core.tracking.synthetic import SyntheticScene, synthetic_dataset

    ds = synthetic_dataset(
        4, n_per_class=1, classes="bd", scene=SyntheticScene(clutter_per_frame=2.0), n_frames=40
    )
    p = TrackerParams.default("cv")
    est, ids = track_with_ids(ds, p)
    ref = track_dataset(ds, p)
    np.testing.assert_array_equal(est.has_estimate, ref.has_estimate)
    np.testing.assert_array_equal(ids >= 0, ref.has_estimate)
    assert ref.has_estimate.any()


def test_breakdown_scores_only_frames_with_the_person_present() -> None:
    p, v = _walk(turn_at=30)  # no manoeuvre
    gone = p.copy()
    gone[20:25] = np.nan  # the person is absent for frames 20–24
    v_gone = v.copy()
    v_gone[20:25] = np.nan  # absent: neither position nor velocity (the data-set rule)
    has = np.ones(30, bool)
    est = p + [0.01, 0.0]
    bd = loss_breakdown(_dataset(gone, v_gone), _estimates(est, has), n_transient=5)
    assert bd.n_c[0] == 25 and bd.sse[0] == pytest.approx(25e-4)
    assert bd.loss[0] == pytest.approx(25e-4 / 25**2)
    # the estimate "reappears" at frame 25: a second transient of 5 frames
    np.testing.assert_array_equal(bd.frames_by_category[0], [10, 0, 15])
    json.dumps(bd.class_table(), allow_nan=False)


def test_breakdown_without_any_person_scores_one() -> None:
    p, v = _walk()
    ds = _dataset(p, v)
    from dataclasses import replace

    nobody = replace(ds, truth_xy_m=np.zeros((30, 0, 2)), truth_v_mps=np.zeros((30, 0, 2)))
    bd = loss_breakdown(nobody, _estimates(p.copy(), np.ones(30, bool)))
    assert bd.loss[0] == 1.0 and bd.n_c[0] == 0
    json.dumps(bd.class_table(), allow_nan=False)
