"""Every track's path and existence probability ψ over the frames so far, as curves to draw.

One owner for the trails and ψ curves of a tracking run, whether the frames are tracked in one
batch (the app's re-track of its cache) or one at a time as they arrive (a live link):
:class:`TrackHistory` keeps every track of every frame as rows sorted by (track id, frame) and
:meth:`TrackHistory.curves` gives them as NaN-separated polylines, one piece per track.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

__all__ = ["TrackCurves", "TrackHistory"]


@dataclass(frozen=True, slots=True, kw_only=True)
class TrackCurves:
    """Trails and ψ curves of a run (M track-frames, T tracks).

    ``trail_*`` (M,) rows sorted by (id, frame): ``trail_id``, ``trail_t_index`` (frame index),
    ``trail_xy_m`` (M, 2) positions in m. ``psi_t_s``, ``psi_value``, ``psi_confirmed_value``
    (M + T − 1,): time (s) and ψ of each row, a NaN between two tracks breaking the curve;
    ``psi_confirmed_value`` is NaN where the track was not confirmed.
    """

    trail_id: np.ndarray
    trail_t_index: np.ndarray
    trail_xy_m: np.ndarray
    psi_t_s: np.ndarray
    psi_value: np.ndarray
    psi_confirmed_value: np.ndarray


def _rows(index: int, tracks) -> tuple[np.ndarray, ...]:
    """(ids, frame, xy, ψ, confirmed) of a ``FrameTracks``-like frame (``ids``, ``state``,
    ``psi``, ``confirmed``; x, y the state's first two components)."""
    ids = np.asarray(tracks.ids, dtype=np.int64)
    n = len(ids)
    state = np.asarray(tracks.state, dtype=float)
    xy = state.reshape(n, -1)[:, :2] if n else np.zeros((0, 2))
    return (
        ids,
        np.full(n, index, dtype=np.int64),
        xy,
        np.asarray(tracks.psi, dtype=float).reshape(n),
        np.asarray(tracks.confirmed, dtype=bool).reshape(n),
    )


class TrackHistory:
    """Every track of every frame so far, sorted by (id, frame); frames added in order."""

    def __init__(self) -> None:
        self._rows: tuple[np.ndarray, ...] = (
            np.zeros(0, np.int64),
            np.zeros(0, np.int64),
            np.zeros((0, 2)),
            np.zeros(0),
            np.zeros(0, bool),
        )

    @classmethod
    def of_frames(cls, frames: Iterable) -> TrackHistory:
        """The history of a whole run (frame ``k`` of ``frames`` has index ``k``), sorted once."""
        parts = [_rows(k, ft) for k, ft in enumerate(frames)]
        h = cls()
        if parts:
            cols = [np.concatenate([p[i] for p in parts]) for i in range(5)]
            order = np.lexsort((cols[1], cols[0]))
            h._rows = tuple(c[order] for c in cols)
        return h

    def add(self, index: int, tracks) -> None:
        """The tracks (a ``FrameTracks``) of frame ``index``, later than every frame so far."""
        new = _rows(index, tracks)
        if len(new[0]) == 0:
            return
        merged = [np.concatenate((a, b)) for a, b in zip(self._rows, new)]
        # the new rows are the latest frame: a stable sort by id keeps (id, frame) order
        order = np.argsort(merged[0], kind="stable")
        self._rows = tuple(a[order] for a in merged)

    def curves(self, frame_period_s: float) -> TrackCurves:
        """Trails and ψ curves, frame ``k`` at time ``k · frame_period_s``."""
        ids, t_idx, xy, psi, conf = self._rows
        breaks = np.flatnonzero(np.diff(ids)) + 1
        return TrackCurves(
            trail_id=ids,
            trail_t_index=t_idx,
            trail_xy_m=xy,
            psi_t_s=np.insert(t_idx * frame_period_s, breaks, np.nan),
            psi_value=np.insert(psi, breaks, np.nan),
            psi_confirmed_value=np.insert(np.where(conf, psi, np.nan), breaks, np.nan),
        )
