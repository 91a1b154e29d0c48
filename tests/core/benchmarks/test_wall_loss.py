"""The ghost-fraction estimator and the loss fit's crossing (hand-made frames and curves)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from core.benchmarks.wall_loss import (
    bootstrap_interval,
    crossing,
    fit,
    frame_ghosts,
    ghost_fraction,
)


def _frame(extra_xy, extra_v):
    # a person of 5 moving points around (0, 3) m
    x = np.array([-0.1, 0.0, 0.1, 0.0, 0.05, *[p[0] for p in extra_xy]])
    y = np.array([3.0, 3.1, 2.9, 3.05, 2.95, *[p[1] for p in extra_xy]])
    v = np.array([1.0] * 5 + list(extra_v))
    return {"x": x, "y": y, "v": v}


def test_a_ghost_is_a_moving_point_over_1_m_behind_within_10_degrees():
    # behind at 5 m and 3.4 deg off: a ghost; 0.6 m behind: not; 5 m at 30 deg: not;
    # behind but static: not counted at all (neither ghost nor moving)
    f = _frame([(0.3, 5.0), (0.0, 3.6), (2.5, 4.33), (0.0, 6.0)], [1.0, 1.0, 1.0, 0.0])
    assert frame_ghosts(f["x"], f["y"], f["v"]) == (1, 8)
    # 9.5 deg off boresight at 5 m is inside, 10.5 deg outside
    for deg, inside in ((9.5, 1), (10.5, 0)):
        a = math.radians(deg)
        g = _frame([(5 * math.sin(a), 5 * math.cos(a))], [1.0])
        assert frame_ghosts(g["x"], g["y"], g["v"])[0] == inside
    # no moving point: nothing to measure
    assert frame_ghosts([1.0], [2.0], [0.0]) == (0, 0)
    assert ghost_fraction([{"x": np.ones(1), "y": np.ones(1), "v": np.zeros(1)}]) is None


def test_ghost_fraction_sums_over_frames_and_its_interval_holds_it():
    rng = np.random.default_rng(3)
    n = rng.integers(0, 3, size=200)
    frames = [_frame([(0.2, 5.0)] * int(k), [1.0] * int(k)) for k in n]
    g = np.array([frame_ghosts(f["x"], f["y"], f["v"]) for f in frames])
    assert ghost_fraction(frames) == pytest.approx(g[:, 0].sum() / g[:, 1].sum())
    lo, hi = bootstrap_interval(frames)
    assert lo < ghost_fraction(frames) < hi


def test_crossing_from_the_lossy_end_of_a_curve_with_a_peak():
    losses = np.array([-40.0, -30.0, -20.0, -10.0, 0.0])
    frac = np.array([0.02, 0.06, 0.20, 0.10, 0.08])
    # 0.04 is reached between -40 and -30 (at -35), not on the falling side
    assert crossing(losses, frac, 0.04) == pytest.approx(-35.0)
    assert crossing(losses, frac, 0.01) is None  # below the floor
    rows = [{"reflection_db": float(L), "ghost_fraction": float(f)} for L, f in zip(losses, frac)]
    rows.append({"reflection_db": None, "ghost_fraction": 0.015})
    r = fit(rows, 0.04, (0.03, 0.05))
    assert r["reflection_db"] == pytest.approx(-35.0)
    assert r["interval_db"] == pytest.approx([-37.5, -32.5])
    assert r["floor_without_bounces"] == 0.015
