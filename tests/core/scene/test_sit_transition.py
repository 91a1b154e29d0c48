"""Sitting down and standing up: the seated fraction ramps over SIT_TRANSITION_S."""

from __future__ import annotations

import numpy as np
import pytest

import core.scene.walking as W

H = 1.75
DT = 0.02


def hold(t_a: float, t_b: float, t_end: float = 12.0):
    t = np.arange(0.0, t_end, DT)
    return t, (t >= t_a - 1e-9) & (t <= t_b + 1e-9)


def test_fraction_is_a_smoothstep_at_both_ends_of_the_hold():
    t, m = hold(2.0, 8.0)
    s = W.sit_transition(t, m)
    assert s is not None
    f, rate = s[:, 0], s[:, 1]
    T = W.SIT_TRANSITION_S
    at = lambda x: int(np.argmin(np.abs(t - x)))  # noqa: E731
    assert f[at(1.9)] == 0.0 and f[at(8.1)] == 0.0  # standing outside the hold
    assert f[at(2.0)] == 0.0 and f[at(8.0)] == 0.0  # the ramps start and end at rest
    assert f[at(2.0 + T / 2)] == pytest.approx(0.5)  # smoothstep's midpoint
    assert f[at(8.0 - T / 2)] == pytest.approx(0.5)
    assert np.all(f[(t >= 2.0 + T) & (t <= 8.0 - T)] == 1.0)
    # sitting down rises, standing up falls, monotonically
    down, up = (t >= 2.0) & (t <= 2.0 + T), (t >= 8.0 - T) & (t <= 8.0)
    assert np.all(np.diff(f[down]) > 0) and np.all(np.diff(f[up]) < 0)
    # the rate is the fraction's derivative: peak 1.5 / T at the midpoints
    # (central differences err by ~3 s^2 dt / 2 dt next to the ramps' ends)
    np.testing.assert_allclose(rate[1:-1], np.gradient(f, t)[1:-1], atol=0.04)
    assert rate.max() == pytest.approx(1.5 / T) and rate.min() == pytest.approx(-1.5 / T)


def test_short_hold_ramps_over_half_its_length_each_way():
    t, m = hold(2.0, 2.8)
    f = W.sit_transition(t, m)[:, 0]  # type: ignore[index]
    assert f.max() == pytest.approx(1.0)  # seated exactly at the middle of the hold
    assert t[np.argmax(f)] == pytest.approx(2.4)


def test_no_sit_gives_none_and_the_standing_body_unchanged():
    t = np.arange(0.0, 3.0, DT)
    assert W.sit_transition(t, None) is None
    assert W.sit_transition(t, np.zeros(len(t), dtype=bool)) is None


def body_through_a_sit(t_a: float = 1.0, t_b: float = 6.0):
    t, m = hold(t_a, t_b, 7.0)
    n = len(t)
    zero = np.zeros(n)
    xy = np.tile([0.0, 3.0], (n, 1))
    vxy = np.zeros((n, 2))
    sit = W.sit_transition(t, m)
    pos, vel = W.walking_scatterers(xy, vxy, zero, zero, zero, t, H, sit)
    return t, pos, vel


def test_pelvis_descends_to_the_seat_over_the_ramp_and_velocity_matches():
    t, pos, vel = body_through_a_sit()
    k = W.SEGMENT_NAMES.index("hip_r")
    z = pos[:, k, 2] + W.RADAR_HEIGHT_M
    stand = W.body_frame_segments(np.zeros(1), np.zeros(1), np.zeros(1), H)[0, k, 2]
    seat = W.KNEE_Z * H
    T = W.SIT_TRANSITION_S
    assert z[0] == pytest.approx(stand)
    np.testing.assert_allclose(z[(t >= 1.0 + T) & (t <= 6.0 - T)], seat)
    # halfway through sitting down, halfway down (the pose's straight-line blend)
    mid = int(np.argmin(np.abs(t - (1.0 + T / 2))))
    assert z[mid] == pytest.approx(0.5 * (stand + seat), abs=1e-3)
    # the vertical velocity is the derivative of the height: the drop times 1.5 / T at its peak
    np.testing.assert_allclose(vel[1:-1, k, 2], np.gradient(z, t)[1:-1], atol=0.02)
    assert vel[:, k, 2].min() == pytest.approx(-(stand - seat) * 1.5 / T, rel=1e-3)
    assert vel[:, k, 2].max() == pytest.approx((stand - seat) * 1.5 / T, rel=1e-3)


def test_fully_seated_frames_equal_the_instantaneous_posture():
    t, m = hold(1.0, 6.0, 7.0)
    zero = np.zeros(len(t))
    ramp = W.sit_transition(t, m)[:, 0]  # type: ignore[index]
    a = W.body_frame_segments(zero, zero, t, H, ramp)
    b = W.body_frame_segments(zero, zero, t, H, m)
    full = ramp == 1.0
    assert full.sum() > 100
    np.testing.assert_array_equal(a[full], b[full])
    np.testing.assert_array_equal(a[~m], b[~m])
