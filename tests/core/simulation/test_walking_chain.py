"""The walking body through the chain: each segment where its range and Doppler put it, the
exact and fast levels agreeing on the noise-free map, points spread over the body."""

from __future__ import annotations

import json

import numpy as np
import pytest

from core.config import DEFAULT_PROCESSING, PAPER_RADAR, ProcessingSettings
from core.pipeline import simulate_scene
from core.pipeline.reflectors import frame_scatterers
from core.processing import doppler_fft, range_doppler_map, range_fft, remove_static_clutter
from core.scene import Scene
from core.scene.walking import N_SEGMENTS
from core.simulation import AntennaGain, Scatterers, synthesize_signal
from core.simulation.fast import fast_spectrum

RADAR = PAPER_RADAR
ANT = AntennaGain.ideal(RADAR)


def walking_scene(frames: int = 12, clutter: float = 0.0) -> Scene:
    return Scene.from_json_text(
        json.dumps(
            {
                "schema_version": 1,
                "seed": 2,
                "clutter_density_per_m2": clutter,
                "persons": [
                    {
                        "model": "walking",
                        "rcs_dbsm": 0.0,
                        "gait_phase": 0.6,  # the right leg in mid-swing at frame 0
                        "trajectory": {
                            "initial_position_m": [0.4, 4.5],
                            "initial_velocity_mps": [0.0, -1.3],
                            "acceleration_mps2": [0.0, 0.0],
                            "frames": frames,
                        },
                    }
                ],
            }
        )
    )


def one(sc: Scatterers, k: int) -> Scatterers:
    return Scatterers(
        position_m=sc.position_m[k : k + 1],
        velocity_mps=sc.velocity_mps[k : k + 1],
        rcs_dbsm=sc.rcs_dbsm[k : k + 1],
        source=sc.source[k : k + 1],
    )


@pytest.mark.parametrize("frame", [0, 5])
def test_each_segment_lands_in_the_bin_its_range_and_radial_velocity_predict(frame) -> None:
    sc = frame_scatterers(walking_scene(), frame)
    assert len(sc) == N_SEGMENTS
    n_d = RADAR.n_loops
    # without static clutter removal, which empties the zero-Doppler bin of a foot in stance
    settings = ProcessingSettings(static_clutter_removal=False)
    checked = 0
    for k in range(len(sc)):
        s = one(sc, k)
        spec = fast_spectrum(RADAR, s, None, antenna=ANT, settings=settings, noise=False)
        r_bin, d_idx = np.unravel_index(spec.rd_map.argmax(), spec.rd_map.shape)
        # Doppler bin of v_r (zero velocity at n_d / 2, aliased beyond +-v_max)
        d = s.radial_velocity_mps[0] / RADAR.velocity_resolution_mps
        r = s.range_m[0] / RADAR.range_resolution_m
        if abs(d - np.floor(d) - 0.5) < 0.15 or abs(r - np.floor(r) - 0.5) < 0.15:
            continue  # between two bins: either neighbour is right
        assert d_idx == (int(np.round(d)) + n_d // 2) % n_d, k
        assert r_bin == int(np.round(r)), k
        checked += 1
    assert checked >= 6
    # and the segments spread over several Doppler bins (micro-Doppler)
    assert np.ptp(sc.radial_velocity_mps) > 3 * RADAR.velocity_resolution_mps


def test_exact_and_fast_agree_on_the_noise_free_map() -> None:
    """As tests/core/simulation/test_fast.py does for point scatterers, on a walking body."""
    sc = frame_scatterers(walking_scene(), 3)
    assert not sc.is_planar  # segments at their heights
    rc = range_fft(synthesize_signal(RADAR, sc, ANT), DEFAULT_PROCESSING.range_window)
    dc = doppler_fft(remove_static_clutter(rc), DEFAULT_PROCESSING.doppler_window)
    spec = fast_spectrum(RADAR, sc, None, antenna=ANT, noise=False)
    k, d = spec.patch.T
    x_exact = dc[:, k, d].T
    err = np.linalg.norm(spec.signal - x_exact) / np.linalg.norm(x_exact)
    assert err < 0.005
    rd = range_doppler_map(dc).astype(np.float64)
    assert rd[k, d].sum() / rd.sum() > 0.999
    assert np.unravel_index(rd.argmax(), rd.shape) == np.unravel_index(
        spec.rd_map.argmax(), rd.shape
    )
    assert spec.rd_map.max() == pytest.approx(rd.max(), rel=0.03)


@pytest.mark.parametrize("fidelity", ["exact", "fast"])
def test_the_walking_body_gives_several_points_spread_in_doppler(fidelity) -> None:
    run = simulate_scene(walking_scene(frames=15), fidelity=fidelity)
    pts = [c.source == 0 for c in run.clouds]
    n = np.array([int(p.sum()) for p in pts])
    assert n.mean() >= 2
    vr = np.concatenate([c.radial_velocity_mps[p] for c, p in zip(run.clouds, pts, strict=True)])
    assert np.ptp(vr) > 1.5
    # elevation estimated: the points have heights, spread over the body
    z = np.concatenate([c.z_m[p] for c, p in zip(run.clouds, pts, strict=True)])
    assert np.ptp(z) > 0.2
