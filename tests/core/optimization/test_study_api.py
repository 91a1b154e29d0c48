"""Study API in one process: reproducibility, refusal of the other model, crash recovery."""

from __future__ import annotations

from pathlib import Path

import optuna
import pytest

from core.errors import InputError
from core.optimization import (
    StudySettings,
    enqueue_params,
    fail_stale_trials,
    open_storage,
    prepare_study,
    run_worker,
    study_progress,
)
from core.optimization.space import search_space
from core.optimization.study import trial_seed
from core.tracking.space import tracker_params_dict


def settings(tmp_path: Path, **kw) -> StudySettings:
    base = dict(
        model="cv",
        n_trials=14,
        storage=f"memory://{tmp_path}",
        objective="quadratic",
        objective_options={"n_trajectories": 5},
    )
    return StudySettings(**{**base, **kw})


def run(s: StudySettings, seed: int) -> list:
    prepare_study(s)
    run_worker(s.storage, s.name, seed=seed)
    summaries, _ = study_progress(s.storage, s.name)
    return summaries


@pytest.mark.parametrize("sampler", ["tpe", "random"])
def test_same_seed_same_trials_other_seed_other_trials(tmp_path: Path, sampler: str) -> None:
    a = run(settings(tmp_path, study_name="a", sampler=sampler, pruner="none"), seed=5)
    b = run(settings(tmp_path, study_name="b", sampler=sampler, pruner="none"), seed=5)
    c = run(settings(tmp_path, study_name="c", sampler=sampler, pruner="none"), seed=6)
    assert len(a) == 14  # beyond TPE's 10 start-up trials
    assert [t.params for t in a] == [t.params for t in b]
    assert [t.value for t in a] == [t.value for t in b]
    assert [t.params for t in a] != [t.params for t in c]


def test_tpe_finds_a_lower_loss_than_random_on_the_quadratic(tmp_path: Path) -> None:
    best = {}
    for sampler in ("tpe", "random"):
        s = settings(tmp_path, study_name=sampler, sampler=sampler, pruner="none", n_trials=40)
        _, b = run(s, seed=1), study_progress(s.storage, s.name)[1]
        best[sampler] = b.value
    assert best["tpe"] < best["random"]


def test_exact_total_counts_complete_and_pruned(tmp_path: Path) -> None:
    s = settings(tmp_path, n_trials=25, pruner="asha", objective_options={"n_trajectories": 15})
    summaries = run(s, seed=0)
    states = [t.state for t in summaries]
    assert states.count("COMPLETE") + states.count("PRUNED") == 25
    assert "PRUNED" in states and "RUNNING" not in states
    # asking again runs nothing: the total is reached
    assert run_worker(s.storage, s.name, seed=1) == 0


def test_other_model_under_the_same_name_is_refused_and_study_untouched(tmp_path: Path) -> None:
    s = settings(tmp_path, n_trials=3)
    before = run(s, seed=0)
    with pytest.raises(InputError, match="has model='cv', asked 'ca'"):
        prepare_study(settings(tmp_path, model="ca", study_name=s.name, n_trials=50))
    after, _ = study_progress(s.storage, s.name)
    assert after == before
    study = optuna.load_study(study_name=s.name, storage=open_storage(s.storage))
    assert study.user_attrs["n_trials"] == 3 and study.user_attrs["model"] == "cv"


def test_dead_workers_running_trial_fails_on_resume(tmp_path: Path) -> None:
    s = settings(tmp_path, n_trials=4)
    run(s, seed=0)
    study = optuna.load_study(study_name=s.name, storage=open_storage(s.storage))
    dead = study.ask()
    # a worker on this host whose process no longer exists (pid 2**22 + 1 > pid_max default)
    import socket

    dead.set_user_attr("worker", f"{socket.gethostname()}:{2**22 + 1}:123")
    alive = study.ask()
    alive.set_user_attr("worker", f"other-host:{2**22 + 1}:123")  # remote, fresh: kept
    assert fail_stale_trials(study) == [dead.number]
    states = {t.number: t.state.name for t in study.get_trials()}
    assert states[dead.number] == "FAIL" and states[alive.number] == "RUNNING"
    assert fail_stale_trials(study, stale_after_s=0.0) == [alive.number]


def test_a_worker_ended_but_not_yet_reaped_is_dead(tmp_path: Path) -> None:
    """A killed worker stays a zombie until ``tune`` reaps it (every 0.5 s); a worker finishing
    the study in that window must free the zombie's RUNNING trial and reach the total."""
    import socket
    import subprocess
    import sys
    import time

    from core.optimization.study import _start_ticks, worker_alive

    child = subprocess.Popen([sys.executable, "-c", "import sys; sys.stdin.read()"],
                             stdin=subprocess.PIPE)  # fmt: skip
    try:
        wid = f"{socket.gethostname()}:{child.pid}:{_start_ticks(child.pid)}"
        assert worker_alive(wid) is True
        child.stdin.close()  # it exits; not polled, so it stays a zombie
        stat = Path(f"/proc/{child.pid}/stat")
        deadline = time.monotonic() + 20
        while stat.read_text().rsplit(")", 1)[1].split()[0] != "Z":
            assert time.monotonic() < deadline, "the child did not exit"
            time.sleep(0.02)
        assert worker_alive(wid) is False
        s = settings(tmp_path, n_trials=4, pruner="none")
        prepare_study(s)
        study = optuna.load_study(study_name=s.name, storage=open_storage(s.storage))
        orphan = study.ask()
        orphan.set_user_attr("worker", wid)
        run_worker(s.storage, s.name, seed=0)
        states = {t.number: t.state.name for t in study.get_trials()}
        assert states[orphan.number] == "FAIL"
        assert list(states.values()).count("COMPLETE") == 4 and "RUNNING" not in states.values()
    finally:
        child.wait(10)


