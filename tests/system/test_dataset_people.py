"""``radartune dataset --persons N``: a multi-person data set for studies, reproducible by seed,
and a short study on it with the multi-person loss."""

from __future__ import annotations

import hashlib
import json
import math

import numpy as np
import pytest

from core.cli import main
from core.dataset import Dataset
from core.scene import paper_scenes


def _make(tmp_path, seed: int, name: str, persons: int = 2) -> Dataset:
    out = tmp_path / name
    args = ["dataset", "--out", str(out), "--seed", str(seed), "--trajectories", "3"]
    args += ["--persons", str(persons), "--fidelity", "measurement", "--no-cache", "--jobs", "1"]
    assert main(args) == 0
    return out


@pytest.fixture(scope="module")
def two(tmp_path_factory):
    return _make(tmp_path_factory.mktemp("people"), 3, "a.npz")


def test_same_seed_same_bytes_other_seed_different(two, tmp_path) -> None:
    again = _make(tmp_path, 3, "b.npz")
    other = _make(tmp_path, 4, "c.npz")
    digest = [hashlib.sha256(p.read_bytes()).hexdigest() for p in (two, again, other)]
    assert digest[0] == digest[1] != digest[2]


def test_persons_and_classes(two) -> None:
    ds = Dataset.load(two)
    assert ds.n_persons == 2 and ds.trajectory_class.tolist() == ["a", "b", "c"]
    # person j of trajectory k walks class abcde[(k + j) % 5]; person 0 is the one-person set's
    multi, single = paper_scenes(3, 3, n_persons=2), paper_scenes(3, 3)
    for k, (m, s) in enumerate(zip(multi, single)):
        assert [p.trajectory.trajectory_class for p in m.persons] == ["abcde"[k], "abcde"[k + 1]]
        np.testing.assert_array_equal(
            m.persons[0].trajectory.position_m, s.persons[0].trajectory.position_m
        )
        assert m.seed == s.seed
    # each person is present from frame 0 of its trajectory; NaN once its trajectory has ended
    off = ds.trajectory_offsets
    assert np.isfinite(ds.truth_xy_m[off[:-1]]).all()


@pytest.mark.parametrize("n", [0, 9])
def test_persons_out_of_range_is_one_line(n, tmp_path, capsys) -> None:
    out = tmp_path / "x.npz"
    assert main(["dataset", "--out", str(out), "--persons", str(n)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--persons must be in [1, 8]" in err[0]
    assert not out.exists()


def test_study_on_two_person_set_gives_finite_losses(two, tmp_path, capsys) -> None:
    from core.optimization.objective import TrackerLosses, evaluate
    from core.tracking import TrackerParams

    ds = Dataset.load(two)
    losses = TrackerLosses(ds).losses(TrackerParams.default("cv").to_dict(), [0, 1, 2])
    assert all(math.isfinite(s.loss) and 0 < s.loss <= 1.0 for s in losses)
    assert all(math.isfinite(s.capped) and 0 <= s.capped <= 0.5**2 for s in losses)
    # the objective is the multi-person loss: the mean over both persons of eq. (13)
    from core.evaluation import evaluate as evaluate_run
    from core.tracking import track_dataset

    ev = evaluate_run(ds, track_dataset(ds, TrackerParams.default("cv"), with_tracks=True))
    assert [s.loss for s in losses] == ev.loss.tolist()
    result = evaluate(TrackerLosses(ds), TrackerParams.default("ca").to_dict())
    assert math.isfinite(result.value) and len(result.losses) == 3
    storage = f"sqlite:///{tmp_path / 's.db'}"
    code = main(["tune", "--model", "cv", "--trials", "3", "--dataset", str(two),
                 "--storage", storage, "--no-progress"])  # fmt: skip
    assert code == 0
    best = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert math.isfinite(best["best_loss"]) and 0 < best["best_loss"] <= 1.0
