"""Test data sets: per-set scores are the tracked losses, summaries and ratios bracket them."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from core.errors import InputError
from core.evaluation import evaluate as evaluate_table
from core.evaluation.intervals import bootstrap_interval
from core.optimization.testsets import compare_models, score_test_sets, summarise
from core.tracking import TrackerParams, track_dataset
from core.tracking.synthetic import synthetic_dataset

CV = TrackerParams(model="cv").to_dict()
CA = TrackerParams(model="ca").to_dict()


@pytest.fixture(scope="module")
def paths(tmp_path_factory) -> list[str]:
    d = tmp_path_factory.mktemp("tests")
    out = []
    for seed in (11, 12, 13):
        p = d / f"s{seed}.npz"
        synthetic_dataset(seed=seed, n_per_class=1, classes="abc", n_frames=40).save(p)
        out.append(str(p))
    return out


@pytest.fixture(scope="module")
def scores(paths) -> dict[str, list]:
    return {
        m: score_test_sets(p, paths, training_path=paths[0]) for m, p in (("cv", CV), ("ca", CA))
    }


def test_per_set_totals_are_the_tracked_loss(paths, scores) -> None:
    from core.dataset import Dataset

    for path, s in zip(paths, scores["cv"], strict=True):
        ds = Dataset.load(path)
        ev = evaluate_table(ds, track_dataset(ds, TrackerParams.from_dict(CV)))
        assert s.loss["total"] == pytest.approx(ev.loss_total, rel=1e-12)
        rows = {r["class"]: r["loss"] for r in ev.to_dict()["table"]}
        for c in "ABC":
            assert s.loss[c] == pytest.approx(rows[c], rel=1e-12)
        # one trajectory per class: the total is the mean of the three classes
        assert s.loss["total"] == pytest.approx(np.mean([s.loss[c] for c in "ABC"]))
        assert 0.0 <= s.unconfirmed["total"] <= 1.0
        # a capped trajectory loss never exceeds c² = 0.25 m²
        assert 0.0 <= s.capped["total"] <= 0.25


def test_summary_brackets_mean_and_median(scores) -> None:
    summ = summarise(scores["cv"])
    assert list(summ) == ["A", "B", "C", "total"]
    totals = np.array([s.loss["total"] for s in scores["cv"]])
    t = summ["total"]
    assert t.n_sets == 3
    assert t.mean == pytest.approx(totals.mean()) and t.median == pytest.approx(np.median(totals))
    assert t.mean_lo <= t.mean <= t.mean_hi
    assert t.median_lo <= t.median <= t.median_hi
    # a resampled mean or median lies within the range of the sets
    assert totals.min() <= t.mean_lo and t.mean_hi <= totals.max()
    with pytest.raises(InputError, match="metric must be one of"):
        summarise(scores["cv"], "rmse")


def test_identical_sets_give_zero_width_intervals(paths) -> None:
    s = score_test_sets(CV, [paths[0]] * 4)
    t = summarise(s)["total"]
    assert t.mean_lo == t.mean == t.mean_hi == t.median_lo == t.median_hi
    r = compare_models(s, s)
    assert r["median_ratio"] == r["median_ratio_lo"] == r["median_ratio_hi"] == 1.0
    assert r["mean_ratio"] == 1.0 and r["cv_better_sets"] == 0


def test_model_ratio_is_paired(scores) -> None:
    r = compare_models(scores["cv"], scores["ca"])
    a = np.array([s.loss["total"] for s in scores["cv"]])
    b = np.array([s.loss["total"] for s in scores["ca"]])
    assert r["median_ratio"] == pytest.approx(np.median(a) / np.median(b))
    assert r["mean_ratio"] == pytest.approx(a.mean() / b.mean())
    assert r["mean_ratio_lo"] <= r["mean_ratio"] <= r["mean_ratio_hi"]
    # paired resampling: a constant ratio between the models has a zero-width interval
    v, lo, hi = bootstrap_interval(lambda x, y: x.mean(-1) / y.mean(-1), a, 2 * a)
    assert v == lo == hi == pytest.approx(0.5)
    with pytest.raises(InputError, match="different test data sets"):
        compare_models(scores["cv"], scores["ca"][:2])


def test_a_test_set_of_another_radar_is_refused(paths, tmp_path: Path) -> None:
    from core.dataset import Dataset

    ds = Dataset.load(paths[1])
    radar = json.loads(ds.radar_json) if ds.radar_json else {}
    radar["frame_period_s"] = 0.05
    other = tmp_path / "other.npz"
    dataclasses.replace(ds, radar_json=json.dumps(radar)).save(other)
    with pytest.raises(InputError, match="test data set .* another radar configuration"):
        score_test_sets(CV, [paths[1], str(other)], training_path=paths[0])


@pytest.fixture(scope="module")
def storage(paths, tmp_path_factory) -> str:
    from core.optimization import StudySettings, prepare_study, run_worker

    d = tmp_path_factory.mktemp("studies")
    url = f"sqlite:///{d}/s.db"
    for model in ("cv", "ca"):
        s = StudySettings(model=model, n_trials=3, storage=url, study_name=f"{model}-main",
                          dataset=paths[0], pruner="none")  # fmt: skip
        prepare_study(s, dataset_path=paths[0])
        run_worker(url, s.name, seed=0)
    return url


def test_report_scores_the_chosen_parameters_on_the_test_sets(
    paths, storage, tmp_path: Path, capsys
) -> None:
    from core.cli import main
    from core.optimization.testsets import chosen_params
    from core.optimization.validation import validate_study

    # CV validated on the second set: the report takes its validated choice, CA its best trial
    validated = validate_study(storage, "cv-main", paths[1], top_k=3)
    out = tmp_path / "out"
    argv = ["report", "--storage", storage, "--out", str(out), "--generalisation", "none"]
    code = main([*argv, *(a for p in paths[1:] for a in ("--test-set", p))])
    assert code == 0, capsys.readouterr().err
    r = json.loads((out / "report.json").read_text())
    t = r["test_sets"]
    assert t["datasets"] == [Path(p).name for p in paths[1:]]
    cv, ca = t["models"]["cv"], t["models"]["ca"]
    assert (cv["chosen_by"], cv["trial"]) == ("validation", validated[0].number)
    assert ca["chosen_by"] == "training"
    params, _, number, _ = chosen_params(storage, ["ca-main"], "ca")
    assert number == ca["trial"]
    expect = score_test_sets(params, paths[1:])
    assert [s["loss"]["total"] for s in ca["per_set"]] == [s.loss["total"] for s in expect]
    assert ca["loss"]["total"]["median"] == pytest.approx(
        np.median([s.loss["total"] for s in expect])
    )
    assert t["cv_over_ca"]["n_sets"] == 2
    assert (out / "test_sets.png").stat().st_size > 0
    md = (out / "report.md").read_text()
    assert "## Test data sets (2 sets no study saw)" in md
    assert f"{ca['loss']['total']['median'] * 1e3:.4f}" in md


def test_report_bad_test_set_arguments(paths, storage, tmp_path: Path, capsys) -> None:
    from core.cli import main
    from core.dataset import Dataset

    argv = [
        "report",
        "--storage",
        storage,
        "--out",
        str(tmp_path / "o"),
        "--generalisation",
        "none",
    ]
    assert main([*argv, "--test-sets", "-1"]) == 2
    err = capsys.readouterr().err.strip()
    assert "--test-sets must be in [0, 20], got -1" in err and len(err.splitlines()) == 1
    assert not (tmp_path / "o").exists() or not any((tmp_path / "o").iterdir())
    ds = Dataset.load(paths[1])
    radar = json.loads(ds.radar_json) if ds.radar_json else {}
    radar["frame_period_s"] = 0.05
    other = tmp_path / "other.npz"
    dataclasses.replace(ds, radar_json=json.dumps(radar)).save(other)
    assert main([*argv, "--test-set", str(other)]) == 2
    err = capsys.readouterr().err.strip()
    assert "another radar configuration" in err and len(err.splitlines()) == 1
    assert not (tmp_path / "o").exists() or not any((tmp_path / "o").iterdir())


def test_default_test_sets_are_made_like_the_training_set(paths, tmp_path: Path, monkeypatch):
    """The paper test seeds, with the training set's trajectory count, person model and persons
    (the generator is replaced: no paper data set is simulated here)."""
    import core.pipeline
    from core.dataset import Dataset
    from core.optimization.testsets import default_test_paths
    from core.optimization.validation import TEST_SEEDS

    ds = Dataset.load(paths[0])
    scenes = [{"persons": [{"model": "walking"}]}] * ds.n_trajectories
    train = tmp_path / "walking.npz"
    dataclasses.replace(ds, scene_json=json.dumps(scenes)).save(train)
    calls = []

    def fake(seed, n, *, person_model, n_persons):
        calls.append((seed, n, person_model, n_persons))
        return tmp_path / f"{seed}.npz"

    monkeypatch.setattr(core.pipeline, "paper_dataset_file", fake)
    got = default_test_paths(str(train), 3)
    assert (
        got
        == [str(tmp_path / f"{s}.npz") for s in TEST_SEEDS[:3]]
        == [str(tmp_path / f"{s}.npz") for s in (2000, 2001, 2002)]
    )
    assert calls == [(s, ds.n_trajectories, "walking", 1) for s in (2000, 2001, 2002)]
    assert default_test_paths(str(train), 0) == []
    with pytest.raises(InputError, match=r"--test-sets must be in \[0, 20\], got 21"):
        default_test_paths(str(train), 21)
