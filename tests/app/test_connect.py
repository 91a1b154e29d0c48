"""File → Connect sensor: the dialog, and a live link over the sensor emulator drawn through the
window's cache and playback (frames tracked and followed, Stop sends sensorStop, errors in the
message box, the GUI never waits on a port)."""

from __future__ import annotations

import numpy as np
import pytest

from core.live import LinkSettings
from core.live.emulator import Faults, SensorEmulator
from tests.live_capture import person_xy, write_capture


@pytest.fixture
def capture(tmp_path):
    return write_capture(tmp_path)


def test_dialog_lists_ports_and_builds_settings(qtbot, monkeypatch, tmp_path) -> None:
    import app.connect_dialog as cd

    monkeypatch.setattr(
        cd,
        "list_ports",
        lambda: [
            ("/dev/ttyACM0", "XDS110 Class Application/User UART"),
            ("/dev/ttyACM1", "XDS110 Class Auxiliary Data Port"),
        ],
    )
    d = cd.ConnectDialog(cfg=str(tmp_path / "a.cfg"))
    qtbot.addWidget(d)
    assert [d.cli_combo.itemText(i) for i in range(d.cli_combo.count())] == [
        "/dev/ttyACM0",
        "/dev/ttyACM1",
    ]
    assert d.cli_combo.currentText() == "/dev/ttyACM0"
    assert d.data_combo.currentText() == "/dev/ttyACM1"
    s = d.settings()
    assert (s.cli_port, s.data_port, s.cli_baud, s.data_baud) == (
        "/dev/ttyACM0",
        "/dev/ttyACM1",
        115_200,
        None,
    )
    d.data_baud.setCurrentText("fast")
    d._on_accept()
    assert d.result() == 0 and "data baud must be a whole number" in d.error_label.text()
    d.data_baud.setCurrentText("921600")
    assert d.settings().data_baud == 921_600


def test_live_frames_are_tracked_drawn_and_stopped(window, qtbot, capture, tmp_path) -> None:
    data, cfg = capture
    rec = tmp_path / "rec.dat"
    with SensorEmulator(data, faults=Faults(frame_period_s=0.02)) as em:
        settings = LinkSettings(cli_port=em.cli_port, data_port=em.data_port, cfg=str(cfg))
        draws0 = window.n_draws
        window.live.start(settings, str(rec))
        assert window.live.running and not window.live.act_connect.isEnabled()
        qtbot.waitUntil(lambda: window.live.n_frames >= 40, timeout=30000)
        # the GUI kept drawing while the link ran in its worker
        assert window.n_draws > draws0
        # while live, the overlay is the link's own tracks (no truth: no loss, RMSE, OSPA)
        live = window.tracking_model.result
        assert live.params_key == "live" and live.n_frames >= 40
        assert np.isnan(live.running_loss).all() and np.isnan(live.ospa_m).all()
        # a sensor's face: no truth (paths, marks, metrics), the track counts, no cube views
        window.redraw()
        assert not window.psi_view.has_truth and not window.top_view.has_truth
        assert "no ground truth" in window.metrics_label.text()
        rows = [label.text for _s, label in window.top_view.getPlotItem().legend.items]
        assert not {"truth", "truth path", "estimate"} & set(rows)
        assert window.psi_view.metric_plot.titleLabel.text.startswith("tracks a frame")
        assert "received" in window.fps_label.text()
        assert "truth" not in window.top_view.count_label.text()
        # nothing pops the arrival times here (only the latency benchmark does): they are
        # bounded all the same, the oldest let go and counted
        arrivals = window.live.received_s
        assert len(arrivals) == min(window.live.n_frames, arrivals.capacity)
        assert len(arrivals) + arrivals.n_evicted == window.live.n_frames
        window.live.stop()
        qtbot.waitUntil(window.live.act_connect.isEnabled, timeout=10000)
        assert em.commands[-1] == "sensorStop" and em.stopped.is_set()
        sent = bytes(em.sent)
    # after Stop the session is re-tracked with the panel's parameters (the same as the link's
    # here): the same tracks, from the compiled kernel
    qtbot.waitUntil(
        lambda: (
            window.tracking_model.result.params_key != "live"
            and window.tracking_model.result.n_frames == len(window.cache)
        ),
        timeout=30000,
    )
    retracked = window.tracking_model.result
    for a, b in zip(live.frames, retracked.frames):
        np.testing.assert_array_equal(a.track_id, b.track_id)
        np.testing.assert_allclose(a.xy_m, b.xy_m, rtol=0, atol=1e-6)
    frames = window.cache.frames
    assert len(frames) >= 40 and all(len(f.cloud) == 3 for f in frames)
    assert [f.index for f in frames] == list(range(len(frames)))
    # the view follows the newest tracked frame
    result = window.tracking_model.result
    assert window.playback.frame >= result.n_frames - 2
    # the person is tracked: a confirmed track within 0.3 m of the truth on the last frame
    tf = result.frames[-1]
    t = (result.n_frames - 1) * 0.05  # the cfg's frame period
    d = np.hypot(*(tf.xy_m[tf.confirmed] - person_xy(t)).T)
    assert d.size and d.min() < 0.3
    got = rec.read_bytes()
    assert sent.startswith(got) and len(got) >= len(frames) * len(data) // 60
    assert "sensor stopped after" in window.live.last_summary
    assert window.live.act_connect.isEnabled()
    assert window.errors == []
    # the scene adopted again: its truth and metrics are back
    window.scene_control.load_paper_scene()
    qtbot.waitUntil(lambda: window.psi_view.has_truth, timeout=30000)
    assert window.top_view.has_truth


