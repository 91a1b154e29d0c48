"""``radartune bench cvca_seeds`` (core.benchmarks.cvca_seeds) in its quick form.

Four tiny studies (CV and CA, sampler seeds 0 and 1, 6 trials each) on the first five
trajectories of paper:0; their best parameters re-tracked on paper:0 and paper:1; the polish.
The study's objective is eq. (14) on the training set, so re-tracking a study's best trial on
that set must give its value back; the polish only accepts improvements; the comparisons are
ratios of the re-tracked totals.
"""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest

from core.benchmarks import cvca_seeds
from core.optimization.space import search_space

pytestmark = pytest.mark.slow
S = cvca_seeds.QUICK


@pytest.fixture(scope="module")
def result() -> dict:
    return cvca_seeds.run(quick=True)


def test_one_study_per_model_and_seed_with_its_trials(result: dict) -> None:
    names = {f"{m}-tpe-asha-{S.n_trials}-s{s}" for m, s in itertools.product(("cv", "ca"), S.seeds)}
    assert set(result["studies"]) == names
    for r in result["studies"].values():
        assert r["trials"] == S.n_trials
        assert 0 <= r["pruned"] < S.n_trials


def test_retracking_a_best_trial_gives_its_value_back(result: dict) -> None:
    for r in result["studies"].values():
        assert r["paper:0"] == pytest.approx(r["best_value"], rel=1e-12)
        # fewer trials than the early budget: the first 300 are all of them
        assert r[f"best_value_first_{cvca_seeds.EARLY_BUDGET}"] == r["best_value"]


def test_per_model_statistics_and_ratios(result: dict) -> None:
    for m in ("cv", "ca"):
        pm = result["per_model"][m]
        values = [result["studies"][n]["paper:1"] for n in pm["studies"]]
        assert pm["paper:1"]["median"] == pytest.approx(float(np.median(values)))
        assert pm["paper:1"]["min"] <= pm["paper:1"]["median"] <= pm["paper:1"]["max"]
    med = result["median_ratio_cv_over_ca"]
    pm = result["per_model"]
    assert med["paper:1"] == pytest.approx(
        pm["cv"]["paper:1"]["median"] / pm["ca"]["paper:1"]["median"]
    )
    for pair in result["paired"].values():
        for k in ("paper:0", "paper:1"):
            ratio = result["studies"][pair["cv"]][k] / result["studies"][pair["ca"]][k]
            assert pair[k]["ratio"] == pytest.approx(ratio, rel=1e-9)


def test_polish_only_improves_and_counts_its_evaluations(result: dict) -> None:
    best = result["paired"]["best of all seeds"]
    for m in ("cv", "ca"):
        p = result["polished"][m]
        assert p["start_study"] == best[m]
        h = p["history"]
        assert h[0] == pytest.approx(result["studies"][best[m]]["best_value"], rel=1e-12)
        assert all(b <= a for a, b in itertools.pairwise(h))
        assert p["paper:0"] == pytest.approx(h[-1], rel=1e-12)
        sweeps = len(h) - 1
        assert p["evaluations"] == 1 + sweeps * S.polish_points * len(search_space(m))
        assert p["params"]["model"] == m
    k = "paper:0"
    ratio = result["polished"]["cv"][k] / result["polished"]["ca"][k]
    assert result["polished_paired"][k]["ratio"] == pytest.approx(ratio, rel=1e-9)


def test_result_is_json_and_summarised(result: dict) -> None:
    json.dumps(result, allow_nan=False)
    text = cvca_seeds.summary(result)
    assert all(name in text for name in result["studies"])
