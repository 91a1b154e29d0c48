"""Trajectories: eq. (6) exactly, classes a–e as in the paper's Fig. 3, inside the AOI."""

from __future__ import annotations

import numpy as np
import pytest

from core.errors import InputError
from core.scene import (
    AOI,
    TRAJECTORY_CLASSES,
    generate_trajectory,
    paper_scenes,
    profile_trajectory,
    waypoint_trajectory,
)

DT = 0.08
SEEDS = range(12)


def eq6_residual(tr) -> float:
    """Largest violation of v(t) = v(t-1) + a(t-1)Δt and p(t) = p(t-1) + v(t)Δt."""
    p, v, a, dt = tr.position_m, tr.velocity_mps, tr.acceleration_mps2, tr.frame_period_s
    rv = v[1:] - (v[:-1] + a[:-1] * dt)
    rp = p[1:] - (p[:-1] + v[1:] * dt)
    return float(max(np.abs(rv).max(), np.abs(rp).max()))


@pytest.mark.parametrize("cls", TRAJECTORY_CLASSES)
def test_generated_classes_follow_eq6_and_stay_inside(cls: str) -> None:
    aoi = AOI()
    for seed in SEEDS:
        tr = generate_trajectory(cls, np.random.default_rng(seed))
        assert tr.trajectory_class == cls
        assert eq6_residual(tr) < 1e-12
        assert aoi.contains(tr.position_m).all()
        assert 75 <= tr.n_frames <= 250, (cls, seed, tr.n_frames)
        speed = tr.speed_mps
        assert 0.5 - 1e-9 <= speed.max() <= 1.8 + 1e-9  # cruise speed in 0.5–1.8 m/s


def test_class_a_straight_along_an_axis_at_constant_speed() -> None:
    orientations = set()
    for seed in SEEDS:
        tr = generate_trajectory("a", np.random.default_rng(seed))
        v = tr.velocity_mps
        assert np.ptp(v, axis=0).max() < 1e-12  # constant velocity
        assert min(abs(v[0, 0]), abs(v[0, 1])) == 0.0  # horizontal or vertical
        orientations.add("horizontal" if v[0, 1] == 0 else "vertical")
        # ends where the path would leave the AOI (or at 20 s)
        nxt = tr.position_m[-1] + v[-1] * DT
        assert tr.n_frames == 250 or not AOI().contains(nxt)
    assert orientations == {"horizontal", "vertical"}


def test_class_b_radially_toward_the_radar() -> None:
    for seed in SEEDS:
        tr = generate_trajectory("b", np.random.default_rng(seed))
        p, v = tr.position_m, tr.velocity_mps
        cross = p[:, 0] * v[:, 1] - p[:, 1] * v[:, 0]
        assert np.abs(cross).max() < 1e-9  # velocity along the line of sight
        np.testing.assert_allclose(tr.radial_velocity_mps, -tr.speed_mps, rtol=1e-12)
        r_end = np.hypot(*(p[-1] + v[-1] * DT))
        assert tr.n_frames == 250 or r_end < AOI().min_range_m


def test_class_c_constant_speed_with_turns() -> None:
    for seed in SEEDS:
        tr = generate_trajectory("c", np.random.default_rng(seed))
        s = tr.speed_mps
        assert np.ptp(s) < 1e-9 * s.max()
        heading = np.unwrap(np.arctan2(tr.velocity_mps[:, 0], tr.velocity_mps[:, 1]))
        turned = np.abs(np.diff(heading)).sum()
        assert turned > np.radians(30), f"seed {seed}: turned only {np.degrees(turned):.1f} deg"
        # turns are smooth: at most 90 deg/s or the drawn turn spread over >= 2 frames
        assert np.abs(np.diff(heading)).max() <= np.radians(60) + 1e-9


def test_class_d_stops_and_walks_again() -> None:
    for seed in SEEDS:
        tr = generate_trajectory("d", np.random.default_rng(seed))
        s = tr.speed_mps
        cruise = s.max()
        stopped = s < 1e-12
        assert stopped.any(), f"seed {seed}: no stop"
        first_stop = int(np.argmax(stopped))
        assert s[:first_stop].max() == pytest.approx(cruise)
        # decelerates gradually (several frames), not in one step
        assert s[first_stop - 1] < cruise


def test_class_e_circle_not_centred_on_the_radar() -> None:
    for seed in SEEDS:
        tr = generate_trajectory("e", np.random.default_rng(seed))
        p = tr.position_m
        # algebraic circle fit x^2 + y^2 + D x + E y + F = 0
        A = np.column_stack((p[:, 0], p[:, 1], np.ones(len(p))))
        D, E, F = np.linalg.lstsq(A, -(p**2).sum(axis=1), rcond=None)[0]
        c = np.array([-D / 2, -E / 2])
        R = np.sqrt(c @ c - F)
        np.testing.assert_allclose(np.hypot(*(p - c).T), R, atol=1e-9)
        assert np.hypot(*c) > R  # the radar is outside the circle, so not its centre
        s = tr.speed_mps
        assert np.ptp(s) < 1e-9
        # centripetal acceleration |a| ≈ v^2 / R, perpendicular to v
        a = tr.acceleration_mps2[:-1]
        np.testing.assert_allclose(np.hypot(*a.T), s[0] ** 2 / R, rtol=2e-3)


