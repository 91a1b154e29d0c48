"""The sampler factory: names, their Optuna classes, missing packages, CMA-ES across workers."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import optuna
import pytest

from core.errors import InputError
from core.optimization import StudySettings, prepare_study, run_worker, study_progress
from core.optimization.storage import open_storage
from core.optimization.study import SAMPLER_PACKAGES, SAMPLERS, check_sampler, make_sampler

HAS_CMAES = importlib.util.find_spec("cmaes") is not None
HAS_TORCH = importlib.util.find_spec("torch") is not None


def test_unknown_sampler_is_one_line_naming_the_choices() -> None:
    for call in (lambda: make_sampler("bogus", 0), lambda: StudySettings(sampler="bogus")):
        with pytest.raises(InputError) as info:
            call()
        msg = str(info.value)
        assert "\n" not in msg and "'bogus'" in msg
        assert all(name in msg for name in SAMPLERS)


@pytest.mark.parametrize(
    ("kind", "cls"),
    [
        ("tpe", optuna.samplers.TPESampler),
        ("random", optuna.samplers.RandomSampler),
        pytest.param(
            "cmaes",
            optuna.samplers.CmaEsSampler,
            marks=pytest.mark.skipif(not HAS_CMAES, reason="cmaes not installed"),
        ),
        pytest.param(
            "gp",
            optuna.samplers.GPSampler,
            marks=pytest.mark.skipif(not HAS_TORCH, reason="torch not installed"),
        ),
    ],
)
def test_each_name_gives_its_optuna_sampler(kind: str, cls: type) -> None:
    assert isinstance(make_sampler(kind, 3), cls)
    assert check_sampler(kind) == kind


@pytest.mark.parametrize("kind", sorted(SAMPLER_PACKAGES))
def test_a_missing_package_is_one_line_before_any_study(
    kind: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    package = SAMPLER_PACKAGES[kind]
    real = importlib.util.find_spec

    def find_spec(name: str, *args: object) -> object:
        return None if name == package else real(name, *args)

    monkeypatch.setattr(importlib.util, "find_spec", find_spec)
    for call in (
        lambda: make_sampler(kind, 0),
        lambda: StudySettings(sampler=kind, storage=f"sqlite:///{tmp_path}/s.db"),
    ):
        with pytest.raises(InputError, match=f"sampler '{kind}' needs the Python package"):
            call()
    assert not (tmp_path / "s.db").exists()  # refused in the settings: no study touched


@pytest.mark.skipif(not HAS_CMAES, reason="cmaes not installed")
def test_cmaes_resumes_one_optimizer_across_the_per_trial_samplers(tmp_path: Path) -> None:
    # A worker makes a fresh sampler for every trial (its seed depends on the trial number);
    # CMA-ES keeps its state in the trials, so the generations must advance. 12 parameters:
    # population 4 + floor(3 ln 12) = 11, so 1 start-up + 40 trials reach generation 3.
    s = StudySettings(
        model="cv",
        n_trials=41,
        storage=f"memory://{tmp_path}-cma",
        objective="quadratic",
        objective_options={"n_trajectories": 5},
        sampler="cmaes",
        pruner="none",
    )
    prepare_study(s)
    run_worker(s.storage, s.name, seed=4)
    summaries, best = study_progress(s.storage, s.name)
    assert len(summaries) == 41
    trials = optuna.load_study(study_name=s.name, storage=open_storage(s.storage)).trials
    generations = [t.system_attrs.get("cma:generation") for t in trials]
    assert generations[0] is None  # the random start-up trial
    assert max(g for g in generations if g is not None) == 3
    # generation g holds the population of 11 trials, in order
    assert generations[1:12] == [0] * 11 and generations[12:23] == [1] * 11
    assert best is not None and best.value < max(t.value for t in summaries)
