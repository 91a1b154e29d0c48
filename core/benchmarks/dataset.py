"""``radartune bench dataset``: cost of a simulated frame and of data-set generation.

Figures, each against a reference measured in the same run (the machine is shared and noisy):

- ``frame``: seconds per frame (best of 4 repeats, alternating order) of ``simulate_scene`` with the
  plan (no elevation on a planar scene, no range-Doppler map kept) against the same scene with
  every optional stage forced on (elevation and range-Doppler maps, what a naive simulator
  would always do); ratio.
- ``parallel``: ``build_dataset`` of K scenes with one process against all cores (no cache);
  speed-up, and whether both data sets are identical.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from typing import TypeVar

import numpy as np

from core.pipeline import build_dataset, plan, simulate_scene
from core.pointcloud import POINT_FIELDS
from core.scene import class_scene

T = TypeVar("T")


def _time(fn: Callable[[], T]) -> tuple[float, T]:
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def run(quick: bool = False) -> dict:
    n_frames = 25 if quick else 125
    scene = class_scene("c", 3, seed=7, duration_s=n_frames * 0.08)
    simulate_scene(class_scene("c", 3, duration_s=0.8))  # warm up imports and caches
    planned = plan(scene)
    everything = plan(scene, force=("elevation", "keep_rd_map"))
    # best of repeats: the machine is shared
    t_plan = t_all = float("inf")
    for i in range(4):  # alternate which goes first: the first of a pair runs slower here
        for which in ("plan", "all") if i % 2 == 0 else ("all", "plan"):
            if which == "plan":
                t_plan = min(t_plan, _time(lambda: simulate_scene(scene, the_plan=planned))[0])
            else:
                t_all = min(t_all, _time(lambda: simulate_scene(scene, the_plan=everything))[0])

    k, dur = (4, 1.6) if quick else (10, 4.0)
    scenes = [class_scene("cde"[i % 3], 100 + i, duration_s=dur) for i in range(k)]
    jobs = os.cpu_count() or 1
    t1, ds1 = _time(lambda: build_dataset(scenes, seed=1, jobs=1, use_cache=False))
    tk, dsk = _time(lambda: build_dataset(scenes, seed=1, jobs=jobs, use_cache=False))
    identical = all(
        np.array_equal(getattr(ds1, f), getattr(dsk, f), equal_nan=True)
        for f in ("frame", *POINT_FIELDS, "source", "truth_xy_m")
    )
    return {
        "frame": {
            "frames": scene.n_frames,
            "planned_s_per_frame": t_plan / scene.n_frames,
            "all_stages_s_per_frame": t_all / scene.n_frames,
            "ratio_all_over_planned": t_all / t_plan,
        },
        "parallel": {
            "scenes": k,
            "frames": int(ds1.n_frames),
            "jobs": jobs,
            "one_process_s": t1,
            "all_cores_s": tk,
            "speedup": t1 / tk,
            "identical": identical,
        },
    }


def summary(result: dict) -> str:
    f, p = result["frame"], result["parallel"]
    return (
        f"frame: planned {1e3 * f['planned_s_per_frame']:.1f} ms/frame, all stages forced "
        f"{1e3 * f['all_stages_s_per_frame']:.1f} ms/frame "
        f"(ratio {f['ratio_all_over_planned']:.2f}, {f['frames']} frames)\n"
        f"dataset: {p['scenes']} scenes / {p['frames']} frames: "
        f"1 process {p['one_process_s']:.1f} s, "
        f"{p['jobs']} processes {p['all_cores_s']:.1f} s (speed-up {p['speedup']:.2f}, "
        f"identical: {p['identical']})"
    )
