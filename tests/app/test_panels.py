"""Every panel both ways: editing a widget changes the model; changing the model updates the
widget."""

from __future__ import annotations

import math

import pytest
from PySide6 import QtCore

from app import engine
from app.panels.tracker_panel import SLIDER_STEPS
from core.config import RadarConfig

PAPER = engine.PAPER_SCENE_DOCUMENT


def test_tracker_panel_both_ways(window) -> None:
    panel, model = window.tracker_panel, window.params_model
    row = panel.rows["q_coeff"]
    # widget → model: the slider's middle is the geometric mean of [0.1, 30] (log scale)
    row.slider.setValue(SLIDER_STEPS // 2)
    assert model.values["q_coeff"] == pytest.approx(math.sqrt(3.0), rel=1e-6)
    assert row.spin.value() == pytest.approx(math.sqrt(3.0), abs=1e-4)
    row.spin.setValue(2.5)
    assert model.values["q_coeff"] == pytest.approx(2.5)
    # model → widget
    model.set_value("p_d", 0.95)
    p_d = panel.rows["p_d"]
    assert p_d.spin.value() == pytest.approx(0.95)
    assert p_d.slider.value() == round((0.95 - 0.8) / (0.99 - 0.8) * SLIDER_STEPS)
    # CV → CA adds the acceleration rows; the shared values are kept
    assert "p0_44" not in panel.rows
    panel.model_combo.setCurrentIndex(1)
    assert model.model == "ca" and {"p0_44", "p0_55"} <= set(panel.rows)
    assert model.values["q_coeff"] == pytest.approx(2.5)
    model.set_model("cv")
    assert panel.model_combo.currentData() == "cv" and "p0_44" not in panel.rows
    # fixed settings both ways
    panel.confirm.setValue(0.8)
    assert model.params().confirm_threshold == pytest.approx(0.8)
    panel.rho_np.setChecked(True)
    assert model.params().clutter_density == "nonparametric"
    model.set_extra(clutter_density=0.01)
    assert not panel.rho_np.isChecked() and panel.rho.value() == pytest.approx(0.01)
    # labels with units, from the search-space table
    # each slider shows its bounds and unit (from core/tracking/space.py), the spin box the unit
    assert "r11 range σ<br>" in panel.rows["r11"].label.text()
    assert "0.01 … 0.5 m, log" in panel.rows["r11"].label.text()
    assert "q_coeff process noise<br>" in panel.rows["q_coeff"].label.text()
    assert "0.1 … 30 m²/s⁴, log" in panel.rows["q_coeff"].label.text()
    assert panel.rows["q_coeff"].spin.suffix() == " m²/s⁴"
    assert "0.8 … 0.99 (no unit)" in panel.rows["p_d"].label.text()
    assert panel.rows["p_d"].spin.suffix() == ""
    # reset
    panel.reset_button.click()
    assert model.values == engine.default_values("cv")
    assert panel.rows["q_coeff"].spin.value() == pytest.approx(model.values["q_coeff"])


def test_radar_panel_both_ways_and_derived_values(window) -> None:
    panel, model = window.radar_panel, window.radar_model
    d = panel.derived_labels
    # SPEC §1 derived values of the paper radar
    assert d["range_resolution_m"].text() == "5.630 cm"
    assert d["max_range_m"].text() == "14.41 m"
    assert d["max_velocity_mps"].text() == "7.241 m/s"
    assert d["velocity_resolution_mps"].text() == "0.4526 m/s"
    # widget → model: doubling the loops halves the velocity bin
    panel.spins["n_loops"].setValue(64)
    assert model.radar.n_loops == 64
    assert d["velocity_resolution_mps"].text() == "0.2263 m/s"
    panel.spins["start_frequency_hz"].setValue(77.0)
    assert model.radar.start_frequency_hz == pytest.approx(77e9)
    assert d["wavelength_m"].text() == "3.8934 mm"
    # model → widget
    model.set_radar(RadarConfig(n_samples=128))
    assert panel.spins["n_samples"].value() == 128
    assert panel.spins["n_loops"].value() == 32
    assert d["max_range_m"].text() == "14.41 m"  # max range does not depend on Nadc
    assert not panel.spins["n_tx"].isEnabled()  # comes with the antenna layout
    # an invalid combination is refused with a message, the model keeps its value
    panel.spins["frame_period_s"].setValue(1.0)  # 1 ms is shorter than the chirps of a frame
    assert model.radar.frame_period_s == pytest.approx(0.08)
    assert panel.spins["frame_period_s"].value() == pytest.approx(80.0)
    assert "frame_period_s" in window.errors[-1]


def test_scene_panel_both_ways(window, qtbot) -> None:
    window.scene_model.set_document(PAPER)
    panel, model = window.scene_panel, window.scene_model
    # widget → model
    panel.clutter.setValue(0.05)
    assert model.document["clutter_density_per_m2"] == pytest.approx(0.05)
    assert model.scene.clutter_density_per_m2 == pytest.approx(0.05)
    # one start coordinate: the other is kept where the trajectory starts now
    x0, y0 = model.scene.persons[0].trajectory.position_m[0]
    panel.class_params["start_x_m"].setValue(round(float(x0), 2) + 0.1)
    start = model.document["persons"][0]["trajectory"].get("start_m")
    assert start is not None and start[1] == pytest.approx(y0, abs=0.01), window.errors
    assert panel.class_params["start_y_m"].value() == pytest.approx(y0, abs=0.01)
    assert model.scene.persons[0].trajectory.position_m[0][0] == pytest.approx(
        round(float(x0), 2) + 0.1
    )
    panel.class_combo.setCurrentIndex(4)  # e — circle
    traj = model.document["persons"][0]["trajectory"]
    assert traj["class"] == "e"
    assert model.scene.persons[0].trajectory.trajectory_class == "e"
    panel.class_params["radius_m"].setValue(1.5)
    assert model.document["persons"][0]["trajectory"]["radius_m"] == pytest.approx(1.5)
    assert not panel.class_params["stop_rate_hz"].isEnabled()  # not a parameter of class e
    seed = model.document["persons"][0]["trajectory"]["seed"]
    panel.regen_button.click()
    assert model.document["persons"][0]["trajectory"]["seed"] != seed
    # model → widget
    doc = model.document
    doc["clutter_density_per_m2"] = 0.0
    doc["aoi"]["max_range_m"] = 8.0
    model.set_document(doc)
    assert panel.clutter.value() == 0.0 and panel.max_range.value() == pytest.approx(8.0)
    # waypoints: a drawn person, its table, and clicks in the top view
    panel.add_wp_button.click()
    assert model.n_persons == 2 and model.selected_person == 1
    assert model.document["persons"][1]["model"] == "walking"  # decision scene-07
    assert panel.stack.currentIndex() == 1 and panel.waypoints.rowCount() == 2
    panel.waypoints.item(1, 2).setText("0.8")
    wp = model.document["persons"][1]["trajectory"]["waypoints"]
    assert wp[1][2] == pytest.approx(0.8)
    panel.draw_button.setChecked(True)
    assert window.top_view.draw_mode
    window.top_view.waypoint_added.emit(2.0, 5.0)
    wp = model.document["persons"][1]["trajectory"]["waypoints"]
    assert len(wp) == 3 and wp[2][:2] == [2.0, 5.0]
    assert panel.waypoints.rowCount() == 3
    # dragging a waypoint in the top view moves it in the document
    item = window.top_view._waypoint_items[0]
    item.setPos(-1.5, 4.0)
    item.sigPositionChangeFinished.emit(item)
    wp = model.document["persons"][1]["trajectory"]["waypoints"]
    assert wp[0][:2] == [-1.5, 4.0]
    # a bad table entry is refused with a message naming the cell
    panel.waypoints.item(0, 0).setText("abc")
    assert "row 1, x [m]" in window.errors[-1]
    assert model.document["persons"][1]["trajectory"]["waypoints"][0][0] == -1.5
    # reflectors
    panel.add_refl.click()
    assert model.document["static_reflectors"] == [{"x_m": 2.0, "y_m": 6.0, "rcs_dbsm": 10.0}]
    assert panel.reflectors.rowCount() == 1
    panel.remove_button.click()
    assert model.n_persons == 1


def test_study_panel_both_ways(window) -> None:
    panel, model = window.study_panel, window.study_model
    panel.trials.setValue(12)
    assert model.form.n_trials == 12
    panel.jobs.setValue(2)
    assert model.form.n_jobs == 2
    panel.storage.setText("other.db")
    panel.storage.editingFinished.emit()
    assert model.form.storage == "other.db"
    model.set_form(model="ca", n_trials=7, dataset="paper")
    assert panel.model_combo.currentData() == "ca"
    assert panel.trials.value() == 7
    assert panel.dataset.currentData() == "paper"
    assert panel.progress_bar.maximum() == 7


def test_playback_bar_both_ways(window, long_scene_frames, long_scene_doc, fill_cache) -> None:
    scene, frames = long_scene_frames
    fill_cache(window, long_scene_doc, frames)
    window.timeline.setValue(40)
    assert window.playback.frame == 40
    window.playback.set_frame(100)
    assert window.timeline.value() == 100
    assert "frame 101 / 250" in window.frame_label.text()
    assert "(of" not in window.frame_label.text()  # the total once when the cache is full
    window.act_fwd.trigger()
    assert window.playback.frame == 101
    window.act_back.trigger()
    window.act_back.trigger()
    assert window.playback.frame == 99
    window.speed_combo.setCurrentIndex(window.speed_combo.findData(4.0))
    assert window.playback.speed == 4.0
    assert window._play_timer.interval() == 20  # 80 ms / 4
    window.playback.set_speed(0.5)
    assert window.speed_combo.currentData() == 0.5
    window.act_play.trigger()
    assert window.playback.playing
    window.playback.set_playing(False)
    assert not window.act_play.isChecked()
    window.colour_combo.setCurrentIndex(1)
    assert window.top_view.colour_by == "label"
    window.persistence_spin.setValue(9)
    assert window.top_view.persistence == 9
    assert QtCore.QCoreApplication.instance() is not None


def test_users_count_from_one_and_the_counter_reads_out_of_the_scene(
    window, long_scene_frames
) -> None:
    """Persons are numbered from 1 wherever a user reads them (the scene panel's list as its
    waypoint table's rows), and the frame counter counts out of the scene's frames, saying how
    many are simulated while the cache fills."""
    from tests.app.conftest import LONG_SCENE

    _scene, frames = long_scene_frames
    window.scene_model.set_document(LONG_SCENE)
    window._scene_timer.stop()
    assert window.scene_panel.person_list.item(0).text().startswith("person 1: ")
    info = window.engine.scene_info(window.scene_model.scene)
    window.cache.clear(expected=info.n_frames, truth_paths=info.truth_paths)
    for f in frames[:3]:
        window.cache.append(f)
    window.playback_control.update_frame_label()
    text = window.frame_label.text()
    assert f"frame 1 / {info.n_frames} (3 simulated so far)" in text, text
    for f in frames[3:]:
        window.cache.append(f)
    window.cache.mark_complete()
    window.playback_control.update_frame_label()
    assert f"/ {info.n_frames} ·" in window.frame_label.text()
    assert "simulated" not in window.frame_label.text()
