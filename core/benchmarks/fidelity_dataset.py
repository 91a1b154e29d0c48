"""End-to-end cost of a data set per fidelity level: ``build_dataset(jobs=1)``.

``python -m core.benchmarks.fidelity_dataset [n_trajectories] [repeats]`` simulates the first
``n_trajectories`` of ``paper_scenes(0)`` at every level into a data set (one process, no cache:
truth, reflectors and generators of every frame, the simulator, the point clouds and the
assembled :class:`core.dataset.Dataset`), levels interleaved per repeat, after a warm-up on one
trajectory; reports the best process CPU time of the repeats as frames per second and the
ratio to ``exact`` measured in the same run (the machine is shared: compare ratios).
"""

from __future__ import annotations

import json
import sys
import time


def run(n_trajectories: int = 5, repeats: int = 2) -> dict:
    """Frames per second of ``build_dataset(jobs=1, use_cache=False)`` per level."""
    from core.pipeline import build_dataset
    from core.scene import paper_scenes
    from core.simulation import LEVELS

    scenes = paper_scenes(0, n_trajectories)
    frames = sum(s.n_frames for s in scenes)
    levels = list(LEVELS)
    for name in levels:  # compilation, tables, false-alarm pool
        build_dataset(scenes[:1], fidelity=name, jobs=1, use_cache=False)
    best = {name: float("inf") for name in levels}
    for _ in range(repeats):
        for name in levels:
            t0 = time.process_time()
            build_dataset(scenes, fidelity=name, jobs=1, use_cache=False)
            best[name] = min(best[name], time.process_time() - t0)
    return {
        "n_trajectories": n_trajectories,
        "frames": frames,
        "levels": {
            name: {
                "cpu_s": best[name],
                "ms_per_frame": 1e3 * best[name] / frames,
                "frames_per_s": frames / best[name],
                "speed_up": best["exact"] / best[name],
            }
            for name in levels
        },
    }


def main(argv: list[str] | None = None) -> None:
    argv = sys.argv[1:] if argv is None else argv
    n = int(argv[0]) if argv else 5
    repeats = int(argv[1]) if len(argv) > 1 else 2
    result = run(n, repeats)
    print(json.dumps(result, indent=1))
    for name, r in result["levels"].items():
        print(
            f"{name:12s} {r['ms_per_frame']:7.3f} ms/frame  {r['frames_per_s']:8.0f} frames/s  "
            f"{r['speed_up']:6.1f}x exact"
        )


if __name__ == "__main__":
    main()
