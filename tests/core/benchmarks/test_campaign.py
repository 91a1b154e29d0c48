"""``radartune bench campaign`` (core.benchmarks.campaign): pre-registered rules, a quick run.

The verdict and the objective rule are checked on numbers whose answer is known; the quick run
(two objectives, one or two tiny studies per model, three five-trajectory test sets) checks
that each study's test scores are the paper's L_t the objective itself computes, that the tables
are the statistics of those cells, and that the files are written.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from core.benchmarks import campaign


def test_verdict_is_decided_on_the_upper_and_lower_bound() -> None:
    assert campaign.verdict(0.90, 1.05) == "CV not worse than CA by more than 5 %"
    assert campaign.verdict(0.99, 1.0501) == "not settled by this design"
    assert campaign.verdict(1.0501, 1.30) == "CV worse than CA by more than 5 %"
    assert campaign.verdict(1.05, 1.30) == "not settled by this design"


def _row(median: float, cat: int, iqr: float) -> dict:
    return {"median": median, "catastrophic": cat, "seed_iqr_rel": iqr}


def test_objective_rule_ties_within_five_percent_then_catastrophic_then_spread() -> None:
    # R: paper 1, capped 0.97, median 0.99, trimmed 1.2 → capped lowest; paper and median tied
    table = {
        "paper": {"cv": _row(1.0, 5, 0.1), "ca": _row(2.0, 5, 0.1)},
        "capped": {"cv": _row(0.97, 6, 0.1), "ca": _row(1.94, 6, 0.1)},
        "median": {"cv": _row(0.99, 3, 0.5), "ca": _row(1.98, 3, 0.5)},
        "trimmed": {"cv": _row(1.2, 0, 0.0), "ca": _row(2.4, 0, 0.0)},
    }
    c = campaign.choose_objective(table)
    assert c["relative_median"]["capped"] == pytest.approx(0.97)
    assert set(c["tied"]) == {"paper", "capped", "median"}
    assert c["winner"] == "median"  # fewest catastrophic among the tied (6 of trimmed not tied)
    table["median"]["cv"]["catastrophic"] = 5
    table["median"]["ca"]["catastrophic"] = 5
    assert campaign.choose_objective(table)["winner"] == "paper"  # tie on 10: smaller spread


@pytest.fixture(scope="module")
def quick(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, Path]:
    root = tmp_path_factory.mktemp("campaign")
    mp = pytest.MonkeyPatch()
    mp.setenv("RADARTUNE_CAMPAIGN_DIR", str(root / "work"))
    mp.chdir(root)
    try:
        result = campaign.run(quick=True)
    finally:
        mp.undo()
    return result, root


@pytest.mark.slow
def test_quick_run_scores_are_the_objectives_paper_loss(quick: tuple[dict, Path]) -> None:
    from core.dataset import Dataset
    from core.optimization.objective import TrackerLosses, evaluate

    result, _ = quick
    s = campaign.QUICK
    recs = result["objectives"]["records"]
    assert len(recs) == len(s.objectives) * 2 * len(s.compare_seeds)
    test0 = Dataset.load(result["data"]["test"][0])
    val = Dataset.load(result["data"]["validation"])
    for r in recs:
        assert len(r["loss"]["total"]) == s.n_test
        # the test score at ρ × 1 is L_t (eq. 14) as the study objective computes it
        assert r["loss"]["total"][0] == pytest.approx(
            evaluate(TrackerLosses(test0), r["params"]).paper_value, rel=1e-12
        )
        assert r["validation_paper_loss"] == pytest.approx(
            evaluate(TrackerLosses(val), r["params"]).paper_value, rel=1e-12
        )
        assert 0 <= r["never"][0] + r["clutter"][0] <= s.n_trajectories


@pytest.mark.slow
def test_quick_run_tables_are_the_statistics_of_the_cells(quick: tuple[dict, Path]) -> None:
    result, root = quick
    f = result["final"]
    assert result["objectives"]["choice"]["winner"] in campaign.QUICK.objectives
    for m in campaign.MODELS:
        recs = sorted((r for r in f["records"] if r["model"] == m), key=lambda r: r["seed"])
        cells = np.array([r["loss"]["total"] for r in recs])
        assert f["table"][m]["total"]["median"] == pytest.approx(np.median(cells))
        assert f["table"][m]["total"]["mean"] == pytest.approx(np.mean(cells))
        t = f["table"][m]["total"]
        assert t["median_lo"] <= t["median"] <= t["median_hi"]
        best = json.loads(
            (root / "bench/results/campaign-quick/params" / f"best_{m}.json").read_text()
        )
        assert best == f["chosen"][m]["params"]
    cv = np.array([r["loss"]["total"] for r in f["records"] if r["model"] == "cv"])
    ca = np.array([r["loss"]["total"] for r in f["records"] if r["model"] == "ca"])
    r = f["ratios"]["total"]
    assert r["median_ratio"] == pytest.approx(np.median(cv) / np.median(ca))
    assert f["verdict"] == campaign.verdict(r["median_ratio_lo"], r["median_ratio_hi"])
    for name in ("campaign.md", "test_sets.png", "table1.png", "objectives.png"):
        assert (root / "bench/results/campaign-quick" / name).stat().st_size > 0


@pytest.mark.slow
def test_quick_run_lambda_check_is_the_plain_score_at_factor_one(
    quick: tuple[dict, Path],
) -> None:
    from core.dataset import Dataset
    from core.evaluation.robustness import scene_clutter_rate

    result, _ = quick
    s = campaign.QUICK
    test0 = Dataset.load(result["data"]["test"][0])
    lam = result["data"]["lambda"]
    assert sorted(lam) == sorted(str(f) for f in campaign.LAMBDA_FACTORS)
    for f, paths in lam.items():
        assert len(paths) == s.n_lambda
        # λ' = f · λ: the variant's scenes carry the scaled scene clutter rate
        assert scene_clutter_rate(Dataset.load(paths[0])) == pytest.approx(
            float(f) * scene_clutter_rate(test0), rel=1e-12
        )
    for r in (*result["objectives"]["records"], *result["final"]["records"]):
        for f in lam:
            assert len(r["lambda"][f]["total"]) == s.n_lambda
            assert 0 <= r["lambda"][f]["catastrophic"][0] <= s.n_trajectories
        # the same test set at λ × 1 is the plain score exactly, catastrophic runs included
        one = campaign.score_lambda(r["params"], {"1.0": [test0]})["1.0"]
        assert one["total"][0] == r["loss"]["total"][0]
        assert one["catastrophic"][0] == r["never"][0] + r["clutter"][0]
    for o, per in result["objectives"]["table"].items():
        for m in campaign.MODELS:
            recs = [x for x in result["objectives"]["records"]
                    if x["objective"] == o and x["model"] == m]  # fmt: skip
            x = per[m]["lambda"]["factors"]
            cells1 = np.array([sorted(recs, key=lambda r: r["seed"])[i]["loss"]["total"][:1]
                               for i in range(len(recs))])  # fmt: skip
            assert x["1.0"]["median"] == np.median(cells1)
            for f in lam:
                cells = np.array([r["lambda"][f]["total"] for r in recs])
                assert x[f]["median"] == pytest.approx(np.median(cells), rel=1e-12)
                assert x[f]["ratio"] == pytest.approx(np.median(cells) / np.median(cells1))
                lo, hi = x[f]["ratio_ci95"]
                assert lo <= x[f]["ratio"] <= hi


@pytest.mark.slow
def test_add_lambda_adds_the_same_scores_and_changes_nothing_else(
    quick: tuple[dict, Path],
) -> None:
    result, _ = quick
    stripped = json.loads(json.dumps(result))
    del stripped["data"]["lambda"]
    for r in (*stripped["objectives"]["records"], *stripped["final"]["records"]):
        del r["lambda"]
    for per in stripped["objectives"]["table"].values():
        for m in campaign.MODELS:
            del per[m]["lambda"]
    for m in campaign.MODELS:
        del stripped["final"]["models"][m]["lambda"]
    assert campaign.lambda_table(stripped) == ""
    added = campaign.add_lambda(stripped, quick=True)
    assert added == json.loads(json.dumps(result))
    assert "λ×2" in campaign.lambda_table(added)


def test_lambda_only_bad_input_is_one_line_and_exit_2(tmp_path: Path, capsys) -> None:
    from core.cli import main

    out = ["--out-dir", str(tmp_path)]
    assert main(["bench", "track", "--lambda-only", *out]) == 2
    assert main(["bench", "campaign", "--lambda-only", *out]) == 2  # no campaign.json
    (tmp_path / "campaign.json").write_text('{"settings": {}}')
    before = (tmp_path / "campaign.json").read_text()
    assert main(["bench", "campaign", "--lambda-only", *out]) == 2  # not a campaign result
    assert (tmp_path / "campaign.json").read_text() == before  # nothing half-written
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 3 and "Traceback" not in "".join(err)
