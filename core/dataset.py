"""Data set files (SPEC §6): point clouds and ground truth of a set of trajectories in one .npz.

Plain arrays only (loadable with ``allow_pickle=False``), written to a temporary name and renamed
so that no half-written file ever exists.
"""

from __future__ import annotations

import json
import os
import tempfile
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from core.errors import InputError
from core.pointcloud import POINT_FIELDS, PointCloud

PER_POINT = ("frame", *POINT_FIELDS, "source")
PER_FRAME = ("trajectory", "truth_t_s", "truth_xy_m", "truth_v_mps")
REQUIRED = (*PER_POINT, *PER_FRAME, "trajectory_class", "scene_json", "radar_json")


@dataclass(frozen=True, slots=True, kw_only=True)
class Dataset:
    """Point clouds and truth of F frames grouped into K trajectories.

    Per point (length P, sorted by ``frame``): ``frame`` (global frame index), the
    :data:`core.pointcloud.POINT_FIELDS` and ``source``.
    Per frame (length F): ``trajectory`` (index of its trajectory, non-decreasing),
    ``truth_t_s``, ``truth_xy_m`` ``(F, n_persons, 2)``, ``truth_v_mps`` ``(F, n_persons, 2)``.
    Per trajectory (length K): ``trajectory_class`` (``"a"`` … ``"e"`` or ``"drawn"``).
    ``scene_json`` / ``radar_json``: the scene and radar configuration that produced it.
    ``fidelity`` and ``seed`` record how it was simulated.
    """

    frame: np.ndarray
    range_m: np.ndarray
    azimuth_rad: np.ndarray
    elevation_rad: np.ndarray
    radial_velocity_mps: np.ndarray
    snr_db: np.ndarray
    x_m: np.ndarray
    y_m: np.ndarray
    z_m: np.ndarray
    source: np.ndarray
    trajectory: np.ndarray
    truth_t_s: np.ndarray
    truth_xy_m: np.ndarray
    truth_v_mps: np.ndarray
    trajectory_class: np.ndarray
    scene_json: str
    radar_json: str
    fidelity: str = "exact"
    seed: int = 0

    def __post_init__(self) -> None:
        p = len(self.frame)
        for name in PER_POINT:
            if np.shape(getattr(self, name)) != (p,):
                raise ValueError(f"Dataset.{name} must have shape ({p},)")
        f = len(self.trajectory)
        if self.truth_xy_m.ndim != 3 or self.truth_xy_m.shape[0] != f:
            raise ValueError("Dataset.truth_xy_m must have shape (F, n_persons, 2)")
        if p and np.any(np.diff(self.frame) < 0):
            raise ValueError("Dataset.frame must be sorted")
        if f and np.any(np.diff(self.trajectory) < 0):
            raise ValueError("Dataset.trajectory must be non-decreasing")

    # ---- derived -----------------------------------------------------------------------------
    @property
    def n_frames(self) -> int:
        return len(self.trajectory)

    @property
    def n_trajectories(self) -> int:
        return len(self.trajectory_class)

    @property
    def n_persons(self) -> int:
        return self.truth_xy_m.shape[1]

    @property
    def frame_offsets(self) -> np.ndarray:
        """Point index ranges: points of frame f are ``offsets[f]:offsets[f+1]``, shape (F+1,)."""
        return np.searchsorted(self.frame, np.arange(self.n_frames + 1)).astype(np.int64)

    @property
    def trajectory_offsets(self) -> np.ndarray:
        """Frame index ranges: frames of trajectory k are ``offsets[k]:offsets[k+1]``."""
        return np.searchsorted(self.trajectory, np.arange(self.n_trajectories + 1)).astype(np.int64)

    def measurements(self) -> np.ndarray:
        """All points as tracker measurements ``[r, az, vr]``, shape (P, 3), float64."""
        return np.column_stack((self.range_m, self.azimuth_rad, self.radial_velocity_mps)).astype(
            np.float64
        )

    def point_cloud(self, frame: int) -> PointCloud:
        """The point cloud of one global frame."""
        lo, hi = np.searchsorted(self.frame, [frame, frame + 1])
        return PointCloud(
            **{f: getattr(self, f)[lo:hi] for f in POINT_FIELDS}, source=self.source[lo:hi]
        )

    def scene(self) -> dict:
        return json.loads(self.scene_json)

    # ---- building ----------------------------------------------------------------------------
    @classmethod
    def from_frames(
        cls,
        *,
        clouds: list[PointCloud],
        trajectory: np.ndarray,
        truth_t_s: np.ndarray,
        truth_xy_m: np.ndarray,
        truth_v_mps: np.ndarray,
        trajectory_class: list[str],
        scene_json: str,
        radar_json: str,
        fidelity: str = "exact",
        seed: int = 0,
    ) -> Dataset:
        """Assemble from one point cloud per global frame."""
        return cls.from_cloud(
            cloud=PointCloud.concatenate(clouds),
            counts=np.array([len(c) for c in clouds], dtype=np.int64),
            trajectory=trajectory,
            truth_t_s=truth_t_s,
            truth_xy_m=truth_xy_m,
            truth_v_mps=truth_v_mps,
            trajectory_class=trajectory_class,
            scene_json=scene_json,
            radar_json=radar_json,
            fidelity=fidelity,
            seed=seed,
        )

    @classmethod
    def from_cloud(
        cls,
        *,
        cloud: PointCloud,
        counts: np.ndarray,
        trajectory: np.ndarray,
        truth_t_s: np.ndarray,
        truth_xy_m: np.ndarray,
        truth_v_mps: np.ndarray,
        trajectory_class: list[str],
        scene_json: str,
        radar_json: str,
        fidelity: str = "exact",
        seed: int = 0,
    ) -> Dataset:
        """Assemble from the points of every global frame in frame order, ``counts[f]`` of frame
        ``f`` (what :meth:`from_frames` makes of one cloud per frame, without the split)."""
        merged = cloud
        counts = np.asarray(counts, dtype=np.int64)
        if counts.sum() != len(merged):
            raise InputError(f"counts: {counts.sum()} points counted, {len(merged)} given")
        frame = np.repeat(np.arange(len(counts)), counts).astype(np.int32)
        return cls(
            frame=frame,
            **{f: getattr(merged, f).astype(np.float64) for f in POINT_FIELDS},
            source=merged.source.astype(np.int32),
            trajectory=np.asarray(trajectory, dtype=np.int32),
            truth_t_s=np.asarray(truth_t_s, dtype=np.float64),
            truth_xy_m=np.asarray(truth_xy_m, dtype=np.float64),
            truth_v_mps=np.asarray(truth_v_mps, dtype=np.float64),
            trajectory_class=np.asarray(trajectory_class, dtype="U5"),
            scene_json=scene_json,
            radar_json=radar_json,
            fidelity=fidelity,
            seed=int(seed),
        )

    # ---- files -------------------------------------------------------------------------------
    def save(self, path: str | os.PathLike) -> Path:
        """Write atomically: a temporary file in the same folder, then rename."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        arrays = {name: getattr(self, name) for name in (*PER_POINT, *PER_FRAME)}
        arrays["trajectory_class"] = self.trajectory_class
        arrays["scene_json"] = np.array(self.scene_json)
        arrays["radar_json"] = np.array(self.radar_json)
        arrays["fidelity"] = np.array(self.fidelity)
        arrays["seed"] = np.array(self.seed)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
        try:
            with os.fdopen(fd, "wb") as fh:
                np.savez_compressed(fh, **arrays)
            os.replace(tmp, path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
        return path

    @classmethod
    def load(cls, path: str | os.PathLike) -> Dataset:
        """Read a data set; a missing or malformed file is an :class:`InputError` naming it."""
        path = Path(path)
        try:
            with np.load(path, allow_pickle=False) as data:
                missing = [k for k in REQUIRED if k not in data.files]
                if missing:
                    raise InputError(
                        f"not a RadarTune data set: missing arrays {missing}", str(path)
                    )
                kw = {k: data[k] for k in (*PER_POINT, *PER_FRAME, "trajectory_class")}
                kw["scene_json"] = str(data["scene_json"])
                kw["radar_json"] = str(data["radar_json"])
                if "fidelity" in data.files:
                    kw["fidelity"] = str(data["fidelity"])
                if "seed" in data.files:
                    kw["seed"] = int(data["seed"])
        except FileNotFoundError:
            raise InputError("file not found", str(path)) from None
        except (OSError, ValueError, zipfile.BadZipFile) as exc:
            if isinstance(exc, InputError):
                raise
            raise InputError(f"cannot read data set ({exc})", str(path)) from None
        try:
            return cls(**kw)
        except ValueError as exc:
            raise InputError(str(exc), str(path)) from None
