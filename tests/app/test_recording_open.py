"""Recordings in the window: File → Open recording (read in a worker thread), drag and drop,
recent files, bad files as one line, the replay's face (facts instead of the scene editor,
views without a radar cube saying why, TI's tracks as a layer, the people count) and back."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest
from PySide6 import QtCore, QtGui, QtWidgets

from core.config import PAPER_RADAR
from core.formats import ti_uart
from core.pointcloud import PointCloud

N_FRAMES = 30
PERIOD = PAPER_RADAR.frame_period_s


def _cloud(k: int, snr: float = 20.0) -> PointCloud:
    """One reflector walking away at 1 m/s (radial velocity ≈ +1 m/s) and one still point."""
    y = 3.0 + 1.0 * k * PERIOD
    x = np.array([0.5, -2.0])
    yy = np.array([y, 6.0])
    r = np.hypot(x, yy)
    return PointCloud(
        range_m=r, azimuth_rad=np.arctan2(x, yy), elevation_rad=np.zeros(2),
        radial_velocity_mps=np.array([yy[0] / r[0], 0.0]), snr_db=np.array([snr, snr - 11]),
        x_m=x, y_m=yy, z_m=np.array([1.0, 0.2]), source=np.zeros(2, dtype=np.int32),
    )  # fmt: skip


def _log(path: Path) -> Path:
    with open(path, "wb") as fh:
        for k in range(N_FRAMES):
            fh.write(ti_uart.encode_frame(_cloud(k), 1 + k))
    return path


def _dataset_with_reference(path: Path) -> Path:
    """A data set without SNR (0 dB everywhere), with TI's track 7 on the walker and a head
    count of 1, saved as ``path``."""
    from core.dataset import Dataset

    clouds = [dataclasses.replace(_cloud(k), snr_db=np.zeros(2)) for k in range(N_FRAMES)]
    f = N_FRAMES
    nan = np.full((f, 0, 2), np.nan)
    ds = Dataset.from_frames(
        clouds=clouds, trajectory=np.zeros(f, np.int64), truth_t_s=np.arange(f) * PERIOD,
        truth_xy_m=nan, truth_v_mps=nan, trajectory_class=["real"],
        scene_json=json.dumps({"imported": {"format": "people-csv", "device": "IWR6843",
                                            "notes": ["a note"]}}),
        radar_json=json.dumps(PAPER_RADAR.to_dict()),
    )  # fmt: skip
    ds = dataclasses.replace(
        ds,
        ref_frame=np.arange(f, dtype=np.int64),
        ref_track_id=np.full(f, 7, dtype=np.int64),
        ref_x_m=np.full(f, 0.45),
        ref_y_m=3.0 + np.arange(f) * PERIOD + 0.05,
        ref_z_m=np.zeros(f),
        ref_vx_mps=np.zeros(f),
        ref_vy_mps=np.ones(f),
        ref_point_track=np.tile([7, -1], f).astype(np.int64),
        people_count=np.ones(f, dtype=np.int64),
    )
    return ds.save(path)


def _open(qtbot, w, path) -> None:
    with qtbot.waitSignal(w.recording.opened, timeout=60000):
        w.recording.load(path)
    qtbot.waitUntil(lambda: w.cache.complete and len(w.cache) == N_FRAMES, timeout=60000)


def test_open_recording_replays_it_with_its_facts(qtbot, window, tmp_path) -> None:
    from app.views.unavailable import unavailable_reason

    w = window
    w.scene_control.load_paper_scene()
    log = _log(tmp_path / "walk.dat")
    _open(qtbot, w, log)
    assert w.recording.replaying and not w.engine.has_truth
    np.testing.assert_allclose(w.cache.frames[4].cloud.x_m, [0.5, -2.0], atol=1e-6)
    assert "walk.dat" in w.windowTitle()
    assert w.recording.dock.isVisibleTo(w) and not w.docks["Scene"].isVisibleTo(w)
    facts = dict(w.recording.facts.rows())
    assert facts["frames"] == str(N_FRAMES)
    assert facts["format"] == "uart"
    assert facts["SNR"] == "yes" and facts["TI's tracks"] == "no"
    assert facts["points a frame"].startswith("2.0")
    assert w.recording.panel.values["frames"].text() == str(N_FRAMES)
    # views a recording of points cannot feed say why
    assert "range-Doppler" in unavailable_reason(w.rd_view)
    assert "micro-Doppler" in unavailable_reason(w.views_control.spectrogram_view)
    assert unavailable_reason(w.views_control.elevation_view) is None
    assert Path(w.recording.recent()[0]) == log.resolve()
    # the people count: RadarTune's confirmed tracks of the frame shown
    qtbot.waitUntil(lambda: w.tracking_model.result is not None, timeout=60000)
    w.playback.set_frame(N_FRAMES - 1)
    w.redraw()
    result = w.tracking_model.result
    n_conf = int(result.frames[N_FRAMES - 1].confirmed.sum())
    assert n_conf >= 1
    assert f">{n_conf}</span>" in w.top_view.count_label.text()
    stats = w.recording.frame_stats(N_FRAMES - 1, w.cache.frames[-1], result)
    assert (stats.n_points, stats.n_confirmed, stats.ti_count) == (2, n_conf, -1)
    # back to the simulation: the class's own simulate, the scene editor, the maps
    w.recording.close_recording()
    assert not w.recording.replaying and w.engine.has_truth
    assert "simulate" not in w.engine.__dict__
    assert w.docks["Scene"].isVisibleTo(w) and not w.recording.dock.isVisibleTo(w)
    assert unavailable_reason(w.rd_view) is None
    assert "RadarTune" in w.windowTitle() and "walk.dat" not in w.windowTitle()


def test_bad_recording_is_one_line_and_nothing_is_lost(qtbot, window, tmp_path) -> None:
    w = window
    w.scene_control.load_paper_scene()
    bad = tmp_path / "x.dat"
    bad.write_bytes(b"\x00" * 100)
    with qtbot.waitSignal(w.recording.failed, timeout=60000):
        w.recording.load(bad)
    assert not w.recording.replaying
    assert len(w.errors) == 1 and str(bad) in w.errors[0] and "\n" not in w.errors[0]
    assert "format not recognised" in w.errors[0]
    assert w.recording.recent() == []
    assert w._error_box is not None and w._error_box.text() == w.errors[0]


def test_recent_files_keep_eight_and_drop_missing_ones(qtbot, window, tmp_path) -> None:
    from app.recording_control import MAX_RECENT

    rc = window.recording
    paths = [str((tmp_path / f"r{k}.dat").resolve()) for k in range(MAX_RECENT + 3)]
    for p in paths:
        rc._remember(p)
    assert rc.recent() == paths[::-1][:MAX_RECENT]
    assert len(rc.recent_menu.actions()) == MAX_RECENT
    rc._remember(paths[5])  # opened again: first, not twice
    assert rc.recent()[0] == paths[5] and rc.recent().count(paths[5]) == 1
    rc.open_recent(paths[5])  # it does not exist: removed, with a message
    assert paths[5] not in rc.recent()
    assert "no longer exists" in window.errors[-1]
    # a settings value that is not a JSON list is no list at all
    window.settings.setValue("recording/recent", "{oops")
    assert rc.recent() == []


def test_drop_a_file_on_the_window_opens_it(qtbot, window, tmp_path) -> None:
    w = window
    w.scene_control.load_paper_scene()
    log = _log(tmp_path / "dropped.dat")
    mime = QtCore.QMimeData()
    mime.setUrls([QtCore.QUrl.fromLocalFile(str(log))])
    pos = QtCore.QPointF(50, 50)
    enter = QtGui.QDragEnterEvent(
        pos.toPoint(), QtCore.Qt.CopyAction, mime, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier
    )
    QtWidgets.QApplication.sendEvent(w, enter)
    assert enter.isAccepted()
    drop = QtGui.QDropEvent(
        pos, QtCore.Qt.CopyAction, mime, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier
    )
    with qtbot.waitSignal(w.recording.opened, timeout=60000):
        QtWidgets.QApplication.sendEvent(w, drop)
    assert w.recording.path == str(log)


def test_reference_layer_colour_by_and_head_count(qtbot, window, tmp_path) -> None:
    """TI's tracks drawn as their own layer (toggle, legend); a recording without SNR is
    coloured by Doppler; the count shows TI's count and the head count beside RadarTune's."""
    import pyqtgraph as pg

    from app.views.top_view import COLOUR_MODES, N_SNR_COLOURS

    w = window
    w.scene_control.load_paper_scene()
    path = _dataset_with_reference(tmp_path / "ref.npz")
    _open(qtbot, w, path)
    facts = dict(w.recording.facts.rows())
    assert facts["SNR"] == "no" and facts["TI's tracks"] == "1 ids"
    assert facts["head count"] == "1" and facts["device"] == "IWR6843"
    assert w.top_view.colour_by == "doppler" and w.colour_combo.currentData() == "doppler"
    assert w.top_view.colour_bar.isVisible()
    k = 10
    w.playback.set_frame(k)
    w.redraw()
    x, y = w.top_view.reference.getData()
    np.testing.assert_allclose([x[0], y[0]], [0.45, 3.0 + k * PERIOD + 0.05])
    assert w.top_view.reference_trails.getData()[0] is not None
    legend = {label.text: label.isVisible() for _s, label in w.top_view.getPlotItem().legend.items}
    assert legend["TI's tracks"] and not legend.get("nothing", False)
    text = w.top_view.count_label.text()
    assert "TI 1" in text and "head count 1" in text
    # Doppler colours: the walker (+1 m/s) and the still point (0 m/s) from the colour map
    lo, hi = COLOUR_MODES["doppler"][3]
    cmap = pg.colormap.get(COLOUR_MODES["doppler"][1])
    lut = cmap.getLookupTable(0.0, 1.0, N_SNR_COLOURS, alpha=False)
    brushes = w.top_view.points.data["brush"][-2:]
    for vr, brush in zip(w.cache.frames[k].cloud.radial_velocity_mps, brushes):
        i = int(round((vr - lo) / (hi - lo) * (N_SNR_COLOURS - 1)))
        assert brush.color().getRgb()[:3] == tuple(int(c) for c in lut[i])
    # colour by TI's track: the walker's point takes track 7's identity colour, the other grey
    from app.colours import identity_colour

    w.colour_combo.setCurrentIndex(w.colour_combo.findData("track"))
    w.redraw()
    b = w.top_view.points.data["brush"][-2:]
    assert b[0].color().getRgb()[:3] == identity_colour(7)
    assert b[1].color().getRgb()[:3] == (130, 130, 130)
    assert not w.top_view.colour_bar.isVisible()  # categories: no scale
    # the toggle hides TI's tracks
    w.recording.reference_check.setChecked(False)
    w.redraw()
    assert len(w.top_view.reference.getData()[0]) == 0


def _legend_rows(plot) -> list[str]:
    return [label.text for _s, label in plot.legend.items]


def test_replay_face_without_truth(qtbot, window, tmp_path) -> None:
    """No truth, no estimate and no scene rows in the top view's legend; the lower plot of the
    ψ view counts tracks (RadarTune's confirmed ones against TI's) instead of metrics; the
    notes name the file, not where it lives; back to the scene, all as before."""
    w = window
    w.scene_control.load_paper_scene()
    qtbot.waitUntil(lambda: w.cache.complete and w.tracking_model.result is not None, timeout=60000)
    scene_rows = _legend_rows(w.top_view.getPlotItem())
    assert {"truth", "truth path", "estimate"} <= set(scene_rows)
    assert _legend_rows(w.psi_view.metric_plot) == ["RMSE", "OSPA"]
    path = _dataset_with_reference(tmp_path / "ref.npz")
    _open(qtbot, w, path)
    qtbot.waitUntil(
        lambda: (
            w.tracking_model.result is not None and w.tracking_model.result.n_frames == N_FRAMES
        ),
        timeout=30000,
    )
    w.playback.set_frame(N_FRAMES - 1)
    w.redraw()
    rows = _legend_rows(w.top_view.getPlotItem())
    assert not {"truth", "truth path", "estimate", "static reflector"} & set(rows)
    assert {"points", "tracks", "TI's tracks", "radar"} <= set(rows)
    assert len(w.top_view.estimate.data) == 0
    psi = w.psi_view
    assert _legend_rows(psi.metric_plot) == ["confirmed tracks", "TI's tracks"]
    assert psi.rmse_curve.getData()[0] is None or len(psi.rmse_curve.getData()[0]) == 0
    result = w.tracking_model.result
    confirmed = [int(f.confirmed.sum()) for f in result.frames]
    np.testing.assert_array_equal(psi.count_curve.getData()[1], confirmed)
    np.testing.assert_array_equal(psi.ti_curve.getData()[1], np.ones(N_FRAMES))  # track 7
    text = psi.metric_text.text
    assert "2 points" in text and f"confirmed tracks {confirmed[-1]}" in text and "TI 1" in text
    w.recording.close_recording()
    qtbot.waitUntil(lambda: w.cache.complete and w.tracking_model.result is not None, timeout=60000)
    w.redraw()
    assert _legend_rows(w.top_view.getPlotItem()) == scene_rows
    assert _legend_rows(w.psi_view.metric_plot) == ["RMSE", "OSPA"]


def test_notes_name_the_file_not_its_folder(tmp_path) -> None:
    from app.replay import short_notes

    src = str(tmp_path / "deep" / "run.csv")
    notes = short_notes([f"{src}: 12 points", "frame period 50 ms"], (src, ""))
    assert notes == ("run.csv: 12 points", "frame period 50 ms")


def test_slow_radar_warning() -> None:
    from app.panels.recording_panel import slow_radar_warning

    assert slow_radar_warning(PAPER_RADAR.max_velocity_mps) == ""
    # v_max = λ / (4 T_c) with T_c the chirp repetition time of one TX (TDM: × n_tx)
    slow = dataclasses.replace(PAPER_RADAR, idle_time_s=400e-6)
    assert slow.max_velocity_mps < 1.5
    text = slow_radar_warning(slow.max_velocity_mps)
    assert f"{slow.max_velocity_mps:.2f} m/s" in text and "walking speed" in text


@pytest.mark.parametrize("name", ["scene.json"])
def test_window_title_names_the_scene(window, tmp_path, name) -> None:
    w = window
    w.scene_control.load_paper_scene()
    assert w.windowTitle() == "paper scene — RadarTune"
    path = tmp_path / name
    w.scene_model.save(path)
    assert w.load_scene(path)
    assert w.windowTitle() == f"{name} — RadarTune"


def test_replay_given_on_the_command_line_can_be_closed(qtbot, settings, tmp_path) -> None:
    """``radartune gui --replay FILE`` (app.main): the window opens with the recording's face
    and File → Close recording goes back to simulating the paper scene."""
    from app.engine import Engine
    from app.replay import ReplayEngine, attach_recording, load_recording
    from app.views.unavailable import unavailable_reason
    from app.window import MainWindow

    log = _log(tmp_path / "cli.dat")
    engine = Engine()
    attach_recording(engine, ReplayEngine(load_recording(log), path=str(log)))
    w = MainWindow(settings, engine)
    qtbot.addWidget(w)
    try:
        assert "cli.dat" in w.windowTitle() and w.recording.act_close.isEnabled()
        assert w.recording.dock.isVisibleTo(w) and unavailable_reason(w.rd_view)
        qtbot.waitUntil(lambda: w.cache.complete and len(w.cache) == N_FRAMES, timeout=60000)
        w.recording.close_recording()
        qtbot.waitUntil(lambda: w.cache.expected != N_FRAMES, timeout=60000)
        assert w.engine.has_truth and w.windowTitle() == "paper scene — RadarTune"
    finally:
        w.shutdown()
