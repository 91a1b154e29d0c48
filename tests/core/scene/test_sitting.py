"""Seated stops: a waypoint [x, y, 0, hold_s, "sit"] seats the walking body for the hold."""

from __future__ import annotations

import numpy as np
import pytest

import core.scene.walking as W
from core.errors import InputError
from core.scene import Scene
from core.scene.trajectory import stopping_waypoint_trajectory
from tests.scenes import small_scene

DT = 0.08
H = 1.75


def seated_body(n: int = 126):
    """Joints and segments of a body seated for 10 s (two sway periods)."""
    t = np.linspace(0.0, 10.0, n)
    z = np.zeros(n)
    sit = np.ones(n, dtype=bool)
    return t, W.body_frame_joints(z, z, t, H, sit), W.body_frame_segments(z, z, t, H, sit)


def test_seated_heights_are_the_seat_and_the_upright_trunk():
    _, j, seg = seated_body()
    # hip joints at knee height 0.285 H (0.499 m): the seat
    np.testing.assert_allclose(j["pelvis"][:, 2], 0.285 * H)
    assert 0.45 <= j["pelvis"][0, 2] <= 0.5
    # the head's centre: (0.285 - 0.530 + 0.870 + 0.065) H = 0.690 H = 1.2075 m
    head = seg[:, W.SEGMENT_NAMES.index("head"), 2]
    np.testing.assert_allclose(head, 0.690 * H, atol=1e-12)
    assert 1.2 <= head[0] <= 1.3
    for s in "rl":
        # thighs horizontal, as long as the standing thigh, pointing forward
        np.testing.assert_allclose(j[f"knee_{s}"][:, 2], j[f"hip_{s}"][:, 2])
        thigh = j[f"knee_{s}"] - j[f"hip_{s}"]
        np.testing.assert_allclose(thigh[:, 0], (W.HIP_Z - W.KNEE_Z) * H)
        # shins vertical down to the ankle height of a standing body
        np.testing.assert_allclose(j[f"ankle_{s}"][:, :2], j[f"knee_{s}"][:, :2])
        np.testing.assert_allclose(j[f"ankle_{s}"][:, 2], W.ANKLE_Z * H)
    # torso upright: neck above the pelvis but for the sway
    off = j["neck_base"][:, :2] - j["pelvis"][:, :2]
    assert np.abs(off[:, 0]).max() <= W.SWAY_AMPLITUDE_M + 1e-12
    np.testing.assert_allclose(j["neck_base"][:, 2] - j["pelvis"][:, 2], (0.818 - 0.530) * H)


def test_seated_body_sways_and_breathes_as_standing():
    t, j, seg = seated_body()
    # the head sways +-1 cm forward at 0.2 Hz (10 s: two periods), the seat and legs are still
    np.testing.assert_allclose(
        j["head_top"][:, 0], W.SWAY_AMPLITUDE_M * np.sin(2 * np.pi * W.SWAY_HZ * t), atol=1e-12
    )
    assert np.ptp(j["knee_r"], axis=0).max() == 0.0
    # the torso's centre: half the sway (pelvis still) plus the breath, as standing
    torso = seg[:, W.SEGMENT_NAMES.index("torso"), 0]
    want = 0.5 * W.SWAY_AMPLITUDE_M * np.sin(2 * np.pi * W.SWAY_HZ * t) + (
        W.BREATH_AMPLITUDE_M * np.sin(2 * np.pi * W.BREATH_HZ * t)
    )
    np.testing.assert_allclose(torso, want, atol=1e-12)


def test_no_seated_frames_change_nothing():
    t = np.linspace(0.0, 4.0, 51)
    ph, v = np.mod(t / 1.1, 1.0), np.full_like(t, 1.2)
    a = W.body_frame_segments(ph, v, t, H)
    b = W.body_frame_segments(ph, v, t, H, np.zeros(len(t), dtype=bool))
    np.testing.assert_array_equal(a, b)


def test_sit_stop_marks_its_hold_frames_seated():
    w = np.array([[0.0, 1.0, 1.0], [0.0, 3.0, 0.0], [2.0, 3.0, 1.0]])
    t = stopping_waypoint_trajectory(
        w, np.array([0.0, 2.0, 0.0]), frame_period_s=DT, sit=np.array([False, True, False])
    )
    still = np.all(np.isclose(t.position_m, [0.0, 3.0]), axis=1)
    # seated from t = 2 s to the end of the hold at 4 s, never while walking
    assert t.seated is not None
    assert t.seated.sum() == pytest.approx(2.0 / DT, abs=1)
    assert not np.any(t.seated & ~still)
    plain = stopping_waypoint_trajectory(w, np.array([0.0, 2.0, 0.0]), frame_period_s=DT)
    assert plain.seated is None
    np.testing.assert_array_equal(plain.position_m, t.position_m)


def scene_with(waypoints) -> dict:
    d = small_scene()
    d["persons"][0] = {"model": "walking", "trajectory": {"waypoints": waypoints}}
    return d


def test_scene_with_sit_round_trips_through_json():
    wp = [[0.0, 1.5, 1.0], [0.0, 4.0, 0.0, 3.0, "sit"], [2.0, 5.0, 1.0]]
    sc = Scene.from_dict(scene_with(wp))
    again = Scene.from_json_text(sc.to_json())
    assert again.to_dict() == sc.to_dict()
    assert sc.to_dict()["persons"][0]["trajectory"]["waypoints"] == wp
    tr = again.persons[0].trajectory
    assert tr == sc.persons[0].trajectory
    assert tr.seated_mask.sum() == pytest.approx(3.0 / DT, abs=1)


@pytest.mark.parametrize(
    ("wp", "needle"),
    [
        ([[0.0, 1.5, 1.0], [0.0, 4.0, 0.0, 3.0, "lie"]], 'waypoints[1][4] (posture) must be "sit"'),
        ([[0.0, 1.5, 1.0], [0.0, 4.0, 0.0, 3.0, True]], "waypoints[1][4] (posture)"),
        ([[0.0, 1.5, 1.0], [0.0, 4.0, 1.0, 3.0, "sit"]], "waypoints[1][2] (speed_mps of a stop)"),
        ([[0.0, 1.5, 1.0], [0.0, 4.0, 0.0, 3.0, "sit", 1]], "waypoints[1] must be"),
    ],
)
def test_bad_sit_names_the_field(wp, needle):
    with pytest.raises(InputError) as exc:
        Scene.from_dict(scene_with(wp))
    assert needle in exc.value.message
    assert "\n" not in exc.value.message
