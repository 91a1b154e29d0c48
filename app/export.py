"""Record and export (Qt-free): point clouds, tracks and metrics of the cached run to CSV and to
``.npz`` (the point clouds in the data-set format of :mod:`core.dataset`).

Every file is written atomically (:mod:`core.files`): a failed export leaves nothing
half-written. Floats are written with 17 significant digits, so a CSV read back gives the same
numbers.
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from app.data import FrameData, TrackingResult
from core.files import write_npz_atomic, write_text_atomic
from core.pointcloud import POINT_FIELDS

POINT_COLUMNS = ("frame", "t_s", *POINT_FIELDS, "source")
TRACK_COLUMNS = (
    "frame", "t_s", "track_id", "confirmed", "psi", "x_m", "y_m", "vx_mps", "vy_mps",
    "sigma_x_m", "sigma_y_m", "age_s", "n_associated", "nis",
)  # fmt: skip
METRIC_COLUMNS = (
    "frame", "t_s", "running_loss_m2", "running_rmse_m", "ospa_m",
    "estimate_x_m", "estimate_y_m", "truth_x_m", "truth_y_m",
)  # fmt: skip


def _csv(columns: Sequence[str], table: np.ndarray, int_columns: Sequence[str]) -> str:
    buf = io.StringIO()
    buf.write(",".join(columns) + "\n")
    fmt = ["%d" if c in int_columns else "%.17g" for c in columns]
    if len(table):
        np.savetxt(buf, table, delimiter=",", fmt=fmt)
    return buf.getvalue()


def point_table(frames: Sequence[FrameData]) -> np.ndarray:
    """Every point of every frame: ``(P, len(POINT_COLUMNS))`` float64, sorted by frame."""
    parts = []
    for f in frames:
        c = f.cloud
        n = len(c)
        cols = [np.full(n, f.index), np.full(n, f.t_s)]
        cols += [np.asarray(getattr(c, name), dtype=float) for name in POINT_FIELDS]
        cols.append(np.asarray(c.source, dtype=float))
        parts.append(np.column_stack(cols) if n else np.zeros((0, len(POINT_COLUMNS))))
    return np.vstack(parts) if parts else np.zeros((0, len(POINT_COLUMNS)))


def track_table(result: TrackingResult, frame_period_s: float) -> np.ndarray:
    """Every live track of every tracked frame: ``(N, len(TRACK_COLUMNS))`` float64."""
    parts = []
    for k, tf in enumerate(result.frames):
        n = len(tf)
        if n == 0:
            continue
        vel = tf.velocity_xy_mps if tf.velocity_xy_mps is not None else np.full((n, 2), np.nan)
        sig = tf.sigma_xy_m if tf.sigma_xy_m is not None else np.full((n, 2), np.nan)
        birth = tf.birth_frame if tf.birth_frame is not None else np.full(n, np.nan)
        assoc = tf.n_associated if tf.n_associated is not None else np.full(n, -1)
        nis = tf.nis if tf.nis is not None else np.full(n, np.nan)
        parts.append(
            np.column_stack(
                [
                    np.full(n, k), np.full(n, k * frame_period_s), tf.track_id, tf.confirmed,
                    tf.psi, tf.xy_m, vel, sig, (k - np.asarray(birth)) * frame_period_s,
                    assoc, nis,
                ]
            ).astype(float)
        )  # fmt: skip
    return np.vstack(parts) if parts else np.zeros((0, len(TRACK_COLUMNS)))


def metric_table(result: TrackingResult, frame_period_s: float) -> np.ndarray:
    """The per-frame metrics of the run: ``(F, len(METRIC_COLUMNS))`` float64."""
    f = result.n_frames
    k = np.arange(f)
    return np.column_stack(
        [
            k, k * frame_period_s, result.running_loss, result.running_rmse_m, result.ospa_m,
            result.estimate_xy_m, result.truth_xy_m,
        ]
    ).astype(float).reshape(f, len(METRIC_COLUMNS))  # fmt: skip


def write_points_csv(path: str | Path, frames: Sequence[FrameData]) -> Path:
    return write_text_atomic(path, _csv(POINT_COLUMNS, point_table(frames), ("frame", "source")))


def write_tracks_csv(path: str | Path, result: TrackingResult, frame_period_s: float) -> Path:
    ints = ("frame", "track_id", "confirmed", "n_associated")
    return write_text_atomic(path, _csv(TRACK_COLUMNS, track_table(result, frame_period_s), ints))


def write_metrics_csv(path: str | Path, result: TrackingResult, frame_period_s: float) -> Path:
    table = metric_table(result, frame_period_s)
    return write_text_atomic(path, _csv(METRIC_COLUMNS, table, ("frame",)))


def write_tracks_npz(path: str | Path, result: TrackingResult, frame_period_s: float) -> Path:
    """Tracks and metrics as plain arrays (``numpy.load(..., allow_pickle=False)``): one array
    per column of the track and metric tables, prefixed ``track_`` and ``metric_``."""
    tracks = track_table(result, frame_period_s)
    metrics = metric_table(result, frame_period_s)
    arrays = {f"track_{c}": tracks[:, i] for i, c in enumerate(TRACK_COLUMNS)}
    arrays |= {f"metric_{c}": metrics[:, i] for i, c in enumerate(METRIC_COLUMNS)}
    return write_npz_atomic(path, arrays)


def read_csv(path: str | Path) -> tuple[list[str], np.ndarray]:
    """A CSV written here, back as (columns, ``(n, m)`` float64)."""
    text = Path(path).read_text(encoding="utf-8")
    header, _, body = text.partition("\n")
    columns = header.split(",")
    if not body.strip():
        return columns, np.zeros((0, len(columns)))
    table = np.loadtxt(io.StringIO(body), delimiter=",", ndmin=2)
    return columns, table


def export_run(
    folder: str | Path,
    frames: Sequence[FrameData],
    result: TrackingResult | None,
    frame_period_s: float,
    write_dataset,
    *,
    stem: str = "radartune",
) -> list[Path]:
    """Write everything of the cached run into ``folder``: ``<stem>-points.csv``,
    ``<stem>-tracks.csv``, ``<stem>-metrics.csv``, ``<stem>-tracks.npz`` and the data set
    ``<stem>-dataset.npz`` (through ``write_dataset(path)``, the engine's data-set writer).
    Tracks and metrics are skipped while no tracker run exists. Returns the files written."""
    folder = Path(folder)
    out = [write_points_csv(folder / f"{stem}-points.csv", frames)]
    out.append(write_dataset(folder / f"{stem}-dataset.npz"))
    if result is not None:
        out.append(write_tracks_csv(folder / f"{stem}-tracks.csv", result, frame_period_s))
        out.append(write_metrics_csv(folder / f"{stem}-metrics.csv", result, frame_period_s))
        out.append(write_tracks_npz(folder / f"{stem}-tracks.npz", result, frame_period_s))
    return [Path(p) for p in out]
