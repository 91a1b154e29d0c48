"""``radartune bench sim``, room case: the walking body in a four-wall room with multipath
against the same walk in the open field, in the same run (docs/rooms.md).

The scene is ``resources/scenes/room_walker.json`` (a 6 x 8 m room whose walls take the shipped
default loss, :data:`core.scene.room.DEFAULT_REFLECTION_DB`, the sensor 2 m up on a wall tilted
15 deg down, one walking body) with the paper's clutter (0.02 m^-2);
the open field is the same scene without walls and sensor pose. The exact chain runs both
interleaved in blocks of 10 frames (frames/s and their ratio); the fast level runs the room's
frames in batches between the exact passes. The reflector stage (image method included) is
timed apart. The ghosts' proxies (:data:`core.simulation.multipath.GHOST_GROUPS`) are checked
against one proxy per segment on the same frames and noise: ghost points per frame and the
fraction of the person's points that are ghosts.
"""

from __future__ import annotations

import dataclasses
import os
import time
from pathlib import Path

import numpy as np

from core.config import PAPER_CLUTTER_DENSITY_PER_M2

SCENE = Path(__file__).resolve().parents[2] / "resources" / "scenes" / "room_walker.json"
BLOCK = 10


def _scenes():
    from core.scene import Scene

    room = Scene.from_json(SCENE)
    room = dataclasses.replace(room, clutter_density_per_m2=PAPER_CLUTTER_DENSITY_PER_M2)
    return room, dataclasses.replace(room, room=None)


def _frames(scene, antenna):
    from core.pipeline.plan import plan, processing_settings
    from core.pipeline.reflectors import Reflectors

    settings = processing_settings(scene)
    t0 = time.perf_counter()
    frames, _ = Reflectors.build(scene, plan(scene), scene.seed, antenna, settings).frames()
    return frames, settings, (time.perf_counter() - t0) / len(frames)


