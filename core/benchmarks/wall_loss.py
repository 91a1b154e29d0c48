"""The walls' reflection loss fitted to the ghost fraction of a real walking recording.

A wall's bounce loss (``reflection_db``) decides how strong the ghosts of a person are, and so
how many of a chain's points are ghosts. The recordings have no labels, so the ghost share is
measured by one estimator on real and simulated clouds alike (:func:`ghost_fraction`): per frame
the *person* is the moving points (|v| > 0.05 m/s) within 1 m (x-y) of their median, and a
*ghost* is a moving point more than 1 m further from the radar (horizontal range) than the
person's centre, within 10 degrees of its bearing; the fraction is ghosts over moving points,
summed over frames.

The fit (:func:`fit`): a walker in a room (:func:`fit_scene`: the route and the room read off the
training recording's point map, see docs/rooms.md) is simulated through the ``oob`` chain at
each loss of a grid; the simulated fraction ``g(L)`` grows with ``L``; the fitted loss is where
the curve, linearly interpolated, crosses the recording's fraction, and its interval where it
crosses the ends of the recording's 95 % block-bootstrap interval (blocks of 50 frames). The
other recordings are then held out: their fractions against the fitted loss's.
"""

from __future__ import annotations

import math

import numpy as np

MOVING_MPS = 0.05
#: A ghost lies this much further (horizontal range) than the person ...
GHOST_BEHIND_M = 1.0
#: ... within this many degrees of its bearing.
GHOST_BEARING_DEG = 10.0
#: Reflection losses (dB) the fit simulates; ``-inf`` (no bounce) gives the estimator's floor.
LOSS_GRID_DB = (
    -3.0,
    -6.0,
    -9.0,
    -12.0,
    -15.0,
    -18.0,
    -21.0,
    -24.0,
    -27.0,
    -30.0,
    -33.0,
    -36.0,
    -40.0,
)
BOOTSTRAP_BLOCK = 50
BOOTSTRAP_DRAWS = 400


def frame_ghosts(x, y, v) -> tuple[int, int]:
    """``(ghost points, moving points)`` of one frame (arrays of its points; :mod:`wall_loss`
    docstring for the estimator); ``(0, 0)`` without moving points."""
    x, y, v = (np.asarray(a, dtype=np.float64) for a in (x, y, v))
    moving = np.abs(v) > MOVING_MPS
    if not moving.any():
        return 0, 0
    cx, cy = np.median(x[moving]), np.median(y[moving])
    bearing = np.arctan2(x, y) - math.atan2(cx, cy)
    bearing = (bearing + np.pi) % (2 * np.pi) - np.pi
    ghost = (
        moving
        & (np.hypot(x, y) > math.hypot(cx, cy) + GHOST_BEHIND_M)
        & (np.abs(bearing) <= math.radians(GHOST_BEARING_DEG))
    )
    return int(ghost.sum()), int(moving.sum())


def ghost_fraction(frames: list[dict]) -> float | None:
    """Ghost points over moving points, summed over frames (dicts of arrays ``x``, ``y``,
    ``v``); None without moving points."""
    g = np.array([frame_ghosts(f["x"], f["y"], f["v"]) for f in frames], dtype=np.int64)
    if not len(g) or g[:, 1].sum() == 0:
        return None
    return float(g[:, 0].sum() / g[:, 1].sum())


def bootstrap_interval(frames: list[dict], seed: int = 0) -> tuple[float, float]:
    """The 95 % interval of :func:`ghost_fraction` by a moving-block bootstrap over frames
    (blocks of :data:`BOOTSTRAP_BLOCK` consecutive frames, :data:`BOOTSTRAP_DRAWS` draws)."""
    g = np.array([frame_ghosts(f["x"], f["y"], f["v"]) for f in frames], dtype=np.float64)
    n = len(g)
    block = min(BOOTSTRAP_BLOCK, n)
    starts = n - block + 1
    k = math.ceil(n / block)
    rng = np.random.default_rng(seed)
    cs = np.vstack((np.zeros((1, 2)), np.cumsum(g, axis=0)))
    s = rng.integers(0, starts, size=(BOOTSTRAP_DRAWS, k))
    sums = (cs[s + block] - cs[s]).sum(axis=1)  # (draws, 2)
    frac = sums[:, 0] / np.maximum(sums[:, 1], 1)
    lo, hi = np.percentile(frac, [2.5, 97.5])
    return float(lo), float(hi)


