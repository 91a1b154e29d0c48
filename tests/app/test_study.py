"""A short study started from the panel completes in separate processes and fills the
best-parameter table, while the event loop keeps running (a test QTimer measures it)."""

from __future__ import annotations

import time

import numpy as np
import pytest
from PySide6 import QtCore


def test_short_study_from_panel_keeps_event_loop_alive(
    window, qtbot, tmp_path, long_scene_frames, long_scene_doc, fill_cache, monkeypatch
) -> None:
    scene, frames = long_scene_frames
    fill_cache(window, long_scene_doc, frames)
    storage = tmp_path / "study.db"
    panel = window.study_panel
    panel.trials.setValue(4)
    panel.jobs.setValue(1)
    panel.storage.setText(str(storage))
    panel.storage.editingFinished.emit()
    assert window.study_model.form.storage == str(storage)

    qtbot.waitUntil(lambda: window.tracker.n_runs >= 1 and window.tracker.idle, timeout=60000)
    ticks: list[float] = []
    timer = QtCore.QTimer()
    timer.setInterval(10)
    timer.timeout.connect(lambda: ticks.append(time.perf_counter()))
    timer.start()
    qtbot.wait(100)

    events = []
    window.study_model.message.connect(lambda m: events.append((time.perf_counter(), m)))
    window.study_model.progress_changed.connect(
        lambda p: events.append((time.perf_counter(), f"progress {p.n_finished}"))
    )
    t_click = time.perf_counter()
    panel.start_button.click()
    events.append((time.perf_counter(), "click returned"))
    assert window.study_model.running and not panel.start_button.isEnabled()
    window.study_model.message.connect(lambda m: print("study:", m, flush=True))
    finished = []
    window.study.finished.connect(lambda: finished.append(True))
    qtbot.waitUntil(lambda: bool(finished), timeout=120000)
    timer.stop()

    p = window.study_model.progress
    assert p.n_complete + p.n_pruned == 4, window.errors
    assert p.n_complete >= 1 and np.isfinite(p.best_loss) and p.best_loss > 0
    assert panel.table.rowCount() == len(window.engine.param_specs("cv")) == 12
    names = {panel.table.item(i, 0).text() for i in range(panel.table.rowCount())}
    assert names == {s.name for s in window.engine.param_specs("cv")}
    assert panel.progress_bar.value() == 4
    assert f"complete {p.n_complete}" in panel.counts.text()
    assert len(p.curve_t_s) == p.n_complete and np.all(np.diff(p.curve_best) <= 0)
    assert not window.study_model.running and panel.start_button.isEnabled()

    gaps = np.diff(ticks)
    i = int(np.argmax(gaps))
    print(f"gaps > 50 ms: {np.sum(gaps > 0.05)}, median {np.median(gaps) * 1e3:.1f} ms")
    print(
        f"\nevent loop: {len(ticks)} ticks, longest gap {gaps.max() * 1e3:.0f} ms "
        f"at {ticks[i] - t_click:.2f} s after start"
    )
    for t, m in events:
        print(f"  {t - t_click:7.2f} s  {m}")
    assert gaps.max() < 0.1

    # apply best: the sliders take the best trial's parameters (and re-track)
    panel.apply_button.click()
    for name, value in p.best_params.items():
        assert window.params_model.values[name] == pytest.approx(value)
        assert window.tracker_panel.rows[name].spin.value() == pytest.approx(value, abs=1e-4)
    # enqueue the current sliders as the next trial of the stored study
    window.params_model.set_value("q_coeff", 3.0)
    panel.enqueue_button.click()
    qtbot.waitUntil(lambda: any("enqueued" in m for _, m in events), timeout=30000)
    assert not window.errors

    # the dashboard serves this storage (the browser call is intercepted)
    opened = []
    from PySide6 import QtGui

    monkeypatch.setattr(
        QtGui.QDesktopServices, "openUrl", lambda url: opened.append(url.toString())
    )
    panel.dashboard_button.click()
    qtbot.waitUntil(lambda: bool(opened), timeout=10000)
    import json
    import urllib.request

    for _ in range(60):
        try:
            with urllib.request.urlopen(opened[0] + "api/studies", timeout=2) as r:
                studies = json.loads(r.read())["study_summaries"]
            break
        except OSError:
            qtbot.wait(500)
    else:
        raise AssertionError("optuna-dashboard did not answer")
    assert [s["study_name"] for s in studies] == ["radartune-cv"]


def test_stop_ends_a_running_study_early(
    window, qtbot, tmp_path, long_scene_frames, long_scene_doc, fill_cache
) -> None:
    scene, frames = long_scene_frames
    fill_cache(window, long_scene_doc, frames)
    window.study_model.set_form(n_trials=500, n_jobs=1, storage=str(tmp_path / "stop.db"))
    window.study_panel.start_button.click()
    qtbot.waitUntil(lambda: window.study_model.progress.n_finished >= 2, timeout=120000)
    assert window.study_panel.stop_button.isEnabled()
    finished = []
    window.study.finished.connect(lambda: finished.append(True))
    window.study_panel.stop_button.click()
    # while the worker finishes its trial: the button says so and cannot be clicked again
    stop = window.study_panel.stop_button
    assert finished or (stop.text() == "Stopping …" and not stop.isEnabled())
    qtbot.waitUntil(lambda: bool(finished), timeout=60000)
    qtbot.waitUntil(lambda: not window.study_model.running, timeout=10000)
    assert stop.text() == "Stop" and not stop.isEnabled()
    p = window.study_model.progress
    assert 2 <= p.n_finished < 500
    assert p.n_running == 0  # the worker finished its trial; nothing is left RUNNING
    assert window.study_panel.start_button.isEnabled()


