"""The tracks-out CSV of a live run (:mod:`core.formats.tracks_csv`'s header and rows).

Rows are kept as the frames arrive (a few numbers a track and frame) and the file is written
whole when the link ends, however it ends — its ``frame`` is the frame's index on the
recording's frame grid (what ``radartune import`` of the recording numbers it), ``time_s`` that
index times the frame period, ``track_id`` unique over the link.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from core.formats.tracks_csv import TrackRows, write_tracks_csv
from core.live.link import LiveFrame
from core.tracking.results import FrameTracks


class LiveTracksWriter:
    """Collects every live track of every frame; :meth:`close` writes the CSV."""

    def __init__(self, path: str | os.PathLike) -> None:
        self.path = Path(path)
        self._frames: list[tuple[int, float, FrameTracks]] = []
        self._closed = False

    def add(self, frame: LiveFrame) -> None:
        self._frames.append((frame.index, frame.t_s, frame.tracks))

    def rows(self) -> TrackRows:
        """The rows so far (frames in arrival order, tracks in the tracker's order)."""
        parts = [ft for _, _, ft in self._frames]
        counts = np.array([len(ft) for ft in parts], dtype=np.int64)
        frame = np.repeat(np.array([f for f, _, _ in self._frames], dtype=np.int64), counts)
        time_s = np.repeat(np.array([t for _, t, _ in self._frames], dtype=np.float64), counts)

        def cat(name: str, dtype: type, shape: tuple[int, ...] = ()) -> np.ndarray:
            arrays: list[np.ndarray] = [np.asarray(getattr(ft, name), dtype=dtype) for ft in parts]
            return np.concatenate(arrays) if arrays else np.zeros((0, *shape), dtype=dtype)

        state = (
            np.concatenate([np.asarray(ft.state, dtype=np.float64)[:, :4] for ft in parts])
            if parts
            else np.zeros((0, 4))
        )
        return TrackRows(
            frame=frame,
            time_s=time_s,
            track_id=cat("ids", np.int64),
            confirmed=cat("confirmed", bool),
            state=state,
            existence=cat("psi", np.float64),
            n_points=np.maximum(cat("n_associated", np.int64), 0),
            nis=cat("nis", np.float64),
        )

    def close(self) -> Path:
        """Write the file (once) and return its path."""
        if not self._closed:
            self._closed = True
            write_tracks_csv(self.path, self.rows())
        return self.path
