"""Pipeline: the plan (run/skip and why), skipped stages not executed and changing nothing,
reproducible and cached data sets, the tracker's clutter density."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import core.pipeline as pipeline
import core.processing.angle as angle
from core.dataset import Dataset
from core.errors import InputError
from core.pipeline import (
    build_dataset,
    dataset_key,
    iter_frames,
    plan,
    scene_clutter_density,
    simulate_scene,
)
from core.pipeline import cache as pipeline_cache
from core.pipeline import frames as pipeline_frames
from core.pipeline import reflectors as pipeline_reflectors
from core.pointcloud import POINT_FIELDS
from core.scene import Person, Scene, class_scene, profile_trajectory

ROOT = Path(__file__).resolve().parents[3]


def short_scene(*, clutter: float = 0.0, frames: int = 8, rcs: float | None = None) -> Scene:
    """One person walking toward the radar at 1.2 m/s from (1, 5) m."""
    traj = profile_trajectory(
        initial_position_m=[1.0, 5.0],
        initial_velocity_mps=[0.0, -1.2],
        acceleration_mps2=[0.0, 0.0],
        frames=frames,
    )
    spec = {
        "initial_position_m": [1.0, 5.0],
        "initial_velocity_mps": [0.0, -1.2],
        "acceleration_mps2": [0.0, 0.0],
        "frames": frames,
    }
    return Scene(
        seed=3,
        clutter_density_per_m2=clutter,
        persons=(Person(trajectory=traj, rcs_dbsm=rcs, spec=spec),),
    )


def assert_clouds_identical(a, b) -> None:
    assert len(a) == len(b)
    for x, y in zip(a, b):
        for f in (*POINT_FIELDS, "source"):
            np.testing.assert_array_equal(getattr(x, f), getattr(y, f), err_msg=f)


# ---- clutter density --------------------------------------------------------------------------


def test_clutter_density_of_the_paper_scene() -> None:
    from core.processing import expected_false_alarms_per_frame

    scene = Scene.from_json(ROOT / "resources/scenes/paper_class_c.json")
    volume = 9.5 * (2 * np.pi / 3) * 2 * scene.radar.max_velocity_mps  # 288.1 m·rad·m/s
    assert volume == pytest.approx(288.1, abs=0.1)
    # SPEC's "about 0.0073" is the clutter term: λ·A / V = 2.0892 / 288.1
    quiet = dataclasses.replace(scene, clutter_density_per_m2=0.0)
    rho_fa = scene_clutter_density(quiet)
    rho = scene_clutter_density(scene)
    assert rho - rho_fa == pytest.approx(0.00725, abs=0.00001)
    # plus the chain's own noise detections (joint two-stage CFAR): ~0.20 per frame
    n_fa = expected_false_alarms_per_frame(scene.radar, pipeline.processing_settings(scene))
    assert 0.1 < n_fa < 0.3
    assert rho_fa == pytest.approx(n_fa / volume, rel=1e-12)
    assert rho == pytest.approx((2.0892 + n_fa) / volume, rel=1e-4)
    assert rho == pytest.approx(0.00795, abs=0.0001)


# ---- the plan ---------------------------------------------------------------------------------


def test_plan_follows_the_scene_and_the_consumer() -> None:
    p = plan(short_scene(clutter=0.0, rcs=-8.0))
    assert not p.runs("clutter") and "clutter_density_per_m2 = 0" in p.explain()
    assert not p.runs("person_rcs")
    assert not p.runs("elevation") and "planar" in p.explain()
    assert not p.runs("keep_rd_map")
    assert not p.runs("static_reflectors")
    assert p.runs("baseband") and p.runs("cfar") and p.runs("azimuth")
    busy = plan(short_scene(clutter=0.02), keep_rd_maps=True)
    assert busy.runs("clutter") and busy.runs("person_rcs") and busy.runs("keep_rd_map")
    assert plan(short_scene(), consumer="gui").runs("keep_rd_map")
    study = plan(short_scene(clutter=0.02), consumer="study")
    assert study.runs("load_point_clouds")
    assert not any(s.run for s in study.stages if s.name != "load_point_clouds")
    with pytest.raises(InputError, match="never simulates"):
        next(iter_frames(short_scene(), the_plan=study))
    # every line names the stage, run/skip, needs -> produces and the reason
    lines = busy.explain().splitlines()[1:]
    assert len(lines) == len(busy.stages)
    assert all(("run " in ln or "skip" in ln) and "->" in ln and "(" in ln for ln in lines)


def test_stages_declare_consistent_needs_and_products() -> None:
    p = plan(short_scene(clutter=0.02))
    produced = {"trajectories", "seed", "dataset_cache"}
    for s in p.stages:
        if s.name == "load_point_clouds":
            continue
        missing = set(s.needs) - produced
        assert not missing, f"{s.name} needs {missing} before anything produces it"
        produced |= set(s.produces)


def test_unknown_fidelity_consumer_or_stage_is_an_input_error() -> None:
    with pytest.raises(InputError, match="fidelity"):
        plan(short_scene(), fidelity="approximate")
    with pytest.raises(InputError, match="consumer"):
        plan(short_scene(), consumer="printer")
    with pytest.raises(InputError, match="clutterr"):
        plan(short_scene(), force=("clutterr",))


# ---- skipped stages are not executed and change nothing --------------------------------------


def test_skipped_clutter_stage_is_not_run_and_changes_nothing(monkeypatch) -> None:
    calls = []
    real = pipeline_reflectors.draw_clutter

    def counting(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(pipeline_reflectors, "draw_clutter", counting)
    scene = short_scene(clutter=0.0)
    skipped = simulate_scene(scene)
    assert calls == []
    forced = simulate_scene(scene, the_plan=plan(scene, force=("clutter",)))
    assert len(calls) == scene.n_frames
    assert_clouds_identical(skipped.clouds, forced.clouds)
    assert forced.n_clutter.sum() == 0


def test_skipped_person_rcs_stage_draws_nothing(monkeypatch) -> None:
    streams = []
    real = pipeline.stage_rng

    def counting(seed, stage, frame=0):
        streams.append(stage)
        return real(seed, stage, frame)

    monkeypatch.setattr(pipeline_reflectors, "stage_rng", counting)
    scene = short_scene(rcs=-8.0)
    skipped = simulate_scene(scene)
    assert "person_rcs" not in streams
    forced = simulate_scene(scene, the_plan=plan(scene, force=("person_rcs",)))
    assert streams.count("person_rcs") == scene.n_frames
    assert_clouds_identical(skipped.clouds, forced.clouds)


def test_rd_maps_only_when_asked_and_clouds_unchanged(monkeypatch) -> None:
    seen = []
    real = pipeline.simulator("exact")

    def recording(*args, **kwargs):
        seen.append(kwargs["keep_rd_map"])
        return real(*args, **kwargs)

    monkeypatch.setattr(pipeline_frames, "simulator", lambda fidelity: recording)
    scene = short_scene(clutter=0.02, frames=4)
    plain = simulate_scene(scene)
    assert plain.rd_maps_db is None and seen == [False] * 4
    kept = simulate_scene(scene, keep_rd_maps=True)
    assert seen[4:] == [True] * 4
    assert kept.rd_maps_db.shape == (4, scene.radar.n_samples, scene.radar.n_loops)
    assert_clouds_identical(plain.clouds, kept.clouds)


def test_skipped_elevation_is_not_computed(monkeypatch) -> None:
    calls = []
    real = angle.elevation_pairs

    def counting(radar):
        calls.append(1)
        return real(radar)

    monkeypatch.setattr(angle, "elevation_pairs", counting)
    scene = short_scene(frames=4)
    skipped = simulate_scene(scene)
    assert calls == []
    assert all(np.all(c.elevation_rad == 0) and np.all(c.z_m == 0) for c in skipped.clouds)
    forced = simulate_scene(scene, the_plan=plan(scene, force=("elevation",)))
    assert len(calls) >= 1
    # elevation changes only the angles of the points (noise on a planar scene), not detection
    for a, b in zip(skipped.clouds, forced.clouds):
        for f in ("range_m", "radial_velocity_mps", "snr_db", "source"):
            np.testing.assert_array_equal(getattr(a, f), getattr(b, f))


# ---- reproducibility, frames, static reflectors ----------------------------------------------


def test_a_frame_alone_equals_the_frame_of_a_full_run() -> None:
    scene = short_scene(clutter=0.05, frames=5)
    full = list(iter_frames(scene))
    alone = list(iter_frames(scene, frames=[3]))
    assert_clouds_identical([full[3].point_cloud], [alone[0].point_cloud])


def small_scenes() -> list[Scene]:
    return [class_scene(c, 10 + i, duration_s=1.6) for i, c in enumerate("cde")]


def test_dataset_same_seed_identical_other_seed_different(tmp_path: Path) -> None:
    scenes = small_scenes()
    a = build_dataset(scenes, seed=4, jobs=1, use_cache=False)
    b = build_dataset(scenes, seed=4, jobs=2, use_cache=False)
    c = build_dataset(scenes, seed=5, jobs=1, use_cache=False)
    for f in ("frame", *POINT_FIELDS, "source", "trajectory", "truth_xy_m", "truth_v_mps"):
        np.testing.assert_array_equal(getattr(a, f), getattr(b, f), err_msg=f)
    assert a.scene_json == b.scene_json
    assert list(a.trajectory_class) == ["c", "d", "e"]
    assert a.n_frames == 60
    # same trajectories (the scenes fix them), different radar noise, RCS and clutter
    np.testing.assert_array_equal(a.truth_xy_m, c.truth_xy_m)
    assert len(a.frame) != len(c.frame) or not np.array_equal(a.range_m, c.range_m)


def test_dataset_is_the_scenes_runs_frame_by_frame() -> None:
    """build_dataset assembles the concatenated points directly; the same data set as
    Dataset.from_frames of every scene's per-frame clouds (the straightforward assembly)."""
    scenes = small_scenes()[:2]
    for fidelity in ("exact", "fast"):
        ds = build_dataset(scenes, seed=4, fidelity=fidelity, jobs=1, use_cache=False)
        seeds = pipeline.trajectory_seeds(4, len(scenes))
        runs = [simulate_scene(s, fidelity=fidelity, seed=sd) for s, sd in zip(scenes, seeds)]
        want = Dataset.from_frames(
            clouds=[c for r in runs for c in r.clouds],
            trajectory=np.concatenate([np.full(len(r.clouds), k) for k, r in enumerate(runs)]),
            truth_t_s=np.concatenate([r.truth_t_s for r in runs]),
            truth_xy_m=np.concatenate([r.truth_xy_m for r in runs]),
            truth_v_mps=np.concatenate([r.truth_v_mps for r in runs]),
            trajectory_class=[s.trajectory_class for s in scenes],
            scene_json=ds.scene_json,
            radar_json=ds.radar_json,
            fidelity=fidelity,
            seed=4,
        )
        assert len(ds.frame) > 0
        for f in ("frame", *POINT_FIELDS, "source", "trajectory", "truth_t_s", "truth_xy_m"):
            a, b = getattr(ds, f), getattr(want, f)
            assert a.dtype == b.dtype and a.tobytes() == b.tobytes(), (fidelity, f)
    with pytest.raises(InputError, match="counts: 3 points counted, 2 given"):
        Dataset.from_cloud(
            cloud=_two_points(),
            counts=np.array([1, 2]),
            trajectory=np.zeros(2, np.int32),
            truth_t_s=np.zeros(2),
            truth_xy_m=np.zeros((2, 1, 2)),
            truth_v_mps=np.zeros((2, 1, 2)),
            trajectory_class=["a"],
            scene_json="{}",
            radar_json="{}",
        )


