"""Scene → frames → point clouds → data set: the only orchestration of the radar chain.

One module per job:

- :mod:`core.pipeline.plan`: which stages run for a scene and a consumer, and why
  (``radartune simulate --explain``); the processing settings and the tracker's clutter density
  of a scene;
- :mod:`core.pipeline.streams`: the per-stage random streams,
  ``SeedSequence(seed, spawn_key=(stage, frame))``, so skipping a stage (or running one more)
  leaves every other stage's numbers bit for bit unchanged, and any frame can be simulated alone;
- :mod:`core.pipeline.reflectors`: the reflectors of every frame (persons, bodies, clutter,
  static reflectors);
- :mod:`core.pipeline.frames`: a scene simulated frame by frame (the GUI) or in one batch call;
- :mod:`core.pipeline.cache`: data sets, simulated in a process pool and cached by content key;
- :mod:`core.pipeline.views`: what the app's range-profile and micro-Doppler views draw of a
  frame's map.
"""

from core.pipeline.cache import (
    CACHE_VERSION,
    build_dataset,
    code_fingerprint,
    dataset_key,
    default_cache_dir,
    paper_dataset,
    paper_dataset_file,
    trajectory_seeds,
)
from core.pipeline.frames import (
    FrameResult,
    ProgressCallback,
    SceneRun,
    iter_frames,
    simulate_scene,
)
from core.pipeline.plan import (
    CONSUMERS,
    Plan,
    Stage,
    plan,
    processing_settings,
    scene_clutter_density,
    simulator,
)
from core.pipeline.reflectors import Reflectors, frame_scatterers
from core.pipeline.streams import stage_rng

__all__ = [
    "CACHE_VERSION",
    "CONSUMERS",
    "FrameResult",
    "Plan",
    "ProgressCallback",
    "Reflectors",
    "SceneRun",
    "Stage",
    "build_dataset",
    "code_fingerprint",
    "dataset_key",
    "default_cache_dir",
    "frame_scatterers",
    "iter_frames",
    "paper_dataset",
    "paper_dataset_file",
    "plan",
    "processing_settings",
    "scene_clutter_density",
    "simulate_scene",
    "simulator",
    "stage_rng",
    "trajectory_seeds",
]
