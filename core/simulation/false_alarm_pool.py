"""The exact chain's own false alarms, measured once per radar and settings: the pool the
``measurement`` level resamples (:mod:`core.simulation.measurement`, step 4).

:func:`chain_false_alarms` runs :data:`FALSE_ALARM_FRAMES` seeded noise-only frames through the
exact chain and keeps every point (Doppler index, reported SNR, azimuth, fractional range bin)
with the rate per frame; the pool is cached in memory and on disk, keyed by the radar, the
settings and a hash of the chain's sources.
"""

from __future__ import annotations

import functools
import hashlib
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from core.config import ProcessingSettings, RadarConfig
from core.errors import InputError
from core.files import read_npz, sources_hash, write_npz_atomic
from core.pointcloud import PointCloud
from core.simulation.antenna import AntennaGain
from core.simulation.scatterers import Scatterers

__all__ = ["FALSE_ALARM_FRAMES", "FalseAlarms", "chain_false_alarms"]

#: Noise-only exact frames used to measure the chain's own false alarms.
FALSE_ALARM_FRAMES = 300


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class FalseAlarms:
    """The chain's own false alarms, measured on noise-only exact frames.

    Attributes
    ----------
    rate_per_frame
        Mean number of false-alarm points per frame.
    doppler_index, snr_db, azimuth_rad, range_frac
        ``(n_pool,)`` the measured points (Doppler index, reported SNR, azimuth, fractional
        part of the range bin), resampled as a pool.
    n_frames
        Frames measured.
    """

    rate_per_frame: float
    doppler_index: np.ndarray
    snr_db: np.ndarray
    azimuth_rad: np.ndarray
    range_frac: np.ndarray
    n_frames: int


@functools.lru_cache(maxsize=16)
def chain_false_alarms(
    radar: RadarConfig, settings: ProcessingSettings, n_frames: int = FALSE_ALARM_FRAMES
) -> FalseAlarms:
    """Run ``n_frames`` noise-only frames through the exact chain (seeded) and pool the points.

    The pool is cached on disk (``<cache>/false_alarms/<key>.npz`` in the data-set cache
    folder; key: radar, settings, ``n_frames`` and the chain's source fingerprint), so a
    worker process loads it instead of spending ~1 s of exact frames; a missing or unreadable
    file is simply recomputed.
    """
    path = _false_alarm_cache_path(radar, settings, n_frames)
    try:
        z = read_npz(path, what="false-alarm cache")
        return FalseAlarms(
            rate_per_frame=float(z["rate_per_frame"]),
            doppler_index=z["doppler_index"].astype(np.int64),
            snr_db=z["snr_db"].astype(np.float64),
            azimuth_rad=z["azimuth_rad"].astype(np.float64),
            range_frac=z["range_frac"].astype(np.float64),
            n_frames=int(z["n_frames"]),
        )
    except (KeyError, ValueError, TypeError):  # InputError is a ValueError
        pass
    fa = _measure_false_alarms(radar, settings, n_frames)
    arrays = {
        "rate_per_frame": np.asarray(fa.rate_per_frame),
        "doppler_index": fa.doppler_index,
        "snr_db": fa.snr_db,
        "azimuth_rad": fa.azimuth_rad,
        "range_frac": fa.range_frac,
        "n_frames": np.asarray(fa.n_frames),
    }
    try:
        write_npz_atomic(path, arrays, compressed=False)  # a reader never sees half a file
    except (OSError, InputError):
        pass  # a read-only cache only costs the recomputation
    return fa


@functools.cache
def _chain_fingerprint() -> str:
    """Hash of the sources the exact chain's false alarms depend on (config, simulation,
    processing), so a changed chain never serves a stale pool."""
    root = Path(__file__).resolve().parent.parent
    files = [root / "config.py", root / "pointcloud.py"]
    for pkg in ("simulation", "processing"):
        files += sorted((root / pkg).rglob("*.py"))
    return sources_hash(files, root)


def _false_alarm_cache_path(radar: RadarConfig, settings: ProcessingSettings, n_frames: int):
    """``<cache>/false_alarms/<key>.npz``; ``<cache>``: ``$RADARTUNE_CACHE`` or
    ``~/.cache/radartune`` (the data-set cache's folder, see ``core.pipeline``)."""
    env = os.environ.get("RADARTUNE_CACHE")
    root = Path(env) if env else Path.home() / ".cache" / "radartune"
    key = hashlib.sha256(
        f"{radar!r}\n{settings!r}\n{n_frames}\n{_chain_fingerprint()}".encode()
    ).hexdigest()[:32]
    return root / "false_alarms" / f"{key}.npz"


def _measure_false_alarms(
    radar: RadarConfig, settings: ProcessingSettings, n_frames: int
) -> FalseAlarms:
    """The pool itself: ``n_frames`` seeded noise-only frames of the exact chain."""
    from core.simulation.frame import simulate_frame

    rng = np.random.default_rng(20_261_121)
    ant = AntennaGain.ideal(radar)
    empty = Scatterers.empty()
    clouds, dets = [], []
    for _ in range(n_frames):
        out = simulate_frame(radar, empty, rng, antenna=ant, settings=settings)
        clouds.append(out.point_cloud)
        dets.append(out.detections)
    pc = PointCloud.concatenate(clouds)
    det = np.concatenate(dets) if dets else np.zeros((0, 2), dtype=np.int64)
    r_bin = pc.range_m / radar.range_resolution_m
    return FalseAlarms(
        rate_per_frame=len(pc) / n_frames,
        doppler_index=det[:, 1].astype(np.int64),
        snr_db=pc.snr_db,
        azimuth_rad=pc.azimuth_rad,
        range_frac=r_bin - np.round(r_bin),
        n_frames=n_frames,
    )
