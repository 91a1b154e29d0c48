"""A recording that opens with empty frames re-tracks in the app: no track in the first frames
is an empty track table, not a reshape error."""

from __future__ import annotations

import numpy as np

from app.engine import track_frame
from core.tracking import TrackerParams, run_tracker


def test_frames_without_tracks_become_empty_track_frames() -> None:
    """Five empty frames, then a point walking away: the first frames have no track, later
    ones do; every frame converts."""
    n_empty, n_walk = 5, 20
    z, counts = [], []
    for k in range(n_empty + n_walk):
        if k < n_empty:
            counts.append(0)
            continue
        r = 3.0 + 0.08 * (k - n_empty)
        z.append([r, 0.1, 1.0])
        counts.append(1)
    offsets = np.concatenate(([0], np.cumsum(counts))).astype(np.int64)
    for engine in ("numpy", "numba"):
        res = run_tracker(
            (np.array(z, dtype=float), offsets), TrackerParams(), 0.08, keep_tracks=True,
            engine=engine,
        )  # fmt: skip
        frames = [track_frame(ft) for ft in res.frames]
        assert all(len(f.track_id) == 0 for f in frames[:n_empty])
        assert frames[0].xy_m.shape == (0, 2) and frames[0].sigma_xy_m.shape == (0, 2)
        assert any(len(f.track_id) > 0 for f in frames[n_empty:])
