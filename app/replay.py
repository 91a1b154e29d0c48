"""``radartune gui --replay FILE``: play a recording through the same views.

A recording (an imported data set ``.npz``, or any file ``radartune import`` reads) becomes a
:class:`~core.dataset.Dataset`; :class:`ReplayEngine` is the app's :class:`~app.engine.Engine`
with the simulation replaced by that data set's frames. Everything else (the frame cache,
re-tracking, the views) works as for a simulated scene; editing the scene only restarts the
replay. Qt-free: the window receives the engine.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from app.data import FrameData
from app.engine import Engine, SceneInfo
from core.config import RadarConfig
from core.dataset import Dataset


def load_recording(path: str | Path, cfg: str | None = None) -> Dataset:
    """A data set ``.npz`` as is; any other recording imported (no truth) as
    ``radartune import`` would. Bad input raises :class:`~core.errors.InputError`."""
    path = Path(path)
    if path.suffix == ".npz":
        return Dataset.load(path)
    from core.formats.recording import to_dataset
    from core.recordings import read_recording

    return to_dataset(read_recording(path, fmt=None, cfg=cfg), source_name=str(path))


#: Walking speed (m/s): a radar whose unambiguous radial velocity is below it folds a walking
#: person's Doppler (the app warns).
WALKING_SPEED_MPS = 1.5

#: File-dialog filter of everything :func:`load_recording` reads.
RECORDING_FILTER = (
    "Recordings (*.dat *.bin *.json *.csv *.txt *.npz);;TI UART logs (*.dat *.bin);;"
    "Visualizer replays (*.json);;Point-cloud CSVs (*.csv *.txt);;DCA1000 captures (*.bin);;"
    "Data sets (*.npz);;All files (*)"
)


@dataclass(frozen=True, slots=True, kw_only=True)
class RecordingFacts:
    """What a loaded recording is and holds, as the recording panel shows it.

    ``dropped_frames`` is None where the file does not tell; ``n_ref_tracks`` counts TI's
    distinct track ids (0: no reference layer); ``max_head_count`` is -1 without a head count.
    """

    name: str
    format: str
    device: str
    n_frames: int
    dropped_frames: int | None
    frame_period_s: float
    points_per_frame: float
    max_points_per_frame: int
    has_snr: bool
    has_elevation: bool
    n_ref_tracks: int
    max_head_count: int
    has_truth: bool
    max_velocity_mps: float
    notes: tuple[str, ...] = ()

    @property
    def slow_radar(self) -> bool:
        """True when the radar folds walking speed (its maximum velocity is below it)."""
        return self.max_velocity_mps < WALKING_SPEED_MPS

    def rows(self) -> list[tuple[str, str]]:
        """(label, value) rows, in the panel's order."""
        yes = {True: "yes", False: "no"}
        dropped = "not recorded" if self.dropped_frames is None else str(self.dropped_frames)
        return [
            ("file", self.name),
            ("format", self.format),
            ("device", self.device),
            ("frames", str(self.n_frames)),
            ("dropped frames", dropped),
            ("frame period", f"{self.frame_period_s * 1e3:.1f} ms"),
            ("points a frame", f"{self.points_per_frame:.1f} (max {self.max_points_per_frame})"),
            ("SNR", yes[self.has_snr]),
            ("elevation", yes[self.has_elevation]),
            ("TI's tracks", f"{self.n_ref_tracks} ids" if self.n_ref_tracks else "no"),
            ("head count", str(self.max_head_count) if self.max_head_count >= 0 else "no"),
            ("ground truth", yes[self.has_truth]),
            ("max velocity", f"{self.max_velocity_mps:.2f} m/s"),
        ]


def short_notes(notes, sources) -> tuple[str, ...]:
    """The reader's notes with each path of ``sources`` (the file as read, the file a data set
    was imported from) shortened to its file name: the panel names the file once, in full
    nowhere (a path says where the user keeps it, not what the recording holds)."""
    paths = sorted({str(s) for s in sources if s and Path(str(s)).name != str(s)}, key=len)
    out = []
    for note in notes:
        for p in reversed(paths):  # the longest first: a path may contain a shorter one
            note = note.replace(p, Path(p).name)
        out.append(note)
    return tuple(out)


def recording_facts(ds: Dataset, name: str = "", source: str | Path = "") -> RecordingFacts:
    """The facts of data set ``ds`` (an imported recording or a simulated data set) read from
    the file ``source`` (its path shortened to the file name in the notes)."""
    from core.formats.recording import has_truth

    scene = json.loads(ds.scene_json) if ds.scene_json else {}
    imported = scene.get("imported") if isinstance(scene, dict) else None
    radar_doc = json.loads(ds.radar_json) if ds.radar_json else {}
    radar = RadarConfig.from_dict(radar_doc) if radar_doc else RadarConfig()
    if isinstance(imported, dict):
        fmt = str(imported.get("format", "recording"))
        notes = short_notes(
            (str(n) for n in imported.get("notes", ())),
            (source, imported.get("imported_from", "")),
        )
        assumed = any("radar assumed" in n for n in notes)
        device = str(imported.get("device") or "")
        if not device:
            device = "not stated" + (" (paper radar assumed)" if assumed else f" ({radar.name})")
        dropped = imported.get("dropped_frames")
        dropped = int(dropped) if isinstance(dropped, (int, float)) else None
    else:
        fmt, notes, device, dropped = f"RadarTune data set ({ds.fidelity})", (), radar.name, 0
    counts = np.diff(ds.frame_offsets)
    hc = np.asarray(ds.people_count)
    return RecordingFacts(
        name=name,
        format=fmt,
        device=device,
        n_frames=ds.n_frames,
        dropped_frames=dropped,
        frame_period_s=radar.frame_period_s,
        points_per_frame=float(counts.mean()) if len(counts) else 0.0,
        max_points_per_frame=int(counts.max()) if len(counts) else 0,
        # a reader without SNR fills one value (0 dB); elevation likewise
        has_snr=bool(len(ds.snr_db) and np.ptp(ds.snr_db) > 0),
        has_elevation=bool(len(ds.elevation_rad) and np.ptp(ds.elevation_rad) > 0),
        n_ref_tracks=len(np.unique(ds.ref_track_id)),
        max_head_count=int(hc.max()) if len(hc) and hc.max() >= 0 else -1,
        has_truth=has_truth(ds),
        max_velocity_mps=radar.max_velocity_mps,
        notes=notes,
    )


