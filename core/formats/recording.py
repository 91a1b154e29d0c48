"""Recordings from real sensors as RadarTune data sets, and the table of importable formats.

A reader turns a file into a :class:`Recording` (point clouds per frame, frame times, the radar
configuration, what it dropped); :func:`to_dataset` adds the optional ground truth (a CSV of
``time_s, person, x_m, y_m``) and builds a :class:`~core.dataset.Dataset` that ``radartune
track``, the report and (with truth) studies use like a simulated one.

The table of formats is :mod:`core.recordings`.
"""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import math
import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from core.config import RadarConfig
from core.dataset import Dataset
from core.errors import InputError
from core.limits import MAX_DATASET_FRAMES, MAX_PERSONS
from core.pointcloud import SOURCE_OTHER, PointCloud

#: A gap in the frame numbers up to this many frames is filled with empty frames (missed
#: detections at the constant frame period the tracker assumes); a longer gap, or a frame number
#: going back (device reset), starts a new trajectory.
MAX_FILLED_GAP_FRAMES = 100
#: ``trajectory_class`` of an imported trajectory (classes a-e and "drawn" are simulated ones).
REAL_CLASS = "real"
#: The columns of a truth CSV, in order.
TRUTH_COLUMNS = ("time_s", "person", "x_m", "y_m")
#: Truth samples further than this from a frame time (in frame periods) do not count for it.
TRUTH_TOLERANCE_FRAMES = 0.5


@dataclass(frozen=True, slots=True, kw_only=True)
class Recording:
    """Point clouds of F frames read from a sensor file.

    ``cloud``: all points in frame order, ``counts`` ``(F,)`` of each frame; ``t_s`` ``(F,)`` frame
    times in s (from 0); ``trajectory`` ``(F,)`` index of the continuous run each frame belongs
    to (a new one after a device reset or a long gap); ``radar``: the configuration (from the
    ``.cfg`` or the file), ``notes``: what was dropped or skipped, one line each.
    """

    format: str
    cloud: PointCloud
    counts: np.ndarray
    t_s: np.ndarray
    trajectory: np.ndarray
    radar: RadarConfig
    notes: tuple[str, ...] = ()
    meta: dict = field(default_factory=dict)
    #: TI's own tracks, when the recording has them: ``frame`` (index into the frames),
    #: ``track_id``, ``x_m``, ``y_m``, ``z_m``, ``vx_mps``, ``vy_mps``, one entry per track row.
    ref_tracks: dict[str, np.ndarray] | None = None
    #: Per point of ``cloud``, the id of TI's track the firmware gave it (-1: none).
    ref_point_track: np.ndarray | None = None

    @property
    def n_frames(self) -> int:
        return len(self.counts)


