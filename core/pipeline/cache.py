"""Data sets: scenes simulated in a process pool, cached under a hash of scenes, seeds and code."""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import multiprocessing
import os
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

from core.config import RadarConfig
from core.dataset import Dataset
from core.errors import InputError
from core.files import sources_hash
from core.pipeline.frames import ProgressCallback, simulate_scene
from core.pointcloud import PointCloud
from core.scene import Scene, paper_scenes
from core.scene.room import Room

#: Bump when the simulation changes in a way that invalidates cached data sets.
CACHE_VERSION = 1


def default_cache_dir() -> Path:
    """``$RADARTUNE_CACHE`` or ``~/.cache/radartune``."""
    env = os.environ.get("RADARTUNE_CACHE")
    return Path(env) if env else Path.home() / ".cache" / "radartune"


#: Sources whose code determines a simulated data set (their text is part of the cache key).
_SIMULATION_SOURCES = ("config.py", "kinematics.py", "pointcloud.py", "dataset.py")
_SIMULATION_PACKAGES = ("pipeline", "scene", "simulation", "processing")


@functools.cache
def code_fingerprint() -> str:
    """Hash of the source of every module that shapes a simulated data set.

    Part of the cache key, so a change to the radar chain, the scenes or this pipeline never
    serves a stale cached data set.
    """
    root = Path(__file__).resolve().parents[1]  # core/
    files = [root / name for name in _SIMULATION_SOURCES]
    for pkg in _SIMULATION_PACKAGES:
        files += sorted((root / pkg).rglob("*.py"))
    return sources_hash(files, root)


def dataset_key(
    scenes: Sequence[Scene], *, fidelity: str, seed: int, seeds: Sequence[int] | None = None
) -> str:
    """Hash of the scenes (with their resolved radar), the fidelity level, the seed(s), the code.

    The code part is :func:`code_fingerprint` (the simulation's source) and
    :data:`CACHE_VERSION`.
    """
    seeds = list(seeds) if seeds is not None else trajectory_seeds(seed, len(scenes))
    h = hashlib.sha256()
    h.update(
        f"radartune-dataset v{CACHE_VERSION} code={code_fingerprint()} "
        f"fidelity={fidelity} seed={seed} seeds={seeds}\n".encode()
    )
    for s in scenes:
        h.update(s.canonical_json().encode())
        h.update(b"\n")
    return h.hexdigest()[:32]


def trajectory_seeds(seed: int, n: int) -> list[int]:
    """Simulation seed of each of ``n`` scenes: ``SeedSequence([seed, 1]).spawn(n)``.

    (Entropy ``[seed, 1]`` keeps them apart from :func:`core.scene.paper_scenes`, which spawns
    trajectory seeds from ``SeedSequence(seed)``.)
    """
    return [int(c.generate_state(1)[0]) for c in np.random.SeedSequence([seed, 1]).spawn(n)]


def _simulate_task(args: tuple[str, int, str]) -> dict[str, Any]:
    """Worker process: one scene → plain arrays (picklable, small)."""
    scene_json, seed, fidelity = args
    scene = Scene.from_json_text(scene_json)
    run = simulate_scene(scene, fidelity=fidelity, seed=seed)
    merged = PointCloud.concatenate(list(run.clouds))
    return {
        "counts": np.array([len(c) for c in run.clouds], dtype=np.int64),
        "cloud": merged,
        "truth_t_s": run.truth_t_s,
        "truth_xy_m": run.truth_xy_m,
        "truth_v_mps": run.truth_v_mps,
        "n_clutter": run.n_clutter,
    }