def _two_points():
    from core.pointcloud import PointCloud

    z = np.zeros(2)
    return PointCloud(**{f: z for f in POINT_FIELDS}, source=np.zeros(2, dtype=np.int32))


def test_dataset_is_cached_by_hash_and_saved_atomically(tmp_path: Path, monkeypatch) -> None:
    scenes = small_scenes()[:1]
    monkeypatch.setenv("RADARTUNE_CACHE", str(tmp_path))
    first = build_dataset(scenes, seed=1, jobs=1)
    key = dataset_key(scenes, fidelity="exact", seed=1)
    cached = tmp_path / "datasets" / f"{key}.npz"
    assert cached.is_file()
    assert [p.name for p in cached.parent.iterdir()] == [cached.name]  # no temporary left

    def no_simulation(*args, **kwargs):
        raise AssertionError("simulated although cached")

    monkeypatch.setattr(pipeline_cache, "_simulate_task", no_simulation)
    again = build_dataset(scenes, seed=1, jobs=1)
    np.testing.assert_array_equal(first.range_m, again.range_m)
    assert isinstance(again, Dataset)
    # the key changes with seed, fidelity and scene
    assert dataset_key(scenes, fidelity="exact", seed=2) != key
    assert dataset_key(scenes, fidelity="fast", seed=1) != key
    other = [dataclasses.replace(scenes[0], clutter_density_per_m2=0.01)]
    assert dataset_key(other, fidelity="exact", seed=1) != key


