"""Defects of the app's windows and views, each with the test that failed before its fix."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from app import engine
from app.data import StudyForm


def test_dashboard_opens_the_guis_storage_by_absolute_path(tmp_path, monkeypatch) -> None:
    """A relative storage is the file in the GUI's working folder, named absolutely; the
    dashboard process never starts in (so never writes into) the install folder."""
    gui_cwd = tmp_path / "work"
    gui_cwd.mkdir()
    monkeypatch.chdir(gui_cwd)
    (gui_cwd / "radartune-studies.db").write_bytes(b"")  # an existing storage
    calls = []

    class FakePopen:
        def __init__(self, cmd, cwd=None, **_kw) -> None:
            calls.append((cmd, cwd))

        def poll(self):
            return 0

    monkeypatch.setattr(subprocess, "Popen", FakePopen)
    engine.serve_dashboard(StudyForm(storage="radartune-studies.db"))
    ((cmd, cwd),) = calls
    url = cmd[cmd.index("--storage") + 1]
    assert url == f"sqlite:///{gui_cwd / 'radartune-studies.db'}"
    assert Path(cwd).resolve() != engine.ROOT
    assert not Path(cwd).resolve().is_relative_to(engine.ROOT)


def test_storage_url_is_absolute_for_the_study_service(tmp_path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    assert engine.storage_url("s.db") == f"sqlite:///{tmp_path / 's.db'}"
    assert engine.storage_url("runs/j.log") == f"journal:///{tmp_path / 'runs' / 'j.log'}"
    assert engine.storage_url("postgresql://u@h:5/d") == "postgresql+psycopg2://u@h:5/d"


def test_study_failure_reasons_reach_the_panel(qtbot, tmp_path) -> None:
    """Trials that failed show their reasons in the study panel, not only in a log file."""
    import optuna
    from optuna.trial import TrialState

    from app.panels.study_panel import StudyPanel
    from app.study import StudyModel
    from app.study_service import progress_from_dict, progress_to_dict

    storage = tmp_path / "s.db"
    optuna.logging.set_verbosity(optuna.logging.ERROR)
    study = optuna.create_study(storage=f"sqlite:///{storage}", study_name="radartune-cv")
    reasons = ["FloatingPointError: trajectory 0: loss is nan"] * 3 + ["ValueError: bad"]
    for reason in reasons:
        trial = study.ask()
        trial.set_user_attr("error", reason)
        study.tell(trial, state=TrialState.FAIL)
    study.tell(study.ask(), state=TrialState.FAIL)  # no reason recorded
    study.tell(study.ask(), 2.0)

    progress = engine.study_progress(StudyForm(storage=str(storage)))
    assert progress.n_failed == 5 and progress.n_complete == 1
    assert progress.failures[0] == ("FloatingPointError: trajectory 0: loss is nan", 3)
    assert {r for r, _ in progress.failures[1:]} == {
        "ValueError: bad",
        "no reason recorded (see the workers' log)",
    }
    progress = progress_from_dict(progress_to_dict(progress))  # through the study service

    model = StudyModel()
    panel = StudyPanel(model)
    qtbot.addWidget(panel)
    panel.show()
    assert panel.failures.isHidden()
    model.set_progress(progress)
    assert not panel.failures.isHidden()
    text = panel.failures.text()
    assert "3 × FloatingPointError: trajectory 0: loss is nan" in text
    assert "1 × ValueError: bad" in text


def test_rejected_waypoint_drag_puts_the_handle_back(window, qtbot) -> None:
    """A waypoint dropped outside the area of interest is refused; table, path and handle all
    return to the last accepted position."""
    window.scene_model.set_document(dict(engine.PAPER_SCENE_DOCUMENT))
    window._scene_timer.stop()
    window.scene_panel.add_wp_button.click()
    qtbot.waitUntil(lambda: len(window.top_view._waypoint_items) == 2, timeout=5000)
    wp = [list(r) for r in window.scene_model.document["persons"][1]["trajectory"]["waypoints"]]
    item = window.top_view._waypoint_items[0]
    item.setPos(40.0, 40.0)  # the area of interest ends at 10 m
    item.sigPositionChangeFinished.emit(item)
    assert window.errors, "the drag must be refused with a message"
    assert window.scene_model.document["persons"][1]["trajectory"]["waypoints"] == wp
    assert float(window.scene_panel.waypoints.item(0, 0).text()) == wp[0][0]
    pos = window.top_view._waypoint_items[0].pos()
    assert (pos.x(), pos.y()) == (wp[0][0], wp[0][1])
    line_x, line_y = window.top_view.waypoint_line.getData()
    assert (line_x[0], line_y[0]) == (wp[0][0], wp[0][1])


@pytest.mark.parametrize("accept", [True, False])
def test_short_range_cfg_offers_to_shrink_the_area_of_interest(window, monkeypatch, accept):
    """high_velocity.cfg sees 7.49 m, the default area reaches 10 m: the user is asked; yes
    shrinks the area to the radar's range (1 cm inside) and adopts the radar, no keeps both."""
    from PySide6 import QtWidgets

    window.scene_model.set_document(dict(engine.PAPER_SCENE_DOCUMENT))
    window._scene_timer.stop()
    asked = []

    def question(*args, **_kw):
        asked.append(args[2])
        return QtWidgets.QMessageBox.Yes if accept else QtWidgets.QMessageBox.No

    monkeypatch.setattr(QtWidgets.QMessageBox, "question", question)
    cfg = engine.ROOT / "resources" / "radar" / "high_velocity.cfg"
    radar = engine.read_ti_cfg(cfg)
    assert radar.max_range_m < 10.0
    window.load_cfg(cfg)
    window._scene_timer.stop()
    assert len(asked) == 1 and "7.49 m" in asked[0]
    scene = window.scene_model.scene
    if accept:
        assert window.scene_model.document["aoi"]["max_range_m"] == 7.49
        assert scene.radar == radar and window.radar_model.radar == radar
        assert not window.errors
    else:
        assert window.scene_model.document["aoi"]["max_range_m"] == 10.0
        assert scene.radar != radar and window.radar_model.radar == scene.radar
        assert "exceeds the radar's maximum range" in window.errors[-1]
