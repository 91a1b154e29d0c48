"""Stops in drawn paths: a waypoint [x, y, 0, hold_s] holds the person still for hold_s."""

from __future__ import annotations

import numpy as np
import pytest

from core.errors import InputError
from core.scene import Scene
from core.scene.trajectory import stopping_waypoint_trajectory, waypoint_trajectory
from tests.scenes import small_scene

DT = 0.08


def test_stop_holds_still_for_its_time():
    w = np.array([[0.0, 1.0, 1.0], [0.0, 3.0, 0.0], [2.0, 3.0, 1.0]])
    t = stopping_waypoint_trajectory(w, np.array([0.0, 2.0, 0.0]), frame_period_s=DT)
    # 2 m at 1 m/s, 2 s still, 2 m at 1 m/s: 6 s
    assert t.n_frames == int(6.0 / DT + 1e-9) + 1
    still = np.all(np.isclose(t.position_m, [0.0, 3.0]), axis=1)
    # the frames at the stop: from t = 2 s to t = 4 s inclusive
    assert still.sum() == pytest.approx(2.0 / DT + 1, abs=1)
    speed = np.hypot(*t.velocity_mps.T)
    np.testing.assert_allclose(speed[still][1:], 0.0, atol=1e-9)
    np.testing.assert_allclose(speed[~still][1:], 1.0, atol=0.02)
    np.testing.assert_allclose(t.position_m[-1], [2.0, 3.0], atol=1e-9)


def test_without_stops_it_is_the_plain_path():
    w = np.array([[0.0, 1.0, 1.0], [0.0, 3.0, 1.2], [2.0, 3.0, 0.8]])
    a = stopping_waypoint_trajectory(w, np.zeros(3), frame_period_s=DT)
    b = waypoint_trajectory(w, frame_period_s=DT)
    np.testing.assert_array_equal(a.position_m, b.position_m)
    np.testing.assert_array_equal(a.velocity_mps, b.velocity_mps)


def test_stop_first_and_last():
    w = np.array([[0.0, 1.0, 0.0], [0.0, 3.0, 1.0], [0.0, 4.0, 0.0]])
    t = stopping_waypoint_trajectory(w, np.array([1.0, 0.0, 1.0]), frame_period_s=DT)
    assert t.n_frames == int(5.0 / DT + 1e-9) + 1
    np.testing.assert_allclose(t.position_m[0], [0.0, 1.0])
    np.testing.assert_allclose(t.position_m[-1], [0.0, 4.0])


def scene_with(waypoints) -> dict:
    d = small_scene()
    d["persons"][0] = {"model": "walking", "trajectory": {"waypoints": waypoints}}
    return d


def test_scene_reads_and_writes_stops():
    wp = [[0.0, 1.5, 1.0], [0.0, 4.0, 0.0, 3.0], [2.0, 5.0, 1.0]]
    sc = Scene.from_dict(scene_with(wp))
    assert Scene.from_json_text(sc.to_json()).persons[0].trajectory.n_frames == (
        sc.persons[0].trajectory.n_frames
    )
    assert sc.to_dict()["persons"][0]["trajectory"]["waypoints"] == wp


@pytest.mark.parametrize(
    ("wp", "needle"),
    [
        ([[0.0, 1.5, 1.0], [0.0, 4.0, 0.5, 3.0]], "waypoints[1][2] (speed_mps of a stop)"),
        ([[0.0, 1.5, 1.0], [0.0, 4.0, 0.0]], "waypoints[1][2] (speed_mps)"),
        ([[0.0, 1.5, 1.0], [0.0, 4.0, 0.0, -1.0]], "waypoints[1][3] (hold_s)"),
        ([[0.0, 1.5, 0.0, 1.0], [0.0, 4.0, 0.0, 1.0]], "stops only"),
    ],
)
def test_bad_stops_name_the_field(wp, needle):
    with pytest.raises(InputError) as exc:
        Scene.from_dict(scene_with(wp))
    assert needle in exc.value.message
