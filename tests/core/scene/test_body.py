"""Extended person model: body scatterers with micro-Doppler (optional, not the default)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from core.errors import InputError
from core.pipeline import plan, simulate_scene
from core.scene import Scene
from core.scene.body import body_scatterers, walking_headings


def test_body_parts_share_the_rcs_and_swing_about_the_person() -> None:
    p, v = np.array([1.0, 6.0]), np.array([0.0, -1.4])
    heading = math.atan2(v[0], v[1])
    period = 1.4 / 1.4  # f = v / L_stride = 1 Hz
    ts = np.linspace(0, period, 200, endpoint=False)
    parts = [body_scatterers(p, v, heading, t) for t in ts]
    frac = parts[0][2]
    assert frac.sum() == pytest.approx(1.0)
    np.testing.assert_allclose(parts[0][0][0], p)  # torso on the trajectory
    vel = np.stack([q[1] for q in parts])  # (T, 5, 2)
    # over one gait cycle every limb moves on average with the body
    np.testing.assert_allclose(vel.mean(axis=0), np.tile(v, (5, 1)), atol=1e-12)
    # leg swing: ω A = 2π · 1 Hz · 0.30 m = 1.885 m/s either side of the body velocity
    leg_vy = vel[:, 3, 1]
    assert leg_vy.max() - leg_vy.min() == pytest.approx(2 * 2 * math.pi * 0.30, rel=1e-3)
    # arms swing opposite to each other
    np.testing.assert_allclose(vel[:, 1] - v, -(vel[:, 2] - v), atol=1e-12)


def test_standing_person_does_not_swing() -> None:
    p = np.array([0.0, 4.0])
    pos, vel, _ = body_scatterers(p, np.zeros(2), 0.3, 1.234)
    assert np.all(vel == 0)
    assert np.hypot(*(pos - p).T).max() <= 0.22 + 1e-12


def test_heading_is_held_through_a_stop() -> None:
    v = np.array([[0.0, 1.0], [1.0, 0.0], [0.0, 0.0], [0.0, 0.0], [-1.0, 0.0]])
    np.testing.assert_allclose(
        walking_headings(v), [0, math.pi / 2, math.pi / 2, math.pi / 2, -math.pi / 2]
    )


def scene(model: str) -> Scene:
    return Scene.from_json_text(
        json.dumps(
            {
                "schema_version": 1,
                "seed": 1,
                "clutter_density_per_m2": 0.0,
                "persons": [
                    {
                        "model": model,
                        "trajectory": {
                            "initial_position_m": [0.5, 7.0],
                            "initial_velocity_mps": [0.0, -1.4],
                            "acceleration_mps2": [0.0, 0.0],
                            "frames": 12,
                        },
                    }
                ],
            }
        )
    )


def test_extended_person_spreads_over_doppler() -> None:
    point, ext = scene("point"), scene("extended")
    assert not plan(point).runs("body_model")
    assert plan(ext).runs("body_model")
    run_p, run_e = simulate_scene(point), simulate_scene(ext)
    n_p = [int(np.sum(c.source == 0)) for c in run_p.clouds]
    n_e = [int(np.sum(c.source == 0)) for c in run_e.clouds]
    assert max(n_p) == 1  # one point scatterer: one point
    assert np.mean(n_e) >= 2  # body parts resolved in Doppler (micro-Doppler)
    vr = np.concatenate([c.radial_velocity_mps[c.source == 0] for c in run_e.clouds])
    assert np.ptp(vr) > 2.0  # limbs at −1.4 ± 1.9 m/s
    assert json.loads(ext.to_json())["persons"][0]["model"] == "extended"


def test_unknown_person_model_names_the_field() -> None:
    with pytest.raises(InputError, match=r"persons\[0\].model"):
        scene("stick-figure")
