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
import re
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


# ---- truth ----------------------------------------------------------------------------------
#: A plain decimal number as a truth CSV holds it (Python's ``float`` would also take ``1_0``,
#: non-ASCII digits, ``inf`` and ``nan``).
_NUMBER = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$", re.ASCII)
#: Positions in a truth CSV beyond this (m) are refused: no room or hall is that large.
TRUTH_MAX_ABS_M = 1_000.0
#: Height (m) of a person's position when a truth CSV has no ``z_m`` column (the torso, where a
#: radar's points on a walking person centre; used only to project onto a tilted sensor).
TRUTH_DEFAULT_Z_M = 1.0
#: The columns of a head-count CSV.
COUNT_COLUMNS = ("t_start_s", "t_end_s", "people")


def _number(cell: str, name: str, where: str) -> float:
    c = cell.strip()
    if not _NUMBER.match(c):
        if c.isascii() and c.lower().lstrip("+-") in ("nan", "inf", "infinity"):
            raise InputError(f"{name} must be finite, got {c[:40]!r}", where)
        raise InputError(f"{name} must be a number, got {c[:40]!r}", where)
    val = float(c)
    if not math.isfinite(val):
        raise InputError(f"{name} must be finite, got {c[:40]!r}", where)
    return val


def _csv_rows(path: str | os.PathLike, what: str) -> list[tuple[int, list[str]]]:
    """(line number, stripped cells) of every non-blank, non-comment line."""
    from core.files import read_text

    text = read_text(path, what=what)
    out = []
    for lineno, row in enumerate(csv.reader(io.StringIO(text)), start=1):
        cells = [c.strip() for c in row]
        if not cells or all(not c for c in cells) or cells[0].startswith("#"):
            continue
        out.append((lineno, cells))
    return out


def read_truth_csv(path: str | os.PathLike) -> np.ndarray:
    """Ground truth ``time_s, person, x_m, y_m[, z_m]`` (a header line naming these columns,
    then one row per sample); returns a structured array sorted by time (``z_m`` NaN when the
    file has no such column).

    Bad input is one :class:`InputError` naming the file, line and field: a number that is not
    a plain ASCII decimal, a position beyond :data:`TRUTH_MAX_ABS_M`, a header without rows,
    times that go backwards or repeat for a person, times that are all equal.
    """
    src = str(path)
    rows = _csv_rows(path, "truth CSV")
    if not rows:
        raise InputError(f"no header line {','.join(TRUTH_COLUMNS)}", src)
    lineno, cells = rows[0]
    header = tuple(c.lower() for c in cells)
    if header not in (TRUTH_COLUMNS, (*TRUTH_COLUMNS, "z_m")):
        raise InputError(
            f"the first line must name the columns {','.join(TRUTH_COLUMNS)}[,z_m], got "
            f"{','.join(cells)[:80]!r}",
            f"{src}:{lineno}",
        )
    if len(rows) == 1:
        raise InputError("the truth CSV has a header line and no samples", f"{src}:{lineno}")
    out: list[tuple[float, int, float, float, float]] = []
    last_t: dict[int, tuple[float, int]] = {}
    for lineno, cells in rows[1:]:
        where = f"{src}:{lineno}"
        if len(cells) != len(header):
            raise InputError(
                f"expected {len(header)} fields ({','.join(header)}), got {len(cells)}", where
            )
        vals = [_number(c, name, where) for name, c in zip(header, cells)]
        t, person, x, y = vals[:4]
        z = vals[4] if len(vals) == 5 else math.nan
        if t < 0:
            raise InputError(f"time_s must be >= 0, got {t:g}", where)
        if person != int(person) or not 0 <= person < MAX_PERSONS:
            raise InputError(
                f"person must be an integer in [0, {MAX_PERSONS}), got {cells[1][:20]!r}", where
            )
        for name, val in zip(("x_m", "y_m", "z_m"), (x, y, z)):
            if abs(val) > TRUTH_MAX_ABS_M:
                raise InputError(
                    f"{name} must be within ±{TRUTH_MAX_ABS_M:g} m, got {val:g}", where
                )
        p = int(person)
        if p in last_t and t <= last_t[p][0]:
            prev, prev_line = last_t[p]
            raise InputError(
                f"time_s of person {p} must increase: {t:g} s after {prev:g} s (line {prev_line})",
                where,
            )
        last_t[p] = (t, lineno)
        out.append((t, p, x, y, z))
    a = np.array(
        out,
        dtype=[("time_s", "f8"), ("person", "i4"), ("x_m", "f8"), ("y_m", "f8"), ("z_m", "f8")],
    )
    if len(a) > 1 and np.all(a["time_s"] == a["time_s"][0]):
        raise InputError(f"all {len(a)} samples have the same time_s {a['time_s'][0]:g} s", src)
    return np.sort(a, order=("time_s", "person"))


