"""``radartune bench samplers`` (core.benchmarks.samplers) in its quick form, and its reading.

Quick: CV studies of 12 trials (TPE, random, CMA-ES when installed; ASHA and none; seeds 0, 1)
on five walking trajectories at the measurement level. A study's objective is the paper's L_t
on its training set, so an incumbent re-tracked there gives its training loss back; TPE's
first 10 trials are its random start-up, drawn with the seeds the random sampler uses.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from core.benchmarks import samplers
from core.cli import main

pytestmark = pytest.mark.slow
S = samplers.QUICK


@pytest.fixture(scope="module")
def result() -> dict:
    return samplers.run(quick=True)


def test_one_study_per_sampler_pruner_and_seed_with_all_its_trials(result: dict) -> None:
    names = {f"cv-{a}-{p}-s{s}" for a in result["samplers"] for p in S.pruners for s in S.seeds}
    assert set(result["studies"]) == names
    assert {"tpe", "random"} <= set(result["samplers"])
    for r in result["studies"].values():
        assert r["trials"] == S.n_trials and r["failed"] == 0
        assert r["complete"] + r["pruned"] == S.n_trials
        # the objective is part of the study's process time, measured inside it
        assert 0 < r["objective_cpu_s"] <= r["cpu_s"] + 1e-3


def test_incumbents_improve_in_order_and_retrack_to_their_training_loss(result: dict) -> None:
    train = samplers.HeldOut([samplers.dataset_path(S.training_seed, S)])
    for r in result["studies"].values():
        inc = r["incumbents"]
        assert inc, "the first trial of a study always completes"
        assert all(a["train_loss"] > b["train_loss"] for a, b in zip(inc, inc[1:]))
        for key in ("trials", "wall_s", "cpu_s"):
            assert all(a[key] <= b[key] for a, b in zip(inc, inc[1:])), key
        last = inc[-1]
        assert train.score(last["params"])["paper"][0] == pytest.approx(
            last["train_loss"], rel=1e-12
        )
        assert last["heldout_paper"] == pytest.approx(np.mean(last["heldout_paper_per_set"]))


def _first10(incumbents: list[dict]) -> list[tuple]:
    keys = ("trials", "number", "train_loss", "params", "heldout_paper")
    return [tuple(i[k] for k in keys) for i in incumbents if i["trials"] <= 10]


def test_tpe_starts_with_the_random_samplers_trials(result: dict) -> None:
    # make_sampler: TPE's 10 start-up trials are random draws with the trial's seed
    for p in S.pruners:
        for s in S.seeds:
            tpe = result["studies"][f"cv-tpe-{p}-s{s}"]["incumbents"]
            rnd = result["studies"][f"cv-random-{p}-s{s}"]["incumbents"]
            assert _first10(tpe) == _first10(rnd) and _first10(tpe)


def test_checkpoints_read_the_incumbent_step_function(result: dict) -> None:
    for r in result["studies"].values():
        for c in r["checkpoints"]["by_trials"]:
            want = [i["heldout_paper"] for i in r["incumbents"] if i["trials"] <= c["trials"]]
            assert c["heldout_paper"] == want[-1]
        assert r["checkpoints"]["by_trials"][-1]["trials"] == S.n_trials


def test_at_and_band_by_hand() -> None:
    inc = [{"trials": 2, "heldout_paper": 4.0}, {"trials": 5, "heldout_paper": 1.0}]
    assert math.isnan(samplers.at(inc, "trials", 1))
    assert [samplers.at(inc, "trials", x) for x in (2, 4, 5, 9)] == [4.0, 4.0, 1.0, 1.0]
    studies = [{"incumbents": [{"trials": 1, "heldout_paper": v}]} for v in (1.0, 2.0, 3.0, 9.0)]
    med, lo, hi = samplers.band(studies, "trials", np.array([0.0, 1.0]))
    assert math.isnan(med[0])
    assert (med[1], lo[1], hi[1]) == (2.5, 1.75, 4.5)  # numpy's linear quartiles


def test_render_only_rewrites_the_table_and_plot(result: dict, tmp_path) -> None:
    (tmp_path / "samplers-quick.json").write_text(json.dumps(result))
    args = ["bench", "samplers", "--render-only", "--quick", "--out-dir", str(tmp_path)]
    assert main(args) == 0
    md = (samplers.report_dir(quick=True) / "samplers.md").read_text()
    assert "| CV | TPE | asha |" in md and "L_t at 12 trials" in md
    assert (samplers.report_dir(quick=True) / "samplers.png").stat().st_size > 10_000
