"""Live behaviour: simulation fills the cache while playback advances; a slider change
re-tracks and changes the overlay in time; thousands of repaints do not crash."""

from __future__ import annotations

import time

import numpy as np
import pytest

from app.panels.tracker_panel import SLIDER_STEPS

SHORT_SCENE = {
    "schema_version": 1,
    "radar": "paper",
    "seed": 5,
    "clutter_density_per_m2": 0.02,
    "aoi": {"min_range_m": 0.5, "max_range_m": 10.0, "max_azimuth_deg": 60.0},
    "static_reflectors": [{"x_m": 2.0, "y_m": 6.0, "rcs_dbsm": 10.0}],
    "persons": [{"trajectory": {"class": "b", "seed": 4}}],
}


def test_simulation_fills_cache_and_playback_advances(window, qtbot) -> None:
    window.scene_model.set_document(SHORT_SCENE)
    n_expected = window.scene_model.scene.n_frames
    window.playback.set_speed(4.0)
    window.playback.set_playing(True)
    # the worker delivers frames while the GUI keeps playing them
    qtbot.waitUntil(lambda: len(window.cache) >= 10, timeout=30000)
    qtbot.waitUntil(lambda: window.playback.frame >= 5, timeout=10000)
    assert window.cache.frames[0].rd_map_db.shape == (256, 32)
    qtbot.waitUntil(lambda: window.cache.complete, timeout=60000)
    assert len(window.cache) == n_expected
    assert [f.index for f in window.cache.frames] == list(range(n_expected))
    # frames advance in playback order and loop at the end
    seen = []
    window.playback.frame_changed.connect(seen.append)
    qtbot.waitUntil(lambda: len(seen) >= 10, timeout=10000)
    steps = np.diff(seen)
    assert np.all((steps == 1) | (np.array(seen[1:]) == 0))
    # the views drew the current frame: its points, the static reflector and the truth path
    qtbot.waitUntil(lambda: window.tracking_model.result is not None, timeout=30000)
    qtbot.wait(100)
    assert window.n_draws > 10
    assert window.top_view.reflectors.data.size == 1
    assert window.rd_view.image.image is not None
    assert "simulated" in window.fps_label.text()
    window.playback.set_playing(False)


def test_slider_retracks_and_changes_overlay_within_budget(
    window, qtbot, long_scene_frames, long_scene_doc, fill_cache
) -> None:
    scene, frames = long_scene_frames
    fill_cache(window, long_scene_doc, frames)
    qtbot.waitUntil(lambda: window.tracker.n_runs >= 1, timeout=30000)
    qtbot.waitUntil(lambda: window.tracker.idle, timeout=30000)
    window.playback.set_frame(200)
    window.redraw()
    before = window.tracking_model.result
    assert before.n_frames == 250
    conf_before = np.array([tf.confirmed.sum() for tf in before.frames])

    results = []
    window.tracking_model.changed.connect(lambda r: results.append((time.perf_counter(), r)))

    def move(name: str, pos: int) -> tuple[float, object]:
        """Slider → the full overlay (every track, ids, ψ, gates, metrics) of the new values."""
        results.clear()
        old = window.params_model.key()
        t0 = time.perf_counter()
        window.tracker_panel.rows[name].slider.setValue(pos)
        key = window.params_model.key()
        assert key != old  # the move changed the parameters
        qtbot.waitUntil(
            lambda: any(r is not None and r.params_key == key for _, r in results), timeout=30000
        )
        t, r = next((t, r) for t, r in results if r is not None and r.params_key == key)
        qtbot.waitUntil(lambda: window.tracker.idle, timeout=30000)
        return t - t0, r

    # a drastic change: P_te = 1 makes clutter tracks confirm at once
    latency, after = move("p_te", SLIDER_STEPS)
    latencies = [latency]
    assert after.n_frames == 250 and after.params_key != before.params_key
    conf_after = np.array([tf.confirmed.sum() for tf in after.frames])
    assert conf_after.sum() != conf_before.sum()
    # the first result after the move is already the whole overlay: ids, ψ, gates of every track
    tf = after.frames[200]
    assert len(tf) > 0 and np.all(tf.track_id >= 0) and np.all(np.isfinite(tf.psi))
    assert np.all(np.linalg.eigvalsh(tf.gate_shape_xy_m2) > 0)
    assert after.psi_value.size >= after.n_frames  # ψ of every track over time
    # the overlay shows the new tracks of the current frame
    window.redraw()
    assert window.top_view.last_n_tracks == len(tf)
    xs, ys = window.top_view.tracks.getData()
    np.testing.assert_allclose(xs, tf.xy_m[:, 0])
    np.testing.assert_allclose(ys, tf.xy_m[:, 1])
    moves = [("q_coeff", 300), ("r11", 600), ("q_coeff", 700), ("r22", 250)]
    moves += [("r11", 400), ("q_coeff", 500), ("r22", 650), ("r11", 800)]
    for name, pos in moves:
        latencies.append(move(name, pos)[0])
    med = float(np.median(latencies))
    print(
        f"\nslider → full overlay for 250 frames: median {med * 1e3:.0f} ms over "
        f"{len(latencies)} moves (min {min(latencies) * 1e3:.0f}, max "
        f"{max(latencies) * 1e3:.0f}; re-track {window.tracker.last_elapsed_s * 1e3:.0f} ms)"
    )
    # budget 200 ms incl. the 30 ms debounce; a generous bound for the loaded test machine that
    # the former two-stage re-track (every track after 0.9–4 s) does not meet
    assert med < 0.5
    # several fast slider moves: only the last parameter vector ends up drawn
    for pos in (100, 300, 500, 700):
        window.tracker_panel.rows["q_coeff"].slider.setValue(pos)
    qtbot.waitUntil(lambda: window.tracker.idle, timeout=30000)
    qtbot.waitUntil(
        lambda: window.tracking_model.result.params_key == window.params_model.key(),
        timeout=30000,
    )