def frames_from_numbers(
    frame_numbers: np.ndarray, frame_period_s: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Place packets on a uniform frame grid from their frame numbers.

    Parameters
    ----------
    frame_numbers
        ``(N,)`` frame number of each packet, in stream order (sub-frames repeat a number).
    frame_period_s
        The frame period, s.

    Returns
    -------
    slot
        ``(N,)`` output frame of each packet (packets with the same number share one).
    t_s
        ``(F,)`` time of each output frame, s; ``trajectory`` ``(F,)`` its run.
    n_filled
        Empty frames inserted for gaps of at most :data:`MAX_FILLED_GAP_FRAMES`.
    """
    fn = np.asarray(frame_numbers, dtype=np.int64)
    if len(fn) == 0:
        return np.zeros(0, np.int64), np.zeros(0), np.zeros(0, np.int32), 0
    d = np.diff(fn)
    new_run = (d < 0) | (d > MAX_FILLED_GAP_FRAMES + 1)
    # frames advanced per packet: the gap inside a run, 1 at a new run, 0 for a repeated number
    step = np.where(new_run, 1, d)
    slot = np.concatenate(([0], np.cumsum(step)))
    n_frames = int(slot[-1]) + 1
    run_of_packet = np.concatenate(([0], np.cumsum(new_run)))
    trajectory = np.zeros(n_frames, dtype=np.int32)
    trajectory[slot] = run_of_packet
    trajectory = np.maximum.accumulate(trajectory)
    # time: frame index within the whole grid times the period, runs back to back
    t_s = np.arange(n_frames) * frame_period_s
    n_filled = n_frames - len(np.unique(slot))
    return slot, t_s, trajectory, n_filled


def points_to_cloud(
    x: np.ndarray, y: np.ndarray, z: np.ndarray, v: np.ndarray, snr_db: np.ndarray
) -> tuple[PointCloud, np.ndarray]:
    """Cartesian points (any float dtype) as a point cloud, all at once; returns the cloud of the
    finite points and the mask of those kept."""
    x, y, z, v, snr = (np.asarray(a, dtype=np.float64) for a in (x, y, z, v, snr_db))
    keep = np.isfinite(x) & np.isfinite(y) & np.isfinite(z) & np.isfinite(v)
    if not keep.all():
        x, y, z, v, snr = (a[keep] for a in (x, y, z, v, snr))
    # r = sqrt(x² + y² + z²), az = atan2(x, y), el = atan2(z, hypot(x, y))
    rho = np.hypot(x, y)
    cloud = PointCloud(
        range_m=np.hypot(rho, z),
        azimuth_rad=np.arctan2(x, y),
        elevation_rad=np.arctan2(z, rho),
        radial_velocity_mps=v,
        snr_db=np.where(np.isfinite(snr), snr, 0.0),
        x_m=x,
        y_m=y,
        z_m=z,
        source=np.full(len(x), SOURCE_OTHER, dtype=np.int32),
    )
    return cloud, keep


#: Target-index values that are not a track id (TI's people-tracking demo: 253 SNR too weak,
#: 254 outside the boundary box, 255 not associated).
TARGET_INDEX_NONE = 253


def point_tracks_from_indices(
    counts: np.ndarray, indices: list[tuple[int, np.ndarray]]
) -> tuple[np.ndarray, int]:
    """Per point, the firmware's track id from its target-index lists (TLV 1011 / 309, vendor
    CSV rows v8); -1 for none.

    ``counts[k]``: points of frame (or packet) k, in order; ``indices``: ``(k, index)`` pairs,
    the index sent with frame k labelling the points of frame k-1 (the firmware associates the
    previous frame's cloud). Values >= :data:`TARGET_INDEX_NONE` are -1; an index whose length
    is not the previous frame's point count labels nothing. Returns the ids and how many index
    lists were used.
    """
    counts = np.asarray(counts, dtype=np.int64)
    out = np.full(int(counts.sum()), -1, dtype=np.int64)
    starts = np.concatenate(([0], np.cumsum(counts)))
    used = 0
    for k, idx in indices:
        if not 1 <= k <= len(counts) or len(idx) != counts[k - 1]:
            continue
        ids = np.asarray(idx, dtype=np.int64)
        out[starts[k - 1] : starts[k]] = np.where((ids >= 0) & (ids < TARGET_INDEX_NONE), ids, -1)
        used += 1
    return out, used


# ---- truth ------------------------------------------------------------------------------------
def read_truth_csv(path: str | os.PathLike) -> np.ndarray:
    """Ground truth ``time_s, person, x_m, y_m`` (a header line naming these columns, then one
    row per sample); returns a structured array sorted by time.

    Bad input is one :class:`InputError` naming the file, line and field.
    """
    from core.files import read_text

    src = str(path)
    text = read_text(path, what="truth CSV")
    rows = csv.reader(io.StringIO(text))
    out: list[tuple[float, int, float, float]] = []
    header_seen = False
    for lineno, row in enumerate(rows, start=1):
        cells = [c.strip() for c in row]
        if not cells or all(not c for c in cells) or cells[0].startswith("#"):
            continue
        if not header_seen:
            if tuple(c.lower() for c in cells) != TRUTH_COLUMNS:
                raise InputError(
                    f"the first line must name the columns {','.join(TRUTH_COLUMNS)}, got "
                    f"{','.join(cells)[:80]!r}",
                    f"{src}:{lineno}",
                )
            header_seen = True
            continue
        if len(cells) != len(TRUTH_COLUMNS):
            raise InputError(
                f"expected {len(TRUTH_COLUMNS)} fields ({','.join(TRUTH_COLUMNS)}), got "
                f"{len(cells)}",
                f"{src}:{lineno}",
            )
        vals: list[float] = []
        for name, c in zip(TRUTH_COLUMNS, cells):
            try:
                val = float(c)
            except ValueError:
                raise InputError(
                    f"{name} must be a number, got {c[:40]!r}", f"{src}:{lineno}"
                ) from None
            if not math.isfinite(val):
                raise InputError(f"{name} must be finite, got {c[:40]!r}", f"{src}:{lineno}")
            vals.append(val)
        t, person, x, y = vals
        if t < 0:
            raise InputError(f"time_s must be >= 0, got {t:g}", f"{src}:{lineno}")
        if person != int(person) or not 0 <= person < MAX_PERSONS:
            raise InputError(
                f"person must be an integer in [0, {MAX_PERSONS}), got {cells[1][:20]!r}",
                f"{src}:{lineno}",
            )
        out.append((t, int(person), x, y))
    if not header_seen:
        raise InputError(f"no header line {','.join(TRUTH_COLUMNS)}", src)
    a = np.array(out, dtype=[("time_s", "f8"), ("person", "i4"), ("x_m", "f8"), ("y_m", "f8")])
    return np.sort(a, order=("time_s", "person"))


def truth_on_frames(
    truth: np.ndarray, t_s: np.ndarray, frame_period_s: float
) -> tuple[np.ndarray, np.ndarray]:
    """Truth positions and velocities on the frame times: each person's samples interpolated
    linearly in time; NaN (absent) outside the person's first..last sample (by more than
    :data:`TRUTH_TOLERANCE_FRAMES` periods). Returns ``(F, n_persons, 2)`` twice (m, m/s)."""
    n_persons = int(truth["person"].max()) + 1 if len(truth) else 0
    f = len(t_s)
    xy = np.full((f, n_persons, 2), np.nan)
    v = np.full((f, n_persons, 2), np.nan)
    tol = TRUTH_TOLERANCE_FRAMES * frame_period_s
    for p in range(n_persons):
        s = truth[truth["person"] == p]
        if len(s) == 0:
            continue
        ts, idx = np.unique(s["time_s"], return_index=True)
        px, py = s["x_m"][idx], s["y_m"][idx]
        inside = (t_s >= ts[0] - tol) & (t_s <= ts[-1] + tol)
        xy[inside, p, 0] = np.interp(t_s[inside], ts, px)
        xy[inside, p, 1] = np.interp(t_s[inside], ts, py)
        if len(ts) > 1:
            vx, vy = np.gradient(px, ts), np.gradient(py, ts)
            v[inside, p, 0] = np.interp(t_s[inside], ts, vx)
            v[inside, p, 1] = np.interp(t_s[inside], ts, vy)
        else:
            v[inside, p] = 0.0
    return xy, v


def to_dataset(
    rec: Recording, *, truth: np.ndarray | None = None, source_name: str = ""
) -> Dataset:
    """The recording as a data set; without truth the data set has no persons (``truth_xy_m``
    of shape ``(F, 0, 2)``): it can be tracked and shown, not scored or tuned on."""
    if rec.n_frames > MAX_DATASET_FRAMES:
        raise InputError(
            f"{rec.n_frames} frames, more than the data-set limit {MAX_DATASET_FRAMES}", source_name
        )
    if rec.n_frames == 0:
        raise InputError("no frames to import", source_name)
    if truth is not None and len(truth):
        xy, v = truth_on_frames(truth, rec.t_s, rec.radar.frame_period_s)
    else:
        xy = np.zeros((rec.n_frames, 0, 2))
        v = np.zeros((rec.n_frames, 0, 2))
    n_traj = int(rec.trajectory[-1]) + 1
    meta = {
        "imported_from": source_name,
        "format": rec.format,
        "notes": list(rec.notes),
        **rec.meta,
    }
    ds = Dataset.from_cloud(
        cloud=rec.cloud,
        counts=rec.counts,
        trajectory=rec.trajectory,
        truth_t_s=rec.t_s,
        truth_xy_m=xy,
        truth_v_mps=v,
        trajectory_class=[REAL_CLASS] * n_traj,
        scene_json=json.dumps({"imported": meta}),
        radar_json=json.dumps(rec.radar.to_dict()),
        fidelity="real",
        seed=0,
    )
    return with_reference(ds, rec.ref_tracks, rec.ref_point_track)


def with_reference(
    ds: Dataset, ref_tracks: dict[str, np.ndarray] | None, point_track: np.ndarray | None
) -> Dataset:
    """``ds`` with TI's own tracks as its reference layer (rows sorted by frame, stable) and
    the per-point track ids; unchanged when both are None."""
    kw: dict[str, Any] = {}
    if ref_tracks is not None and len(ref_tracks["frame"]):
        order = np.argsort(ref_tracks["frame"], kind="stable")
        kw["ref_frame"] = np.asarray(ref_tracks["frame"], dtype=np.int64)[order]
        kw["ref_track_id"] = np.asarray(ref_tracks["track_id"], dtype=np.int64)[order]
        for key in ("x_m", "y_m", "z_m", "vx_mps", "vy_mps"):
            kw[f"ref_{key}"] = np.asarray(ref_tracks[key], dtype=np.float64)[order]
        finite = np.ones(len(order), dtype=bool)
        for key in ("x_m", "y_m", "z_m", "vx_mps", "vy_mps"):
            finite &= np.isfinite(kw[f"ref_{key}"])
        if not finite.all():  # a track row with a non-finite value is not a position
            kw = {k: v[finite] for k, v in kw.items()}
    if point_track is not None and len(point_track) == len(ds.frame):
        kw["ref_point_track"] = np.asarray(point_track, dtype=np.int64)
    if not kw:
        return ds
    try:
        return dataclasses.replace(ds, **kw)
    except ValueError as exc:
        raise InputError(f"the recording's reference tracks: {exc}") from None


def has_truth(ds: Dataset) -> bool:
    """True when the data set has at least one person with a position somewhere."""
    return ds.n_persons > 0 and bool(np.isfinite(ds.truth_xy_m).any())
