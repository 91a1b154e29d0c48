"""The radar views draw what the data says: the range-azimuth peak at the person's range bin
and angle index, the range profile and its CFAR threshold from the frame, the micro-Doppler
columns of the selected person, the track table rows equal the tracker's tracks of the frame
shown; exports read back equal the data; workspaces round-trip and a bad one names its field."""

from __future__ import annotations

import json

import numpy as np
import pytest

from app import export
from app.views.track_table import track_rows
from core.processing import azimuth_sines


@pytest.fixture
def tracked(window, qtbot, long_scene_frames, long_scene_doc, fill_cache):
    scene, frames = long_scene_frames
    fill_cache(window, long_scene_doc, frames)
    qtbot.waitUntil(lambda: window.tracker.n_runs >= 1, timeout=60000)
    qtbot.waitUntil(lambda: window.tracker.idle, timeout=60000)
    return window, scene, frames


def _strong_person_frame(frames) -> int:
    """A frame whose strongest detection is a person point (well inside the AOI)."""
    for f in frames[20:]:
        c = f.cloud
        if len(c) and c.source[np.argmax(c.snr_db)] == 0 and c.snr_db.max() > 25:
            return f.index
    raise AssertionError("no frame with a strong person detection")


def test_range_azimuth_peak_at_the_persons_range_bin_and_angle(tracked) -> None:
    window, scene, frames = tracked
    k = _strong_person_frame(frames)
    window.playback.set_frame(k)
    v = window.views_control
    v.draw_all(k, frames[k], window.tracking_model.result)
    img = v.ra_view.image.image.T  # drawn [angle, range]
    f = frames[k]
    assert np.array_equal(img, f.ra_map_db)
    radar = scene.radar
    x, y = f.truth_xy_m[0]
    # range bin round(R / dR), angle index N/2 + N sin(az) / 2 (u = 2 (i - N/2) / N)
    r_bin = round(np.hypot(x, y) / radar.range_resolution_m)
    n = img.shape[1]
    a_idx = n // 2 + np.sin(np.arctan2(x, y)) * n / 2
    limit = int((scene.aoi.max_range_m + 0.5) / radar.range_resolution_m)
    r, i = np.unravel_index(np.argmax(img[:limit]), img[:limit].shape)
    assert abs(r - r_bin) <= 2
    assert abs(i - a_idx) <= 1.5
    assert azimuth_sines(n)[i] == pytest.approx(np.sin(np.arctan2(x, y)), abs=2.5 * 2 / n)


def test_range_profile_draws_the_column_and_its_threshold(tracked) -> None:
    window, scene, frames = tracked
    k = _strong_person_frame(frames)
    f = frames[k]
    pv = window.views_control.profile_view
    pv.show_frame(f)
    j = pv.column
    det = f.detections
    strongest = det[np.argmax(f.rd_map_db[det[:, 0], det[:, 1]])]
    assert j == strongest[1]  # auto: the column of the strongest detection
    _, y = pv.profile.getData()
    assert np.array_equal(y, f.rd_map_db[:, j])
    _, th = pv.threshold.getData()
    np.testing.assert_array_equal(th, f.cfar_threshold_db[:, j])
    dr, dp = pv.detections.getData()
    rows = np.round(dr / scene.radar.range_resolution_m).astype(int)
    assert strongest[0] in rows
    # every detection drawn lies above the threshold drawn (the detector's own definition)
    assert np.all(dp > f.cfar_threshold_db[rows, j])
    # a fixed Doppler bin
    pv.bin_spin.setValue(3)
    assert pv.column == 3 + scene.radar.n_loops // 2


