"""Data set files (SPEC §6): point clouds and ground truth of a set of trajectories in one .npz.

Plain arrays only (loadable with ``allow_pickle=False``), written to a temporary name and renamed
so that no half-written file ever exists.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from core.errors import InputError
from core.files import check_text_field, parse_json, read_npz, write_npz_atomic
from core.limits import FRAME_PERIOD_RANGE_S, MAX_DATASET_FRAMES, MAX_PERSONS
from core.pointcloud import POINT_FIELDS, PointCloud

PER_POINT = ("frame", *POINT_FIELDS, "source")
PER_FRAME = ("trajectory", "truth_t_s", "truth_xy_m", "truth_v_mps")
REQUIRED = (*PER_POINT, *PER_FRAME, "trajectory_class", "scene_json", "radar_json")
#: The reference layer (optional): TI's own tracks of a recording, one entry per track row.
REF_INT = ("ref_frame", "ref_track_id")
REF_FLOAT = ("ref_x_m", "ref_y_m", "ref_z_m", "ref_vx_mps", "ref_vy_mps")
REF_FIELDS = (*REF_INT, *REF_FLOAT)
#: Optional per-frame head count (-1: unknown) and per-point reference track id (-1: none).
OPTIONAL_ARRAYS = (*REF_FIELDS, "ref_point_track", "people_count")


def _empty_int() -> np.ndarray:
    return np.zeros(0, dtype=np.int64)


def _empty_float() -> np.ndarray:
    return np.zeros(0, dtype=np.float64)


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

    Optional, empty (length 0) when absent:

    * the reference layer, TI's own tracks of a recording, one entry per track row (length R,
      sorted by ``ref_frame``): ``ref_frame`` (the data set's frame index), ``ref_track_id``,
      ``ref_x_m``, ``ref_y_m``, ``ref_z_m``, ``ref_vx_mps``, ``ref_vy_mps`` (as the firmware
      reports them);
    * ``ref_point_track`` (length P): per point, the id of TI's track the firmware associated it
      with, -1 for none;
    * ``people_count`` (length F): the number of people present in each frame (a head count),
      -1 where unknown.
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
    ref_frame: np.ndarray = field(default_factory=_empty_int)
    ref_track_id: np.ndarray = field(default_factory=_empty_int)
    ref_x_m: np.ndarray = field(default_factory=_empty_float)
    ref_y_m: np.ndarray = field(default_factory=_empty_float)
    ref_z_m: np.ndarray = field(default_factory=_empty_float)
    ref_vx_mps: np.ndarray = field(default_factory=_empty_float)
    ref_vy_mps: np.ndarray = field(default_factory=_empty_float)
    ref_point_track: np.ndarray = field(default_factory=_empty_int)
    people_count: np.ndarray = field(default_factory=_empty_int)

    def __post_init__(self) -> None:
        p = np.shape(self.frame)[0] if np.ndim(self.frame) == 1 else -1
        for name in PER_POINT:
            if np.shape(getattr(self, name)) != (p,):
                raise ValueError(
                    f"Dataset.{name} must have shape (P,) like frame, got "
                    f"{np.shape(getattr(self, name))}"
                )
        if np.ndim(self.trajectory) != 1:
            raise ValueError(
                f"Dataset.trajectory must have shape (F,), got {np.shape(self.trajectory)}"
            )
        f = len(self.trajectory)
        if np.shape(self.truth_t_s) != (f,):
            raise ValueError(
                f"Dataset.truth_t_s must have shape ({f},), got {np.shape(self.truth_t_s)}"
            )
        for name in ("truth_xy_m", "truth_v_mps"):
            shape = np.shape(getattr(self, name))
            if len(shape) != 3 or shape[0] != f or shape[2] != 2:
                raise ValueError(f"Dataset.{name} must have shape ({f}, n_persons, 2), got {shape}")
        if np.shape(self.truth_v_mps) != np.shape(self.truth_xy_m):
            raise ValueError("Dataset.truth_v_mps must have the shape of truth_xy_m")
        if self.truth_xy_m.shape[1] > MAX_PERSONS:
            raise ValueError(
                f"Dataset has {self.truth_xy_m.shape[1]} persons, more than the limit {MAX_PERSONS}"
            )
        if f > MAX_DATASET_FRAMES:
            raise ValueError(f"Dataset has {f} frames, more than the limit {MAX_DATASET_FRAMES}")
        if p and np.any(np.diff(self.frame) < 0):
            raise ValueError("Dataset.frame must be sorted")
        if p and not (0 <= self.frame[0] and self.frame[-1] < f):
            raise ValueError(
                f"Dataset.frame must index the {f} frames, got {self.frame[0]}..{self.frame[-1]}"
            )
        if f and np.any(np.diff(self.trajectory) < 0):
            raise ValueError("Dataset.trajectory must be non-decreasing")
        k = len(self.trajectory_class)
        if np.ndim(self.trajectory_class) != 1:
            raise ValueError("Dataset.trajectory_class must have shape (K,)")
        if f and not (self.trajectory[0] == 0 and self.trajectory[-1] == k - 1):
            raise ValueError(
                f"Dataset.trajectory must number the {k} trajectories of trajectory_class "
                f"0..{k - 1}, got {self.trajectory[0]}..{self.trajectory[-1]}"
            )
        if f and np.any(np.diff(self.trajectory) > 1):
            raise ValueError("Dataset.trajectory skips a trajectory (a step > 1)")
        if not f and k:
            raise ValueError(f"Dataset has no frames but {k} trajectory classes")
        for name in (*POINT_FIELDS, "truth_t_s"):
            if not np.all(np.isfinite(getattr(self, name))):
                raise ValueError(f"Dataset.{name} must be finite")
        for name in ("truth_xy_m", "truth_v_mps"):
            a = getattr(self, name)
            if np.any(np.isinf(a)):  # NaN marks a person absent from a frame
                raise ValueError(f"Dataset.{name} must be finite or NaN (absent), got infinity")
        absent = np.isnan(self.truth_xy_m)
        if np.any(absent != absent[..., :1]) or np.any(np.isnan(self.truth_v_mps) != absent):
            raise ValueError(
                "Dataset.truth_xy_m and truth_v_mps must be NaN together (a person absent from "
                "a frame has neither position nor velocity)"
            )
        self._check_optional(p, f)

    def _check_optional(self, p: int, f: int) -> None:
        r = np.shape(self.ref_frame)[0] if np.ndim(self.ref_frame) == 1 else -1
        for name in REF_FIELDS:
            a = getattr(self, name)
            if np.shape(a) != (r,):
                raise ValueError(
                    f"Dataset.{name} must have shape (R,) like ref_frame, got {np.shape(a)}"
                )
        for name in (*REF_INT, "ref_point_track", "people_count"):
            if getattr(self, name).dtype.kind not in "iu":
                raise ValueError(f"Dataset.{name} must hold integers")
        if r:
            if np.any(np.diff(self.ref_frame) < 0):
                raise ValueError("Dataset.ref_frame must be sorted")
            if not (0 <= self.ref_frame[0] and self.ref_frame[-1] < f):
                raise ValueError(
                    f"Dataset.ref_frame must index the {f} frames, got "
                    f"{self.ref_frame[0]}..{self.ref_frame[-1]}"
                )
            if np.any(self.ref_track_id < 0):
                raise ValueError("Dataset.ref_track_id must be >= 0")
            for name in REF_FLOAT:
                if not np.all(np.isfinite(getattr(self, name))):
                    raise ValueError(f"Dataset.{name} must be finite")
        if np.shape(self.ref_point_track) not in ((0,), (p,)):
            raise ValueError(
                f"Dataset.ref_point_track must have shape (0,) or ({p},), got "
                f"{np.shape(self.ref_point_track)}"
            )
        if np.any(self.ref_point_track < -1):
            raise ValueError("Dataset.ref_point_track must be a track id >= 0 or -1 (none)")
        if np.shape(self.people_count) not in ((0,), (f,)):
            raise ValueError(
                f"Dataset.people_count must have shape (0,) or ({f},), got "
                f"{np.shape(self.people_count)}"
            )
        if np.any(self.people_count < -1) or np.any(self.people_count > MAX_PERSONS):
            raise ValueError(
                f"Dataset.people_count must be a count in [0, {MAX_PERSONS}] or -1 (unknown)"
            )

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
    def has_reference(self) -> bool:
        """True when the data set carries TI's own tracks (the reference layer)."""
        return len(self.ref_frame) > 0

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
        for name in OPTIONAL_ARRAYS:
            if len(getattr(self, name)):
                arrays[name] = getattr(self, name)
        write_npz_atomic(path, arrays)
        return path

    @classmethod
    def load(cls, path: str | os.PathLike) -> Dataset:
        """Read a data set; a missing or malformed file is an :class:`InputError` naming it."""
        src = str(path)
        data = read_npz(path, what="data set")
        missing = [k for k in REQUIRED if k not in data]
        if missing:
            raise InputError(f"not a RadarTune data set: missing arrays {missing}", src)
        kw: dict = {}
        for k in (*PER_POINT, *PER_FRAME, "trajectory_class"):
            kw[k] = _typed(data[k], k, src)
        for k in OPTIONAL_ARRAYS:  # absent from files written before they existed
            if k in data:
                kw[k] = _typed(data[k], k, src)
                if k in REF_FLOAT:
                    kw[k] = kw[k].astype(np.float64)
        present = [k for k in REF_FIELDS if k in kw]
        if present and len(present) != len(REF_FIELDS):
            missing_ref = [k for k in REF_FIELDS if k not in kw]
            raise InputError(
                f"the reference layer is incomplete: missing arrays {missing_ref}", src
            )
        for k in ("scene_json", "radar_json", *(("fidelity",) if "fidelity" in data else ())):
            kw[k] = _text(data[k], k, src)
        if kw["scene_json"]:
            parse_json(kw["scene_json"], f"{src} (scene_json)")
        radar = parse_json(kw["radar_json"], f"{src} (radar_json)") if kw["radar_json"] else {}
        if not isinstance(radar, dict):
            raise InputError(
                f"radar_json must be a JSON object (the radar configuration), got "
                f"{kw['radar_json'][:40]!r}",
                src,
            )
        if isinstance(radar, dict) and "frame_period_s" in radar:
            t = radar["frame_period_s"]
            lo, hi = FRAME_PERIOD_RANGE_S
            if isinstance(t, bool) or not isinstance(t, int | float) or not lo <= t <= hi:
                raise InputError(
                    f"radar_json frame_period_s must be in [{lo:g}, {hi:g}] s, got {t!r}", src
                )
        if "seed" in data:
            seed = data["seed"]
            if seed.shape != () or seed.dtype.kind not in "iu" or int(seed) < 0:
                raise InputError(f"seed must be one integer >= 0, got {seed!r}", src)
            kw["seed"] = int(seed)
        try:
            return cls(**kw)
        except ValueError as exc:
            raise InputError(str(exc), src) from None