def test_enqueued_parameters_run_first(tmp_path: Path) -> None:
    s = settings(tmp_path, n_trials=2, pruner="none")
    prepare_study(s)
    flat = {b.name: b.high for b in search_space("cv")}
    enqueue_params(s.storage, s.name, tracker_params_dict(flat, "cv"))
    run_worker(s.storage, s.name, seed=0)
    summaries, _ = study_progress(s.storage, s.name)
    assert summaries[0].params == flat
    assert summaries[0].tracker_params("cv")["p0"] == [10.0, 10.0, 10.0, 10.0]
    with pytest.raises(InputError, match="study is 'cv'"):
        enqueue_params(s.storage, s.name, {**tracker_params_dict(flat, "cv"), "model": "ca"})


def test_trial_seeds_are_distinct_per_trial_and_reproducible() -> None:
    # (h(seed) + n) mod 2**32: one seed per trial number, whoever asks; another base: other seeds
    seeds = [trial_seed(0, n) for n in range(10_000)]
    assert len(set(seeds)) == 10_000
    assert seeds == [trial_seed(0, n) for n in range(10_000)]
    assert (seeds[1] - seeds[0]) % 2**32 == 1
    assert trial_seed(1, 0) not in seeds[:100]
    assert 0 <= trial_seed(-3, 2**40) < 2**32


def test_two_workers_with_one_seed_repeat_no_parameter_set(tmp_path: Path) -> None:
    # two workers (or two tune runs) joining one study with the same base seed: trial numbers
    # differ, so the sampler seeds differ; with the random sampler every trial is a new point
    s = settings(tmp_path, n_trials=12, sampler="random", pruner="none")
    prepare_study(s)
    run_worker(s.storage, s.name, seed=7, stop=_after(6, s))
    run_worker(s.storage, s.name, seed=7)
    summaries, _ = study_progress(s.storage, s.name)
    points = [tuple(sorted(t.params.items())) for t in summaries if t.state == "COMPLETE"]
    assert len(points) == 12 and len(set(points)) == 12
    # the study's own seed is the default base: trial n samples as with seed=s.seed
    t = settings(tmp_path, study_name="default", n_trials=3, sampler="random", pruner="none")
    u = settings(tmp_path, study_name="explicit", n_trials=3, sampler="random", pruner="none")
    prepare_study(t), prepare_study(u)
    run_worker(t.storage, t.name, seed=None)
    run_worker(u.storage, u.name, seed=t.seed)
    a, b = study_progress(t.storage, t.name)[0], study_progress(u.storage, u.name)[0]
    assert [x.params for x in a] == [x.params for x in b]


def _after(n: int, s: StudySettings):
    """A stop() that is true once the study has n trials."""
    return lambda: len(study_progress(s.storage, s.name)[0]) >= n


@pytest.mark.parametrize(("pruner", "pruned"), [("wilcoxon", True), ("none", False)])
def test_wilcoxon_prunes_and_none_never_does(tmp_path: Path, pruner: str, pruned: bool) -> None:
    s = settings(
        tmp_path, n_trials=30, pruner=pruner, sampler="random",
        objective_options={"n_trajectories": 20},
    )  # fmt: skip
    summaries = run(s, seed=2)
    states = [t.state for t in summaries]
    assert states.count("COMPLETE") + states.count("PRUNED") == 30
    assert ("PRUNED" in states) == pruned
    study = optuna.load_study(study_name=s.name, storage=open_storage(s.storage))
    for t in study.get_trials():
        if pruner == "wilcoxon":
            # per-trajectory losses reported at the trajectory's index
            assert set(t.intermediate_values) <= set(range(20))
        else:
            assert t.intermediate_values == {}


def test_trial_carries_its_worker_from_the_first_write(tmp_path: Path) -> None:
    # a worker killed right after creating its trial must leave a trial that resume can fail:
    # the worker record is part of the write that creates the RUNNING trial
    import socket

    from optuna.trial import TrialState

    from core.optimization.study import _ask_as, fail_stale_trials

    study = optuna.create_study(storage=f"sqlite:///{tmp_path}/s.db")
    # a dead worker on this host: pid 2^22 + 1 is above the largest pid Linux allows (2^22)
    dead = f"{socket.gethostname()}:4194305:1"
    trial = _ask_as(study, dead)
    stored = study.get_trials(deepcopy=False)[0]
    assert stored.state == TrialState.RUNNING and stored.user_attrs["worker"] == dead
    assert fail_stale_trials(study) == [trial.number]
    assert study.get_trials(deepcopy=False)[0].state == TrialState.FAIL


def test_a_surplus_trial_is_neither_counted_nor_failed(tmp_path: Path) -> None:
    """Two workers racing for the last slot leave one trial stored as FAIL with surplus=True;
    the summaries call it SURPLUS, so "failed" counts only trials whose objective failed."""
    from core.optimization.study import load_existing_study

    s = settings(tmp_path, n_trials=3)
    run(s, seed=0)
    study = load_existing_study(open_storage(s.storage, create=False), s.name)
    surplus = study.ask()
    surplus.set_user_attr("surplus", True)
    study.tell(surplus, state=optuna.trial.TrialState.FAIL)
    broken = study.ask()
    broken.set_user_attr("error", "ValueError: x")
    study.tell(broken, state=optuna.trial.TrialState.FAIL)
    states = [t.state for t in study_progress(s.storage, s.name)[0]]
    assert states.count("COMPLETE") == 3
    assert states[-2:] == ["SURPLUS", "FAIL"]
