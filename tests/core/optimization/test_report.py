"""The report: Table I numbers are the re-tracked losses of the best trials, files are complete."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from core.evaluation import evaluate as evaluate_table
from core.optimization import StudySettings, prepare_study, run_worker
from core.optimization.report import PAPER_TABLE_I, write_report
from core.tracking import TrackerParams, track_dataset
from core.tracking.synthetic import synthetic_dataset


def test_report_from_two_small_studies(tmp_path: Path) -> None:
    train = synthetic_dataset(seed=1, n_per_class=1, n_frames=50)
    other = synthetic_dataset(seed=2, n_per_class=1, n_frames=50)
    train.save(tmp_path / "train.npz")
    other.save(tmp_path / "other.npz")
    url = f"memory://{tmp_path}"
    for model in ("cv", "ca"):
        s = StudySettings(model=model, n_trials=3, storage=url, study_name=f"{model}-main",
                          dataset=str(tmp_path / "train.npz"))  # fmt: skip
        prepare_study(s, dataset_path=s.dataset)
        run_worker(url, s.name, seed=0)
    r = write_report(url, tmp_path / "out", generalisation_dataset=str(tmp_path / "other.npz"))
    for name in ("report.md", "report.json", "best_cv.json", "best_ca.json", "tracks.png",
                 "loss_vs_time_cv.png", "loss_vs_time_ca.png"):  # fmt: skip
        assert (tmp_path / "out" / name).stat().st_size > 0, name
    assert not list((tmp_path / "out").glob(".*tmp*"))
    for model in ("cv", "ca"):
        params = TrackerParams.load(tmp_path / "out" / f"best_{model}.json")
        ev = evaluate_table(train, track_dataset(train, params))
        m = r["models"][model]
        assert m["training"]["loss_total"] == pytest.approx(ev.loss_total, rel=1e-12)
        # the objective's value of the best trial is the same L_t
        assert m["best_value_in_study"] == pytest.approx(ev.loss_total, rel=1e-12)
        gen = evaluate_table(other, track_dataset(other, params))
        assert m["generalisation"]["loss_total"] == pytest.approx(gen.loss_total, rel=1e-12)
    cv, ca = (r["models"][m]["training"]["loss_total"] for m in ("cv", "ca"))
    assert r["conclusion"]["cv_over_ca"] == pytest.approx(cv / ca)
    assert r["conclusion"]["cv_not_worse_than_ca_by_more_than_5_percent"] == (cv <= 1.05 * ca)
    md = (tmp_path / "out" / "report.md").read_text()
    assert f"{PAPER_TABLE_I['cv']['total']:.3f}" in md and f"{cv * 1e3:.4f}" in md
    assert json.loads((tmp_path / "out" / "report.json").read_text())["models"].keys() == {
        "cv",
        "ca",
    }


def test_report_on_a_two_person_data_set(tmp_path: Path) -> None:
    """Studies and the report on several persons: the best value is the multi-person loss of
    the re-tracked run; GOSPA, count error, identities and one row per person are reported."""
    from dataclasses import replace

    import numpy as np

    base = synthetic_dataset(seed=3, n_per_class=1, classes="ab", n_frames=40)
    second = base.truth_xy_m + [1.5, 0.0]
    second[:10] = np.nan  # person 1 absent from the first frames
    v = base.truth_v_mps.copy()
    v[:10] = np.nan
    train = replace(base, truth_xy_m=np.concatenate((base.truth_xy_m, second), axis=1),
                    truth_v_mps=np.concatenate((base.truth_v_mps, v), axis=1))  # fmt: skip
    train.save(tmp_path / "two.npz")
    url = f"memory://{tmp_path}"
    s = StudySettings(model="cv", n_trials=2, storage=url, study_name="cv-two",
                      dataset=str(tmp_path / "two.npz"))  # fmt: skip
    prepare_study(s, dataset_path=s.dataset)
    run_worker(url, s.name, seed=0)
    r = write_report(url, tmp_path / "out", generalisation_dataset=None)
    m = r["models"]["cv"]
    params = TrackerParams.load(tmp_path / "out" / "best_cv.json")
    ev = evaluate_table(train, track_dataset(train, params, with_tracks=True))
    assert m["best_value_in_study"] == pytest.approx(ev.loss_total, rel=1e-12)
    assert [p["person"] for p in m["training"]["persons"]] == [0, 1]
    assert m["training"]["persons"][1]["frames_present"] == train.n_frames - 10
    md = (tmp_path / "out" / "report.md").read_text()
    assert "## Persons: GOSPA, people count, identities" in md and "2 persons per" in md
    assert "nan" not in md.lower()


def test_report_after_repeats_uses_the_validated_choice(tmp_path: Path) -> None:
    """Studies trained on their own sets (tune --repeats): Table I is re-made on the shared
    validation set with the trial validation chose, not with the best training trial; without
    validation such studies are refused with one line."""
    from core.errors import InputError
    from core.optimization.validation import validate_study

    paths = {}
    for name, seed in (("t0", 1), ("t1", 2), ("val", 3)):
        paths[name] = str(tmp_path / f"{name}.npz")
        synthetic_dataset(seed=seed, n_per_class=1, n_frames=40).save(paths[name])
    url = f"memory://{tmp_path}"
    for i in (0, 1):
        s = StudySettings(model="cv", n_trials=4, storage=url, study_name=f"cv-r{i}",
                          dataset=paths[f"t{i}"], pruner="none")  # fmt: skip
        prepare_study(s, dataset_path=s.dataset)
        run_worker(url, s.name, seed=i)
    with pytest.raises(InputError, match="not all validated on one set"):
        write_report(url, tmp_path / "refused", generalisation_dataset=None)
    assert not (tmp_path / "refused").exists()  # nothing written
    tops = [validate_study(url, f"cv-r{i}", paths["val"], top_k=4)[0] for i in (0, 1)]
    chosen = min(tops, key=lambda v: (v.validation_value, v.study, v.number))
    r = write_report(url, tmp_path / "out", generalisation_dataset=None)
    m = r["models"]["cv"]
    assert r["training_dataset"]["role"] == "validation"
    assert (m["study"], m["best_trial"], m["chosen_by"]) == (
        chosen.study,
        chosen.number,
        "validation",
    )
    val = synthetic_dataset(seed=3, n_per_class=1, n_frames=40)
    ev = evaluate_table(val, track_dataset(val, TrackerParams.from_dict(chosen.params)))
    # Table I on the validation set is the chosen trial's validation L_t
    assert m["training"]["loss_total"] == pytest.approx(ev.loss_total, rel=1e-12)
    assert m["training"]["loss_total"] == pytest.approx(chosen.validation_paper_loss, rel=1e-12)
    assert (
        "validation set the studies chose their parameters on"
        in (tmp_path / "out" / "report.md").read_text()
    )