def test_static_reflectors_are_removed_by_the_chain() -> None:
    scene = Scene.from_json(ROOT / "resources/scenes/waypoints_static.json")
    assert scene.clutter_density_per_m2 == 0 and len(scene.static_reflectors) == 3
    p = plan(scene)
    assert p.runs("static_reflectors") and not p.runs("clutter")
    run = simulate_scene(scene, the_plan=p, seed=5)
    src = np.concatenate([c.source for c in run.clouds])
    # the only -1 reflectors are static: static clutter removal must take them all out
    assert not np.any(src == -1)
    assert np.mean([np.any(c.source == 0) for c in run.clouds]) > 0.9


def test_frame_scatterers_are_persons_clutter_and_static_reflectors() -> None:
    from core.pipeline import frame_scatterers

    scene = dataclasses.replace(
        Scene.from_json(ROOT / "resources/scenes/waypoints_static.json"),
        clutter_density_per_m2=0.2,
    )
    t, xy, v = scene.truth()
    for f in (0, 10):
        s = frame_scatterers(scene, f)
        person = s.source == 0
        assert person.sum() == 1
        np.testing.assert_array_equal(s.position_m[person, :2], xy[f, :1])
        np.testing.assert_array_equal(s.velocity_mps[person, :2], v[f, :1])
        assert s.rcs_dbsm[person][0] == -8.0  # fixed in the scene file
        static = (s.source == -1) & (np.abs(s.velocity_mps).sum(axis=1) == 0)
        assert static.sum() == 3
        moving_clutter = (s.source == -1) & ~static
        # same stream as in a full run: equals the clutter count iter_frames reports
        n = next(iter_frames(scene, frames=[f])).n_clutter
        assert moving_clutter.sum() == n
        assert np.all(np.abs(s.radial_velocity_mps[moving_clutter]) >= 2 * 0.4526)


