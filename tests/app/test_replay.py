"""``radartune gui --replay``: a recording plays through the same views — its frames fill the
cache in order with the recorded points, playback advances, and the tracker runs on them."""

from __future__ import annotations

import json

import numpy as np
import pytest

from core.config import PAPER_RADAR
from core.errors import InputError
from core.formats import ti_uart
from core.pointcloud import PointCloud

N_FRAMES = 30


def _log(path) -> list[np.ndarray]:
    """A UART log of one reflector walking away at 1 m/s plus one clutter point a frame."""
    xs = []
    with open(path, "wb") as fh:
        for k in range(N_FRAMES):
            y = 3.0 + 1.0 * k * PAPER_RADAR.frame_period_s
            x = np.array([0.5, -2.0])
            yy = np.array([y, 6.0 + 0.1 * (k % 3)])
            r = np.hypot(x, yy)
            c = PointCloud(
                range_m=r,
                azimuth_rad=np.arctan2(x, yy),
                elevation_rad=np.zeros(2),
                radial_velocity_mps=np.array([yy[0] / r[0], 0.0]),
                snr_db=np.array([20.0, 9.0]),
                x_m=x,
                y_m=yy,
                z_m=np.zeros(2),
                source=np.zeros(2, dtype=np.int32),
            )
            xs.append(x)
            fh.write(ti_uart.encode_frame(c, 1 + k))
    return xs


def test_replay_plays_a_uart_log(qtbot, settings, tmp_path) -> None:
    from app.replay import ReplayEngine, load_recording
    from app.window import MainWindow

    log = tmp_path / "walk.dat"
    _log(log)
    engine = ReplayEngine(load_recording(log))
    w = MainWindow(settings, engine)
    qtbot.addWidget(w)
    try:
        w.playback.set_playing(True)
        qtbot.waitUntil(lambda: w.cache.complete, timeout=60000)
        assert [f.index for f in w.cache.frames] == list(range(N_FRAMES))
        np.testing.assert_allclose(w.cache.frames[4].cloud.x_m, [0.5, -2.0], atol=1e-6)
        qtbot.waitUntil(lambda: w.playback.frame >= 3, timeout=20000)
        qtbot.waitUntil(lambda: w.tracking_model.result is not None, timeout=60000)
        result = w.tracking_model.result
        assert result.n_frames == N_FRAMES
        # the walking reflector is tracked: a confirmed estimate near it at the end
        est = result.estimate_xy_m[-1]
        y_end = 3.0 + (N_FRAMES - 1) * PAPER_RADAR.frame_period_s
        assert np.hypot(est[0] - 0.5, est[1] - y_end) < 0.5
        # a recording without truth shows no loss, RMSE or OSPA (it once showed L = 1 m²)
        assert not engine.has_truth
        w._show_metrics(w.playback.frame, result)
        assert w.metrics_label.text().startswith("no ground truth")
        w.psi_view.set_frame(w.playback.frame)
        assert "no ground truth" in w.psi_view._metric_text
        assert w.psi_view.ospa_curve.getData()[0] is None or not len(
            w.psi_view.ospa_curve.getData()[0]
        )
    finally:
        w.playback.set_playing(False)
        w.shutdown()


def test_a_study_on_a_replay_needs_truth(tmp_path) -> None:
    from app.replay import ReplayEngine, load_recording

    log = tmp_path / "walk.dat"
    _log(log)
    engine = ReplayEngine(load_recording(log))
    with pytest.raises(InputError, match="no ground truth"):
        engine.scene_dataset([], None, tmp_path / "s.npz")
    assert not (tmp_path / "s.npz").exists()


def test_bad_recording_is_one_line(tmp_path) -> None:
    from app.replay import load_recording

    bad = tmp_path / "x.dat"
    bad.write_bytes(b"\x00" * 100)
    with pytest.raises(InputError, match="format not recognised"):
        load_recording(bad)


def test_replay_of_a_recording_that_starts_with_empty_frames(tmp_path) -> None:
    """The first frames of a recording often hold no point (the sensor starts before anyone
    walks in): the frames without a track are drawn empty and the walker is tracked after."""
    from app import engine as eng
    from app.replay import ReplayEngine
    from core.dataset import Dataset
    from core.tracking import TrackerParams

    n_empty, n_walk = 12, 30
    period = PAPER_RADAR.frame_period_s
    clouds = [PointCloud.empty() for _ in range(n_empty)]
    for k in range(n_walk):
        x, y = 0.5, 3.0 + 1.0 * k * period
        r = float(np.hypot(x, y))
        clouds.append(
            PointCloud(
                range_m=np.array([r]),
                azimuth_rad=np.array([np.arctan2(x, y)]),
                elevation_rad=np.zeros(1),
                radial_velocity_mps=np.array([y / r]),
                snr_db=np.array([20.0]),
                x_m=np.array([x]),
                y_m=np.array([y]),
                z_m=np.zeros(1),
                source=np.zeros(1, dtype=np.int32),
            )  # fmt: skip
        )
    f = n_empty + n_walk
    nan = np.full((f, 0, 2), np.nan)
    ds = Dataset.from_frames(
        clouds=clouds, trajectory=np.zeros(f, np.int64), truth_t_s=np.arange(f) * period,
        truth_xy_m=nan, truth_v_mps=nan, trajectory_class=["real"], scene_json="{}",
        radar_json=json.dumps(PAPER_RADAR.to_dict()),
    )  # fmt: skip
    frames = list(ReplayEngine(ds).simulate(None))
    for engine in ("numpy", "numba"):
        res = eng.track(frames, TrackerParams.default("cv"), period, engine=engine)
        assert len(res.frames) == f
        assert all(len(t.track_id) == 0 and t.xy_m.shape == (0, 2) for t in res.frames[:n_empty])
        assert all(t.velocity_xy_mps.shape == (0, 2) for t in res.frames[:n_empty])
        # the walker is confirmed and followed once points arrive
        last = res.frames[-1]
        y_end = 3.0 + (n_walk - 1) * period
        assert last.confirmed.any()
        xy = last.xy_m[last.confirmed][0]
        assert np.hypot(xy[0] - 0.5, xy[1] - y_end) < 0.5
