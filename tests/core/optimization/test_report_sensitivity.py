"""The report's sensitivity sections, and the paper data set with another scene clutter rate."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from core.dataset import Dataset
from core.errors import InputError
from core.evaluation.robustness import scene_clutter_rate
from core.optimization import StudySettings, prepare_study, run_worker
from core.optimization.data import paper_dataset_variant
from core.optimization.report import write_report
from core.tracking.synthetic import synthetic_dataset


def test_report_sensitivity_sections(tmp_path: Path) -> None:
    train = synthetic_dataset(seed=1, n_per_class=1, classes="abc", n_frames=45)
    other = synthetic_dataset(seed=2, n_per_class=1, classes="abc", n_frames=45)
    train.save(tmp_path / "train.npz")
    other.save(tmp_path / "other.npz")
    url = f"memory://{tmp_path}"
    for model, n in (("cv", 12), ("ca", 3)):
        s = StudySettings(model=model, n_trials=n, storage=url, study_name=f"{model}-main",
                          dataset=str(tmp_path / "train.npz"), pruner="none")  # fmt: skip
        prepare_study(s, dataset_path=s.dataset)
        run_worker(url, s.name, seed=0)
    out = tmp_path / "out"
    r = write_report(url, out, generalisation_dataset=str(tmp_path / "other.npz"),
                     sensitivity=True, sensitivity_points=2)  # fmt: skip
    e = r["sensitivity"]
    assert e["evaluator"] == "PED-ANOVA"
    # CV has 12 completed trials: an importance; CA's 3 are too few, and the report says so
    assert [i["study"] for i in e["models"]["cv"]["importance"]] == ["cv-main"]
    assert "at least 10" in e["models"]["ca"]["importance_skipped"][0]["reason"]
    for model in ("cv", "ca"):
        m = e["models"][model]
        best = r["models"][model]
        # the sweeps pass through the chosen trial's own value, on the training set
        for sweep in m["oat"]["training"].values():
            assert sweep["loss"][sweep["optimum_index"]] == best["best_value_in_study"]
        assert set(m["oat"]) == {"training", "held-out"}
        held = m["oat"]["held-out"]["r11"]
        assert held["loss"][held["optimum_index"]] == pytest.approx(
            best["generalisation"]["loss_total"], rel=1e-12
        )
        rows = {(row["dataset"], row["rho_factor"]): row for row in m["clutter"]["rows"]}
        # ρ ×1 on the training set is Table I's evaluation of the same parameters
        assert rows[("training", 1.0)]["loss_total"] == best["training"]["loss_total"]
        assert len(rows) == 2 * 5  # no λ variants of a synthetic set
        assert (out / f"sensitivity_{model}.png").stat().st_size > 0
    assert (out / "importance_cv.png").stat().st_size > 0
    assert not (out / "importance_ca.png").exists()
    assert any("not a paper data set" in n for n in e["notes"])
    md = (out / "report.md").read_text()
    for heading in ("## Sensitivity", "### Parameter importance (PED-ANOVA)",
                    "### One parameter at a time", "### Clutter robustness"):  # fmt: skip
        assert heading in md
    assert "nan" not in md.lower()
    assert "sensitivity" in json.loads((out / "report.json").read_text())
    # a "held-out" set some study trained on is named in a note
    r = write_report(url, tmp_path / "out3", generalisation_dataset=str(tmp_path / "train.npz"),
                     sensitivity=True, sensitivity_points=0, clutter_variants=False)  # fmt: skip
    assert any("is the training set of ca-main, cv-main" in n for n in r["sensitivity"]["notes"])
    assert "oat" not in r["sensitivity"]["models"]["cv"]
    r = write_report(url, tmp_path / "out2", generalisation_dataset=None, sensitivity=False)
    assert "sensitivity" not in r
    assert "## Sensitivity" not in (tmp_path / "out2" / "report.md").read_text()


def test_paper_dataset_variant_scales_the_scene_clutter_only() -> None:
    from core.pipeline import paper_dataset_file

    path = str(paper_dataset_file(0, 1, fidelity="measurement"))
    assert paper_dataset_variant(path) == path  # λ ×1: the paper data set itself
    base = Dataset.load(path)
    double = Dataset.load(paper_dataset_variant(path, clutter_factor=2.0))
    assert scene_clutter_rate(base) == 0.02
    assert scene_clutter_rate(double) == pytest.approx(0.04, rel=1e-15)
    # the same trajectory and truth; twice the Poisson clutter reflectors on average
    np.testing.assert_array_equal(double.truth_xy_m, base.truth_xy_m)
    n1, n2 = (int(np.sum(d.source == -1)) for d in (base, double))
    assert n1 > 100 and 1.6 < n2 / n1 < 2.4
    with pytest.raises(InputError, match="clutter_factor"):
        paper_dataset_variant(path, clutter_factor=0.0)


def test_paper_dataset_variant_refuses_a_set_that_is_not_a_paper_set(tmp_path: Path) -> None:
    synthetic_dataset(seed=1, n_per_class=1, n_frames=45).save(tmp_path / "s.npz")
    with pytest.raises(InputError, match="not a paper data set"):
        paper_dataset_variant(str(tmp_path / "s.npz"), clutter_factor=2.0)


@pytest.mark.parametrize("points", ["1", "201", "-3"])
def test_cli_refuses_a_bad_sweep_size_before_anything_is_written(
    tmp_path: Path, capsys, points: str
) -> None:
    from core.cli import main

    code = main(["report", "--storage", f"sqlite:///{tmp_path}/none.db", "--out",
                 str(tmp_path / "out"), "--sensitivity-points", points])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 2 and len(err.splitlines()) == 1 and "--sensitivity-points" in err
    assert not (tmp_path / "out").exists() and not (tmp_path / "none.db").exists()
