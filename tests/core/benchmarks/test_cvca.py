"""``radartune bench cvca`` (core.benchmarks.cvca): its figures agree with the definitions.

The quick data set (the first five paper:0 trajectories, one per class) is tracked with the
default CV and CA parameters and with CV against itself. The loss of eq. (14) comes out of two
independent implementations (core.evaluation and core.evaluation.loss_breakdown); they
must agree, the breakdown's parts must add up, and the paired ratio is the ratio of the totals.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from core.benchmarks import cvca
from core.tracking import TrackerParams

ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="module")
def result() -> dict:
    sets = cvca.datasets(quick=True)
    params = cvca.pairs(quick=True)
    cv = params["defaults"][0]
    return cvca.table(sets, {**params, "cv against itself": (cv, cv)}, cvca.QUICK_Q_GRID)


def _rows(result: dict, parameters: str) -> list[dict]:
    return [r for r in result["rows"] if r["parameters"] == parameters]


def test_quick_set_is_one_trajectory_per_class(result: dict) -> None:
    (info,) = result["datasets"].values()
    assert info["trajectories"] == cvca.QUICK_TRAJECTORIES
    (row,) = _rows(result, "defaults")
    classes = [c["class"] for c in row["breakdown"]["cv"]]
    assert classes == ["A", "B", "C", "D", "E", "total"]
    assert all(c["n_trajectories"] == 1 for c in row["breakdown"]["cv"][:-1])
    # the person is seen: its points lie within decimetres of the truth
    assert 0 < info["spread"]["rms_position_m"] < 0.5


def test_totals_are_the_mean_of_the_trajectory_losses(result: dict) -> None:
    for row in result["rows"]:
        loss = {m: np.asarray(v) for m, v in row["trajectory_loss"].items()}
        for m in ("cv", "ca"):
            assert row[f"{m}_x1e3"] == pytest.approx(1e3 * loss[m].mean(), rel=1e-12)
        # eq. (14) ratio: L_t(CV) / L_t(CA)
        assert row["paired"]["ratio"] == pytest.approx(loss["cv"].mean() / loss["ca"].mean())
        assert row["paired"]["wins_a"] == int(np.sum(loss["cv"] < loss["ca"]))
        assert row["paired"]["wins_b"] == int(np.sum(loss["ca"] < loss["cv"]))


def test_breakdown_agrees_with_the_evaluation_and_adds_up(result: dict) -> None:
    for row in result["rows"]:
        for m in ("cv", "ca"):
            loss = np.asarray(row["trajectory_loss"][m])
            *per_class, total = row["breakdown"][m]
            # two implementations of eqs. (12)-(14): evaluation and the breakdown
            assert total["loss"] == pytest.approx(loss.mean(), rel=1e-9)
            for c in per_class:
                assert c["n_c"] > 0  # every quick trajectory is confirmed
                parts = ("transient", "manoeuvre", "steady")
                assert sum(c[f"loss_{p}"] for p in parts) == pytest.approx(c["loss"], rel=1e-9)
                assert sum(c[f"frames_{p}"] for p in parts) == pytest.approx(c["n_c"])


def test_a_model_against_itself_is_a_tie(result: dict) -> None:
    (row,) = _rows(result, "cv against itself")
    p = row["paired"]
    assert p["ratio"] == 1.0 and p["ci_low"] == 1.0 and p["ci_high"] == 1.0
    assert p["wins_a"] == p["wins_b"] == 0
    assert row["trajectory_loss"]["cv"] == row["trajectory_loss"]["ca"]
    (defaults,) = _rows(result, "defaults")
    # the same CV run as in the defaults pair: tracking is deterministic
    assert row["trajectory_loss"]["cv"] == defaults["trajectory_loss"]["cv"]


def test_matched_comparison_scans_q_around_the_other_parameters(result: dict) -> None:
    for row in result["rows"]:
        m = row["matched_cv_with_ca_params"]
        assert m["best_x1e3"] == pytest.approx(1e3 * min(m["loss_total"]), rel=1e-12)
        assert m["best_q"] == m["q_grid"][int(np.argmin(m["loss_total"]))]
        ratio = m["best_x1e3"] / row["ca_x1e3"]
        assert m["paired_with_ca"]["ratio"] == pytest.approx(ratio, rel=1e-9)
    # swapping a CV parameter set to CV changes nothing: at its own q it scores its own L_t
    (row,) = _rows(result, "cv against itself")
    m = row["matched_cv_with_ca_params"]
    own = m["q_grid"].index(TrackerParams(model="cv").q_coeff)
    assert m["loss_total"][own] == pytest.approx(row["cv_x1e3"] / 1e3, rel=1e-12)
    assert m["best_x1e3"] <= row["cv_x1e3"]


def test_result_is_json_and_summary_has_a_line_per_row(result: dict) -> None:
    text = json.dumps(result, allow_nan=False)
    assert json.loads(text)["rows"][0]["dataset"] == "paper:0 (first 5)"
    lines = cvca.summary(result).splitlines()
    assert len(lines) == 1 + len(result["rows"])
    assert "CV/CA 1.00 [1.00, 1.00]  wins 0/0" in lines[-1]


def test_committed_pairs_load_with_their_models() -> None:
    pairs = cvca.available_pairs(ROOT)
    assert len(pairs) >= 2  # docs/report/best_*.json and current-chain at least
    for p_cv, p_ca in pairs.values():
        assert isinstance(p_cv, TrackerParams) and p_cv.model == "cv"
        assert p_ca.model == "ca"