@dataclass(frozen=True, slots=True, kw_only=True)
class TruthAlignment:
    """How a camera's or motion-capture system's samples map onto the recording.

    Time: ``t_recording = offset_s + t_truth · (1 + drift_ppm · 1e-6)`` (the truth's clock may
    start elsewhere and run fast or slow). Pose: the radar in the truth's coordinates, at
    ``(sensor_x_m, sensor_y_m)`` and ``sensor_height_m`` above the truth's z = 0, its
    boresight at ``yaw_deg`` from the truth's +y axis towards +x and tilted down by
    ``tilt_deg``. A position becomes the radar's x (right), y (along the boresight), z (up
    along the array).
    """

    offset_s: float = 0.0
    drift_ppm: float = 0.0
    sensor_x_m: float = 0.0
    sensor_y_m: float = 0.0
    sensor_height_m: float = 0.0
    yaw_deg: float = 0.0
    tilt_deg: float = 0.0

    def __post_init__(self) -> None:
        for name in ("offset_s", "drift_ppm", "sensor_x_m", "sensor_y_m", "sensor_height_m",
                     "yaw_deg", "tilt_deg"):  # fmt: skip
            val = getattr(self, name)
            if isinstance(val, bool) or not isinstance(val, int | float) or not math.isfinite(val):
                raise InputError(f"TruthAlignment.{name} must be a finite number, got {val!r}")
        if abs(self.drift_ppm) >= 1e5:
            raise InputError(f"drift_ppm must be within ±100000, got {self.drift_ppm:g}")
        if not -90.0 < self.tilt_deg < 90.0:
            raise InputError(f"tilt_deg must be in (-90, 90), got {self.tilt_deg:g}")
        for name in ("sensor_x_m", "sensor_y_m", "sensor_height_m"):
            if abs(getattr(self, name)) > TRUTH_MAX_ABS_M:
                raise InputError(f"{name} must be within ±{TRUTH_MAX_ABS_M:g} m")

    @property
    def is_identity(self) -> bool:
        return self == TruthAlignment()

    def times(self, t: np.ndarray) -> np.ndarray:
        return self.offset_s + np.asarray(t, dtype=np.float64) * (1.0 + self.drift_ppm * 1e-6)

    def positions(self, x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
        """``(N, 3)`` radar-frame x, y, z of truth-frame positions (z NaN: the default
        height :data:`TRUTH_DEFAULT_Z_M`; with no height and no tilt it does not matter)."""
        z = np.where(np.isnan(z), TRUTH_DEFAULT_Z_M, z)
        dx = np.asarray(x) - self.sensor_x_m
        dy = np.asarray(y) - self.sensor_y_m
        dz = z - self.sensor_height_m
        yaw, tilt = math.radians(self.yaw_deg), math.radians(self.tilt_deg)
        # level frame: rotate the horizontal plane so that +y is the boresight's bearing
        xl = math.cos(yaw) * dx - math.sin(yaw) * dy
        yl = math.sin(yaw) * dx + math.cos(yaw) * dy
        # tilted down by θ: boresight (0, cos θ, -sin θ), array up (0, sin θ, cos θ)
        ys = math.cos(tilt) * yl - math.sin(tilt) * dz
        zs = math.sin(tilt) * yl + math.cos(tilt) * dz
        return np.column_stack((xl, ys, zs))


def align_truth(truth: np.ndarray, alignment: TruthAlignment) -> np.ndarray:
    """Truth samples (from :func:`read_truth_csv`) on the recording's clock and in the radar's
    coordinates; unchanged when the alignment is the identity and the truth has no heights."""
    if alignment.is_identity:
        return truth
    out = truth.copy()
    out["time_s"] = alignment.times(truth["time_s"])
    xyz = alignment.positions(truth["x_m"], truth["y_m"], truth["z_m"])
    out["x_m"], out["y_m"], out["z_m"] = xyz[:, 0], xyz[:, 1], xyz[:, 2]
    return np.sort(out, order=("time_s", "person"))


def read_count_csv(path: str | os.PathLike) -> np.ndarray:
    """A head count over time intervals ``t_start_s,t_end_s,people`` (header, then rows; times
    in s on the recording's clock, ``t_start_s < t_end_s``, intervals not overlapping);
    returns ``(K, 3)`` float64 rows sorted by start."""
    src = str(path)
    rows = _csv_rows(path, "head-count CSV")
    if not rows:
        raise InputError(f"no header line {','.join(COUNT_COLUMNS)}", src)
    lineno, cells = rows[0]
    if tuple(c.lower() for c in cells) != COUNT_COLUMNS:
        raise InputError(
            f"the first line must name the columns {','.join(COUNT_COLUMNS)}, got "
            f"{','.join(cells)[:80]!r}",
            f"{src}:{lineno}",
        )
    if len(rows) == 1:
        raise InputError("the head-count CSV has a header line and no rows", f"{src}:{lineno}")
    out = []
    for lineno, cells in rows[1:]:
        where = f"{src}:{lineno}"
        if len(cells) != 3:
            raise InputError(f"expected 3 fields ({','.join(COUNT_COLUMNS)}), got {len(cells)}",
                             where)  # fmt: skip
        t0, t1, n = (_number(c, name, where) for name, c in zip(COUNT_COLUMNS, cells))
        if not t0 < t1:
            raise InputError(f"t_end_s must be after t_start_s, got {t0:g} .. {t1:g}", where)
        if n != int(n) or not 0 <= n <= MAX_PERSONS:
            raise InputError(f"people must be an integer in [0, {MAX_PERSONS}], got {cells[2]!r}",
                             where)  # fmt: skip
        out.append((t0, t1, n, lineno))
    out.sort()
    for (_, a1, _, _), (b0, _, _, line_b) in zip(out, out[1:]):
        if b0 < a1:
            raise InputError(f"the interval overlaps the one ending at {a1:g} s", f"{src}:{line_b}")
    return np.array([r[:3] for r in out], dtype=np.float64)


def count_on_frames(counts: np.ndarray, t_s: np.ndarray) -> np.ndarray:
    """Per frame, the head count of the interval holding its time (``t_start <= t < t_end``),
    -1 where no interval does."""
    out = np.full(len(t_s), -1, dtype=np.int64)
    for t0, t1, n in counts:
        out[(t_s >= t0) & (t_s < t1)] = int(n)
    return out


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
    rec: Recording,
    *,
    truth: np.ndarray | None = None,
    source_name: str = "",
    alignment: TruthAlignment | None = None,
    counts: np.ndarray | None = None,
    people: int | None = None,
    truth_name: str = "the truth CSV",
) -> Dataset:
    """The recording as a data set; without truth the data set has no persons (``truth_xy_m``
    of shape ``(F, 0, 2)``): it can be tracked and shown, not scored on positions.

    ``truth``: samples of :func:`read_truth_csv`, mapped by ``alignment`` (time offset and
    drift, sensor pose) onto the frames; a truth that overlaps no frame is refused.
    ``counts``: head counts over intervals (:func:`read_count_csv`, on the same clock after
    ``alignment``'s time mapping), or ``people``: one head count for every frame; either fills
    ``people_count``.
    """
    if rec.n_frames > MAX_DATASET_FRAMES:
        raise InputError(
            f"{rec.n_frames} frames, more than the data-set limit {MAX_DATASET_FRAMES}", source_name
        )
    if rec.n_frames == 0:
        raise InputError("no frames to import", source_name)
    align = alignment or TruthAlignment()
    tol = TRUTH_TOLERANCE_FRAMES * rec.radar.frame_period_s
    t_first, t_last = float(rec.t_s[0]), float(rec.t_s[-1])
    if truth is not None and len(truth):
        truth = align_truth(truth, align)
        ts = truth["time_s"]
        if not np.any((ts >= t_first - tol) & (ts <= t_last + tol)) and not (
            ts[0] < t_first and ts[-1] > t_last
        ):
            raise InputError(
                f"{truth_name}'s times ({ts[0]:.6g} .. {ts[-1]:.6g} s on the recording's clock) "
                f"overlap none of the frames ({t_first:g} .. {t_last:g} s); align them with "
                "--truth-offset",
                source_name,
            )
        xy, v = truth_on_frames(truth, rec.t_s, rec.radar.frame_period_s)
    else:
        xy = np.zeros((rec.n_frames, 0, 2))
        v = np.zeros((rec.n_frames, 0, 2))
    people_count = None
    if counts is not None and people is not None:
        raise InputError("give a head count once: --people or --people-csv, not both")
    if counts is not None:
        c = np.array(counts, dtype=np.float64).reshape(-1, 3)
        c[:, :2] = align.times(c[:, :2])
        people_count = count_on_frames(c, rec.t_s)
        if np.all(people_count < 0):
            raise InputError(
                f"the head count's intervals ({c[0, 0]:.6g} .. {c[-1, 1]:.6g} s) overlap none "
                f"of the frames ({t_first:g} .. {t_last:g} s)",
                source_name,
            )
    elif people is not None:
        if (
            isinstance(people, bool)
            or not isinstance(people, int)
            or not 0 <= people <= MAX_PERSONS
        ):
            raise InputError(f"--people must be an integer in [0, {MAX_PERSONS}], got {people!r}")
        people_count = np.full(rec.n_frames, people, dtype=np.int64)
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
    ds = with_reference(ds, rec.ref_tracks, rec.ref_point_track)
    if people_count is not None:
        ds = dataclasses.replace(ds, people_count=people_count)
    return ds


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