def build_dataset(
    scenes: Sequence[Scene],
    *,
    fidelity: str = "exact",
    seed: int = 0,
    jobs: int | None = None,
    cache_dir: str | os.PathLike | None = None,
    progress: ProgressCallback | None = None,
    use_cache: bool = True,
    seeds: Sequence[int] | None = None,
) -> Dataset:
    """Simulate scenes into one data set, cached by hash and written atomically.

    Scene ``k`` is simulated with seed ``seeds[k]`` (default ``trajectory_seeds(seed, K)[k]``),
    one scene per task in a process pool of ``jobs`` workers (default: all cores; ``1`` runs in
    this process), so the result does not depend on ``jobs``.

    Parameters
    ----------
    seed
        Seed of the whole set (recorded in the data set).
    seeds
        Explicit per-scene simulation seeds (the paper set uses each scene's own seed, so any
        trajectory re-simulated alone with :func:`simulate_scene` gives the same frames).
    progress
        Called as ``progress(done, total)`` after each scene.
    use_cache
        Read and write ``<cache_dir>/datasets/<key>.npz`` (key: :func:`dataset_key`).
    """
    from core.simulation.levels import fidelity_level

    if not scenes:
        raise InputError("a data set needs at least one scene")
    fidelity_level(fidelity)  # InputError for an unknown level
    radar: RadarConfig = scenes[0].radar
    if any(s.radar != radar for s in scenes):
        raise InputError("all scenes of a data set must use the same radar configuration")
    cache_file = None
    if use_cache:
        root = Path(cache_dir) if cache_dir is not None else default_cache_dir()
        key = dataset_key(scenes, fidelity=fidelity, seed=seed, seeds=seeds)
        cache_file = root / "datasets" / f"{key}.npz"
        if cache_file.is_file():
            try:
                ds = Dataset.load(cache_file)
                if progress is not None:
                    progress(len(scenes), len(scenes))
                return ds
            except InputError:
                cache_file.unlink(missing_ok=True)  # corrupt cache entry: simulate again
    if seeds is None:
        seeds = trajectory_seeds(seed, len(scenes))
    elif len(seeds) != len(scenes):
        raise InputError(f"seeds: {len(seeds)} given for {len(scenes)} scenes")
    # self-contained scenes (radar as fields): workers may not see a .cfg relative to a file
    tasks = [
        (json.dumps(s.to_dict(resolve_radar=True)), sd, fidelity) for s, sd in zip(scenes, seeds)
    ]
    jobs = (os.cpu_count() or 1) if jobs is None else max(1, int(jobs))
    results: list[dict[str, Any]] = []
    if jobs == 1 or len(tasks) == 1:
        for i, t in enumerate(tasks):
            results.append(_simulate_task(t))
            if progress is not None:
                progress(i + 1, len(tasks))
    else:
        # workers fork from a single-threaded server that has imported the chain once: safe when
        # the caller has threads (GUI, FFT pools: forking a threaded process can deadlock) and
        # cheaper than "spawn", which imports the chain in every worker
        ctx = _worker_context()
        with ProcessPoolExecutor(max_workers=min(jobs, len(tasks)), mp_context=ctx) as pool:
            for i, r in enumerate(pool.map(_simulate_task, tasks)):
                results.append(r)
                if progress is not None:
                    progress(i + 1, len(tasks))
    ds = _assemble(scenes, results, fidelity=fidelity, seed=seed)
    if cache_file is not None:
        ds.save(cache_file)
    return ds


def _worker_context() -> multiprocessing.context.BaseContext:
    if "forkserver" in multiprocessing.get_all_start_methods():
        ctx = multiprocessing.get_context("forkserver")
        ctx.set_forkserver_preload(["core.pipeline", "core.simulation"])
        return ctx
    return multiprocessing.get_context("spawn")