#: dtype kinds accepted per array: integers for indices, real numbers for values, text for class.
_INTEGER_ARRAYS = ("frame", "source", "trajectory", *REF_INT, "ref_point_track", "people_count")


def _typed(a: np.ndarray, name: str, src: str) -> np.ndarray:
    """``a`` checked for the kind of values array ``name`` holds."""
    if name == "trajectory_class":
        if a.dtype.kind != "U" or a.ndim != 1:
            raise InputError(
                f"trajectory_class must be a 1-D text array, got {a.dtype} {a.shape}", src
            )
        return a
    if name in _INTEGER_ARRAYS:
        if a.dtype.kind not in "iu":
            raise InputError(f"{name} must hold integers, got dtype {a.dtype}", src)
        if name in OPTIONAL_ARRAYS:
            if a.ndim != 1:
                raise InputError(f"{name} must be 1-D, got shape {a.shape}", src)
            if a.dtype.kind == "u" and a.size and int(a.max()) > np.iinfo(np.int64).max:
                raise InputError(f"{name} holds values beyond int64", src)
            return a.astype(np.int64)
        return a
    if a.dtype.kind not in "iuf":
        raise InputError(f"{name} must hold real numbers, got dtype {a.dtype}", src)
    if name in OPTIONAL_ARRAYS and a.ndim != 1:
        raise InputError(f"{name} must be 1-D, got shape {a.shape}", src)
    return a


def _text(a: np.ndarray, name: str, src: str) -> str:
    if a.shape != () or a.dtype.kind != "U":
        raise InputError(f"{name} must be one text value, got {a.dtype} {a.shape}", src)
    return check_text_field(str(a), name)