def test_micro_doppler_columns_are_the_selected_persons(tracked) -> None:
    window, scene, frames = tracked
    sv = window.views_control.spectrogram_view
    sv.show_frame(120, frames)
    img = sv.image.image
    assert img.shape == (scene.radar.n_loops, len(frames))
    col = np.array([f.person_doppler_db[0] for f in frames]).T
    np.testing.assert_array_equal(img, col)
    assert sv.cursor.value() == pytest.approx(120 * scene.radar.frame_period_s)
    # the person's own Doppler (truth radial velocity) is the loudest bin at its range
    f = frames[_strong_person_frame(frames)]
    c = f.cloud
    p = np.argmax(np.where(c.source == 0, c.snr_db, -np.inf))
    j = int(np.argmax(f.person_doppler_db[0]))
    v = (j - scene.radar.n_loops // 2) * scene.radar.velocity_resolution_mps
    assert v == pytest.approx(
        c.radial_velocity_mps[p], abs=1.01 * scene.radar.velocity_resolution_mps
    )


def test_track_table_rows_equal_the_trackers_tracks(tracked) -> None:
    window, scene, frames = tracked
    result = window.tracking_model.result
    # a frame in which a confirmed track took a measurement into its update
    k = next(
        i
        for i in range(100, 250)
        if np.any(result.frames[i].confirmed & (result.frames[i].n_associated > 0))
    )
    window.playback.set_frame(k)
    window.views_control.draw_all(k, frames[k], result)
    table = window.views_control.track_table
    # the tracker's own FrameTracks at frame k, run again through core
    from core.tracking import run_tracker

    z = np.concatenate([f.cloud.measurements() for f in frames])
    off = np.concatenate(([0], np.cumsum([len(f.cloud) for f in frames])))
    res = run_tracker((z, off), window.params_model.params(), scene.radar.frame_period_s,
                      keep_tracks=True, engine="numba")  # fmt: skip
    ft = res.frames[k]
    assert table.rowCount() == len(ft)
    ids = [int(table.item(r, 0).text()) for r in range(table.rowCount())]
    assert ids == [int(i) for i in ft.ids]
    for r in range(table.rowCount()):
        assert table.item(r, 2).text() == f"{ft.psi[r]:.3f}"
        assert table.item(r, 3).text() == f"{ft.state[r, 0]:.2f}"
        assert table.item(r, 6).text() == f"{ft.state[r, 3]:.2f}"
        age = (k - ft.birth_frame[r]) * scene.radar.frame_period_s
        assert table.item(r, 8).text() == f"{age:.2f}"
        assert table.item(r, 1).text() == ("confirmed" if ft.confirmed[r] else "tentative")
        # gated measurements and NIS ε = ν̃ᵀ S⁻¹ ν̃ of this frame's update, as recorded
        assert table.item(r, 9).text() == str(int(ft.n_associated[r]))
        nis = f"{ft.nis[r]:.2f}" if np.isfinite(ft.nis[r]) else "–"
        assert table.item(r, 10).text() == nis
    shown = [r for r in range(table.rowCount()) if ft.confirmed[r] and ft.n_associated[r] > 0]
    assert shown and all(table.item(r, 10).text() != "–" for r in shown)
    assert track_rows(result.frames[k], k, scene.radar.frame_period_s)[0][0] == str(ids[0])


def test_export_round_trip(tracked, tmp_path) -> None:
    window, scene, frames = tracked
    written = window.record.export_run(tmp_path)
    names = sorted(p.name for p in written)
    assert names == sorted(
        f"radartune-{n}"
        for n in ("points.csv", "dataset.npz", "tracks.csv", "metrics.csv", "tracks.npz")
    )
    cols, pts = export.read_csv(tmp_path / "radartune-points.csv")
    assert tuple(cols) == export.POINT_COLUMNS
    assert len(pts) == sum(len(f.cloud) for f in frames)
    np.testing.assert_array_equal(pts, export.point_table(frames))
    x = np.concatenate([f.cloud.x_m for f in frames])
    np.testing.assert_array_equal(pts[:, cols.index("x_m")], x)
    result = window.tracking_model.result
    cols, tr = export.read_csv(tmp_path / "radartune-tracks.csv")
    assert len(tr) == sum(len(tf) for tf in result.frames)
    np.testing.assert_array_equal(tr, export.track_table(result, scene.radar.frame_period_s))
    ids = np.concatenate([tf.track_id for tf in result.frames])
    np.testing.assert_array_equal(tr[:, cols.index("track_id")], ids)
    cols, me = export.read_csv(tmp_path / "radartune-metrics.csv")
    np.testing.assert_array_equal(me[:, cols.index("ospa_m")], result.ospa_m)
    # the data set holds the same points
    from core.dataset import Dataset

    ds = Dataset.load(tmp_path / "radartune-dataset.npz")
    np.testing.assert_array_equal(ds.x_m, x)
    with np.load(tmp_path / "radartune-tracks.npz", allow_pickle=False) as z:
        np.testing.assert_array_equal(z["track_track_id"], ids)


def test_export_plots_and_screenshot(tracked, tmp_path) -> None:
    window, _scene, _frames = tracked
    window.playback.set_frame(100)
    out = window.record.export_plots(tmp_path / "plots")
    assert {p.name for p in out} >= {"range-azimuth.png", "micro-doppler.png", "top-view.png"}
    from PySide6 import QtGui

    from app.record import EXPORT_WIDTH_PX

    for p in out:
        img = QtGui.QImage(str(p))
        assert not img.isNull() and img.width() >= 50
        if p.name in ("range-azimuth.png", "micro-doppler.png", "top-view.png"):  # plots
            assert img.width() >= EXPORT_WIDTH_PX >= 1200, (p.name, img.width())
    shot = window.record.screenshot(tmp_path / "window.png")
    assert shot is not None and QtGui.QImage(str(shot)).width() > 500


def test_workspace_round_trip(tracked, tmp_path) -> None:
    window, scene, _frames = tracked
    path = tmp_path / "ws.json"
    window.params_model.set_value("q_coeff", window.params_model.values["q_coeff"] * 0.5)
    window.study_model.set_form(n_trials=17, storage="studies.db")
    saved_values = window.params_model.values
    doc_before = window.scene_model.document
    assert window.record.save_workspace(path)
    stored = json.loads(path.read_text())
    assert stored["study"]["storage"].startswith("/")  # absolute, never the install folder
    # change everything, then reopen
    window.params_model.reset()
    window.study_model.set_form(n_trials=3)
    doc = window.scene_model.document
    doc["seed"] = 99
    window.scene_model.set_document(doc)
    assert window.record.open_workspace(path)
    assert window.params_model.values == saved_values
    assert window.study_model.form.n_trials == 17
    assert window.scene_model.document["seed"] == doc_before["seed"]
    assert window.scene_model.scene.radar == scene.radar


@pytest.mark.parametrize(
    ("edit", "field"),
    [
        (lambda d: d.pop("tracker"), "'tracker' is missing"),
        (lambda d: d["tracker"]["values"].update(q_coeff="x"), "tracker.values.q_coeff"),
        (lambda d: d["tracker"]["values"].update(bogus=1.0), "tracker.values.bogus"),
        (lambda d: d["study"].update(n_jobs=0), "study."),
        (lambda d: d["radar"].update(n_loops=-3), "'radar'"),
        (lambda d: d["scene"]["persons"][0]["trajectory"].update({"class": "z"}), "'scene'"),
        (lambda d: d.update(schema="other"), "'schema'"),
    ],
)
def test_bad_workspace_is_refused_naming_the_field(tracked, tmp_path, edit, field) -> None:
    window, _scene, _frames = tracked
    path = tmp_path / "ws.json"
    assert window.record.save_workspace(path)
    d = json.loads(path.read_text())
    edit(d)
    path.write_text(json.dumps(d))
    values, form, doc = (
        window.params_model.values, window.study_model.form, window.scene_model.document
    )  # fmt: skip
    window.errors.clear()
    assert not window.record.open_workspace(path)
    assert len(window.errors) == 1
    assert str(path) in window.errors[0] and field in window.errors[0]
    assert "\n" not in window.errors[0]
    # nothing changed
    assert window.params_model.values == values
    assert window.study_model.form == form
    assert window.scene_model.document == doc


def test_not_json_workspace(window, tmp_path) -> None:
    path = tmp_path / "ws.json"
    path.write_text("{not json")
    assert not window.record.open_workspace(path)
    assert str(path) in window.errors[-1]
