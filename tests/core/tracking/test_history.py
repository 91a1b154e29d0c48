"""Trails and ψ curves (core.tracking.history): the batch history of a run and the one built
frame by frame as a live link adds them are the same rows, checked against hand-written ones."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from core.tracking import TrackerParams, run_tracker
from core.tracking.history import TrackHistory


def _frame(ids, xy, psi, confirmed):
    ids = np.asarray(ids, dtype=np.int64)
    state = np.zeros((len(ids), 4))
    state[:, :2] = np.asarray(xy, dtype=float).reshape(-1, 2)
    return SimpleNamespace(ids=ids, state=state, psi=np.asarray(psi, float), confirmed=confirmed)


def test_hand_written_rows() -> None:
    frames = [
        _frame([1], [[0.0, 1.0]], [0.5], [False]),
        _frame([], np.zeros((0, 2)), [], []),
        _frame([1, 2], [[0.1, 1.1], [3.0, 4.0]], [0.9, 0.2], [True, False]),
    ]
    c = TrackHistory.of_frames(frames).curves(0.1)
    assert list(c.trail_id) == [1, 1, 2] and list(c.trail_t_index) == [0, 2, 2]
    np.testing.assert_array_equal(c.trail_xy_m, [[0.0, 1.0], [0.1, 1.1], [3.0, 4.0]])
    # a NaN between tracks 1 and 2 breaks the curves
    np.testing.assert_array_equal(c.psi_t_s, [0.0, 0.2, np.nan, 0.2])
    np.testing.assert_array_equal(c.psi_value, [0.5, 0.9, np.nan, 0.2])
    np.testing.assert_array_equal(c.psi_confirmed_value, [np.nan, 0.9, np.nan, np.nan])
    empty = TrackHistory().curves(0.1)
    assert empty.trail_id.shape == (0,) and empty.trail_xy_m.shape == (0, 2)
    assert empty.psi_value.shape == (0,)


def test_frame_by_frame_equals_batch_on_a_tracked_run() -> None:
    rng = np.random.default_rng(3)
    n_f, z, off = 60, [], [0]
    for k in range(n_f):  # two walkers and clutter: tracks born, confirmed and deleted
        walkers = [[2.0 + 0.04 * k, 0.3, 0.8], [5.0 - 0.03 * k, -0.4, -0.6]]
        clutter = np.column_stack(
            [rng.uniform(1, 8, 3), rng.uniform(-1, 1, 3), rng.uniform(-2, 2, 3)]
        )
        z.append(np.vstack([walkers, clutter]))
        off.append(off[-1] + len(z[-1]))
    res = run_tracker(
        (np.vstack(z), np.array(off)), TrackerParams(), 0.08, keep_tracks=True, engine="numpy"
    )
    live = TrackHistory()
    for k, ft in enumerate(res.frames):
        live.add(k, ft)
    a, b = live.curves(0.08), TrackHistory.of_frames(res.frames).curves(0.08)
    assert len(np.unique(a.trail_id)) >= 3  # several tracks, so the ordering is exercised
    for name in ("trail_id", "trail_t_index", "trail_xy_m", "psi_t_s", "psi_value"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    np.testing.assert_array_equal(a.psi_confirmed_value, b.psi_confirmed_value)
    # rows sorted by (id, frame), one per track and frame
    key = a.trail_id * (n_f + 1) + a.trail_t_index
    assert (np.diff(key) > 0).all() and len(key) == sum(len(ft.ids) for ft in res.frames)
