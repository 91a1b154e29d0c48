"""The batching storages (decision tuning-07): same studies as Optuna's own storages, fewer
round trips, held writes all or nothing, own-trial answers equal to the database's."""

from __future__ import annotations

from pathlib import Path

import optuna
import pytest
from optuna.distributions import FloatDistribution
from optuna.trial import TrialState

from core.optimization import StudySettings, batching, open_storage, prepare_study, run_worker
from core.optimization.batching import BatchingJournalStorage, BatchingRDBStorage, batched


def _study_rows(storage: str, name: str) -> list[tuple]:
    study = optuna.load_study(study_name=name, storage=open_storage(storage))
    rows = []
    for t in study.get_trials(deepcopy=False):
        user = {k: v for k, v in t.user_attrs.items() if k != "worker"}
        rows.append(
            (t.number, t.state, t.params, t.values, t.intermediate_values, t.system_attrs, user)
        )
    return rows


def _run(tmp_path: Path, url: str, tag: str) -> list[tuple]:
    s = StudySettings(
        model="cv",
        n_trials=30,  # beyond TPE's 10 random start-up trials
        storage=url,
        study_name=f"s-{tag}",
        objective="quadratic",
        objective_options={"n_trajectories": 20},  # ASHA rungs at 5 and 15
        seed=3,
    )
    prepare_study(s)
    run_worker(s.storage, s.name, seed=3)
    return _study_rows(s.storage, s.name)