@pytest.mark.parametrize(
    ("faults", "expected"),
    [
        (Faults(error_on="frameCfg"), "the sensor rejected 'frameCfg 0 2 32 0 50 1 0': Error -1"),
        (Faults(frame_period_s=0.01, vanish_after=8), "the data port vanished after"),
    ],
    ids=["error-answer", "port-closed"],
)
def test_link_errors_are_one_line_in_a_message_box(
    window, qtbot, capture, tmp_path, faults, expected
) -> None:
    data, cfg = capture
    with SensorEmulator(data, faults=faults) as em:
        settings = LinkSettings(cli_port=em.cli_port, data_port=em.data_port, cfg=str(cfg))
        window.live.start(settings, str(tmp_path / "rec.dat"))
        qtbot.waitUntil(window.live.act_connect.isEnabled, timeout=20000)
    assert len(window.errors) == 1 and expected in window.errors[0]
    assert window.errors[0].startswith("live sensor: ")
    assert window._error_box is not None and window._error_box.isVisible()
    assert window.live.act_connect.isEnabled()


def test_connect_again_after_stop(window, qtbot, capture) -> None:
    data, cfg = capture
    with SensorEmulator(data, faults=Faults(frame_period_s=0.01)) as em:
        settings = LinkSettings(cli_port=em.cli_port, data_port=em.data_port, cfg=str(cfg))
        for session in range(2):
            window.live.start(settings)
            qtbot.waitUntil(lambda: window.live.n_frames >= 5, timeout=20000)
            window.live.stop()
            qtbot.waitUntil(window.live.act_connect.isEnabled, timeout=10000)
            assert em.commands.count("sensorStart") == session + 1
            assert em.commands[-1] == "sensorStop"
    # the second session's frames replaced the first's, from its own frame 0
    assert window.cache.frames[0].index == 0 and len(window.cache) >= 5
    assert window.errors == []


@pytest.mark.xcb
def test_connect_dialog_under_xcb_fits_the_screen(qtbot, monkeypatch, tmp_path) -> None:
    """The dialog in the real window system: shown whole on the screen, every field visible."""
    from PySide6 import QtWidgets

    if QtWidgets.QApplication.platformName() != "xcb":
        pytest.skip("needs the real xcb platform (make test-xcb runs it under Xvfb)")
    import app.connect_dialog as cd

    monkeypatch.setattr(cd, "list_ports", lambda: [("/dev/ttyACM0", "XDS110 UART")])
    d = cd.ConnectDialog(cfg=str(tmp_path / "a.cfg"))
    qtbot.addWidget(d)
    d.show()
    qtbot.waitExposed(d)
    screen = d.screen().availableGeometry()
    assert screen.contains(d.frameGeometry()), (d.frameGeometry(), screen)
    for w in (d.cli_combo, d.data_combo, d.data_baud, d.error_label.parentWidget()):
        assert w.isVisible() and w.width() > 0 and w.height() > 0
    d.reject()


def test_live_link_tracks_with_gtrack_when_chosen(window, qtbot, capture) -> None:
    """gtrack chosen in the tracker panel: the link tracks each frame with gtrack, and the
    re-track after Stop (the app's batch gtrack) gives the same tracks."""
    data, cfg = capture
    w = window
    w.params_model.set_tracker("gtrack")
    # the capture's walker is two points a frame: allocation thresholds that small a cluster
    # passes (below the sliders' range, set as a parameter file could)
    w.params_model.set_values({"points_thre": 1, "snr_thre": 1.0, "max_distance_thre_m2": 2.0})
    with SensorEmulator(data, faults=Faults(frame_period_s=0.02)) as em:
        settings = LinkSettings(cli_port=em.cli_port, data_port=em.data_port, cfg=str(cfg))
        w.live.start(settings)
        assert w.live.running, w.errors
        qtbot.waitUntil(lambda: w.live.n_frames >= 40, timeout=30000)
        w.live.stop()
        qtbot.waitUntil(w.live.act_connect.isEnabled, timeout=10000)
    live = w.live._tracks.result(w.live.frame_period_s)
    assert live.n_frames >= 40
    assert sum(int(f.confirmed.sum()) for f in live.frames[20:]) > 0  # the walker is tracked
    qtbot.waitUntil(
        lambda: (
            w.tracking_model.result.params_key != "live"
            and w.tracking_model.result.n_frames == len(w.cache)
        ),
        timeout=60000,
    )
    retracked = w.tracking_model.result
    for a, b in zip(live.frames, retracked.frames):
        np.testing.assert_array_equal(a.track_id, b.track_id)
        np.testing.assert_allclose(a.xy_m, b.xy_m, rtol=0, atol=1e-6)
        np.testing.assert_allclose(a.velocity_xy_mps, b.velocity_xy_mps, rtol=0, atol=1e-6)
    assert w.errors == []
