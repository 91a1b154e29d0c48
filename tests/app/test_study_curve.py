"""The best-loss curve of a study run twice on one storage, an hour apart: its time axis is the
study's busy time (the idle hour left out), from constructed trial summaries."""

from __future__ import annotations

import datetime as dt

import numpy as np

from app.data import StudyForm, StudyProgress
from app.engine import studies
from core.optimization.progress import TrialSummary

T0 = dt.datetime(2026, 1, 1, 12, 0, 0)


def _trial(n: int, start_s: float, dur_s: float, value: float, state="COMPLETE") -> TrialSummary:
    return TrialSummary(
        number=n,
        state=state,
        value=value,
        params={},
        duration_s=dur_s,
        datetime_start=T0 + dt.timedelta(seconds=start_s),
        datetime_complete=T0 + dt.timedelta(seconds=start_s + dur_s),
    )


def _two_runs() -> list[TrialSummary]:
    """Run 1: 10 trials of 2 s back to back (0.1 s between) from t = 0; run 2: 5 trials of 2 s
    from t = 3600 s (the study resumed an hour later)."""
    run1 = [_trial(i, i * 2.1, 2.0, 1.0 / (i + 1)) for i in range(10)]
    run2 = [_trial(10 + i, 3600.0 + i * 2.1, 2.0, 0.05 / (i + 1)) for i in range(5)]
    # a pruned trial in run 2 counts for the busy time but is not on the curve
    return run1 + run2 + [_trial(15, 3600.0 + 5 * 2.1, 1.0, 0.9, state="PRUNED")]


def test_busy_time_leaves_out_the_idle_hour_between_two_runs() -> None:
    trials = _two_runs()
    done = [s for s in trials if s.state == "COMPLETE"]
    t = studies.busy_time_s(trials, [s.datetime_complete for s in done])
    # run 1 is one stretch 0 … 9·2.1 + 2 = 20.9 s; run 2's k-th trial ends 2.1 k + 2 s after
    # run 2 started, i.e. at 20.9 + 2.1 k + 2 s of busy time
    expect = [i * 2.1 + 2.0 for i in range(10)] + [20.9 + k * 2.1 + 2.0 for k in range(5)]
    np.testing.assert_allclose(t, expect, atol=1e-9)
    assert np.all(np.diff(t) > 0)
    assert t[-1] < 60.0  # not the hour


def test_parallel_trials_count_once() -> None:
    # two workers: trials overlapping in time, 4 s busy in all
    trials = [_trial(0, 0.0, 3.0, 1.0), _trial(1, 1.0, 3.0, 0.5)]
    t = studies.busy_time_s(trials, [s.datetime_complete for s in trials])
    np.testing.assert_allclose(t, [3.0, 4.0])


def test_the_report_plots_the_same_busy_time() -> None:
    """The exported report's loss-against-time curve and the study panel's: one time axis."""
    from core.optimization.report import StudyRecord

    trials = _two_runs()
    record = StudyRecord(
        name="s", model="cv", sampler="tpe", pruner="asha", dataset="", trials=tuple(trials)
    )
    secs, best = record.best_against_time()
    done = sorted((s for s in trials if s.state == "COMPLETE"), key=lambda s: s.datetime_complete)
    np.testing.assert_allclose(
        secs, studies.busy_time_s(trials, [s.datetime_complete for s in done])
    )
    assert secs[-1] < 60.0  # not the idle hour
    np.testing.assert_allclose(best, np.minimum.accumulate([s.value for s in done]))


def test_study_progress_and_panel_plot_the_busy_time(qtbot, tmp_path, monkeypatch) -> None:
    import core.optimization as opt
    from app.panels.study_panel import StudyPanel
    from app.study import StudyModel

    storage = tmp_path / "s.db"
    storage.write_bytes(b"")
    trials = _two_runs()
    monkeypatch.setattr(opt, "study_progress", lambda url, name: (trials, trials[14]))
    p = studies.study_progress(StudyForm(storage=str(storage)))
    assert isinstance(p, StudyProgress) and p.n_complete == 15 and p.n_pruned == 1
    assert len(p.curve_t_s) == 15
    assert p.curve_t_s[0] == 2.0 and abs(p.curve_t_s[-1] - (20.9 + 4 * 2.1 + 2.0)) < 1e-9
    np.testing.assert_allclose(p.curve_best[-1], 0.01)

    model = StudyModel()
    panel = StudyPanel(model)
    qtbot.addWidget(panel)
    model.progress = p
    panel.show_progress(p)
    x, _y = panel.curve.getData()
    assert x is not None and len(x) == 15
    assert x.max() - x.min() < 60.0  # the busy time, not the idle hour
    axis = panel.curve_plot.getAxis("bottom").labelText
    assert "busy time" in axis
