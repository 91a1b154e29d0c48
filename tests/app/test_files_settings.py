"""Bad files show a message and leave the current state intact; settings persist with types."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from PySide6 import QtCore

from app import engine
from core.config import PAPER_RADAR

ROOT = Path(__file__).resolve().parents[2]

GOOD_CFG = """\
% minimal TI mmWave SDK configuration
sensorStop
channelCfg 15 7 0
adcCfg 2 1
profileCfg 0 60 7 6 50.5 0 0 61.366 1 256 5900 0 0 30
chirpCfg 0 0 0 0 0 0 0 1
chirpCfg 1 1 0 0 0 0 0 2
chirpCfg 2 2 0 0 0 0 0 4
frameCfg 0 2 64 0 80 1 0
"""


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ('{"schema_version": 1, "persons": [', "invalid JSON"),
        ('{"schema_version": 1, "colour": "red", "persons": []}', "colour"),
        ('{"schema_version": 1, "persons": [{"trajectory": {"class": "z"}}]}', "class"),
        ("[1, 2, 3]", ""),
    ],
)
def test_malformed_scene_shows_error_and_keeps_scene(window, tmp_path, text, expected) -> None:
    window.scene_model.set_document(engine.PAPER_SCENE_DOCUMENT)
    before = window.scene_model.document
    scene_before = window.scene_model.scene
    bad = tmp_path / "bad.json"
    bad.write_text(text)
    assert not window.load_scene(bad)
    assert window.errors and str(bad) in window.errors[-1]
    assert expected in window.errors[-1]
    assert window._error_box is not None and window._error_box.isVisible()
    assert window.scene_model.document == before
    assert window.scene_model.scene is scene_before
    assert not window.load_scene(tmp_path / "missing.json")
    assert "missing.json" in window.errors[-1]


def test_scene_save_and_load_round_trip(window, tmp_path) -> None:
    window.scene_model.set_document(engine.PAPER_SCENE_DOCUMENT)
    window.scene_panel.clutter.setValue(0.03)
    path = tmp_path / "s.json"
    window.scene_model.save(path)
    assert json.loads(path.read_text())["clutter_density_per_m2"] == pytest.approx(0.03)
    assert not list(tmp_path.glob(".*tmp"))  # nothing half-written left behind
    window.scene_model.set_document(engine.PAPER_SCENE_DOCUMENT)
    assert window.load_scene(path)
    assert window.scene_panel.clutter.value() == pytest.approx(0.03)


def test_ti_cfg_good_and_malformed(window, tmp_path) -> None:
    window.scene_model.set_document(engine.PAPER_SCENE_DOCUMENT)
    good = tmp_path / "radar.cfg"
    good.write_text(GOOD_CFG)
    assert window.load_cfg(good), window.errors
    radar = window.radar_model.radar
    assert radar.n_loops == 64 and radar.n_samples == 256
    assert window.radar_panel.spins["n_loops"].value() == 64
    # the scene now carries this radar
    assert window.scene_model.scene.radar.n_loops == 64
    assert window.scene_model.document["radar"]["n_loops"] == 64
    before_doc = window.scene_model.document
    bad = tmp_path / "bad.cfg"
    bad.write_text(GOOD_CFG.replace("profileCfg 0 60 7 6 50.5", "profileCfg 0 sixty 7 6 50.5"))
    assert not window.load_cfg(bad)
    assert "bad.cfg" in window.errors[-1]
    assert window.radar_model.radar == radar
    assert window.scene_model.document == before_doc


def test_settings_persist_with_types(qtbot, settings, tmp_path) -> None:
    from app.window import MainWindow

    w = MainWindow(settings, load_scene=False)
    qtbot.addWidget(w)
    w.playback.set_speed(2.0)
    w.colour_combo.setCurrentIndex(1)
    w.persistence_spin.setValue(12)
    w.tracker_panel.model_combo.setCurrentIndex(1)
    w.params_model.set_value("q_coeff", 4.5)
    w.tracker_panel.confirm.setValue(0.85)
    w.study_model.set_form(n_trials=17, n_jobs=2, storage=str(tmp_path / "st.db"))
    w.show()
    qtbot.waitExposed(w)
    w.resize(790, 560)  # the offscreen screen is 800 px; restoreGeometry clamps to it
    qtbot.wait(50)
    size = (w.width(), w.height())
    w.save_settings()
    w.shutdown()
    # typed values in the file
    assert settings.value("playback/speed", type=float) == 2.0
    assert settings.value("view/persistence", type=int) == 12
    w2 = MainWindow(
        QtCore.QSettings(settings.fileName(), QtCore.QSettings.IniFormat), load_scene=False
    )
    qtbot.addWidget(w2)
    w2.show()
    qtbot.waitExposed(w2)
    assert w2.playback.speed == 2.0 and w2.speed_combo.currentData() == 2.0
    assert w2.top_view.colour_by == "label" and w2.colour_combo.currentData() == "label"
    assert w2.top_view.persistence == 12 and w2.persistence_spin.value() == 12
    assert w2.params_model.model == "ca" and w2.tracker_panel.model_combo.currentData() == "ca"
    assert w2.params_model.values["q_coeff"] == pytest.approx(4.5)
    assert w2.params_model.params().confirm_threshold == pytest.approx(0.85)
    assert w2.study_model.form.n_trials == 17 and w2.study_panel.trials.value() == 17
    assert w2.study_model.form.storage == str(tmp_path / "st.db")
    assert (w2.width(), w2.height()) == size
    w2.shutdown()


def test_corrupt_settings_are_ignored(qtbot, tmp_path) -> None:
    from app.window import MainWindow

    path = tmp_path / "bad.ini"
    path.write_text(
        "[tracker]\nmodel=cv\nvalues={not json\n[view]\npersistence=abc\n[study]\nn_jobs=-3\n"
    )
    w = MainWindow(QtCore.QSettings(str(path), QtCore.QSettings.IniFormat), load_scene=False)
    qtbot.addWidget(w)
    assert w.params_model.values == engine.default_values("cv")
    assert 1 <= w.top_view.persistence <= 100
    assert w.study_model.form.n_jobs >= 1
    w.shutdown()


def test_gui_command_starts_with_the_paper_scene_and_quits(tmp_path) -> None:
    env = {"QT_QPA_PLATFORM": "offscreen", "PATH": "/usr/bin:/bin", "HOME": str(tmp_path)}
    out = subprocess.run(
        [sys.executable, "-m", "core.cli", "gui", "--quit-after", "4",
         "--settings", str(tmp_path / "s.ini")],
        cwd=ROOT, env=env, capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert out.returncode == 0, out.stderr
    s = QtCore.QSettings(str(tmp_path / "s.ini"), QtCore.QSettings.IniFormat)
    assert s.value("playback/speed", type=float) == 1.0  # saved on close
    assert PAPER_RADAR.n_loops == 32
