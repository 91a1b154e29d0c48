"""Qt-free parts of the app: slider mapping, drawing geometry, the engine's loss and tracks."""

from __future__ import annotations

import math

import numpy as np
import pytest

from app.data import ParamSpec
from app.geometry import aoi_polyline, ellipse_polyline, trails_polyline
from app.panels.tracker_panel import SLIDER_STEPS, from_slider, to_slider


def test_log_slider_midpoint_is_the_geometric_mean_and_round_trips() -> None:
    spec = ParamSpec(name="q_coeff", low=0.1, high=30.0, log=True)
    # log scale: the middle of the slider is sqrt(low * high)
    assert from_slider(spec, SLIDER_STEPS // 2) == pytest.approx(math.sqrt(0.1 * 30.0), rel=1e-9)
    assert from_slider(spec, 0) == pytest.approx(0.1)
    assert from_slider(spec, SLIDER_STEPS) == pytest.approx(30.0)
    for v in (0.1, 0.37, 1.0, 7.7, 30.0):
        assert from_slider(spec, to_slider(spec, v)) == pytest.approx(v, rel=0.01)
    lin = ParamSpec(name="p_d", low=0.8, high=0.99, log=False)
    assert from_slider(lin, SLIDER_STEPS // 2) == pytest.approx(0.895)
    assert to_slider(lin, 5.0) == SLIDER_STEPS  # clipped into the range


def test_ellipse_points_lie_on_the_gate_boundary() -> None:
    rng = np.random.default_rng(1)
    a = rng.normal(size=(3, 2, 2))
    g = a @ np.swapaxes(a, 1, 2) + 0.1 * np.eye(2)  # SPD gate shapes G
    c = rng.normal(size=(3, 2))
    line = ellipse_polyline(c, g, 1.0)
    assert line.shape == (3 * 34, 2)
    pts = line.reshape(3, 34, 2)
    assert np.isnan(pts[:, -1]).all()
    for k in range(3):
        d = pts[k, :-1] - c[k]
        # dᵀ G⁻¹ d = 1 on the boundary
        m = np.einsum("ni,ij,nj->n", d, np.linalg.inv(g[k]), d)
        np.testing.assert_allclose(m, 1.0, rtol=1e-9)


def test_the_tracker_gates_are_drawn_on_their_boundary() -> None:
    """The overlay's ellipse of a real tracker frame: every vertex satisfies dᵀ G⁻¹ d = 1 with
    the gate shape G the tracker reports (already scaled by its threshold γ)."""
    from core.tracking import TrackerParams, run_tracker

    ft = run_tracker([np.array([[4.0, 0.2, 0.0]])], TrackerParams()).frames[0]
    pts = ellipse_polyline(ft.gate_center_xy, ft.gate_shape_xy, 1.0).reshape(len(ft.ids), 34, 2)
    for k in range(len(ft.ids)):
        d = pts[k, :-1] - ft.gate_center_xy[k]
        m = np.einsum("ni,ij,nj->n", d, np.linalg.inv(ft.gate_shape_xy[k]), d)
        np.testing.assert_allclose(m, 1.0, rtol=1e-9)


def test_aoi_outline_and_trails() -> None:
    line = aoi_polyline(0.5, 10.0, 60.0)
    r = np.hypot(line[:, 0], line[:, 1])
    assert r.max() == pytest.approx(10.0) and r.min() == pytest.approx(0.5)
    az = np.degrees(np.arctan2(line[:, 0], line[:, 1]))
    assert np.abs(az).max() == pytest.approx(60.0)
    ids = np.array([1, 1, 1, 2, 2])
    t = np.array([0, 1, 2, 1, 2])
    xy = np.arange(10.0).reshape(5, 2)
    out = trails_polyline(ids, t, xy, frame=2, length=2, live_ids=np.array([1, 2]))
    # track 1 frames 1..2, NaN, track 2 frames 1..2
    assert out.shape == (5, 2) and np.isnan(out[2]).all()
    np.testing.assert_array_equal(out[[0, 1, 3, 4]], xy[[1, 2, 3, 4]])
    assert len(trails_polyline(ids, t, xy, 2, 5, np.array([7]))) == 0


def test_running_loss_ends_at_the_paper_loss(long_scene_frames) -> None:
    from app import engine
    from core.evaluation import trajectory_loss

    scene, frames = long_scene_frames
    params = engine.make_params("cv", engine.default_values("cv"), {})
    from core.tracking import run_tracker

    full = engine.track(frames, params, scene.radar.frame_period_s)
    period = scene.radar.frame_period_s
    ref = run_tracker([f.cloud.measurements() for f in frames], params, period)  # readable
    assert full.n_frames == ref.n_frames == len(frames) == 250
    # the app's compiled re-track and the readable tracker are the same algorithm: every track
    ref_est = np.where(ref.has_estimate[:, None], ref.estimate_xy, np.nan)
    np.testing.assert_allclose(full.estimate_xy_m, ref_est, atol=1e-9, equal_nan=True)
    for tf, rf in zip(full.frames, ref.frames):
        np.testing.assert_array_equal(tf.track_id, rf.ids)
        np.testing.assert_array_equal(tf.confirmed, rf.confirmed)
        np.testing.assert_allclose(tf.xy_m, rf.state[:, :2], atol=1e-9)
        np.testing.assert_allclose(tf.psi, rf.psi, atol=1e-9)
        np.testing.assert_allclose(tf.gate_center_xy_m, rf.gate_center_xy, atol=1e-9)
        np.testing.assert_allclose(tf.gate_shape_xy_m2, rf.gate_shape_xy, rtol=1e-9, atol=1e-9)
    has = np.isfinite(full.estimate_xy_m[:, 0])
    loss, mse, n_c = trajectory_loss(full.estimate_xy_m, has, full.truth_xy_m)
    assert n_c > 100  # the person is tracked most of the time
    assert full.running_loss[-1] == pytest.approx(loss, rel=1e-12)
    assert full.running_rmse_m[-1] == pytest.approx(math.sqrt(mse), rel=1e-12)
    # before the first confirmation the loss is the N_c = 0 value (1.0 m²)
    first = int(np.argmax(has))
    assert np.all(full.running_loss[:first] == 1.0)
    # every track frame agrees with the tracker's per-frame confirmed count
    n_conf_full = np.array([tf.confirmed.sum() for tf in full.frames])
    np.testing.assert_array_equal(n_conf_full, ref.n_confirmed)
    assert np.all((full.ospa_m >= 0) & (full.ospa_m <= 1.0))
    psi = full.psi_value[np.isfinite(full.psi_value)]
    assert psi.size and psi.min() >= 0 and psi.max() <= 1


@pytest.mark.parametrize("model", ["cv", "ca"])
def test_sliders_and_their_defaults_are_the_search_space_table(model: str) -> None:
    from app import engine
    from core.tracking.space import defaults, search_space

    rows = search_space(model)
    assert engine.param_specs(model) == [
        ParamSpec(
            name=p.name,
            low=p.low,
            high=p.high,
            log=p.log,
            label=p.label,
            unit=p.unit,
            title=f"{p.symbol} {p.meaning}",
        )
        for p in rows
    ]
    for p in rows:  # labels show the unit of every dimensioned parameter
        assert p.label.startswith(p.symbol) and (not p.unit or p.label.endswith(f"[{p.unit}]"))
    assert engine.default_values(model) == defaults(model)


def test_running_rmse_of_several_people_scores_each_against_its_own_track() -> None:
    """Two people each tracked 0.1 m off, one of them unpaired in the first frame: the running
    RMSE is 0.1 m from the first pair on (the one scene estimate against person 0 read metres)."""
    import numpy as np

    from app.engine.tracking import running_pair_rmse

    e2 = np.array([[np.nan, np.nan], [0.01, np.nan], [0.01, 0.01], [0.04, 0.01]])
    rmse = running_pair_rmse(e2, 2.0)
    assert np.isnan(rmse[0])
    np.testing.assert_allclose(rmse[1:3], 0.1)
    np.testing.assert_allclose(rmse[3], np.sqrt((0.01 * 3 + 0.04 + 0.01) / 5))
    # GOSPA of order p = 1 gives |error|: the same RMSE
    np.testing.assert_allclose(running_pair_rmse(np.sqrt(e2), 1.0), rmse, equal_nan=True)
