"""Every entry point takes the fidelity level: the pipeline dispatches on FIDELITY_LEVELS."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from core.pipeline import SIMULATORS, build_dataset, simulate_scene, simulator
from core.scene import Person, Scene, profile_trajectory
from core.simulation import FIDELITY_LEVELS


def short_scene(frames: int = 12) -> Scene:
    """One person walking at 1 m/s from (0.5, 4) m, with the paper's clutter."""
    spec = {
        "initial_position_m": [0.5, 4.0],
        "initial_velocity_mps": [0.3, -1.0],
        "acceleration_mps2": [0.0, 0.0],
        "frames": frames,
    }
    traj = profile_trajectory(**spec)
    return Scene(seed=3, clutter_density_per_m2=0.02, persons=(Person(trajectory=traj, spec=spec),))


def test_every_level_is_registered_in_the_pipeline() -> None:
    assert set(SIMULATORS) == set(FIDELITY_LEVELS)
    for name, fn in FIDELITY_LEVELS.items():
        assert simulator(name) is fn


@pytest.mark.parametrize("level", ["fast", "measurement"])
def test_scene_and_dataset_at_a_cheaper_level(level: str, tmp_path: Path) -> None:
    scene = short_scene()
    run = simulate_scene(scene, fidelity=level, keep_rd_maps=True)
    assert len(run.clouds) == scene.n_frames
    assert run.rd_maps_db.shape == (scene.n_frames, 256, 32)
    # the person is seen in (nearly) every frame, near its true position
    hits = 0
    for f, pc in enumerate(run.clouds):
        m = pc.source == 0
        if m.any():
            hits += 1
            d = np.hypot(pc.x_m[m] - run.truth_xy_m[f, 0, 0], pc.y_m[m] - run.truth_xy_m[f, 0, 1])
            assert d.min() < 0.3
    assert hits >= scene.n_frames - 1
    ds = build_dataset([scene], fidelity=level, seed=1, jobs=1, cache_dir=tmp_path)
    assert ds.fidelity == level and ds.n_frames == scene.n_frames