def test_three_thousand_repaints(window, qtbot, long_scene_frames, long_scene_doc, fill_cache):
    """3 000 data updates + synchronous paints of the live views (PySide6 6.12 crashed
    pyqtgraph after a few thousand repaints)."""
    scene, frames = long_scene_frames
    fill_cache(window, long_scene_doc, frames)
    qtbot.waitUntil(lambda: window.tracker.n_runs >= 1, timeout=30000)
    window.resize(800, 500)
    window.show()
    qtbot.waitExposed(window)
    result = window.tracking_model.result
    tv, rd, psi = window.top_view, window.rd_view, window.psi_view
    t0 = time.perf_counter()
    for i in range(3000):
        k = i % 250
        view = i % 3
        if view == 0:
            if i % 600 == 0:
                tv.colour_by = "label" if tv.colour_by == "snr" else "snr"
            tv.show_frame(k, frames, result)
            tv.viewport().repaint()
        elif view == 1:
            rd.show_frame(frames[k])
            rd.viewport().repaint()
        else:
            psi.set_frame(k)
            psi.viewport().repaint()
    elapsed = time.perf_counter() - t0
    print(f"\n3000 updates + repaints: {elapsed:.1f} s")
    assert tv.n_draws >= 1000 and rd.n_draws >= 1000 and psi.n_draws >= 1000
    # still alive and drawing: one full redraw through the window
    window.playback.set_frame(123)
    window.redraw()
    assert tv.last_n_points == sum(len(frames[j].cloud) for j in range(124 - tv.persistence, 124))


def test_overlay_labels_every_track_with_id_and_psi(
    window, qtbot, long_scene_frames, long_scene_doc, fill_cache
):
    scene, frames = long_scene_frames
    fill_cache(window, long_scene_doc, frames)
    qtbot.waitUntil(lambda: window.tracker.n_runs >= 1, timeout=30000)
    window.tracker.wait()
    result = window.tracking_model.result
    k = int(np.argmax([len(tf) for tf in result.frames]))
    tf = result.frames[k]
    assert len(tf) >= 2
    window.playback.set_frame(k)
    window.redraw()
    assert window.top_view.last_n_tracks == len(tf)
    shown = [lb.textItem.toPlainText() for lb in window.top_view._labels if lb.isVisible()]
    assert sorted(shown) == sorted(f"{i} ψ={p:.2f}" for i, p in zip(tf.track_id, tf.psi))


@pytest.mark.parametrize("colour_by", ["snr", "label"])
def test_point_colours_come_from_the_palette(
    window, long_scene_frames, long_scene_doc, fill_cache, colour_by
) -> None:
    scene, frames = long_scene_frames
    fill_cache(window, long_scene_doc, frames)
    window.tracker.wait()
    tv = window.top_view
    tv.colour_by = colour_by
    tv.persistence = 3
    window.playback.set_frame(50)
    window.redraw()
    n = sum(len(frames[k].cloud) for k in (48, 49, 50))
    assert tv.last_n_points == n
    brushes = tv.points.data["brush"]
    palette = list(tv._snr_array) if colour_by == "snr" else list(tv._label_array)
    assert all(any(b is p for p in palette) for b in brushes)
    if colour_by == "label":
        src = np.concatenate([frames[k].cloud.source for k in (48, 49, 50)])
        person = [b is tv._label_array[0] for b in brushes]
        assert person == list(src >= 0)
