"""Tracking a whole data set (the hot path of every Optuna trial).

:func:`track_dataset` runs the tracker from scratch on every selected trajectory and keeps only
what the evaluation needs (the single-person estimate and the confirmed track positions). The
default engine is the numba kernel (:mod:`core.tracking.kernel`); ``engine="numpy"`` runs the
readable reference :func:`core.tracking.tracker.run_tracker` (same algorithm, for tests and the
benchmark's reference).
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from core.dataset import Dataset
from core.errors import InputError
from core.tracking.params import TrackerParams
from core.tracking.results import FrameTracks, TrackRecord
from core.tracking.zones import Zones

__all__ = [
    "ConfirmedTracks",
    "DatasetEstimates",
    "track_dataset",
    "estimate_track_ids",
    "dataset_frame_period_s",
]

DEFAULT_FRAME_PERIOD_S = 0.08


@dataclass(frozen=True, slots=True, kw_only=True)
class ConfirmedTracks:
    """Every confirmed track of every output frame, ranked, with its identity (F_sel frames).

    Column j of frame f is the confirmed track of rank j: ranked by existence probability ψ,
    highest first, ties by the lower id — the order in which the tracker picks its single-person
    estimate (:func:`core.tracking.management.best_confirmed`), so column 0 is the estimate.
    Columns ``j >= n[f]`` are padding.

    Attributes
    ----------
    ids
        (F_sel, C) int64 track ids (per trajectory, from 0 in order of birth), −1 padded.
    xy
        (F_sel, C, 2) positions in m, NaN padded.
    psi
        (F_sel, C) existence probabilities ψ, NaN padded.
    """

    ids: np.ndarray
    xy: np.ndarray
    psi: np.ndarray

    @property
    def n(self) -> np.ndarray:
        """(F_sel,) confirmed tracks per frame."""
        return np.sum(self.ids >= 0, axis=1)

    @classmethod
    def from_slots(
        cls, ids: np.ndarray, xy: np.ndarray, psi: np.ndarray, confirmed: np.ndarray
    ) -> ConfirmedTracks:
        """Rank the confirmed ones among live track slots (F, S): ids, xy (F, S, 2), psi, status.

        Slots that are not confirmed (or padding, id < 0) are dropped; the rest are sorted by
        (−ψ, id) per frame.
        """
        ids = np.asarray(ids, dtype=np.int64)
        keep = np.asarray(confirmed, dtype=bool) & (ids >= 0)
        f, s = ids.shape
        # sort key: confirmed first, then −ψ, then id (lexsort: the last key is the primary one)
        order = np.lexsort((ids, -np.where(keep, psi, 0.0), ~keep), axis=1)
        rows = np.arange(f)[:, None]
        keep_s = keep[rows, order]
        out_ids = np.where(keep_s, ids[rows, order], -1)
        out_xy = np.where(keep_s[..., None], np.asarray(xy)[rows, order], np.nan)
        out_psi = np.where(keep_s, np.asarray(psi)[rows, order], np.nan)
        width = max(int(keep.sum(axis=1).max(initial=0)), 1) if f else s
        return cls(ids=out_ids[:, :width], xy=out_xy[:, :width], psi=out_psi[:, :width])

    @classmethod
    def from_frames(cls, frames: Sequence[FrameTracks]) -> ConfirmedTracks:
        """The confirmed tracks of a readable-tracker run (``TrackerResult.frames``), ranked."""
        width = max((len(ft) for ft in frames), default=0) or 1
        n = len(frames)
        ids = np.full((n, width), -1, np.int64)
        xy = np.full((n, width, 2), np.nan)
        psi = np.full((n, width), np.nan)
        conf = np.zeros((n, width), dtype=bool)
        for f, ft in enumerate(frames):
            k = len(ft)
            ids[f, :k], xy[f, :k], psi[f, :k], conf[f, :k] = (
                ft.ids, ft.state[:, :2], ft.psi, ft.confirmed
            )  # fmt: skip
        return cls.from_slots(ids, xy, psi, conf)


@dataclass(frozen=True, slots=True, kw_only=True)
class DatasetEstimates:
    """Tracker output over the selected trajectories of a data set (F_sel frames in total).

    Attributes
    ----------
    trajectories
        Indices (K_sel,) of the tracked trajectories, in the order tracked.
    frame_index
        Global frame index (F_sel,) of every output frame.
    offsets
        (K_sel + 1,) output-frame ranges per tracked trajectory.
    estimate_xy
        Single-person estimate position (F_sel, 2) in m, NaN where no track is confirmed.
    has_estimate
        (F_sel,) bool.
    estimate_psi
        (F_sel,) ψ of the estimate track, NaN where none.
    confirmed_xy
        (F_sel, max_tracks, 2) positions of all confirmed tracks, NaN-padded.
    n_confirmed, n_tracks
        (F_sel,) counts of confirmed and live tracks.
    model
        ``"cv"`` or ``"ca"``.
    tracks
        Every confirmed track with its id (:class:`ConfirmedTracks`), or None unless asked for
        (``track_dataset(..., with_tracks=True)``): the identities several-person metrics need.
    record
        Every live track (tentative and confirmed) of every output frame with its state, ψ,
        status, gated measurements and NIS (:class:`~core.tracking.results.TrackRecord`, rows
        in output-frame order), or None unless ``with_tracks=True``: the tracks file and the
        scores without positions read it.
    height_m
        (F_sel, max_tracks) height of every live track slot (m; the room mode: the mean z of the
        track's latest group of points), or None (the paper mode, or without ``with_tracks``).
    """

    trajectories: np.ndarray
    frame_index: np.ndarray
    offsets: np.ndarray
    estimate_xy: np.ndarray
    has_estimate: np.ndarray
    estimate_psi: np.ndarray
    confirmed_xy: np.ndarray
    n_confirmed: np.ndarray
    n_tracks: np.ndarray
    model: str = "cv"
    tracks: ConfirmedTracks | None = None
    record: TrackRecord | None = None
    height_m: np.ndarray | None = None


def dataset_frame_period_s(dataset: Dataset) -> float:
    """Frame period T (s) of a data set: its radar configuration's, else 0.08 s."""
    try:
        radar = json.loads(dataset.radar_json) if dataset.radar_json else {}
    except json.JSONDecodeError:
        radar = {}
    value = radar.get("frame_period_s", DEFAULT_FRAME_PERIOD_S) if isinstance(radar, dict) else 0
    try:
        value = float(value)
    except (TypeError, ValueError):
        value = 0.0
    if not (np.isfinite(value) and value > 0):
        raise InputError(f"radar_json frame_period_s must be positive, got {value!r}")
    return value


_PREPARED: list = []  # single entry: (dataset, z, frame_offsets, trajectory_offsets, period)
_ROOM_PREPARED: list = []  # single entry: (dataset, room points)
_SCENE_WALLS: list = []  # single entry: (dataset, the walls of its scene)


def _prepare(dataset: Dataset) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Measurements, offsets and frame period of a data set, kept for the last data set used.

    A study tracks the same (immutable) data set thousands of times, often one trajectory per
    call; this saves re-deriving ~1 ms of arrays on every call.
    """
    entry = _PREPARED[0] if _PREPARED else None  # one read: safe if a thread replaces it
    if entry is not None and entry[0] is dataset:
        return entry[1:]
    period = dataset_frame_period_s(dataset)
    z = dataset.measurements()
    if not np.all(np.isfinite(z)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(z), axis=1))[0])
        raise InputError(f"measurement of point {bad} (frame {dataset.frame[bad]}) is not finite")
    f_off = dataset.frame_offsets
    t_off = dataset.trajectory_offsets
    _PREPARED[:] = [(dataset, z, f_off, t_off, period)]
    return z, f_off, t_off, period


def room_points_of(dataset: Dataset) -> np.ndarray:
    """The room tracker's points (P, 7) of a data set (:data:`core.tracking.groups.COLUMNS`),
    kept for the last data set used."""
    entry = _ROOM_PREPARED[0] if _ROOM_PREPARED else None
    if entry is not None and entry[0] is dataset:
        return entry[1]
    from core.tracking.room import room_points

    pts = room_points(
        dataset.range_m, dataset.azimuth_rad, dataset.radial_velocity_mps,
        dataset.x_m, dataset.y_m, dataset.z_m, dataset.snr_db,
    )  # fmt: skip
    _ROOM_PREPARED[:] = [(dataset, pts)]
    return pts


def _scene_walls_of(dataset: Dataset) -> tuple:
    """The walls and the sensor's height of the data set's scene (:func:`core.walls.
    scene_walls`, :func:`core.walls.scene_sensor_height`), read once per data set (kept for the
    last one used)."""
    entry = _SCENE_WALLS[0] if _SCENE_WALLS else None
    if entry is not None and entry[0] is dataset:
        return entry[1]
    from core.walls import scene_sensor_height, scene_walls

    scene = dataset.scene()
    walls = (scene_walls(scene), scene_sensor_height(scene))
    _SCENE_WALLS[:] = [(dataset, walls)]
    return walls


def _selection(dataset: Dataset, trajectories: Sequence[int] | None) -> np.ndarray:
    k = dataset.n_trajectories
    if trajectories is None:
        return np.arange(k, dtype=np.int64)
    sel = np.asarray(trajectories, dtype=np.int64).reshape(-1)
    if sel.size and (sel.min() < 0 or sel.max() >= k):
        raise InputError(f"trajectories must be indices in [0, {k}), got {sel.tolist()}")
    return sel


def track_dataset(
    dataset: Dataset,
    params: TrackerParams,
    *,
    trajectories: Sequence[int] | None = None,
    engine: str = "numba",
    with_tracks: bool = False,
    zones: Zones | None = None,
    walls_from_scene: bool = True,
) -> DatasetEstimates:
    """Track every selected trajectory of a data set from scratch.

    Parameters
    ----------
    dataset
        Point clouds and truth; measurements are ``[range_m, azimuth_rad, radial_velocity_mps]``.
    params
        Tracker parameters.
    trajectories
        Indices of the trajectories to track (default: all, in order).
    engine
        ``"numba"`` (compiled kernel, default) or ``"numpy"`` (readable reference).
    with_tracks
        Also return every confirmed track with its id (``tracks``); off on the optimiser's path.
    zones
        The room's zones (room mode only; default: none, every point used). Without walls of
        their own they take the walls of the data set's scene (a data set simulated in a room,
        :func:`core.tracking.zones.with_scene_walls`).
    walls_from_scene
        False: the room mode ignores the walls of the data set's scene (only ``zones``'s).

    Returns
    -------
    DatasetEstimates
    """
    sel = _selection(dataset, trajectories)
    z, f_off, t_off, period = _prepare(dataset)
    tracks: ConfirmedTracks | None = None
    record: TrackRecord | None = None
    height: np.ndarray | None = None
    lengths = t_off[sel + 1] - t_off[sel]
    offsets = np.concatenate(([0], np.cumsum(lengths))).astype(np.int64)
    frame_index = (
        np.concatenate([np.arange(t_off[k], t_off[k + 1]) for k in sel]).astype(np.int64)
        if len(sel)
        else np.zeros(0, dtype=np.int64)
    )
    if params.mode == "room":
        from core.tracking.room import track_room_arrays
        from core.tracking.zones import with_scene_walls

        out = track_room_arrays(
            room_points_of(dataset), f_off, t_off, sel, params, period,
            with_scene_walls(zones, *(_scene_walls_of(dataset) if walls_from_scene else ((), 0.0))),
            record=with_tracks, engine=engine,
        )  # fmt: skip
        est_xy, has, psi, conf_xy, n_conf, n_tr = out[:6]
        if with_tracks:
            rec = record = out[8]
            height = out[9]
            tracks = ConfirmedTracks.from_slots(
                rec.ids, rec.state[..., :2], rec.psi, _live(rec.n_tracks, rec.confirmed)
            )
    elif engine == "numba":
        from core.tracking.kernel import track_frames

        out = track_frames(z, f_off, t_off, sel, params, period, record=with_tracks)
        est_xy, has, psi, conf_xy, n_conf, n_tr = out[:6]
        if with_tracks:
            rec = record = out[-1]
            tracks = ConfirmedTracks.from_slots(
                rec.ids, rec.state[..., :2], rec.psi, _live(rec.n_tracks, rec.confirmed)
            )
    elif engine == "numpy":
        from core.tracking.tracker import run_tracker

        n_sel = int(offsets[-1])
        est_xy = np.full((n_sel, 2), np.nan)
        has = np.zeros(n_sel, dtype=bool)
        psi = np.full(n_sel, np.nan)
        conf_xy = np.full((n_sel, params.max_tracks, 2), np.nan)
        n_conf = np.zeros(n_sel, dtype=np.int64)
        n_tr = np.zeros(n_sel, dtype=np.int64)
        cap = params.max_tracks
        rec = TrackRecord.allocate(n_sel if with_tracks else 0, cap, params.state_dim)
        for i, k in enumerate(sel):
            a, b = t_off[k], t_off[k + 1]
            res = run_tracker(
                (z[f_off[a] : f_off[b]], f_off[a : b + 1] - f_off[a]),
                params,
                period,
                keep_tracks=with_tracks,
            )
            s = slice(offsets[i], offsets[i + 1])
            est_xy[s], has[s], psi[s] = res.estimate_xy, res.has_estimate, res.estimate_psi
            conf_xy[s], n_conf[s], n_tr[s] = res.confirmed_xy, res.n_confirmed, res.n_tracks
            for j, ft in enumerate(res.frames or ()):
                record_frame(rec, offsets[i] + j, ft)
        if with_tracks:
            record = rec._replace(n_tracks=n_tr.copy())
            tracks = ConfirmedTracks.from_slots(
                rec.ids, rec.state[..., :2], rec.psi, _live(record.n_tracks, rec.confirmed)
            )
    else:
        raise InputError(f"engine must be 'numba' or 'numpy', got engine={engine!r}")
    return DatasetEstimates(
        trajectories=sel,
        frame_index=frame_index,
        offsets=offsets,
        estimate_xy=est_xy,
        has_estimate=has,
        estimate_psi=psi,
        confirmed_xy=conf_xy,
        n_confirmed=n_conf,
        n_tracks=n_tr,
        model=params.model,
        tracks=tracks,
        record=record,
        height_m=height,
    )


def record_frame(rec: TrackRecord, row: int, ft: FrameTracks) -> None:
    """Write one frame of the readable tracker (:class:`FrameTracks`) into row ``row`` of a
    :class:`TrackRecord`, as the compiled kernel records it."""
    n = len(ft)
    rec.ids[row, :n], rec.state[row, :n], rec.covariance[row, :n] = (
        ft.ids, ft.state, ft.covariance
    )  # fmt: skip
    rec.psi[row, :n], rec.confirmed[row, :n], rec.birth_frame[row, :n] = (
        ft.psi, ft.confirmed, ft.birth_frame
    )  # fmt: skip
    rec.gate_center_xy[row, :n], rec.gate_shape_xy[row, :n] = ft.gate_center_xy, ft.gate_shape_xy
    rec.n_associated[row, :n], rec.nis[row, :n] = ft.n_associated, ft.nis
    rec.estimate[row] = ft.estimate


def _live(n_tracks: np.ndarray, confirmed: np.ndarray) -> np.ndarray:
    """(F, S) True for the confirmed tracks among the live slots ``t < n_tracks[f]``."""
    return confirmed & (np.arange(confirmed.shape[1])[None, :] < n_tracks[:, None])


def estimate_track_ids(
    dataset: Dataset, params: TrackerParams, *, trajectories: Sequence[int] | None = None
) -> np.ndarray:
    """Id of the track that gives the single-person estimate, per output frame.

    Same selection and frame order as :func:`track_dataset`; runs the compiled kernel with every
    track recorded.

    Returns
    -------
    numpy.ndarray
        (F_sel,) int64: the estimate's track id (ids count per trajectory from 0 in order of
        birth), −1 where there is no estimate.
    """
    from core.tracking.kernel import track_frames

    sel = _selection(dataset, trajectories)
    z, f_off, t_off, period = _prepare(dataset)
    rec = track_frames(z, f_off, t_off, sel, params, period, record=True)[-1]
    ids = np.full(len(rec.estimate), -1, np.int64)
    rows = np.flatnonzero(rec.estimate >= 0)
    ids[rows] = rec.ids[rows, rec.estimate[rows]]
    return ids
