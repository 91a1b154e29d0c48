"""Image-method multipath against hand-derived geometry (docs/rooms.md).

One wall, the plane x = 3 m; the radar at the origin (no height, no tilt); a scatterer at
S = (1, 4, 0) m moving at (0, 1, 0) m/s with 0 dBsm; an ideal (flat) antenna. S's image is
S' = (5, 4, 0): |S| = sqrt(17), |S'| = sqrt(41).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from core.config import DEFAULT_PROCESSING, PAPER_RADAR
from core.scene.room import Room, SensorPose, Wall
from core.simulation.antenna import AntennaGain
from core.simulation.multipath import (
    ghost_groups,
    group_proxies,
    image_paths,
    path_labels,
    split_labels,
)

S = np.array([[1.0, 4.0, 0.0]])
V = np.array([[0.0, 1.0, 0.0]])
ANT = AntennaGain.ideal(PAPER_RADAR)
R1, R2 = math.sqrt(17.0), math.sqrt(41.0)


def one_wall(reflection_db=-6.0, y=(-1.0, 10.0), **pose) -> Room:
    return Room(
        walls=(Wall(from_m=(3.0, y[0]), to_m=(3.0, y[1]), reflection_db=reflection_db),),
        sensor=SensorPose(**pose),
    )


def test_first_order_ghost_from_both_paths():
    p = image_paths(one_wall(), S, V, np.zeros(1), ANT, max_order=1)
    assert p.path_order.tolist() == [1, 1]
    length = R1 + R2
    np.testing.assert_allclose(p.length_m, [length, length])
    # range L / 2, along each path's last leg: from S' (S -> wall -> radar) and from S
    np.testing.assert_allclose(np.linalg.norm(p.position_m, axis=1), [length / 2] * 2)
    np.testing.assert_allclose(p.position_m[0], length / 2 * np.array([5.0, 4.0, 0.0]) / R2)
    np.testing.assert_allclose(p.position_m[1], length / 2 * np.array([1.0, 4.0, 0.0]) / R1)
    # dL/dt = v . S/|S| + v' . S'/|S'| = 4/sqrt(17) + 4/sqrt(41); Doppler half of it
    rate = 4 / R1 + 4 / R2
    np.testing.assert_allclose(p.rate_mps, [rate, rate])
    radial = np.einsum("ij,ij->i", p.position_m, p.velocity_mps) / (length / 2)
    np.testing.assert_allclose(radial, [rate / 2] * 2)
    # eq. (4): sigma_e = sigma rho (L/2)^4 / (|S|^2 |S'|^2)
    rcs = -6.0 + 40 * math.log10(length / 2) - 20 * math.log10(R1 * R2)
    np.testing.assert_allclose(p.rcs_dbsm, [rcs, rcs])


def test_doppler_is_half_the_numerical_path_length_rate():
    dt = 1e-6
    p0 = image_paths(one_wall(), S, V, np.zeros(1), ANT)
    p1 = image_paths(one_wall(), S + V * dt, V, np.zeros(1), ANT)
    np.testing.assert_allclose((p1.length_m - p0.length_m) / dt, p0.rate_mps, atol=1e-5)


def test_second_order_ghost_at_the_image():
    p = image_paths(one_wall(), S, V, np.zeros(1), ANT)
    second = p.path_order == 2
    assert second.sum() == 1
    # radar -> wall -> S -> wall -> radar: L = 2 |S'|, the ghost sits at S'
    np.testing.assert_allclose(p.length_m[second], [2 * R2])
    np.testing.assert_allclose(p.position_m[second][0], [5.0, 4.0, 0.0])
    np.testing.assert_allclose(p.rate_mps[second], [2 * 4 / R2])
    np.testing.assert_allclose(p.rcs_dbsm[second], [-12.0])  # two bounces, (L/2)^4 = |S'|^4


def test_antenna_gain_of_departure_over_arrival():
    ant = AntennaGain.draw(PAPER_RADAR, np.random.default_rng(3))
    p = image_paths(one_wall(), S, V, np.zeros(1), ant, max_order=1)
    az_s, az_img = math.atan2(1.0, 4.0), math.atan2(5.0, 4.0)
    flat = image_paths(one_wall(), S, V, np.zeros(1), ANT, max_order=1)
    # S -> wall -> radar leaves towards S, arrives from S'; the other path the reverse
    expected = flat.rcs_dbsm + np.array(
        [
            ant.gain_db(az_s) - ant.gain_db(az_img),
            ant.gain_db(az_img) - ant.gain_db(az_s),
        ]
    )
    np.testing.assert_allclose(p.rcs_dbsm, expected)


@pytest.mark.parametrize(
    "room",
    [
        one_wall(reflection_db=-math.inf),  # an absorber
        Room(),  # no wall
        one_wall(y=(6.0, 10.0)),  # the reflection point (3, 2.4) is off the segment
    ],
)
def test_no_ghost(room):
    assert len(image_paths(room, S, V, np.zeros(1), ANT)) == 0


def test_scatterer_behind_the_wall_has_no_ghost():
    assert len(image_paths(one_wall(), np.array([[4.0, 4.0, 0.0]]), V, np.zeros(1), ANT)) == 0


def test_sensor_pose_moves_the_radar_up():
    # radar 2 m up: the legs are 3-D, the image keeps S's height
    s = np.array([[1.0, 4.0, 1.0]])
    p = image_paths(one_wall(height_m=2.0), s, V, np.zeros(1), ANT, max_order=1)
    d1 = math.sqrt(1 + 16 + 1)
    d2 = math.sqrt(25 + 16 + 1)
    np.testing.assert_allclose(p.length_m, [d1 + d2] * 2)
    np.testing.assert_allclose(
        p.position_m[0], [0, 0, 2] + (d1 + d2) / 2 * np.array([5, 4, -1]) / d2
    )


def test_labels_round_trip():
    source = np.array([0, 0, 2, -1, -1, -1])
    order = np.array([0, 1, 2, 0, 2, 0])
    clutter = np.array([False, False, False, False, False, True])
    labels = path_labels(source, order, clutter)
    assert np.all(labels[:3] >= 0)  # the levels still see persons
    src, o = split_labels(np.concatenate((labels, [-2])))
    assert src.tolist() == [0, 0, 2, -1, -1, -1, -2]
    assert o.tolist() == [0, 1, 2, 0, 2, -1, -1]


def test_proxies_keep_the_power_and_split_by_speed():
    source = np.zeros(6, dtype=np.int32)
    vel = np.array([[0, s, 0] for s in (0.1, 3.0, 0.2, 2.0, 1.0, 1.1)], dtype=float)
    pos = np.arange(18, dtype=float).reshape(6, 3)
    rcs = np.full(6, -10.0)
    g = ghost_groups(source, vel, np.zeros(6, dtype=bool))
    # sorted by speed: (0, 2) (4, 5) (3, 1)
    assert g[0] == g[2] and g[4] == g[5] and g[1] == g[3] and len(set(g)) == 3
    p_pos, p_vel, p_rcs, _, _ = group_proxies(g, pos, vel, rcs, source)
    np.testing.assert_allclose(p_rcs, 10 * math.log10(2 * 0.1))
    np.testing.assert_allclose(sorted(p_vel[:, 1]), [0.15, 1.05, 2.5])


@pytest.mark.parametrize("size", [1, 2, 3, 4, 5, 7, 17])
def test_groups_cut_like_array_split_per_frame_and_person(size):
    rng = np.random.default_rng(size)
    # two frames, two persons each, shuffled
    frame = np.repeat([0, 0, 1, 1], size)
    source = np.tile(np.repeat([0, 1], size), 2)
    vel = rng.normal(size=(4 * size, 3))
    g = ghost_groups(source, vel, np.zeros(4 * size, dtype=bool), frame)
    for f in (0, 1):
        for p in (0, 1):
            idx = np.flatnonzero((frame == f) & (source == p))
            by_speed = idx[np.argsort(np.linalg.norm(vel[idx], axis=1), kind="stable")]
            expected = [part.tolist() for part in np.array_split(by_speed, min(3, size))]
            got = [by_speed[g[by_speed] == k].tolist() for k in dict.fromkeys(g[by_speed])]
            assert got == expected


# ---- a ghost's two contributions share one tone (docs/rooms.md#speed) ------------------------


def _ghost_pair():
    """The first-order ghost of S in the wall x = 3 m (both orders) as two scatterers, and a
    third scatterer at the same range moving across (not radial: no shared tone)."""
    from core.simulation import Scatterers

    p = image_paths(one_wall(), S, V, np.zeros(1), ANT, max_order=1)
    across = np.cross(p.position_m[0], [0.0, 0.0, 1.0])
    pos = np.vstack((p.position_m, p.position_m[:1] * 1.0))
    vel = np.vstack((p.velocity_mps, 0.5 * across / np.linalg.norm(across)))
    return Scatterers(
        position_m=pos,
        velocity_mps=vel,
        rcs_dbsm=np.array([-10.0, -13.0, -10.0]),
        source=np.zeros(3, dtype=np.int32),
    )


def test_a_ghost_pair_is_one_tone_and_frames_keep_theirs_apart():
    from core.simulation.baseband import coincident_tones

    sc = _ghost_pair()
    # the two paths arrive from different directions at the same range and radial velocity
    assert not np.allclose(sc.position_m[0], sc.position_m[1])
    assert coincident_tones(sc.position_m, sc.velocity_mps).tolist() == [0, 0, 2]
    # the same pair in two frames: a tone per frame
    pos = np.vstack((sc.position_m[:2], sc.position_m[:2]))
    vel = np.vstack((sc.velocity_mps[:2], sc.velocity_mps[:2]))
    assert coincident_tones(pos, vel, np.array([0, 0, 1, 1])).tolist() == [0, 0, 2, 2]
    # 1 mm apart: two tones
    far = sc.position_m[:2] * np.array([[1.0], [1.0 + 1e-3 / np.linalg.norm(sc.position_m[1])]])
    assert coincident_tones(far, sc.velocity_mps[:2]).tolist() == [0, 1]


def test_merged_tone_synthesises_the_sum_of_its_contributions():
    # the cube is linear in the scatterers: one tone with the summed channel weights equals the
    # two contributions synthesised apart, to complex64 rounding
    from core.simulation import Scatterers, synthesize_signal

    sc = _ghost_pair()

    def alone(i):
        return Scatterers(
            position_m=sc.position_m[i : i + 1],
            velocity_mps=sc.velocity_mps[i : i + 1],
            rcs_dbsm=sc.rcs_dbsm[i : i + 1],
            source=sc.source[i : i + 1],
        )

    both = synthesize_signal(PAPER_RADAR, sc, ANT)
    apart = sum(
        synthesize_signal(PAPER_RADAR, alone(i), ANT).astype(np.complex128) for i in range(3)
    )
    scale = np.max(np.abs(apart))
    assert np.max(np.abs(both - apart)) < 1e-6 * scale
    # the merge is real: the two contributions differ in every channel's phase
    a0, a1 = (synthesize_signal(PAPER_RADAR, alone(i), ANT) for i in (0, 1))
    assert np.max(np.abs(a0 - a1)) > 0.1 * np.max(np.abs(a0))


def test_merged_tone_gives_the_fast_level_the_summed_channels():
    # the fast level's noise-free patch cells of the pair: the sum of each contribution's
    # channel values where both see the cell (each contribution's slow time is computed from its
    # own position, the merged tone's range bins follow its own bound: 1e-7 of the cell's
    # channel vector at most, complex64's resolution)
    from core.simulation import Scatterers
    from core.simulation.fast import fast_spectrum, tones

    sc = _ghost_pair()
    pair = Scatterers(
        position_m=sc.position_m[:2],
        velocity_mps=sc.velocity_mps[:2],
        rcs_dbsm=np.array([30.0, 27.0]),
        source=sc.source[:2],
    )
    amp, _, _, _, steer, keep = tones(PAPER_RADAR, pair, ANT, DEFAULT_PROCESSING)
    assert keep.tolist() == [0]
    assert np.max(np.abs(steer)) == pytest.approx(1.0)  # |steer| <= 1, amp the largest channel

    def cells(s):
        spec = fast_spectrum(PAPER_RADAR, s, None, antenna=ANT, noise=False)
        return {tuple(k): x for k, x in zip(spec.patch.tolist(), spec.signal)}

    one = [cells(Scatterers(**{f: getattr(pair, f)[i : i + 1] for f in FIELDS})) for i in (0, 1)]
    merged = cells(pair)
    common = set(one[0]) & set(one[1]) & set(merged)
    assert len(common) > 20
    for c in common:
        want = one[0][c] + one[1][c]
        assert np.linalg.norm(merged[c] - want) <= 1e-7 * np.linalg.norm(want)


FIELDS = ("position_m", "velocity_mps", "rcs_dbsm", "source")