def test_class_parameters_are_respected() -> None:
    rng = np.random.default_rng(1)
    tr = generate_trajectory("a", rng, speed_mps=1.0, start_m=(-4.0, 5.0), orientation="horizontal")
    np.testing.assert_allclose(tr.velocity_mps[0], [1.0, 0.0])
    np.testing.assert_allclose(tr.position_m[0], [-4.0, 5.0])
    tr = generate_trajectory("e", rng, speed_mps=1.2, radius_m=2.0, centre_m=(1.0, 5.0))
    np.testing.assert_allclose(np.hypot(*(tr.position_m - [1.0, 5.0]).T), 2.0, atol=1e-12)
    tr = generate_trajectory("c", rng, duration_s=8.0)
    assert tr.n_frames == 100


@pytest.mark.parametrize(
    ("cls", "params", "field"),
    [
        ("a", {"speed": 1.0}, "speed"),
        ("c", {"speed_mps": 9.0}, "speed_mps"),
        ("e", {"radius_m": "big"}, "radius_m"),
        ("z", {}, "class"),
    ],
)
def test_bad_class_parameters_name_the_field(cls, params, field) -> None:
    with pytest.raises(InputError, match=field):
        generate_trajectory(cls, np.random.default_rng(0), **params)


def test_waypoints_constant_and_varying_speed() -> None:
    # equal speeds: |v| = 1.0 throughout, duration = path length / speed
    w = np.array([[-2.0, 3.0, 1.0], [1.0, 7.0, 1.0]])
    tr = waypoint_trajectory(w)
    assert eq6_residual(tr) < 1e-12
    assert tr.n_frames == int(np.floor(5.0 / 1.0 / DT + 1e-9)) + 1  # 5 m at 1 m/s: 63 frames
    np.testing.assert_allclose(tr.speed_mps[1:], 1.0, rtol=1e-9)
    np.testing.assert_allclose(tr.position_m[0], [-2.0, 3.0])
    # speed linear in distance from 0.5 to 1.5 m/s over 4 m: T = ln(3)/k with k = 0.25 /s
    w = np.array([[0.0, 2.0, 0.5], [0.0, 6.0, 1.5]])
    tr = waypoint_trajectory(w)
    assert tr.n_frames == int(np.floor(np.log(3.0) / 0.25 / DT)) + 1
    s = tr.position_m[:, 1] - 2.0
    np.testing.assert_allclose(s, 0.5 * np.expm1(0.25 * tr.t_s) / 0.25, atol=1e-12)


def test_profile_constant_and_per_frame_acceleration() -> None:
    tr = profile_trajectory(
        initial_position_m=[1.0, 5.0],
        initial_velocity_mps=[0.0, -1.2],
        acceleration_mps2=[0.0, 0.0],
        frames=100,
    )
    assert tr.n_frames == 100
    np.testing.assert_allclose(tr.position_m[-1], [1.0, 5.0 - 1.2 * 99 * DT])
    acc = np.zeros((10, 2))
    acc[:, 0] = 0.5
    tr2 = profile_trajectory(
        initial_position_m=[0.0, 3.0], initial_velocity_mps=[0.0, 0.0], acceleration_mps2=acc
    )
    assert eq6_residual(tr2) < 1e-15
    # v(t) = 0.5 t Δt, x(t) = Δt^2 * 0.5 * t(t+1)/2
    t = np.arange(10)
    np.testing.assert_allclose(tr2.position_m[:, 0], DT**2 * 0.5 * t * (t + 1) / 2, atol=1e-15)
    with pytest.raises(InputError, match="frames"):
        profile_trajectory(
            initial_position_m=[0, 3], initial_velocity_mps=[0, 0], acceleration_mps2=[0, 0]
        )


def test_paper_scenes_round_robin_and_reproducible() -> None:
    a = paper_scenes(5, n_trajectories=10)
    assert [s.trajectory_class for s in a] == list("abcdeabcde")
    b = paper_scenes(5, n_trajectories=10)
    c = paper_scenes(6, n_trajectories=10)
    for s, t in zip(a, b):
        np.testing.assert_array_equal(s.persons[0].trajectory.position_m,
                                      t.persons[0].trajectory.position_m)  # fmt: skip
        assert s.seed == t.seed
    assert not np.array_equal(
        a[0].persons[0].trajectory.position_m[:2], c[0].persons[0].trajectory.position_m[:2]
    )
    # a prefix of the set is the same whatever the total
    assert paper_scenes(5, 3)[2].canonical_json() == a[2].canonical_json()
