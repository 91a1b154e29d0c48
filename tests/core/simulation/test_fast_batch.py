"""The ``fast`` level's batch path (all frames in one call per frame's compiled kernel): equal
to the per-frame entry point bit for bit, and to the library's stage-by-stage functions."""

from __future__ import annotations

import numpy as np
import pytest

from core import pipeline
from core.pointcloud import POINT_FIELDS
from core.processing import Detections
from core.scene import paper_scenes
from core.simulation import LEVELS, AntennaGain, Scatterers
from core.simulation.fast import (
    detected_channels,
    fast_spectrum,
    label_points,
    points_compiled,
    simulate_frame_fast,
    simulate_frames_fast,
)
from core.simulation.fast_cfar import cfar_range_bins, two_stage_cfar_compiled


@pytest.fixture(scope="module")
def trajectory():
    scene = paper_scenes(0, 1)[0]
    antenna = AntennaGain.draw(scene.radar, pipeline.stage_rng(scene.seed, "antenna"))
    settings = pipeline.processing_settings(scene)
    refl = pipeline.Reflectors.build(scene, pipeline.plan(scene), scene.seed, antenna, settings)
    frames = [refl.frame(f)[0] for f in range(40)]
    frames[7] = Scatterers.empty()  # a frame without reflectors
    return scene.radar, frames, antenna, settings


def _rngs(n: int, seed: int = 5) -> list[np.random.Generator]:
    return [pipeline.stage_rng(seed, "noise", f) for f in range(n)]


def test_batch_equals_per_frame_bit_for_bit(trajectory) -> None:
    radar, frames, antenna, settings = trajectory
    batch = simulate_frames_fast(radar, frames, _rngs(len(frames)), antenna=antenna,
                                 settings=settings)  # fmt: skip
    clouds = batch.clouds()
    assert len(clouds) == len(frames) and batch.counts.sum() == len(batch.point_cloud)
    rngs = _rngs(len(frames))
    n_points = 0
    for f, sc in enumerate(frames):
        one = simulate_frame_fast(radar, sc, rngs[f], antenna=antenna, settings=settings)
        for k in (*POINT_FIELDS, "source"):
            assert getattr(one.point_cloud, k).tobytes() == getattr(clouds[f], k).tobytes(), k
        a, b = np.cumsum(np.r_[0, batch.counts])[f : f + 2]
        np.testing.assert_array_equal(one.detections, batch.detections[a:b])
        n_points += len(one.point_cloud)
    assert n_points > 40  # the person is seen in most frames: the comparison is not vacuous
    assert np.mean([np.any(c.source == 0) for c in clouds]) > 0.8


def test_compiled_frame_equals_the_stage_functions(trajectory) -> None:
    """Spectrum, CFAR, conditional channel draws (numpy), points and labels of the documented
    functions, with the same generator: the same detections and labels, values to rounding."""
    radar, frames, antenna, settings = trajectory
    n_use = cfar_range_bins(radar, settings)
    checked = 0
    for f in (0, 3, 11, 25):
        sc = frames[f]
        one = simulate_frame_fast(
            radar, sc, np.random.default_rng(f), antenna=antenna, settings=settings
        )
        rng = np.random.default_rng(f)
        spec = fast_spectrum(radar, sc, rng, antenna=antenna, settings=settings,
                             n_range_bins=n_use)  # fmt: skip
        det = two_stage_cfar_compiled(spec.rd_map, radar, settings, independent_cells=True)
        det = Detections(range_bin=det.range_bin, doppler_index=det.doppler_index,
                         power=det.power, noise_power=det.noise_power)  # fmt: skip
        ch = detected_channels(radar, spec, det)
        pc = label_points(radar, points_compiled(radar, settings, spec.rd_map, det, ch, False), sc)
        np.testing.assert_array_equal(
            one.detections, np.column_stack((det.range_bin, det.doppler_index))
        )
        np.testing.assert_array_equal(one.point_cloud.source, pc.source)
        for k in POINT_FIELDS:
            np.testing.assert_allclose(getattr(one.point_cloud, k), getattr(pc, k),
                                       rtol=1e-9, atol=1e-12, err_msg=k)  # fmt: skip
        checked += len(pc)
    assert checked > 0


def test_pipeline_uses_the_batch_path_with_the_per_frame_frames() -> None:
    scene = paper_scenes(0, 1)[0]
    assert LEVELS["fast"].simulate_frames is simulate_frames_fast
    run = pipeline.simulate_scene(scene, fidelity="fast", seed=9)
    frames = list(pipeline.iter_frames(scene, fidelity="fast", seed=9, frames=range(12)))
    for fr in frames:
        for k in (*POINT_FIELDS, "source"):
            a = getattr(fr.point_cloud, k)
            assert a.tobytes() == getattr(run.clouds[fr.index], k).tobytes(), k
