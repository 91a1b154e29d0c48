"""A seated body's points lie lower than a standing one's through TI's people-counting chain."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import core.scene.walking as W
from core.formats.ti_cfg import read_ti_chain
from core.pipeline import plan
from core.pipeline.frames import iter_frames
from core.scene import Scene

CFG = Path(__file__).parents[3] / "resources" / "radar" / "people_counting_isk_static.cfg"
SPOT = (0.5, 4.0)


def derived_drop_m(height_m: float = W.DEFAULT_HEIGHT_M) -> float:
    """The drop of the body's RCS-weighted mean scatterer height, standing still to seated:
    the segments' heights weighted by their RCS shares (0.905 m and 0.622 m for 1.75 m)."""
    zero = np.zeros(1)
    stand = W.body_frame_segments(zero, zero, zero, height_m)[0, :, 2]
    sit = W.body_frame_segments(zero, zero, zero, height_m, np.ones(1, dtype=bool))[0, :, 2]
    return float(W.RCS_SHARES @ (stand - sit))


def points_z(posture: str, seed: int) -> np.ndarray:
    """z (above the floor) of the points within 0.8 m of a person held 8 s at SPOT, from 12
    frames of the hold's middle (after sitting down), the sensor 2 m up tilted 15 deg."""
    stop: list = [*SPOT, 0.0, 8.0] + (["sit"] if posture == "sit" else [])
    data = {
        "schema_version": 1,
        "radar": str(CFG),
        "seed": seed,
        "clutter_density_per_m2": 0.0,
        "aoi": {"min_range_m": 0.3, "max_range_m": 7.5, "max_azimuth_deg": 60.0},
        "sensor": {"height_m": 2.0, "tilt_deg": 15.0},
        "persons": [{"model": "walking", "trajectory": {"waypoints": [stop, [0.6, 3.0, 0.8]]}}],
    }
    scene = Scene.from_dict(data, source="seated height")
    t = scene.persons[0].trajectory.t_s
    frames = np.flatnonzero((t > 2.0) & (t < 6.0))[::6][:12]
    z = []
    for fr in iter_frames(scene, the_plan=plan(scene, chain=read_ti_chain(CFG)), frames=frames):
        pc = fr.point_cloud
        z.append(pc.z_m[np.hypot(pc.x_m - SPOT[0], pc.y_m - SPOT[1]) < 0.8])
    return np.concatenate(z)


def test_derived_drop_is_the_body_models():
    # the upper body drops by (0.530 - 0.285) H = 0.429 m, the shins and feet not at all
    assert derived_drop_m() == pytest.approx(0.283, abs=0.002)


def test_seated_points_are_lower_by_about_the_derived_drop():
    expected = derived_drop_m()
    drops = []
    for seed in (1, 2, 3):
        stand, sit = points_z("stand", seed), points_z("sit", seed)
        assert len(stand) > 50 and len(sit) > 50  # the still body gives (static) points
        drops.append(np.median(stand) - np.median(sit))
    # each seed lower when seated; the mean drop within half to 1.5 times the derived one
    assert min(drops) > 0.1
    assert 0.5 * expected < float(np.mean(drops)) < 1.5 * expected