def test_dataset_of_scenes_with_a_ti_cfg_radar_from_another_folder(tmp_path, monkeypatch) -> None:
    cfg = ROOT / "resources" / "radar" / "paper.cfg"
    (tmp_path / "radar").mkdir()
    (tmp_path / "radar" / "r.cfg").write_text(cfg.read_text())
    (tmp_path / "scenes").mkdir()
    scenes = []
    for i, cls in enumerate("ce"):
        doc = {
            "schema_version": 1,
            "radar": "../radar/r.cfg",
            "seed": i,
            "clutter_density_per_m2": 0.02,
            "persons": [{"trajectory": {"class": cls, "seed": i, "duration_s": 0.8}}],
        }
        path = tmp_path / "scenes" / f"s{i}.json"
        path.write_text(__import__("json").dumps(doc))
        scenes.append(Scene.from_json(path))
    (tmp_path / "elsewhere" / "deeper").mkdir(parents=True)
    monkeypatch.chdir(tmp_path / "elsewhere" / "deeper")
    ds = build_dataset(scenes, seed=0, jobs=2, use_cache=False)  # worker processes
    assert ds.n_frames == 20 and list(ds.trajectory_class) == ["c", "e"]
    assert '"../radar/r.cfg"' in ds.scene_json  # the data set keeps the scene as written