def _assemble(
    scenes: Sequence[Scene], results: list[dict[str, Any]], *, fidelity: str, seed: int
) -> Dataset:
    n_persons = max(max(s.n_persons for s in scenes), 1)
    traj, t, xy, v = [], [], [], []
    for k, r in enumerate(results):
        f = len(r["counts"])
        traj.append(np.full(f, k, dtype=np.int32))
        t.append(r["truth_t_s"])
        pad = np.full((f, n_persons, 2), np.nan)
        pad[:, : r["truth_xy_m"].shape[1]] = r["truth_xy_m"]
        xy.append(pad)
        pad = np.full((f, n_persons, 2), np.nan)
        pad[:, : r["truth_v_mps"].shape[1]] = r["truth_v_mps"]
        v.append(pad)
    scene_json = (
        scenes[0].to_json()
        if len(scenes) == 1
        else json.dumps([s.to_dict() for s in scenes], indent=1)
    )
    return Dataset.from_cloud(
        cloud=PointCloud.concatenate([r["cloud"] for r in results]),
        counts=np.concatenate([r["counts"] for r in results]),
        trajectory=np.concatenate(traj),
        truth_t_s=np.concatenate(t),
        truth_xy_m=np.concatenate(xy),
        truth_v_mps=np.concatenate(v),
        trajectory_class=[s.trajectory_class for s in scenes],
        scene_json=scene_json,
        radar_json=json.dumps(scenes[0].radar.to_dict()),
        fidelity=fidelity,
        seed=seed,
    )


def in_room(scenes: list[Scene], room: Room | None) -> list[Scene]:
    """The scenes in ``room`` (``None``: as they are)."""
    if room is None:
        return scenes
    return [dataclasses.replace(s, room=room) for s in scenes]


def paper_dataset(
    seed: int = 0,
    n_trajectories: int = 35,
    *,
    fidelity: str = "exact",
    cache_dir: str | os.PathLike | None = None,
    jobs: int | None = None,
    progress: ProgressCallback | None = None,
    use_cache: bool = True,
    person_model: str = "point",
    n_persons: int = 1,
    room: Room | None = None,
) -> Dataset:
    """The paper's data set: :func:`core.scene.paper_scenes` simulated (cached).

    Each trajectory is simulated with its scene's own seed, so ``simulate_scene(scene)`` of any
    of the scenes reproduces its frames of the data set bit for bit. ``person_model``
    (``"point"``, ``"blob"``/``"extended"`` or ``"walking"``) changes only the person's scattering
    model; ``n_persons`` puts that many persons in every scene (:func:`core.scene.paper_scenes`).
    ``room`` puts every scene in that room (walls, furniture, sensor pose; docs/rooms.md): the
    trajectories and seeds stay the paper's, the cache key includes the room.
    """
    scenes = in_room(
        paper_scenes(seed, n_trajectories, person_model=person_model, n_persons=n_persons), room
    )
    return build_dataset(
        scenes,
        seeds=[s.seed for s in scenes],
        fidelity=fidelity,
        seed=seed,
        jobs=jobs,
        cache_dir=cache_dir,
        progress=progress,
        use_cache=use_cache,
    )


def paper_dataset_file(
    seed: int = 0,
    n_trajectories: int = 35,
    *,
    fidelity: str = "exact",
    cache_dir: str | os.PathLike | None = None,
    jobs: int | None = None,
    progress: ProgressCallback | None = None,
    person_model: str = "point",
    n_persons: int = 1,
    room: Room | None = None,
) -> Path:
    """Path of the cached paper data set (simulated first if not cached).

    For study workers, which should receive a file path rather than an in-memory data set: the
    file lives in the cache under its content key, so it is never stale. ``person_model`` as in
    :func:`paper_dataset`, and ``n_persons`` and ``room``.
    """
    scenes = in_room(
        paper_scenes(seed, n_trajectories, person_model=person_model, n_persons=n_persons), room
    )
    seeds = [s.seed for s in scenes]
    root = Path(cache_dir) if cache_dir is not None else default_cache_dir()
    key = dataset_key(scenes, fidelity=fidelity, seed=seed, seeds=seeds)
    path = root / "datasets" / f"{key}.npz"
    if not path.is_file():
        build_dataset(
            scenes,
            seeds=seeds,
            fidelity=fidelity,
            seed=seed,
            jobs=jobs,
            cache_dir=root,
            progress=progress,
        )
    return path
