"""Held-out validation: seeds kept apart, radar configurations checked, the choice by validation."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest

from core.errors import InputError
from core.optimization import StudySettings, prepare_study, run_worker, study_progress
from core.optimization.objective import TrackerLosses, evaluate
from core.optimization.validation import (
    VALIDATION_SEED,
    check_same_radar,
    check_training_seed,
    validate_study,
)
from core.tracking.synthetic import synthetic_dataset


@pytest.fixture(scope="module")
def sets(tmp_path_factory) -> tuple[str, str]:
    d = tmp_path_factory.mktemp("sets")
    train, val = d / "train.npz", d / "val.npz"
    synthetic_dataset(seed=3, n_per_class=1, n_frames=60).save(train)
    synthetic_dataset(seed=4, n_per_class=1, n_frames=60).save(val)
    return str(train), str(val)


def test_training_seeds_stay_below_the_validation_seed() -> None:
    check_training_seed(0, 8)
    check_training_seed(VALIDATION_SEED - 3, 3)
    with pytest.raises(InputError, match="validation and test"):
        check_training_seed(VALIDATION_SEED - 2, 3)
    with pytest.raises(InputError, match="--repeats must be >= 1, got 0"):
        check_training_seed(0, 0)


def test_a_set_of_another_radar_is_refused(sets, tmp_path: Path) -> None:
    train, val = sets
    check_same_radar(train, val, "validation")  # same radar: accepted
    from core.dataset import Dataset

    ds = Dataset.load(val)
    radar = json.loads(ds.radar_json) if ds.radar_json else {}
    radar["frame_period_s"] = 0.05
    other = tmp_path / "other.npz"
    dataclasses.replace(ds, radar_json=json.dumps(radar)).save(other)
    with pytest.raises(InputError, match="validation data set .* another radar configuration"):
        check_same_radar(train, str(other), "validation")


def test_validation_chooses_the_best_held_out_trial(sets, tmp_path: Path, monkeypatch) -> None:
    train, val = sets
    s = StudySettings(
        model="cv", n_trials=6, storage=f"sqlite:///{tmp_path}/s.db", dataset=train, pruner="none"
    )
    prepare_study(s, dataset_path=train)
    run_worker(s.storage, s.name, seed=0)
    validated = validate_study(s.storage, s.name, val, top_k=4)
    assert len(validated) == 4
    # sorted by validation value; each value is what tracking the validation set gives
    values = [v.validation_value for v in validated]
    assert values == sorted(values)
    from core.dataset import Dataset

    losses = TrackerLosses(Dataset.load(val))
    for v in validated:
        assert evaluate(losses, v.params, loss=s.loss).value == v.validation_value
    # the four validated trials are the four best by training loss
    summaries, _ = study_progress(s.storage, s.name)
    best4 = sorted(t.value for t in summaries if t.state == "COMPLETE")[:4]
    assert sorted(v.train_value for v in validated) == best4
    # a second call reads the values recorded in the study instead of tracking again
    import core.optimization.validation as validation

    def no_tracking(*args, **kwargs):
        raise AssertionError("tracked again")

    monkeypatch.setattr(validation, "evaluate", no_tracking)
    assert validate_study(s.storage, s.name, val, top_k=4) == validated
    # another objective is validated afresh
    with pytest.raises(AssertionError, match="tracked again"):
        s2 = dataclasses.replace(s, loss="capped", study_name="other")
        prepare_study(s2, dataset_path=train)
        run_worker(s2.storage, s2.name, seed=0)
        validate_study(s2.storage, s2.name, val, top_k=1)
