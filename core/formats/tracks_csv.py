"""Tracks out: every live track of every frame as a CSV (SPEC §7), for any data set.

Header (exactly)::

    frame,time_s,track_id,status,x_m,y_m,z_m,vx_mps,vy_mps,existence,n_points

One row per live track and frame, frames in the data set's order, tracks in the tracker's order
within a frame:

- ``frame``: the data set's global frame index; ``time_s``: its frame time (``truth_t_s``: for a
  recording the time since its first frame, for a simulated trajectory the time since its start);
- ``track_id``: unique over the file. The tracker numbers the tracks of each run (trajectory)
  from 0 in order of birth; the ids of a run are offset past the largest id of the runs before
  it, so a sensor restart never reuses an id;
- ``status``: ``tentative`` or ``confirmed``; ``existence``: the track's existence probability ψ
  (empty for a tracker without one: gtrack);
- ``x_m, y_m, vx_mps, vy_mps``: the state after the frame's update, m and m/s;
- ``z_m``: the track's height (m) where the tracker gives one: the room mode's mean z of the
  track's latest group of points (empty when every point of the data set has z = 0, a chain
  without elevation), gtrack's 3-D state's height; empty for the paper mode, which tracks in
  the ground plane (x–y);
- ``n_points``: the measurements inside the track's gate in this frame (those that took part in
  its update; 0 for a track born in the frame).

The file is written whole or not at all (:func:`core.files.write_text_atomic`).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from core.dataset import Dataset

__all__ = [
    "TRACKS_HEADER",
    "TrackRows",
    "format_tracks_csv",
    "track_rows",
    "unique_track_ids",
    "write_tracks_csv",
]

#: The header of a tracks file (SPEC §7).
TRACKS_HEADER = (
    "frame",
    "time_s",
    "track_id",
    "status",
    "x_m",
    "y_m",
    "z_m",
    "vx_mps",
    "vy_mps",
    "existence",
    "n_points",
)


@dataclass(frozen=True, slots=True, kw_only=True)
class TrackRows:
    """Every live track of every tracked frame, one row each (R rows, struct of arrays).

    Attributes
    ----------
    frame
        (R,) int64 global frame index of the data set.
    time_s
        (R,) frame time, s.
    track_id
        (R,) int64 id, unique over the rows (see the module).
    confirmed
        (R,) bool status: True confirmed, False tentative.
    state
        (R, 4) ``[x, y, vx, vy]`` in m and m/s.
    existence
        (R,) existence probability ψ.
    n_points
        (R,) int64 measurements gated in the frame.
    nis
        (R,) NIS of the frame's update (NaN when no measurement was gated or the track was born).
    height_m
        (R,) height of the track (m), NaN where none (the ``z_m`` column is then empty).
    """

    frame: np.ndarray
    time_s: np.ndarray
    track_id: np.ndarray
    confirmed: np.ndarray
    state: np.ndarray
    existence: np.ndarray
    n_points: np.ndarray
    nis: np.ndarray
    height_m: np.ndarray | None = None

    def __post_init__(self) -> None:
        r = np.shape(self.frame)
        if self.height_m is None:
            object.__setattr__(self, "height_m", np.full(r, np.nan))
        names = ("time_s", "track_id", "confirmed", "existence", "n_points", "nis", "height_m")
        for name in names:
            if np.shape(getattr(self, name)) != r:
                raise ValueError(f"TrackRows.{name} must have shape {r} like frame")
        if np.shape(self.state) != (*r, 4):
            raise ValueError(f"TrackRows.state must have shape {(*r, 4)}, got {self.state.shape}")

    def __len__(self) -> int:
        return len(self.frame)


def track_rows(dataset: Dataset, estimates: Any) -> TrackRows:
    """The rows of a tracker run (``track_dataset(..., with_tracks=True)``) on ``dataset``.

    Parameters
    ----------
    dataset
        The data set tracked (frame times from ``truth_t_s``).
    estimates
        :class:`core.tracking.DatasetEstimates` with its ``record``.
    """
    rec = estimates.record
    if rec is None:
        raise ValueError("the tracks file needs every track: track_dataset(..., with_tracks=True)")
    ids_all = unique_track_ids(rec, estimates.offsets)
    rows, slots = np.nonzero(ids_all >= 0)  # frames in order, tracks in the tracker's order
    ids = ids_all[rows, slots]
    frame = np.asarray(estimates.frame_index, dtype=np.int64)[rows]
    height = np.full(len(rows), np.nan)
    h = getattr(estimates, "height_m", None)
    if h is not None and np.any(np.asarray(dataset.z_m) != 0.0):
        height = np.asarray(h, dtype=np.float64)[rows, slots]
    return TrackRows(
        frame=frame,
        time_s=np.asarray(dataset.truth_t_s, dtype=np.float64)[frame],
        track_id=ids,
        confirmed=rec.confirmed[rows, slots].astype(bool),
        state=rec.state[rows, slots, :4].astype(np.float64),
        existence=rec.psi[rows, slots].astype(np.float64),
        n_points=np.maximum(rec.n_associated[rows, slots], 0).astype(np.int64),
        nis=rec.nis[rows, slots].astype(np.float64),
        height_m=height,
    )


def unique_track_ids(record: Any, offsets: np.ndarray) -> np.ndarray:
    """(F_sel, cap) int64 id of every live track slot of a :class:`TrackRecord`, −1 elsewhere;
    the ids of each run (``offsets``: output-frame ranges per tracked trajectory) shifted past
    the largest id of the runs before it, so that they are unique over the data set."""
    n = np.asarray(record.n_tracks, dtype=np.int64)
    cap = record.ids.shape[1]
    live = np.arange(cap)[None, :] < n[:, None]
    off = np.asarray(offsets, dtype=np.int64)
    run = np.searchsorted(off, np.arange(len(n)), side="right") - 1  # (F_sel,)
    largest = np.full(len(off) - 1, -1, np.int64)
    np.maximum.at(largest, run, np.where(live, record.ids, -1).max(axis=1, initial=-1))
    shift = np.concatenate(([0], np.cumsum(largest + 1)[:-1])).astype(np.int64)
    return np.where(live, record.ids + shift[run][:, None], -1)


def format_tracks_csv(rows: TrackRows) -> str:
    """The CSV text of ``rows`` (header line first, ``\\n`` line ends)."""
    lines = [",".join(TRACKS_HEADER)]
    status = np.where(rows.confirmed, "confirmed", "tentative")
    height = rows.height_m if rows.height_m is not None else np.full(len(rows), np.nan)
    for i in range(len(rows)):
        x, y, vx, vy = rows.state[i]
        z = f"{height[i]:.4f}" if np.isfinite(height[i]) else ""
        psi = rows.existence[i]
        e = f"{psi:.6f}" if np.isfinite(psi) else ""
        lines.append(
            f"{rows.frame[i]},{rows.time_s[i]:.4f},{rows.track_id[i]},{status[i]},"
            f"{x:.4f},{y:.4f},{z},{vx:.4f},{vy:.4f},{e},{rows.n_points[i]}"
        )
    return "\n".join(lines) + "\n"


def write_tracks_csv(path: str | os.PathLike, rows: TrackRows) -> Path:
    """Write the tracks file atomically (a whole file or none)."""
    from core.files import write_text_atomic

    return write_text_atomic(path, format_tracks_csv(rows))