def test_a_seeded_study_is_the_same_with_and_without_batching_on_every_storage(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # one worker, one seed: the trials (parameters, values, intermediate values, the sampler's
    # and pruner's records) do not depend on the storage or on how writes are grouped
    reference = _run(tmp_path, f"memory://{tmp_path}", "memory")
    assert sum(r[1] == TrialState.PRUNED for r in reference) > 0  # ASHA did prune
    assert sum(r[1] == TrialState.COMPLETE for r in reference) > 0
    assert any("completed_rung_1" in r[5] for r in reference)
    batched_runs = {
        "sqlite": _run(tmp_path, f"sqlite:///{tmp_path}/b.db", "sqlite"),
        "journal": _run(tmp_path, f"journal:///{tmp_path}/b.log", "journal"),
    }
    assert isinstance(open_storage(f"sqlite:///{tmp_path}/b.db"), BatchingRDBStorage)
    assert isinstance(open_storage(f"journal:///{tmp_path}/b.log"), BatchingJournalStorage)
    monkeypatch.setattr(batching, "batching_available", lambda kind: False)
    plain_runs = {
        "sqlite": _run(tmp_path, f"sqlite:///{tmp_path}/p.db", "sqlite"),
        "journal": _run(tmp_path, f"journal:///{tmp_path}/p.log", "journal"),
    }
    assert type(open_storage(f"sqlite:///{tmp_path}/p.db")) is optuna.storages.RDBStorage
    for kind in ("sqlite", "journal"):
        assert batched_runs[kind] == reference, kind
        assert plain_runs[kind] == reference, kind


def _new_trial(store: BatchingRDBStorage) -> tuple[optuna.Study, int]:
    study = optuna.create_study(storage=store, study_name="t")
    return study, study._storage.create_new_trial(study._study_id)


def test_held_writes_reach_the_database_together_at_the_end_of_the_phase(
    tmp_path: Path,
) -> None:
    url = f"sqlite:///{tmp_path}/h.db"
    store = open_storage(url)
    study, trial_id = _new_trial(store)
    reader = optuna.storages.RDBStorage(url)  # another process's view
    x = FloatDistribution(0.0, 1.0)
    with batched(study._storage):
        study._storage.set_trial_param(trial_id, "x", 0.25, x)
        study._storage.set_trial_param(trial_id, "y", 0.5, x)
        study._storage.set_trial_system_attr(trial_id, "note", [1, 2])
        study._storage.set_trial_intermediate_value(trial_id, 5, 0.125)
        assert reader.get_trial(trial_id).params == {}  # not yet written
        assert study._storage.get_trial(trial_id).params == {"x": 0.25, "y": 0.5}  # own view
    seen = reader.get_trial(trial_id)
    assert seen.params == {"x": 0.25, "y": 0.5}
    assert seen.system_attrs == {"note": [1, 2]}
    assert seen.intermediate_values == {5: 0.125}


def test_a_phase_that_raises_writes_nothing(tmp_path: Path) -> None:
    url = f"sqlite:///{tmp_path}/r.db"
    study, trial_id = _new_trial(open_storage(url))
    with pytest.raises(RuntimeError), batched(study._storage):
        study._storage.set_trial_param(trial_id, "x", 0.25, FloatDistribution(0.0, 1.0))
        raise RuntimeError("sampler failed")
    assert optuna.storages.RDBStorage(url).get_trial(trial_id).params == {}


def test_own_trial_answers_equal_what_the_database_holds(tmp_path: Path) -> None:
    # every answer given from the process's own copy equals a fresh read of the database,
    # while the trial runs and right after it is told (when Study.tell reads it back)
    url = f"sqlite:///{tmp_path}/o.db"
    store = open_storage(url)
    study, trial_id = _new_trial(store)
    trial = optuna.Trial(study, trial_id)
    trial.set_user_attr("worker", "w")
    with batched(store):
        trial.suggest_float("x", 0.0, 1.0)
        trial.suggest_float("q", 1e-3, 1.0, log=True)
    with batched(store, read=False):
        trial.report(0.5, 5)
        study._storage.set_trial_system_attr(trial_id, "completed_rung_0", 0.5)
    reader = optuna.storages.RDBStorage(url)

    def same(a: optuna.trial.FrozenTrial, b: optuna.trial.FrozenTrial) -> None:
        for field in (
            "number", "state", "values", "datetime_start", "datetime_complete", "params",
            "distributions", "user_attrs", "system_attrs", "intermediate_values",
        ):  # fmt: skip
            assert getattr(a, field) == getattr(b, field), field

    same(store.get_trial(trial_id), reader.get_trial(trial_id))
    told = study.tell(trial, 0.25)
    same(told, reader.get_trial(trial_id))
    assert told.state == TrialState.COMPLETE and told.values == [0.25]
    # after the next read of the study the finished trial comes from Optuna's cache
    study.get_trials()
    assert trial_id not in store._own


def test_a_write_to_a_trial_failed_by_another_process_is_refused(tmp_path: Path) -> None:
    # crash recovery from another process marks a trial FAIL; the held writes of its (slow,
    # not dead) worker must then fail as Optuna's own writes do, not land in a finished trial
    url = f"sqlite:///{tmp_path}/f.db"
    store = open_storage(url)
    study, trial_id = _new_trial(store)
    optuna.storages.RDBStorage(url).set_trial_state_values(trial_id, TrialState.FAIL)
    with pytest.raises(optuna.exceptions.UpdateFinishedTrialError), batched(store):
        study._storage.set_trial_param(trial_id, "x", 0.25, FloatDistribution(0.0, 1.0))
    assert optuna.storages.RDBStorage(url).get_trial(trial_id).params == {}


def test_a_phase_belongs_to_its_thread(tmp_path: Path) -> None:
    # inside a phase that does not read, this thread sees the study as last read; another
    # thread using the same storage (a progress poll) still reads the database
    import threading

    url = f"sqlite:///{tmp_path}/p.db"
    store = open_storage(url)
    study = optuna.create_study(storage=store, study_name="t")
    elsewhere = optuna.load_study(study_name="t", storage=optuna.storages.RDBStorage(url))
    seen: list[int] = []
    with batched(store, read=False):
        elsewhere.ask()  # a trial made by another process
        assert study.get_trials() == []
        poll = threading.Thread(target=lambda: seen.append(len(study.get_trials())))
        poll.start()
        poll.join()
    assert seen == [1]
    assert len(study.get_trials()) == 1
