"""The loss as a run unfolds: element k is the paper's loss of the first k + 1 frames."""

from __future__ import annotations

import math

import numpy as np

from core.evaluation import (
    NO_CONFIRMATION_LOSS,
    ospa,
    ospa_per_frame,
    running_trajectory_loss,
    trajectory_loss,
)


def test_every_prefix_is_the_paper_loss_of_that_prefix() -> None:
    rng = np.random.default_rng(3)
    n = 60
    truth = rng.normal(size=(n, 2)) * 3
    truth[[5, 17, 40]] = np.nan  # the person absent: not scored
    est = truth + rng.normal(scale=0.2, size=(n, 2))
    has = rng.random(n) < 0.7
    has[:4] = False  # no estimate before frame 4
    loss, rmse = running_trajectory_loss(est, has, truth)
    for k in range(n):
        want_l, want_mse, n_c = trajectory_loss(est[: k + 1], has[: k + 1], truth[: k + 1])
        assert math.isclose(loss[k], want_l, rel_tol=1e-12)
        if n_c == 0:
            assert loss[k] == NO_CONFIRMATION_LOSS and np.isnan(rmse[k])
        else:
            assert math.isclose(rmse[k], math.sqrt(want_mse), rel_tol=1e-12)
    assert np.all(loss[:4] == NO_CONFIRMATION_LOSS)


def test_ospa_per_frame_is_ospa_of_each_frame() -> None:
    tracks = [np.zeros((0, 2)), np.array([[0.0, 1.0]]), np.array([[0.0, 1.0], [3.0, 3.0]])]
    truth = [np.array([[0.0, 1.0]]), np.array([[0.3, 1.4]]), np.array([[np.nan, np.nan]])]
    out = ospa_per_frame(tracks, truth)
    # an empty track set against one person: the cut-off c = 1 m; one pair 0.5 m apart: 0.5 m
    np.testing.assert_allclose(out, [1.0, 0.5, 1.0])
    assert out[1] == ospa(tracks[1], truth[1])
