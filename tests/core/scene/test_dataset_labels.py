"""Labels and clutter over the paper data set (SPEC §2, "Must show")."""

from __future__ import annotations

import json

import numpy as np
import pytest

from core.dataset import Dataset
from core.scene import AOI
from tests.core.scene.conftest import N_TRAJECTORIES


def person_hits(ds: Dataset) -> tuple[np.ndarray, np.ndarray]:
    """Per frame: |radial speed| of person 0, and whether a point labelled 0 lies within 0.2 m."""
    xy, v = ds.truth_xy_m[:, 0], ds.truth_v_mps[:, 0]
    # vr = (x vx + y vy) / r
    vr = (xy * v).sum(axis=1) / np.hypot(xy[:, 0], xy[:, 1])
    off = ds.frame_offsets
    hit = np.zeros(ds.n_frames, dtype=bool)
    for f in range(ds.n_frames):
        a, b = off[f], off[f + 1]
        mine = ds.source[a:b] == 0
        if mine.any():
            d = np.hypot(ds.x_m[a:b][mine] - xy[f, 0], ds.y_m[a:b][mine] - xy[f, 1])
            hit[f] = d.min() <= 0.2
    return np.abs(vr), hit


def test_subset_is_the_round_robin_paper_set(paper_subset: Dataset) -> None:
    ds = paper_subset
    assert list(ds.trajectory_class) == list("abcde")[:N_TRAJECTORIES]
    assert ds.n_persons == 1
    lengths = np.diff(ds.trajectory_offsets)
    assert lengths.min() >= 75 and lengths.max() <= 250
    assert len(json.loads(ds.scene_json)) == N_TRAJECTORIES
    assert json.loads(ds.radar_json)["n_loops"] == 32


def test_moving_person_is_detected_and_labelled(paper_subset: Dataset) -> None:
    speed, hit = person_hits(paper_subset)
    moving = speed >= 0.3
    assert moving.sum() > 400
    rate = hit[moving].mean()
    assert rate >= 0.95, f"only {rate:.3f} of moving frames have a labelled point within 0.2 m"


def test_standing_person_is_removed_by_static_clutter_removal(paper_subset: Dataset) -> None:
    # class d stands still for seconds: a radial speed below a quarter bin (0.11 m/s) is inside
    # the zero-Doppler notch, so the person must (rightly) be missing in most of those frames
    speed, hit = person_hits(paper_subset)
    still = speed < 0.05
    assert still.sum() >= 10
    assert hit[still].mean() < 0.5


def test_clutter_points_per_frame_match_lambda_area(paper_subset: Dataset) -> None:
    ds = paper_subset
    expected = 0.02 * AOI().area_m2  # 2.089 per frame
    per_frame = np.bincount(ds.frame[ds.source == -1], minlength=ds.n_frames)
    assert per_frame.mean() == pytest.approx(expected, rel=0.10)
    # clutter points come from reflectors that move: none inside the zero-Doppler notch
    vr = ds.radial_velocity_mps[ds.source == -1]
    assert np.abs(vr).min() >= 1.0 * 0.4526


def test_false_points_per_frame_match_the_tracker_clutter_density(paper_subset: Dataset) -> None:
    """ρ·V (clutter reflectors + the chain's noise detections) against the points that are not
    the person in the simulated set."""
    from core.pipeline import scene_clutter_density
    from core.scene import paper_scenes

    scene = paper_scenes(0, 1)[0]
    aoi = scene.aoi
    volume = (
        (aoi.max_range_m - aoi.min_range_m) * 2 * aoi.max_azimuth_rad * 2
        * scene.radar.max_velocity_mps
    )  # fmt: skip
    expected = scene_clutter_density(scene) * volume  # ≈ 2.29 per frame
    measured = np.sum(paper_subset.source != 0) / paper_subset.n_frames
    assert measured == pytest.approx(expected, rel=0.10)


def test_a_trajectory_of_the_set_re_simulates_alone(paper_subset: Dataset) -> None:
    from core.pipeline import iter_frames
    from core.scene import paper_scenes

    ds = paper_subset
    k = 2
    scene = paper_scenes(0, N_TRAJECTORIES)[k]
    first = int(ds.trajectory_offsets[k])
    for fr in iter_frames(scene, frames=[0, 7]):
        expected = ds.point_cloud(first + fr.index)
        for f in ("range_m", "azimuth_rad", "radial_velocity_mps", "snr_db", "source"):
            np.testing.assert_array_equal(getattr(fr.point_cloud, f), getattr(expected, f))
        np.testing.assert_array_equal(ds.truth_xy_m[first + fr.index], fr.truth_xy_m)


def test_paper_dataset_file_is_the_cached_set(paper_subset: Dataset, paper_cache) -> None:
    from core.pipeline import paper_dataset_file

    cache = paper_cache
    path = paper_dataset_file(0, N_TRAJECTORIES, cache_dir=cache)
    assert path.parent == cache / "datasets" and path.is_file()
    np.testing.assert_array_equal(Dataset.load(path).range_m, paper_subset.range_m)


def test_tangential_walker_is_hidden_radial_walker_is_seen() -> None:
    """Same speed (0.5 m/s), same place: across the line of sight |vr| <= 0.04 m/s, inside the
    zero-Doppler notch of static clutter removal; along it vr = -0.5 m/s (1.1 bins)."""
    from core.pipeline import simulate_scene
    from core.scene import Person, Scene, profile_trajectory

    def walker(v0):
        traj = profile_trajectory(
            initial_position_m=[-0.4, 5.0],
            initial_velocity_mps=v0,
            acceleration_mps2=[0.0, 0.0],
            frames=20,
        )
        scene = Scene(seed=5, clutter_density_per_m2=0.0, persons=(Person(trajectory=traj),))
        run = simulate_scene(scene)
        return np.mean([np.any(c.source == 0) for c in run.clouds])

    tangential = walker([0.5, 0.0])
    radial = walker([0.0, -0.5])
    assert radial >= 0.95
    assert tangential <= 0.3
