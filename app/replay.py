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


class ReplayEngine(Engine):
    """The engine with ``simulate`` yielding a data set's frames instead of simulating."""

    def __init__(self, dataset: Dataset) -> None:
        from core.formats.recording import has_truth

        self.dataset = dataset
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
        for f in range(ds.n_frames):
            yield FrameData(
                index=f,
                t_s=float(ds.truth_t_s[f]),
                cloud=ds.point_cloud(f),
                truth_xy_m=ds.truth_xy_m[f],
            )
