"""A UART capture of one person walking a straight line (plus one clutter point a frame) and its
TI .cfg, for the live-link tests: the sensor emulator streams it."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from core.config import PAPER_RADAR
from core.formats.recording import points_to_cloud
from core.formats.ti_cfg import write_ti_cfg
from core.formats.ti_uart import encode_frame

#: The person: position (m) at t = 0 and velocity (m/s), in the ground plane (z = 0).
START_XY_M = np.array([-1.0, 3.0])
VELOCITY_XY_MPS = np.array([0.5, 0.8])


def person_xy(t_s: float | np.ndarray) -> np.ndarray:
    """The person's true position (m) at time ``t_s``."""
    return START_XY_M + np.multiply.outer(np.asarray(t_s), VELOCITY_XY_MPS)


def write_capture(
    folder: Path, *, n_frames: int = 60, frame_period_s: float = 0.05, seed: int = 3
) -> tuple[bytes, Path]:
    """The capture's bytes (SDK 3 float points, frame numbers 1..n) and the path of its .cfg."""
    rng = np.random.default_rng(seed)
    radar = replace(PAPER_RADAR, frame_period_s=frame_period_s)
    packets = []
    for k in range(n_frames):
        p = person_xy(k * frame_period_s)
        xy = p + rng.normal(0.0, 0.03, (2, 2))  # two points on the person
        clutter = np.array([rng.uniform(-3, 3), rng.uniform(1, 8)])
        xy = np.vstack([xy, clutter])
        r = np.hypot(xy[:, 0], xy[:, 1])
        # v_r = (x vx + y vy) / r for the person's points, 0 for the clutter
        v = np.where(np.arange(3) < 2, xy @ VELOCITY_XY_MPS / r, 0.0)
        cloud, _ = points_to_cloud(xy[:, 0], xy[:, 1], np.zeros(3), v, np.full(3, 15.0))
        packets.append(encode_frame(cloud, k + 1, fmt="sdk3"))
    cfg = folder / "live.cfg"
    write_ti_cfg(radar, cfg)
    return b"".join(packets), cfg
