"""The live overlay's tracking result (app/live.py LiveTracks, built frame by frame from the
link's own tracks) against the app's batch re-track (engine.track, readable tracker) of the same
frames: the same tracks, estimate, trails and ψ curves."""

from __future__ import annotations

import numpy as np

from app import engine
from app.data import FrameData
from app.live import ArrivalTimes, LiveTracks
from core.formats.recording import points_to_cloud
from core.formats.ti_uart import iter_uart_frames
from core.tracking import TrackerParams
from core.tracking.tracker import StreamTracker
from tests.live_capture import write_capture


def test_live_result_equals_the_batch_retrack(tmp_path) -> None:
    data, _ = write_capture(tmp_path, n_frames=80)
    params, period = TrackerParams.default("cv"), 0.05
    tracker, live, frames = StreamTracker(params, period), LiveTracks(), []
    for k, u in enumerate(iter_uart_frames([data])):
        p = u.points
        cloud, _ = points_to_cloud(p.x_m, p.y_m, p.z_m, p.velocity_mps, p.snr_db)
        frames.append(FrameData(index=k, t_s=k * period, cloud=cloud, truth_xy_m=np.zeros((0, 2))))
        live.add(k, tracker.step(cloud.measurements()))
    got = live.result(period)
    ref = engine.track(frames, params, period, engine="numpy")
    assert got.n_frames == ref.n_frames == 80
    for a, b in zip(got.frames, ref.frames):
        np.testing.assert_array_equal(a.track_id, b.track_id)
        np.testing.assert_allclose(a.xy_m, b.xy_m, rtol=0, atol=1e-12)
        np.testing.assert_array_equal(a.confirmed, b.confirmed)
    np.testing.assert_allclose(got.estimate_xy_m, ref.estimate_xy_m, rtol=0, atol=1e-12)
    for name in ("trail_id", "trail_t_index", "trail_xy_m", "psi_t_s", "psi_value"):
        np.testing.assert_allclose(getattr(got, name), getattr(ref, name), rtol=0, atol=1e-12)
    np.testing.assert_allclose(got.psi_confirmed_value, ref.psi_confirmed_value, atol=1e-12)
    # a sensor has no truth: no loss, RMSE or OSPA
    assert np.isnan(got.running_loss).all() and np.isnan(got.ospa_m).all()
    assert got.estimate_xy_m[20:].size and np.isfinite(got.estimate_xy_m[20:]).all()


def test_frames_that_never_arrived_are_empty(tmp_path) -> None:
    params, period = TrackerParams.default("cv"), 0.05
    tracker, live = StreamTracker(params, period), LiveTracks()
    z = np.array([[3.0, 0.1, 0.5]])
    live.add(0, tracker.step(z))
    live.add(3, tracker.step(z))  # frames 1 and 2 lost
    r = live.result(period)
    assert r.n_frames == 4 and len(r.frames[1]) == 0 and len(r.frames[2]) == 0
    assert list(r.trail_t_index) == [0, 3]


def test_arrival_times_keep_the_newest_frames_only() -> None:
    arrivals = ArrivalTimes(capacity=16)
    for k in range(1000):  # a long session none of whose frames is drawn
        arrivals.add(k, 0.05 * k)
    assert len(arrivals) == 16 and arrivals.n_evicted == 1000 - 16
    assert arrivals.pop(983) is None  # let go: older than the 16 newest
    assert arrivals.pop(984) == 0.05 * 984 and arrivals.pop(984) is None  # popped once
    assert arrivals.pop(999) == 0.05 * 999 and len(arrivals) == 14
    arrivals.clear()  # the next Connect
    assert len(arrivals) == 0 and arrivals.n_evicted == 0
