"""DCA1000 captures through the exact chain's processing half, against the exact chain itself.

The paper's class-c scene (one walking person, clutter at 0.02 m⁻²) is written as a DCA1000
capture (:func:`core.pipeline.capture.write_capture`). Then, in the same process and interleaved in
blocks of :data:`BLOCK` frames so that both see the same machine load:

- the exact chain: :func:`core.simulation.simulate_frame` on each frame's inputs (synthesis,
  noise, FFTs, CFAR, angles, points);
- the capture: each frame read from the ``.bin`` (streamed), decoded to the radar cube and run
  through :func:`core.simulation.frame.process_cube` (the same processing half).

The goal: the capture at no less than the exact chain's frames/s. Also timed: the whole
:func:`~core.pipeline.capture.dataset_from_capture` call (cfg, size check, every frame, data set).

``python -m core.benchmarks.import_adc [--quick] [--out-dir DIR]`` writes ``import_adc.json``.
"""

from __future__ import annotations

import argparse
import itertools
import os
import tempfile
import time
from pathlib import Path

#: Frames per interleaved block.
BLOCK = 10
SCENE_FILE = Path(__file__).resolve().parents[2] / "resources" / "scenes" / "paper_class_c.json"


def run(quick: bool = False) -> dict:
    """Time both paths on the same frames; frames/s (wall and CPU) and their ratio."""
    from core.pipeline.capture import (
        dataset_from_capture,
        iter_capture_clouds,
        open_capture_with_cfg,
        write_capture,
    )
    from core.pipeline.frames import frame_inputs
    from core.pipeline.plan import plan, processing_settings
    from core.scene import Scene
    from core.simulation import simulate_frame

    scene = Scene.from_json(SCENE_FILE)
    n_frames = 40 if quick else scene.n_frames
    radar = scene.radar
    settings = processing_settings(scene)
    p = plan(scene, fidelity="exact")
    inputs = list(itertools.islice(frame_inputs(scene, p, scene.seed), n_frames))
    with tempfile.TemporaryDirectory(prefix="radartune-bench-adc-") as tmp:
        bin_path, cfg_path = write_capture(scene, Path(tmp) / "paper_class_c.bin")
        radar_cfg, capture = open_capture_with_cfg(bin_path, cfg_path)
        # warm up both (numba, FFT plans, threshold caches)
        fi = inputs[0]
        simulate_frame(radar, fi.scatterers, fi.rng, antenna=fi.antenna, settings=settings)
        next(iter_capture_clouds(radar_cfg, capture, settings=settings, elevation=p.elevation))

        clouds = iter_capture_clouds(radar_cfg, capture, settings=settings, elevation=p.elevation)
        wall = {"exact": 0.0, "capture": 0.0}
        cpu = {"exact": 0.0, "capture": 0.0}
        points = {"exact": 0, "capture": 0}
        for start in range(0, n_frames, BLOCK):
            block = inputs[start : start + BLOCK]
            t0, c0 = time.perf_counter(), time.process_time()
            for fi in block:
                out = simulate_frame(
                    radar,
                    fi.scatterers,
                    fi.rng,
                    antenna=fi.antenna,
                    settings=settings,
                    elevation=p.elevation,
                )
                points["exact"] += len(out.point_cloud)
            wall["exact"] += time.perf_counter() - t0
            cpu["exact"] += time.process_time() - c0
            t0, c0 = time.perf_counter(), time.process_time()
            for cloud in itertools.islice(clouds, len(block)):
                points["capture"] += len(cloud)
            wall["capture"] += time.perf_counter() - t0
            cpu["capture"] += time.process_time() - c0
        t0 = time.perf_counter()
        ds = dataset_from_capture(bin_path, cfg_path, settings=settings, elevation=p.elevation)
        whole_s = time.perf_counter() - t0
        frame_mb = capture.layout.frame_bytes / 1e6
    fps = {k: n_frames / v for k, v in wall.items()}
    fps_cpu = {k: n_frames / v for k, v in cpu.items()}
    return {
        "scene": SCENE_FILE.name,
        "frames": n_frames,
        "frame_bytes": capture.layout.frame_bytes,
        "exact_fps": fps["exact"],
        "capture_fps": fps["capture"],
        "capture_over_exact": fps["capture"] / fps["exact"],
        "exact_fps_cpu": fps_cpu["exact"],
        "capture_fps_cpu": fps_cpu["capture"],
        "capture_over_exact_cpu": fps_cpu["capture"] / fps_cpu["exact"],
        "capture_mb_per_s": fps["capture"] * frame_mb,
        "points_per_frame": {k: v / n_frames for k, v in points.items()},
        "dataset_from_capture_fps": ds.n_frames / whole_s,
        "goal": {"capture_over_exact": 1.0},
        "load_average_1min": os.getloadavg()[0] if hasattr(os, "getloadavg") else None,
    }


def main(argv: list[str] | None = None) -> int:
    from core.files import write_json_atomic

    parser = argparse.ArgumentParser(prog="python -m core.benchmarks.import_adc")
    parser.add_argument("--quick", action="store_true", help="40 frames instead of the scene's")
    parser.add_argument("--out-dir", default="bench/results", help="default: %(default)s")
    args = parser.parse_args(argv)
    result = run(args.quick)
    path = write_json_atomic(Path(args.out_dir) / "import_adc.json", result)
    print(
        f"exact chain {result['exact_fps']:.0f} frames/s, DCA1000 capture through its processing "
        f"half {result['capture_fps']:.0f} frames/s ({result['capture_over_exact']:.2f}x; CPU "
        f"{result['capture_over_exact_cpu']:.2f}x), {result['capture_mb_per_s']:.0f} MB/s -> {path}"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
