"""The pipeline's per-frame reflector builder: its shortcuts give the same bits as the
straightforward calls they replace (the frames of every data set depend on it)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from core import pipeline
from core import simulation as sim
from core.errors import InputError
from core.scene import Scene

ROOT = Path(__file__).resolve().parents[3]


def _reflectors(scene: Scene, seed: int = 7) -> pipeline.Reflectors:
    antenna = sim.AntennaGain.draw(scene.radar, pipeline.stage_rng(seed, "antenna"))
    settings = pipeline.processing_settings(scene)
    return pipeline.Reflectors.build(scene, pipeline.plan(scene), seed, antenna, settings)


def test_stage_rng_is_default_rng_of_the_stage_seed_sequence() -> None:
    for stage, key in (("antenna", 0), ("person_rcs", 1), ("clutter", 2), ("noise", 3)):
        for f in (0, 1, 499):
            a = pipeline.stage_rng(123, stage, f).random(5)
            seq = np.random.SeedSequence(123, spawn_key=(key, f))
            assert a.tobytes() == np.random.default_rng(seq).random(5).tobytes()


def test_frames_match_the_straightforward_construction() -> None:
    """Persons, extended bodies, clutter and static reflectors rebuilt with the public calls."""
    from core.scene import draw_clutter
    from core.scene.body import body_scatterers

    base = Scene.from_json(ROOT / "resources/scenes/waypoints_static.json")
    d = base.to_dict(resolve_radar=True)
    d["persons"][0]["model"] = "extended"
    d["clutter_density_per_m2"] = 0.5
    scene = Scene.from_dict(d)
    refl = _reflectors(scene, seed=11)
    assert refl.run_clutter and refl.run_static and refl.extended.all()
    for f in (0, 5, 17):
        s, n_clutter = refl.frame(f)
        xy, v = refl.truth_xy_m[f, 0], refl.truth_v_mps[f, 0]
        bp, bv, frac = body_scatterers(xy, v, refl.headings[0][f], refl.truth_t_s[f])
        c = draw_clutter(
            scene.aoi,
            scene.clutter_density_per_m2,
            scene.radar,
            pipeline.stage_rng(11, "clutter", f),
        )
        assert n_clutter == len(c)
        r = np.hypot(c.position_m[:, 0], c.position_m[:, 1])
        az = np.arctan2(c.position_m[:, 0], c.position_m[:, 1])
        static = scene.static_reflectors
        want_pos = np.concatenate(
            [
                np.column_stack((bp, np.zeros(len(bp)))),
                np.column_stack((c.position_m, np.zeros(len(c)))),
                [[q.x_m, q.y_m, q.z_m] for q in static],
            ]
        )
        want_rcs = np.concatenate(
            [
                scene.persons[0].rcs_dbsm + 10 * np.log10(frac),
                sim.rcs_for_snr_db(scene.radar, r, az, c.snr_db, refl.antenna, refl.settings),
                [q.rcs_dbsm for q in static],
            ]
        )
        assert s.position_m.tobytes() == want_pos.tobytes()
        assert s.rcs_dbsm.tobytes() == want_rcs.tobytes()
        np.testing.assert_array_equal(s.velocity_mps[: len(bp), :2], bv)
        np.testing.assert_array_equal(s.velocity_mps[-len(static) :], 0.0)
        assert s.source.tolist() == [0] * len(bp) + [-1] * (len(c) + len(static))


def test_invalid_reflectors_still_get_the_validating_message() -> None:
    scene = Scene.from_json(ROOT / "resources/scenes/two_persons.json")
    refl = _reflectors(scene)
    bad = dataclasses.replace(refl, truth_xy_m=refl.truth_xy_m.copy())
    bad.truth_xy_m[2, 0] = 0.0  # a person at the radar
    refl.frame(2)  # the original is fine
    with pytest.raises(InputError, match="range 0"):
        bad.frame(2)


@pytest.mark.parametrize(
    "name, extended, density",
    [
        ("waypoints_static", True, 0.5),  # body model, clutter, static reflectors
        ("two_persons", False, None),  # two point persons entering and leaving
        ("paper", False, None),  # a paper trajectory: point person, clutter, drawn RCS
    ],
)
def test_all_frames_at_once_equal_frame_by_frame(name, extended, density) -> None:
    from core.scene import paper_scenes

    if name == "paper":
        scene = paper_scenes(0, 4)[3]
    else:
        d = Scene.from_json(ROOT / f"resources/scenes/{name}.json").to_dict(resolve_radar=True)
        if extended:
            d["persons"][0]["model"] = "extended"
        if density is not None:
            d["clutter_density_per_m2"] = density
        scene = Scene.from_dict(d)
    refl = _reflectors(scene, seed=3)
    frames, n_clutter = refl.frames()
    assert len(frames) == scene.n_frames == len(n_clutter)
    assert refl.run_clutter == bool(n_clutter.any())
    kinds = set()
    for f, s in enumerate(frames):
        one, nc = refl.frame(f)
        assert nc == n_clutter[f]
        for field in ("position_m", "velocity_mps", "rcs_dbsm", "source"):
            a, b = getattr(s, field), getattr(one, field)
            assert a.dtype == b.dtype and a.shape == b.shape, (f, field)
            assert a.tobytes() == b.tobytes(), (f, field)
        kinds.update(one.source.tolist())
    assert 0 in kinds and (-1 in kinds) == (refl.run_clutter or refl.run_static)
    if name == "two_persons":
        assert 1 in kinds
    # a prefix is the same frames
    head, nc = refl.frames(5)
    assert len(head) == 5 and nc.tolist() == n_clutter[:5].tolist()
    assert all(a.position_m.tobytes() == b.position_m.tobytes() for a, b in zip(head, frames))


def test_all_frames_at_once_keep_the_validating_message() -> None:
    scene = Scene.from_json(ROOT / "resources/scenes/two_persons.json")
    refl = _reflectors(scene)
    bad = dataclasses.replace(refl, truth_xy_m=refl.truth_xy_m.copy())
    bad.truth_xy_m[2, 0] = 0.0  # a person at the radar
    with pytest.raises(InputError, match="range 0"):
        bad.frames()
