"""The compiled detection half (labelled_points) equals build_point_cloud + label_sources."""

from __future__ import annotations

import numpy as np
import pytest

from core import pipeline
from core.config import DEFAULT_PROCESSING, PAPER_RADAR
from core.pointcloud import POINT_FIELDS
from core.processing import (
    Detections,
    build_point_cloud,
    label_sources,
    two_stage_cfar,
)
from core.processing.points import labelled_points
from core.scene import paper_scenes
from core.simulation import AntennaGain, simulate_frame
from core.simulation.frame import frame_from_spectrum

RADAR = PAPER_RADAR
T_MID = 0.5 * RADAR.n_loops * RADAR.n_tx * RADAR.chirp_period_s


def _reference(cube, rd, det, pos, vel, source, elevation):
    pc = build_point_cloud(cube, rd, det, RADAR, DEFAULT_PROCESSING, elevation=elevation)
    p = pos + vel * T_MID
    r_mid = np.linalg.norm(p, axis=1)
    vr = np.einsum("ij,ij->i", p, vel) / r_mid
    src = label_sources(pc.range_m, pc.radial_velocity_mps, r_mid, vr, source, RADAR)
    return pc, src


@pytest.mark.parametrize("elevation", [False, True])
def test_labelled_points_equal_numpy_stages(elevation: bool) -> None:
    rng = np.random.default_rng(11)
    n_r, n_d, n = 190, 32, 300
    rd = rng.standard_gamma(12, (n_r, n_d)).astype(np.float32)
    r = rng.integers(0, n_r, n)
    d = rng.integers(0, n_d, n)
    rd[r, d] *= 50
    det = Detections(
        range_bin=r, doppler_index=d, power=rd[r, d].astype(float),
        noise_power=rng.uniform(5, 20, n),
    )  # fmt: skip
    cube = (rng.standard_normal((12, n_r, n_d)) + 1j * rng.standard_normal((12, n_r, n_d))).astype(
        np.complex64
    )
    # reflectors on some of the detections' cells, so that labels are set and contested
    k = rng.choice(n, 40, replace=False)
    rr = r[k] * RADAR.range_resolution_m + rng.uniform(-0.05, 0.05, 40)
    az = rng.uniform(-1, 1, 40)
    pos = np.column_stack((rr * np.sin(az), rr * np.cos(az), np.zeros(40)))
    # radial velocity near the detection's Doppler bin (the refined bin moves it by < 0.5)
    vr = (d[k] - n_d // 2 + rng.uniform(-0.5, 0.5, 40)) * RADAR.velocity_resolution_mps
    vel = pos / rr[:, None] * vr[:, None]
    source = rng.integers(-1, 3, 40).astype(np.int32)
    ref, src = _reference(cube, rd, det, pos, vel, source, elevation)
    got = labelled_points(
        rd, det, cube[:, r, d].T, RADAR, DEFAULT_PROCESSING, elevation=elevation,
        reflector_position_m=pos, reflector_velocity_mps=vel, reflector_source=source,
        t_mid_s=T_MID,
    )  # fmt: skip
    for name in POINT_FIELDS:
        np.testing.assert_allclose(getattr(got, name), getattr(ref, name), rtol=1e-9, atol=1e-12)
    np.testing.assert_array_equal(got.source, src)
    assert np.sum(src != -2) > 20 and np.sum(src == -2) > 20  # both outcomes are exercised
    if elevation:
        assert np.any(got.elevation_rad != 0)


def test_exact_frames_equal_the_numpy_detection_half() -> None:
    """simulate_frame's points (compiled detection half) against the numpy stages, on the
    paper scene's frames: the same detections and labels, values to 1e-9."""
    scene = paper_scenes(0, 1)[0]
    antenna = AntennaGain.draw(scene.radar, pipeline.stage_rng(scene.seed, "antenna"))
    settings = pipeline.processing_settings(scene)
    refl = pipeline.Reflectors.build(scene, pipeline.plan(scene), scene.seed, antenna, settings)
    n_points = 0
    for f in range(0, 40, 4):
        sc = refl.frame(f)[0]
        out = simulate_frame(
            scene.radar, sc, pipeline.stage_rng(3, "noise", f), antenna=antenna, settings=settings
        )
        assert isinstance(out.point_cloud.source, np.ndarray)
        n_points += len(out.point_cloud)
    assert n_points > 10
    # the same spectrum through both detection halves
    rng = np.random.default_rng(2)
    cube = (rng.standard_normal((12, 190, 32)) + 1j * rng.standard_normal((12, 190, 32))) * 30
    cube[:, 80, 20] += 400 * np.exp(1j * np.pi * 0.3 * np.arange(12))
    cube[:, 120, 5] += 300
    cube = cube.astype(np.complex64)
    rd = np.sum(np.abs(cube) ** 2, axis=0).astype(np.float32)
    sc = refl.frame(0)[0]
    got = frame_from_spectrum(cube, rd, scene.radar, sc, settings=settings)
    det = two_stage_cfar(rd, scene.radar, settings)
    ref, src = _reference(cube, rd, det, sc.position_m, sc.velocity_mps, sc.source, False)
    assert len(det) >= 2
    for name in POINT_FIELDS:
        np.testing.assert_allclose(
            getattr(got.point_cloud, name), getattr(ref, name), rtol=1e-9, atol=1e-12
        )
    np.testing.assert_array_equal(got.point_cloud.source, src)
