"""Robust objectives: the capped loss, trimmed and median aggregation, against hand-made numbers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from core.errors import InputError
from core.evaluation.robust import aggregate, capped_loss, check_objective, trimmed_mean
from core.optimization.objective import TrajectoryScore, evaluate


def test_capped_loss_scores_each_kind_of_frame() -> None:
    c = 0.5
    truth = np.array([[0.0, 1.0], [0.0, 2.0], [0.0, 3.0], [np.nan, np.nan]])
    est = np.array([[0.1, 1.0], [1.0, 2.0], [9.0, 9.0], [0.0, 0.0]])
    has = np.array([True, True, False, True])
    # frame 0: 0.1² = 0.01; frame 1: error 1 m > c → c² = 0.25; frame 2: no estimate → c²/2;
    # frame 3: person absent → not scored
    expected = (0.01 + 0.25 + 0.125) / 3
    assert capped_loss(est, has, truth, c) == pytest.approx(expected, rel=1e-12)


def test_capped_loss_is_bounded_and_never_confirmed_costs_half_c_squared() -> None:
    rng = np.random.default_rng(1)
    truth = rng.normal(size=(50, 2))
    est = truth + rng.normal(scale=10.0, size=(50, 2))
    c = 0.3
    # every frame costs at most c², whatever the estimate
    assert capped_loss(est, np.ones(50, bool), truth, c) <= c * c
    assert capped_loss(est, np.zeros(50, bool), truth, c) == pytest.approx(c * c / 2)
    # no frame with the person present: nothing to score
    assert capped_loss(est, np.ones(50, bool), np.full((50, 2), np.nan), c) == 0.0
    with pytest.raises(InputError, match="cutoff_m"):
        capped_loss(est, np.ones(50, bool), truth, 0.0)


def test_trimmed_mean_drops_the_largest_tenth() -> None:
    assert trimmed_mean(list(range(1, 11))) == pytest.approx(5.0)  # mean of 1 … 9
    assert trimmed_mean([1.0, 2.0, 3.0, 4.0, 100.0]) == pytest.approx(22.0)  # floor(0.5) = 0
    assert trimmed_mean([7.0]) == 7.0
    assert math.isnan(trimmed_mean([]))
    assert aggregate([1.0, 2.0, 100.0], "median") == 2.0
    with pytest.raises(InputError, match="aggregation"):
        aggregate([1.0], "max")


def test_unknown_objective_is_one_line() -> None:
    with pytest.raises(InputError, match="loss must be one of paper, capped, median, trimmed"):
        check_objective("rmse")


class _Fixed:
    """A loss source with given scores: nine typical trajectories and one catastrophe."""

    def __init__(self) -> None:
        self.scores = [TrajectoryScore(1e-3, 1e-2, 10, 2e-3) for _ in range(9)]
        self.scores.append(TrajectoryScore(1.0, math.nan, 0, 0.125))  # never confirmed

    @property
    def trajectory_classes(self) -> tuple[str, ...]:
        return tuple("abcde"[k % 5] for k in range(10))

    def losses(self, params, ks):
        return [self.scores[k] for k in ks]


def test_objectives_on_one_catastrophic_trajectory() -> None:
    src = _Fixed()
    paper = evaluate(src, {}, loss="paper")
    # L_t = (9 · 1e-3 + 1) / 10: the one never-confirmed trajectory makes 99 % of it
    assert paper.value == pytest.approx((9e-3 + 1.0) / 10)
    assert paper.paper_value == paper.value
    trimmed = evaluate(src, {}, loss="trimmed")
    assert trimmed.value == pytest.approx(1e-3)  # the largest tenth (one trajectory) left out
    assert trimmed.paper_value == paper.value  # the paper's L_t is reported beside it
    assert evaluate(src, {}, loss="median").value == pytest.approx(1e-3)
    capped = evaluate(src, {}, loss="capped")
    assert capped.value == pytest.approx((9 * 2e-3 + 0.125) / 10)
    assert capped.capped == tuple(s.capped for s in (src.scores[k] for k in capped.order))


def test_a_non_finite_capped_loss_is_an_error() -> None:
    src = _Fixed()
    src.scores[0] = TrajectoryScore(1e-3, 1e-2, 10, math.inf)
    with pytest.raises(FloatingPointError, match="capped loss"):
        evaluate(src, {}, loss="capped")


def test_capped_loss_of_several_people_is_the_mean_over_the_people_present() -> None:
    from types import SimpleNamespace

    from core.evaluation.robust import trajectory_capped_losses

    truth = np.array([[[0.0, 2.0], [3.0, 4.0], [np.nan, np.nan]]] * 3)  # (3 frames, 3 persons, 2)
    ranked = np.full((3, 2, 2), np.nan)
    ranked[:, 0] = [0.1, 2.0]  # one confirmed track, 0.1 m from person 0; person 1 has none
    est = SimpleNamespace(
        frame_index=np.arange(3),
        offsets=np.array([0, 3]),
        trajectories=np.array([0]),
        tracks=SimpleNamespace(xy=ranked),
    )
    # person 0: 0.1² a frame; person 1: c²/2 = 0.125 a frame; person 2 never present
    (value,) = trajectory_capped_losses(SimpleNamespace(truth_xy_m=truth), est)
    assert value == pytest.approx((0.01 + 0.125) / 2)


def test_far_frames_counts_confirmed_estimates_beyond_the_distance() -> None:
    """Frames: on the person (0.1 m), 1.5 m away, no estimate while 3 m away in the array,
    exactly 1 m away (not beyond), 2 m away with the person absent (not scored)."""
    from core.evaluation.robust import far_frames

    truth = np.array([[0.0, 0.0], [0.0, 0.0], [0.0, 0.0], [0.0, 0.0], [np.nan, np.nan]])
    est = np.array([[0.1, 0.0], [1.5, 0.0], [3.0, 0.0], [0.0, 1.0], [2.0, 0.0]])
    has = np.array([True, True, False, True, True])
    assert far_frames(est, has, truth) == 1
    assert far_frames(est, has, truth, distance_m=0.05) == 3
