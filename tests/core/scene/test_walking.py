"""Walking body (core/scene/walking.py): gait kinematics, scene option, RCS split, bad input."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from core.errors import InputError
from core.pipeline import plan
from core.pipeline.plan import processing_settings
from core.pipeline.reflectors import Reflectors
from core.scene import Scene
from core.scene import walking as W
from core.simulation import AntennaGain

NAMES = W.SEGMENT_NAMES
H, V = 1.8, 1.2
# RV = v / H_t = 1.2 / (0.530 * 1.8) = 1.258; D_c = 1.346 / sqrt(RV) = 1.2001 s
DC = 1.346 / math.sqrt(V / (0.530 * H))


def straight(t, v=V, h=H, phase0=0.0):
    """A straight walk along +y at speed v: world positions and velocities of the segments."""
    speed = np.full_like(t, v)
    ph = W.gait_phase(t, speed, h, phase0)
    pos = np.c_[np.zeros_like(t), v * t + 2.0]
    vel = np.tile([0.0, v], (len(t), 1))
    zero = np.zeros_like(t)
    return W.walking_scatterers(pos, vel, zero, zero, ph, t, h), ph


def test_cycle_duration_is_boulics() -> None:
    assert W.cycle_duration_s(np.array([V]), H)[0] == pytest.approx(DC, rel=1e-12)
    assert DC == pytest.approx(1.2001, abs=1e-4)
    t = np.arange(0, 5, 0.01)
    ph = W.gait_phase(t, np.full_like(t, V), H, 0.25)
    np.testing.assert_allclose(np.diff(ph), 0.01 / DC, rtol=1e-12)
    # the body relative to the walker repeats after D_c and not after half or 0.8 of it
    joints = [
        W.body_frame_segments(np.array([p]), np.array([V]), np.array([0.0]), H)[0]
        for p in (0.1, 0.1 + 1.0, 0.1 + 0.5, 0.1 + 0.8)
    ]
    np.testing.assert_allclose(joints[0], joints[1], atol=1e-12)
    assert np.abs(joints[0] - joints[2]).max() > 0.1
    assert np.abs(joints[0] - joints[3]).max() > 0.1
    # the legs' Doppler repeats with the same period: autocorrelation peak at D_c
    t = np.arange(0, 6, 0.005)
    (pos, vel), _ = straight(t)
    vy = vel[:, NAMES.index("lower_leg_r"), 1] - vel[:, NAMES.index("lower_leg_r"), 1].mean()
    lags = np.arange(int(0.7 * DC / 0.005), int(1.3 * DC / 0.005))
    ac = [np.dot(vy[:-lag], vy[lag:]) / (len(vy) - lag) for lag in lags]
    assert lags[int(np.argmax(ac))] * 0.005 == pytest.approx(DC, abs=0.011)


@pytest.mark.parametrize("speed", [0.0, 0.4, 1.2, 1.8])
def test_segment_lengths_are_constant(speed) -> None:
    t = np.arange(0, 4, 0.004)
    ph = W.gait_phase(t, np.full_like(t, speed), H, 0.3)
    j = W.body_frame_joints(ph, np.full_like(t, speed), t, H)
    for name, (a, b) in W.SEGMENT_ENDS.items():
        length = np.linalg.norm(j[a] - j[b], axis=1)
        assert np.ptp(length) < 1e-9, name
    # thigh and shank lengths are those of the body proportions
    thigh = np.linalg.norm(j["hip_r"] - j["knee_r"], axis=1)
    np.testing.assert_allclose(thigh, (0.530 - 0.285) * H, rtol=1e-12)


def test_a_foot_in_stance_stands_still() -> None:
    t = np.arange(0, 4, 0.002)
    (pos, vel), ph = straight(t)
    beta = 0.752 - 0.143 / DC  # Boulic: D_s = 0.752 D_c - 0.143 s
    psi = np.mod(ph, 1.0)
    flat = (psi > 0.1 * beta) & (psi < 0.55 * beta)  # foot flat: after heel strike, before heel-off
    foot = np.linalg.norm(vel[:, NAMES.index("foot_r")], axis=1)
    assert flat.sum() > 100
    assert foot[flat].max() < 0.02  # m/s, against 1.2 m/s of the body
    # and the foot on the floor there: its centre at about half the ankle's height
    z = pos[flat, NAMES.index("foot_r"), 2] + W.RADAR_HEIGHT_M
    assert np.all(np.abs(z - 0.5 * 0.039 * H) < 0.005)
    # in swing it overtakes the body
    assert foot.max() > 2.5 * V


def test_legs_reach_two_to_three_times_the_torso_speed() -> None:
    t = np.arange(0, 4 * DC, 0.002)
    (_, vel), _ = straight(t, v=1.4, h=1.75)
    speed = np.linalg.norm(vel, axis=2)
    torso = speed[:, NAMES.index("torso")].mean()
    assert vel[:, NAMES.index("torso"), 1].mean() == pytest.approx(1.4, rel=0.01)
    assert torso == pytest.approx(1.4, rel=0.03)
    for leg in ("upper_leg_r", "lower_leg_l"):
        ratio = speed[:, NAMES.index(leg)].max() / torso
        assert 2.0 <= ratio <= 3.5, (leg, ratio)
    # the torso itself stays within +-25 % of the walking speed
    assert np.ptp(speed[:, NAMES.index("torso")]) < 0.5 * 1.4


def test_velocities_are_the_derivative_of_the_positions() -> None:
    t = np.arange(0, 3, 0.001)
    (pos, vel), _ = straight(t)
    num = np.gradient(pos, t, axis=0)
    # central differences of the sampled positions against the returned velocities
    err = np.abs(num[5:-5] - vel[5:-5])
    assert np.percentile(err, 99) < 0.02


def test_heights_relative_to_the_radar() -> None:
    t = np.arange(0, 2, 0.01)
    (pos, _), _ = straight(t)
    z = pos[..., 2] + W.RADAR_HEIGHT_M  # above the floor
    head = z[:, NAMES.index("head")]
    # standing 0.935 H; the pelvis is lower while walking (bent stance knee, double support)
    assert np.all((head > 0.87 * H) & (head < 0.94 * H))
    assert np.all(z[:, NAMES.index("foot_r")] < 0.15 * H)
    assert np.all(z > 0)


def scene_dict(model="walking", trajectory=None, **person) -> dict:
    return {
        "schema_version": 1,
        "seed": 4,
        "clutter_density_per_m2": 0.0,
        "persons": [
            {
                "model": model,
                "trajectory": trajectory or {"class": "e", "seed": 3, "speed_mps": 1.2},
                **person,
            }
        ],
    }


def reflectors(d: dict) -> Reflectors:
    scene = Scene.from_dict(d)
    return Reflectors.build(
        scene,
        plan(scene),
        scene.seed,
        AntennaGain.ideal(scene.radar),
        processing_settings(scene),
    )


def test_body_heading_follows_the_trajectory_through_a_turn() -> None:
    refl = reflectors(scene_dict())  # class e: a circle
    frames, _ = refl.frames()
    v = refl.truth_v_mps[:, 0]
    heading = np.arctan2(v[:, 0], v[:, 1])
    assert np.ptp(np.unwrap(heading)) > 1.0  # the walk turns by more than a radian
    r, l_ = NAMES.index("hip_r"), NAMES.index("hip_l")
    for f, sc in enumerate(frames):
        p = sc.position_m[sc.source == 0]
        left = p[l_, :2] - p[r, :2]
        left /= np.linalg.norm(left)
        # left of the walking direction (sin h, cos h) is (-cos h, sin h), up to the pelvis
        # torsion (4 deg * RV = 5.3 deg) and the frame's turn
        want = np.array([-math.cos(heading[f]), math.sin(heading[f])])
        assert math.degrees(math.acos(np.clip(left @ want, -1, 1))) < 8.0
    # on the circle the head's velocity (trajectory + turn of the body) is the derivative of its
    # positions from frame to frame (central differences over 2 frames, 0.16 s)
    k = NAMES.index("head")
    head = np.array([sc.position_m[sc.source == 0][k] for sc in frames])
    head_v = np.array([sc.velocity_mps[sc.source == 0][k] for sc in frames])
    dt = refl.truth_t_s[1] - refl.truth_t_s[0]
    num = (head[2:] - head[:-2]) / (2 * dt)
    assert np.percentile(np.abs(num - head_v[1:-1]), 95) < 0.1


def test_segment_powers_add_up_to_the_eq5_draw() -> None:
    walk = reflectors(scene_dict())
    point = reflectors(scene_dict(model="point"))
    for f in (0, 7, 40):
        w_sc, _ = walk.frame(f)
        p_sc, _ = point.frame(f)
        assert len(w_sc) == W.N_SEGMENTS and len(p_sc) == 1
        total = np.sum(10 ** (w_sc.rcs_dbsm / 10))
        assert total == pytest.approx(10 ** (p_sc.rcs_dbsm[0] / 10), rel=1e-12)
    assert W.RCS_SHARES.sum() == pytest.approx(1.0, rel=1e-15)
    assert np.all(W.RCS_SHARES > 0)


def test_all_frames_at_once_equal_frame_by_frame() -> None:
    refl = reflectors(scene_dict())
    frames, _ = refl.frames()
    for f in (0, 13, len(frames) - 1):
        one, _ = refl.frame(f)
        np.testing.assert_array_equal(one.position_m, frames[f].position_m)
        np.testing.assert_array_equal(one.velocity_mps, frames[f].velocity_mps)
        np.testing.assert_array_equal(one.rcs_dbsm, frames[f].rcs_dbsm)


def test_a_standing_person_breathes_and_sways_only() -> None:
    t = np.arange(0, 8, 0.05)
    zero = np.zeros_like(t)
    ph = W.gait_phase(t, zero, H, 0.4)
    assert np.all(ph == 0.4)
    pos, vel = W.walking_scatterers(
        np.tile([0.0, 3.0], (len(t), 1)), np.zeros((len(t), 2)), zero, zero, ph, t, H
    )
    speed = np.linalg.norm(vel, axis=2)
    assert speed.max() < 0.02  # m/s: sway 2 pi 0.2 Hz 1 cm = 0.013 m/s, breath 0.005 m/s
    torso = pos[:, NAMES.index("torso")]
    assert 0.003 < np.ptp(torso[:, 1]) < 0.03  # it moves, by millimetres to a centimetre
    feet = pos[:, NAMES.index("foot_r")]
    # the feet stay put (to the 0.1 mm the soft reach limit of the straight legs allows)
    assert np.ptp(feet, axis=0).max() < 1e-4


def test_scene_json_round_trip_and_extended_alias() -> None:
    d = scene_dict(height_m=1.62, gait_phase=0.25)
    s = Scene.from_dict(d)
    p = s.persons[0]
    assert (p.kind, p.height_m, p.gait_phase) == ("walking", 1.62, 0.25)
    assert not s.is_planar
    out = json.loads(s.to_json())["persons"][0]
    assert out["model"] == "walking" and out["height_m"] == 1.62 and out["gait_phase"] == 0.25
    # "extended" is the blob's former name: read as the blob, written back as given
    ext = Scene.from_dict(scene_dict(model="extended"))
    blob = Scene.from_dict(scene_dict(model="blob"))
    assert ext.persons[0].kind == blob.persons[0].kind == "blob"
    assert json.loads(ext.to_json())["persons"][0]["model"] == "extended"
    a, b = reflectors(scene_dict(model="extended")), reflectors(scene_dict(model="blob"))
    np.testing.assert_array_equal(a.frame(5)[0].position_m, b.frame(5)[0].position_m)
    assert ext.is_planar


@pytest.mark.parametrize(
    "person, match",
    [
        ({"height_m": 0.0}, r"persons\[0\]\.height_m must be in \[1\.0, 2\.2\]"),
        ({"height_m": -1}, r"persons\[0\]\.height_m"),
        ({"height_m": "tall"}, r"persons\[0\]\.height_m must be a finite number"),
        ({"gait_phase": 1.5}, r"persons\[0\]\.gait_phase"),
        ({"model": "stick-figure"}, r"persons\[0\]\.model must be one of"),
        (
            {"height_m": 1.0, "trajectory": {"class": "a", "seed": 1, "speed_mps": 2.5}},
            r"persons\[0\]: trajectory speed 2\.5 m/s exceeds the walking model's 1\.3",
        ),
    ],
)
def test_bad_person_input_names_the_field(person, match) -> None:
    d = scene_dict()
    d["persons"][0].update(person)
    with pytest.raises(InputError, match=match):
        Scene.from_dict(d)


def test_measurement_level_simulates_the_walking_body() -> None:
    # the measurement level merges the segments that share a cell (core.simulation.body_cells)
    from core.pipeline import simulate_scene

    s = Scene.from_dict(scene_dict())
    run = simulate_scene(s, fidelity="measurement")
    n_person = [int(np.sum(c.source == 0)) for c in run.clouds]
    assert sum(n_person) > 0
    assert max(n_person) < 17  # fewer points than segments: merged cells