def test_a_study_resumed_from_an_older_storage_keeps_its_objective(tmp_path, monkeypatch) -> None:
    """The app has no objective field: a new study minimises the default objective, one made
    before robust objectives existed (no ``loss`` attribute: the paper's) is resumed with it
    instead of refused."""
    import optuna

    import core.optimization
    from app.data import StudyForm
    from app.engine import start_study, storage_url
    from core.evaluation.robust import DEFAULT_OBJECTIVE
    from core.optimization.storage import open_storage
    from core.tracking.synthetic import synthetic_dataset

    data = str(tmp_path / "d.npz")
    synthetic_dataset(seed=1, n_per_class=1, n_frames=50).save(data)
    db = str(tmp_path / "studies.db")
    old = open_storage(storage_url(db)).create_new_study(
        [optuna.study.StudyDirection.MINIMIZE], "old-paper"
    )
    store = open_storage(storage_url(db))
    for key, value in (("model", "cv"), ("objective", "tracker"), ("sampler", "tpe"),
                       ("pruner", "asha")):  # fmt: skip
        store.set_study_user_attr(old, key, value)
    asked = []
    monkeypatch.setattr(core.optimization, "start_study", lambda s, **kw: asked.append(s))
    monkeypatch.setattr("app.engine.studies.StudyProcesses", lambda handle: handle)
    for name in ("old-paper", "new"):
        start_study(StudyForm(storage=db, study_name=name), dataset_path=data)
    assert [s.loss for s in asked] == ["paper", DEFAULT_OBJECTIVE]


def test_a_study_refuses_the_frames_of_a_live_link_in_one_line(
    window, tmp_path, long_scene_frames, long_scene_doc, fill_cache
) -> None:
    """After a live session the window's frames are the sensor's, not the scene's: a study on
    "the scene" would pair the sensor's frames with the scene's truth (it failed with
    "Dataset.truth_t_s must have shape (1209,), got (116,)"); it is refused in one line, and a
    scene simulated again is tuned on as before."""
    scene, frames = long_scene_frames
    fill_cache(window, long_scene_doc, frames)
    window.cache.clear(expected=0, truth_paths=())  # what Connect does
    window.live._generation = window.cache.generation
    assert window.live.owns_frames
    window.study_model.set_form(n_trials=2, n_jobs=1, storage=str(tmp_path / "live.db"))
    window.start_study()
    assert not window.study_model.running
    assert len(window.errors) == 1 and "from the live sensor" in window.errors[0]
    assert "\n" not in window.errors[0]
    fill_cache(window, long_scene_doc, frames)  # the scene simulated again: a new generation
    assert not window.live.owns_frames


@pytest.mark.parametrize("tracker", ["room", "gtrack"])
def test_a_study_of_the_room_mode_or_gtrack_from_the_panel(
    window, qtbot, tmp_path, long_scene_frames, long_scene_doc, fill_cache, tracker
) -> None:
    """The panel's tracker follows the tracker panel; the study tunes that tracker's search
    space (as radartune tune --mode room / --tracker gtrack), under its own name; Apply best
    and Enqueue work on that tracker's sliders."""
    from core.optimization import study_progress
    from core.optimization.storage import absolute_url

    scene, frames = long_scene_frames
    fill_cache(window, long_scene_doc, frames)
    window.params_model.set_tracker(tracker)
    panel = window.study_panel
    form = window.study_model.form
    assert form.tracker == tracker and panel.tracker_combo.currentData() == tracker
    assert panel.model_combo.isEnabled() == (tracker != "gtrack")
    storage = tmp_path / "study.db"
    window.study_model.set_form(n_trials=2, n_jobs=1, storage=str(storage))
    name = {"room": "radartune-cv-room", "gtrack": "radartune-gtrack"}[tracker]
    assert window.study_model.form.effective_name == name
    qtbot.waitUntil(lambda: window.tracker.n_runs >= 1 and window.tracker.idle, timeout=60000)
    finished = []
    window.study.finished.connect(lambda: finished.append(True))
    panel.start_button.click()
    assert window.study_model.running
    qtbot.waitUntil(lambda: bool(finished), timeout=300000)
    p = window.study_model.progress
    assert p.n_complete >= 1, (window.errors, p.failures)
    specs = window.engine.param_specs("gtrack") if tracker == "gtrack" else (
        window.engine.param_specs("cv", "room")
    )  # fmt: skip
    assert set(p.best_params) == {s.name for s in specs}
    summaries, best = study_progress(absolute_url(str(storage)), name)
    assert len(summaries) == 2 and best is not None
    # Apply best: the tracker panel shows that tracker with the best values
    window.params_model.reset()
    panel.apply_button.click()
    assert window.params_model.tracker == tracker
    for k, v in p.best_params.items():
        assert window.params_model.values[k] == pytest.approx(v)
    messages: list[str] = []
    window.study_model.message.connect(messages.append)
    panel.enqueue_button.click()
    qtbot.waitUntil(lambda: any("enqueued" in m for m in messages), timeout=30000)
    assert not window.errors