def fit_scene(cfg: str, reflection_db: float, seed: int):
    """The training recording's room, as far as its points show it: a person walking back and
    forth between (2, 2) and (-2, 6) m at 1.1 m/s (its direct points' diagonal), walls at
    x = +-3 m (its side ghosts at |x| of 4-4.5 m are a person near x = +-2 mirrored there) and
    y = 8 m (its farthest points), the radar on the wall y = 0, 1 m above the floor, not
    tilted (its moving points' height band, -0.4 ... 0.9 m about the radar, is a body seen
    level from about 1 m); the oob radar of ``cfg``."""
    from core.scene import Scene

    walls = [
        ([-3.0, 0.0], [3.0, 0.0]),
        ([3.0, 0.0], [3.0, 8.0]),
        ([3.0, 8.0], [-3.0, 8.0]),
        ([-3.0, 8.0], [-3.0, 0.0]),
    ]
    data = {
        "schema_version": 1,
        "radar": cfg,
        "seed": seed,
        "clutter_density_per_m2": 0.0,
        "aoi": {"min_range_m": 0.5, "max_range_m": 8.0, "max_azimuth_deg": 60.0},
        "walls": [
            {
                "from_m": a,
                "to_m": b,
                "reflection_db": None if reflection_db == -math.inf else reflection_db,
            }
            for a, b in walls
        ],
        "sensor": {"height_m": 1.0, "tilt_deg": 0.0},
        "persons": [
            {
                "model": "walking",
                "trajectory": {
                    "waypoints": [
                        [2.0, 2.0, 1.1],
                        [-2.0, 6.0, 1.1],
                        [2.0, 2.0, 1.1],
                        [-2.0, 6.0, 1.1],
                    ]
                },
            }
        ],
    }
    return Scene.from_dict(data, source="wall-loss fit walker")


def simulated_frames(scene, cfg: str, frames: int | None = None) -> list[dict]:
    """The scene through the chain of ``cfg``: per frame x, y (room), z (room), v, snr and the
    path order."""
    from core.benchmarks.clouds import cloud_frames
    from core.formats.ti_cfg import read_ti_chain
    from core.pipeline import plan

    p = plan(scene, chain=read_ti_chain(cfg))
    n = scene.n_frames if frames is None else min(frames, scene.n_frames)
    return cloud_frames(scene, p, n, path_order=True)


def curve(cfg: str, seeds: tuple[int, ...], frames: int | None = None) -> dict:
    """The simulated ghost fraction (and the share of points with a bounce) at each loss of
    :data:`LOSS_GRID_DB` and without bounces."""
    rows = []
    for loss in (*LOSS_GRID_DB, -math.inf):
        fr: list[dict] = []
        for seed in seeds:
            fr += simulated_frames(fit_scene(cfg, loss, seed), cfg, frames)
        order = np.concatenate([f["path_order"] for f in fr])
        rows.append(
            {
                "reflection_db": None if loss == -math.inf else loss,
                "ghost_fraction": ghost_fraction(fr),
                "bounce_share": float(np.mean(order > 0)) if len(order) else None,
                "points_per_frame": float(len(order) / len(fr)),
                "frames": len(fr),
            }
        )
    return {"rows": rows}


def crossing(losses: np.ndarray, fractions: np.ndarray, target: float) -> float | None:
    """The loss (dB) where the piecewise-linear curve ``fractions(losses)`` first reaches
    ``target`` coming from the lossy end; None if the curve never does (the target lies below
    the floor or above the top)."""
    order = np.argsort(losses)  # most lossy first
    ls, fs = losses[order], fractions[order]
    for k in range(len(ls) - 1):
        f0, f1 = fs[k], fs[k + 1]
        if (f0 - target) * (f1 - target) <= 0 and f0 != f1:
            return float(ls[k] + (target - f0) * (ls[k + 1] - ls[k]) / (f1 - f0))
    return None


def fit(curve_rows: list[dict], target: float, interval: tuple[float, float]) -> dict:
    """The fitted loss and its interval from the simulated curve and the recording's fraction
    with its interval."""
    rows = [r for r in curve_rows if r["reflection_db"] is not None]
    losses = np.array([r["reflection_db"] for r in rows])
    fr = np.array([r["ghost_fraction"] for r in rows])
    floor = next(r["ghost_fraction"] for r in curve_rows if r["reflection_db"] is None)
    return {
        "reflection_db": crossing(losses, fr, target),
        "interval_db": [crossing(losses, fr, interval[0]), crossing(losses, fr, interval[1])],
        "target": target,
        "target_interval": list(interval),
        "floor_without_bounces": floor,
    }
