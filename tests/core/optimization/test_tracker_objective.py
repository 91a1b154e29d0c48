"""The tracker objective: per-trajectory evaluation equals the whole-data-set evaluation."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from core.evaluation import evaluate as evaluate_table
from core.optimization import StudySettings, prepare_study, run_worker, study_progress
from core.optimization.objective import TrackerLosses, evaluate
from core.tracking import TrackerParams, track_dataset
from core.tracking.synthetic import synthetic_dataset


@pytest.fixture(scope="module")
def dataset():
    return synthetic_dataset(seed=3, n_per_class=1, n_frames=60)


def test_objective_equals_the_papers_total_loss(dataset) -> None:
    params = TrackerParams(model="cv").to_dict()
    res = evaluate(TrackerLosses(dataset), params)
    table = evaluate_table(dataset, track_dataset(dataset, TrackerParams.from_dict(params)))
    # eq. (14): L_t = mean_k L(k), independent of the order the trajectories are tracked in
    assert res.value == pytest.approx(table.loss_total, rel=1e-12)
    assert sorted(res.order) == list(range(dataset.n_trajectories))
    np.testing.assert_allclose(sorted(res.losses), sorted(table.loss), rtol=1e-12)
    assert 0 < res.value < 1e-2  # a tracked synthetic walk, far below the no-track score 1.0


def test_study_on_the_tracker_reproduces_its_best_value(dataset, tmp_path: Path) -> None:
    path = tmp_path / "synthetic.npz"
    dataset.save(path)
    s = StudySettings(
        model="ca", n_trials=3, storage=f"memory://{tmp_path}", dataset=str(path), pruner="none"
    )
    prepare_study(s, dataset_path=str(path))
    run_worker(s.storage, s.name, seed=0)
    summaries, best = study_progress(s.storage, s.name)
    assert [t.state for t in summaries] == ["COMPLETE"] * 3
    again = evaluate(TrackerLosses(dataset), best.tracker_params("ca")).value
    assert again == best.value
