"""A scene in a room through the pipeline: ghosts detected where the image method puts them,
labelled with their path order; no walls, no ghosts; scenes without a room unchanged."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from core.dataset import Dataset
from core.pipeline import plan, simulate_scene
from core.scene import Scene
from tests.scenes import small_scene

# a person (point model, 10 dBsm) starting at (0.5, 3) m walking +y at 1 m/s; one wall,
# the plane x = 2 m; the sensor 1 m up (the persons' reference height), no tilt
WALL_X = 2.0


def scene(reflection_db: float = 0.0, **extra) -> Scene:
    d = small_scene(velocity_mps=(0.0, 1.0), frames=4)
    d["persons"][0]["trajectory"]["initial_position_m"] = [0.5, 3.0]
    d["persons"][0]["rcs_dbsm"] = 10.0
    d["walls"] = [
        {"from_m": [WALL_X, -1.0], "to_m": [WALL_X, 12.0], "reflection_db": reflection_db}
    ]
    d["sensor"] = {"height_m": 1.0, "tilt_deg": 0.0}
    d.update(extra)
    return Scene.from_dict(d)


@pytest.mark.parametrize("fidelity", ["exact", "fast"])
def test_first_order_ghost_at_half_the_path_length(fidelity):
    sc = scene()
    run = simulate_scene(sc, fidelity=fidelity)
    radar = sc.radar
    hits = 0
    for f, cloud in enumerate(run.clouds):
        assert cloud.path_order is not None
        # the person's truth mid-frame and its image in the wall
        x, y = run.truth_xy_m[f, 0]
        t_mid = radar.n_tx * radar.n_loops * radar.chirp_period_s / 2
        y = y + 1.0 * t_mid
        d1, d2 = math.hypot(x, y), math.hypot(2 * WALL_X - x, y)
        rate = y / d1 + y / d2  # dL/dt for v = (0, 1)
        first = cloud.path_order == 1
        assert first.any(), f"frame {f}: no first-order point"
        near = np.abs(cloud.range_m[first] - (d1 + d2) / 2) < 2 * radar.range_resolution_m
        assert near.any()
        vr = cloud.radial_velocity_mps[first][near]
        assert np.min(np.abs(vr - rate / 2)) < radar.velocity_resolution_mps
        # the ghost's points lie at the bearings of the two last legs (from S and from S')
        az = cloud.azimuth_rad[first][near]
        legs = np.array([math.atan2(x, y), math.atan2(2 * WALL_X - x, y)])
        assert np.all(np.min(np.abs(az[:, None] - legs[None, :]), axis=1) < math.radians(12))
        hits += int(near.sum())
        assert set(np.unique(cloud.source[cloud.path_order >= 0])) <= {0}
    assert hits >= len(run.clouds)


def test_absorbing_wall_gives_no_ghost_and_the_plan_says_so():
    sc = scene(reflection_db=-math.inf)
    p = plan(sc)
    assert not p.runs("multipath")
    assert "absorbs" in next(s.reason for s in p.stages if s.name == "multipath")
    run = simulate_scene(sc)
    for cloud in run.clouds:
        assert cloud.path_order is not None
        assert not np.any(cloud.path_order > 0)
        assert np.any(cloud.path_order == 0)


def test_no_room_no_multipath_stage_and_no_path_order(tmp_path):
    sc = Scene.from_dict(small_scene())
    p = plan(sc)
    assert not p.runs("multipath")
    assert "no reflecting walls" in next(s.reason for s in p.stages if s.name == "multipath")
    run = simulate_scene(sc)
    assert all(c.path_order is None for c in run.clouds)
    path = run.to_dataset().save(tmp_path / "open.npz")
    assert "path_order" not in np.load(path)
    assert Dataset.load(path).path_order is None


def test_path_order_survives_the_data_set_file(tmp_path):
    run = simulate_scene(scene())
    ds = run.to_dataset()
    assert ds.path_order is not None and np.any(ds.path_order == 1)
    again = Dataset.load(ds.save(tmp_path / "room.npz"))
    np.testing.assert_array_equal(again.path_order, ds.path_order)
    assert again.point_cloud(0).path_order is not None


def test_sensor_pose_puts_points_in_room_coordinates():
    # the direct point of a person at the sensor's height: z near 1 m in room coordinates,
    # whatever the tilt
    sc = scene(reflection_db=-math.inf, sensor={"height_m": 1.0, "tilt_deg": 20.0})
    run = simulate_scene(sc)
    for f, cloud in enumerate(run.clouds):
        direct = cloud.path_order == 0
        i = np.flatnonzero(direct)[np.argmax(cloud.snr_db[direct])]
        np.testing.assert_allclose(cloud.z_m[i], 1.0, atol=0.3)
        np.testing.assert_allclose(cloud.y_m[i], run.truth_xy_m[f, 0, 1], atol=0.3)
        # the sensor sees the person 20 deg above its tilted boresight
        assert cloud.elevation_rad[i] == pytest.approx(math.radians(20.0), abs=math.radians(6))


def test_room_frames_alone_equal_the_batch():
    from core.pipeline.plan import processing_settings
    from core.pipeline.reflectors import Reflectors
    from core.pipeline.streams import stage_rng
    from core.simulation import AntennaGain

    sc = Scene.from_json(Path(__file__).parents[3] / "resources/scenes/room_walker.json")
    antenna = AntennaGain.draw(sc.radar, stage_rng(sc.seed, "antenna"))
    refl = Reflectors.build(sc, plan(sc), sc.seed, antenna, processing_settings(sc))
    every, _ = refl.frames(12)
    for f in (0, 5, 11):
        alone, _ = refl.frame(f)
        for name in ("position_m", "velocity_mps", "rcs_dbsm", "source"):
            np.testing.assert_array_equal(getattr(alone, name), getattr(every[f], name))
    # 17 segments direct, and ghosts of three proxies at most 15 paths each
    assert all(17 <= len(s) <= 17 + 3 * 15 for s in every)


def test_furniture_is_static_and_cleared_by_clutter_removal():
    from core.pipeline.reflectors import frame_scatterers
    from core.simulation.multipath import split_labels

    desk = {
        "x_m": -1.0,
        "y_m": 4.0,
        "width_m": 1.2,
        "depth_m": 0.6,
        "height_m": 0.75,
        "rcs_dbsm": 10.0,
    }
    sc = scene(reflection_db=-math.inf, furniture=[desk])
    s = frame_scatterers(sc, 0)
    src, order = split_labels(s.source)
    fur = (src == -1) & (order == 0)
    assert fur.sum() == 5
    np.testing.assert_array_equal(s.velocity_mps[fur], 0.0)
    # 10 dBsm split over five scatterers
    assert 10 * np.log10(np.sum(10 ** (s.rcs_dbsm[fur] / 10))) == pytest.approx(10.0)
    # the sensor is 1 m up: the desk top is 0.25 m below it
    np.testing.assert_allclose(s.position_m[fur][:, 2], -0.25)
    run = simulate_scene(sc)
    for cloud in run.clouds:
        assert not np.any((cloud.source == -1) & (cloud.path_order == 0))