@dataclass(frozen=True, slots=True, kw_only=True)
class ReferenceLayer:
    """TI's own tracks of a recording, by frame: rows ``offsets[f]:offsets[f+1]`` of ``track_id``
    and ``xy_m`` ``(R, 2)`` are frame f's."""

    offsets: np.ndarray
    track_id: np.ndarray
    xy_m: np.ndarray
    frame: np.ndarray

    @classmethod
    def of(cls, ds: Dataset) -> ReferenceLayer:
        return cls(
            offsets=np.searchsorted(ds.ref_frame, np.arange(ds.n_frames + 1)).astype(np.int64),
            track_id=np.asarray(ds.ref_track_id, dtype=np.int64),
            xy_m=np.column_stack((ds.ref_x_m, ds.ref_y_m)).astype(float).reshape(-1, 2),
            frame=np.asarray(ds.ref_frame, dtype=np.int64),
        )

    def at(self, frame: int) -> tuple[np.ndarray, np.ndarray]:
        """(ids, xy) of TI's tracks at ``frame`` (empty outside the recording)."""
        if not 0 <= frame < len(self.offsets) - 1:
            return np.zeros(0, dtype=np.int64), np.zeros((0, 2))
        a, b = self.offsets[frame], self.offsets[frame + 1]
        return self.track_id[a:b], self.xy_m[a:b]

    def count(self, frame: int) -> int:
        """TI's track count at ``frame``."""
        return len(self.at(frame)[0])

    def counts(self) -> np.ndarray:
        """TI's track count of every frame."""
        return np.diff(self.offsets)


def attach_recording(engine: Engine, replay: ReplayEngine) -> None:
    """Make ``engine`` (the window's, held by every controller) replay ``replay``'s data set:
    its simulation, scene facts, study data set and truth flag are the replay's until
    :func:`detach_recording`."""
    engine.replay = replay  # type: ignore[attr-defined]
    engine.simulate = replay.simulate  # type: ignore[method-assign]
    engine.scene_info = replay.scene_info  # type: ignore[method-assign]
    engine.scene_dataset = replay.scene_dataset  # type: ignore[method-assign]
    engine.has_truth = replay.has_truth


def detach_recording(engine: Engine) -> None:
    """Back to simulating: the class's own functions again."""
    for name in ("replay", "simulate", "scene_info", "scene_dataset", "has_truth"):
        engine.__dict__.pop(name, None)


def replay_of(engine: Engine) -> ReplayEngine | None:
    """The recording ``engine`` replays, None while it simulates."""
    attached = engine.__dict__.get("replay")
    if attached is not None:
        return attached
    return engine if isinstance(engine, ReplayEngine) else None


class ReplayEngine(Engine):
    """The engine with ``simulate`` yielding a data set's frames instead of simulating."""

    def __init__(self, dataset: Dataset, path: str = "") -> None:
        from core.formats.recording import has_truth

        self.dataset = dataset
        #: the file it was read from ("" when not known)
        self.path = str(path)
        self.has_truth = has_truth(dataset)
        radar = json.loads(dataset.radar_json) if dataset.radar_json else {}
        self.radar = RadarConfig.from_dict(radar) if radar else RadarConfig()

    def scene_info(self, scene) -> SceneInfo:
        ds = self.dataset
        paths = tuple(
            ds.truth_xy_m[np.isfinite(ds.truth_xy_m[:, p, 0]), p] for p in range(ds.n_persons)
        )
        return SceneInfo(
            n_frames=ds.n_frames,
            frame_period_s=self.radar.frame_period_s,
            truth_paths=paths,
            reflectors_xy_m=np.zeros((0, 2)),
            aoi=scene.aoi.to_dict(),
            radar=self.radar,
        )

    def scene_dataset(self, frames, scene, path: Path) -> Path:
        """A study "on the current scene" of a replay studies the recording itself, which
        needs its ground truth (imported with ``--truth``)."""
        from core.errors import InputError
        from core.formats.recording import has_truth

        if not has_truth(self.dataset):
            raise InputError(
                "this recording has no ground truth: a study needs it (import the recording "
                "with --truth CSV and replay the data set)"
            )
        return self.dataset.save(path)

    def simulate(self, scene, *, fidelity: str = "exact") -> Iterator[FrameData]:
        ds = self.dataset
        offsets = ds.frame_offsets
        point_track = ds.ref_point_track if len(ds.ref_point_track) else None
        for f in range(ds.n_frames):
            yield FrameData(
                index=f,
                t_s=float(ds.truth_t_s[f]),
                cloud=ds.point_cloud(f),
                truth_xy_m=ds.truth_xy_m[f],
                point_track=(
                    None if point_track is None else point_track[offsets[f] : offsets[f + 1]]
                ),
            )