def run_case(quick: bool = False) -> dict:
    """Frames/s of the exact chain in the room and in the open field, the fast level in the
    room, the reflector stage's ms per frame, and the proxies' check (see the module)."""
    from core.simulation import AntennaGain, simulate_frame
    from core.simulation import multipath as mp
    from core.simulation.fast import simulate_frames_fast
    from core.simulation.multipath import split_labels

    room, open_field = _scenes()
    antenna = AntennaGain.draw(room.radar, np.random.default_rng(7))
    walls, settings, refl_room = _frames(room, antenna)
    field, _, refl_open = _frames(open_field, antenna)
    n = min(len(walls), 40 if quick else len(walls))
    radar = room.radar
    for fr in (walls[0], field[0]):  # compile and warm up
        simulate_frame(radar, fr, np.random.default_rng(0), antenna=antenna, settings=settings)
    simulate_frames_fast(
        radar, walls[:2], [np.random.default_rng(0)] * 2, antenna=antenna, settings=settings
    )
    reps = 1 if quick else 3
    spent = {"room": [0.0, 0.0], "open": [0.0, 0.0]}  # wall clock, CPU
    t_fast = c_fast = 0.0
    for _ in range(reps):
        rngs = [np.random.default_rng(100 + i) for i in range(n)]
        t0, c0 = time.perf_counter(), time.process_time()
        simulate_frames_fast(radar, walls[:n], rngs, antenna=antenna, settings=settings)
        t_fast += time.perf_counter() - t0
        c_fast += time.process_time() - c0
        for b in range(0, n, BLOCK):
            for name, frames in (("room", walls), ("open", field)):
                t0, c0 = time.perf_counter(), time.process_time()
                for i, f in enumerate(frames[b : min(b + BLOCK, n)]):
                    simulate_frame(
                        radar, f, np.random.default_rng(b + i), antenna=antenna, settings=settings
                    )
                spent[name][0] += time.perf_counter() - t0
                spent[name][1] += time.process_time() - c0
    fps = {k: reps * n / v[0] for k, v in spent.items()}
    fps_cpu = {k: reps * n / v[1] for k, v in spent.items()}
    fast_fps, fast_fps_cpu = reps * n / t_fast, reps * n / c_fast

    def ghosts(frames) -> tuple[float, float]:
        counts, person = [], []
        for i, f in enumerate(frames[:n]):
            pc = simulate_frame(
                radar, f, np.random.default_rng(500 + i), antenna=antenna, settings=settings
            ).point_cloud
            src, order = split_labels(pc.source)
            counts.append(int(np.sum((src >= 0) & (order > 0))))
            person.append(int(np.sum(src >= 0)))
        return float(np.mean(counts)), float(np.sum(counts) / max(1, np.sum(person)))

    proxies = ghosts(walls)
    keep = mp.GHOST_GROUPS
    try:
        mp.GHOST_GROUPS = 10_000  # every segment its own proxy
        every, _, _ = _frames(room, antenna)
        segments = ghosts(every)
    finally:
        mp.GHOST_GROUPS = keep
    return {
        "scene": SCENE.name,
        "wall_reflection_db": sorted({w.reflection_db for w in room.room.walls}),
        "frames": n * reps,
        "scatterers_per_frame_room": float(np.mean([len(f) for f in walls[:n]])),
        "scatterers_per_frame_open": float(np.mean([len(f) for f in field[:n]])),
        "exact_fps_room": fps["room"],
        "exact_fps_open": fps["open"],
        "exact_room_cost_over_open": fps["open"] / fps["room"],
        "exact_fps_cpu_room": fps_cpu["room"],
        "exact_fps_cpu_open": fps_cpu["open"],
        "exact_room_cost_over_open_cpu": fps_cpu["open"] / fps_cpu["room"],
        "fast_fps_room": fast_fps,
        "fast_over_exact_room": fast_fps / fps["room"],
        "fast_over_exact_room_cpu": fast_fps_cpu / fps_cpu["room"],
        "load_average_1min": os.getloadavg()[0],
        "reflectors_ms_per_frame_room": 1e3 * refl_room,
        "reflectors_ms_per_frame_open": 1e3 * refl_open,
        "ghost_points_per_frame": {"proxies": proxies[0], "every_segment": segments[0]},
        "ghost_fraction_of_person_points": {"proxies": proxies[1], "every_segment": segments[1]},
        "scatterers_per_frame_every_segment": float(np.mean([len(f) for f in every[:n]])),
        "ghost_groups": keep,
        "goal": {"exact_fps_room": 150.0, "exact_room_cost_over_open": 2.0, "fast_over_exact": 10},
    }


def summary_line(room: dict) -> str:
    """The room case in one line of ``radartune bench sim``'s summary."""
    return (
        f"  room ({room['scene']}, walls {room.get('wall_reflection_db', '?')} dB, "
        f"{room['scatterers_per_frame_room']:.1f} scatterers/frame "
        f"against {room['scatterers_per_frame_open']:.1f} in the open field): exact "
        f"{room['exact_fps_room']:.0f} frames/s, open field {room['exact_fps_open']:.0f} in the "
        f"same run (room cost {room['exact_room_cost_over_open']:.2f}x; CPU "
        f"{room.get('exact_room_cost_over_open_cpu', float('nan')):.2f}x; goal >= 150 frames/s, "
        f"<= 2x); fast {room['fast_over_exact_room']:.1f}x exact (CPU "
        f"{room.get('fast_over_exact_room_cpu', float('nan')):.1f}x; goal >= 10x); reflectors "
        f"{room['reflectors_ms_per_frame_room']:.2f} ms/frame; ghost points/frame "
        f"{room['ghost_points_per_frame']['proxies']:.1f} with {room['ghost_groups']} proxies, "
        f"{room['ghost_points_per_frame']['every_segment']:.1f} with every segment"
    )
