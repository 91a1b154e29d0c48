"""Objective: round-robin order, running-mean reports, pruning, the quadratic test loss."""

from __future__ import annotations

import numpy as np
import pytest

from core.optimization.objective import QuadraticLosses, evaluate, round_robin_order
from core.optimization.space import search_space
from core.tracking.space import tracker_params_dict


class Recorder:
    def __init__(self, prune_at: int | None = None) -> None:
        self.reports: list[tuple[int, float]] = []
        self.asked: list[int] = []
        self.prune_at = prune_at

    def report(self, value: float, step: int) -> None:
        self.reports.append((step, value))

    def should_prune(self) -> bool:
        self.asked.append(self.reports[-1][0])
        return self.prune_at is not None and self.reports[-1][0] >= self.prune_at


def centre(model: str) -> dict:
    flat = {}
    for b in search_space(model):
        flat[b.name] = float(np.sqrt(b.low * b.high)) if b.log else (b.low + b.high) / 2
    return tracker_params_dict(flat, model)


def test_round_robin_order() -> None:
    assert round_robin_order(["a", "a", "b", "b", "c"]) == [0, 2, 4, 1, 3]
    classes = [c for c in "abcde" for _ in range(7)]  # grouped by class
    order = round_robin_order(classes)
    assert sorted(order) == list(range(35))
    # every prefix of 5 covers every class once
    for i in range(0, 35, 5):
        assert sorted(classes[k] for k in order[i : i + 5]) == list("abcde")


def test_quadratic_minimum_is_the_centre_and_grows_away() -> None:
    q = QuadraticLosses(model="cv", n_trajectories=5)
    at_centre = evaluate(q, centre("cv")).value
    assert at_centre == pytest.approx(1e-4, rel=1e-12)
    off = dict(centre("cv"), q_coeff=30.0)
    # u = 1 for q_coeff: L(k) = 1e-4 (1 + w_k 0.25), mean w_k = 1 + mean(k)/5 = 1.4
    assert evaluate(q, off).value == pytest.approx(1e-4 * (1 + 1.4 * 0.25), rel=1e-9)


def test_running_mean_is_reported_after_every_trajectory() -> None:
    q = QuadraticLosses(model="cv", n_trajectories=10)
    params = dict(centre("cv"), r11=0.5)
    rec = Recorder()
    res = evaluate(q, params, trial=rec, pruner="asha")
    assert [s for s, _ in rec.reports] == list(range(1, 11))
    expected = np.cumsum(res.losses) / np.arange(1, 11)
    np.testing.assert_allclose([v for _, v in rec.reports], expected, rtol=1e-12)
    assert res.value == pytest.approx(expected[-1]) and not res.pruned
    # the last step never asks the pruner: the trial is complete
    assert rec.asked == list(range(1, 10))


def test_with_rungs_the_running_mean_is_reported_at_the_rungs_and_the_end() -> None:
    q = QuadraticLosses(model="cv", n_trajectories=35)
    rec = Recorder()
    res = evaluate(q, dict(centre("cv"), r11=0.5), trial=rec, pruner="asha", prune_steps={5, 15})
    assert [s for s, _ in rec.reports] == [5, 15, 35] and rec.asked == [5, 15]
    running = np.cumsum(res.losses) / np.arange(1, 36)
    np.testing.assert_allclose([v for _, v in rec.reports], running[[4, 14, 34]], rtol=1e-12)


def test_pruning_stops_early_with_the_running_mean() -> None:
    q = QuadraticLosses(model="cv", n_trajectories=10)
    rec = Recorder(prune_at=5)
    res = evaluate(q, centre("cv"), trial=rec, pruner="asha", prune_steps={5})
    assert res.pruned and len(res.losses) == 5 and rec.asked == [5]
    assert res.value == pytest.approx(np.mean(res.losses))


def test_wilcoxon_reports_each_trajectory_loss_at_its_index() -> None:
    q = QuadraticLosses(model="cv", n_trajectories=10)
    rec = Recorder()
    res = evaluate(q, dict(centre("cv"), r22=0.2), trial=rec, pruner="wilcoxon")
    assert [s for s, _ in rec.reports] == list(res.order)
    assert [v for _, v in rec.reports] == list(res.losses)
