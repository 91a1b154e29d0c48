"""What the GUI's range-profile and micro-Doppler views draw of one frame's range-Doppler map:
the CFAR threshold the detector applied to every cell and the Doppler spectrum at each person's
range (the app only draws them)."""

from __future__ import annotations

import numpy as np

from core.config import ProcessingSettings, RadarConfig

__all__ = ["map_views"]


def map_views(
    rd_map_db: np.ndarray,
    truth_xy_m: np.ndarray,
    radar: RadarConfig,
    settings: ProcessingSettings,
) -> tuple[np.ndarray, np.ndarray]:
    """The CFAR threshold of every cell and the Doppler spectrum at each person's range.

    Parameters
    ----------
    rd_map_db
        ``(n_range, n_doppler)`` range-Doppler map in dB.
    truth_xy_m
        ``(P, 2)`` persons' positions in m (on the floor, z = 0).
    radar, settings
        The radar and the processing settings the map was made with.

    Returns
    -------
    threshold_db
        ``(n_range, n_doppler)`` float32, the detector's combined CFAR threshold in dB.
    person_doppler_db
        ``(P, n_doppler)`` float32, the map's Doppler cut at each person's range, dB.
    """
    from core.processing import two_stage_thresholds
    from core.processing.micro_doppler import micro_doppler

    rd = np.asarray(rd_map_db)
    # the map's power back from dB: P = 10^(dB/10)
    th = two_stage_thresholds(10.0 ** (rd.astype(np.float64) / 10.0), radar, settings)
    with np.errstate(divide="ignore", invalid="ignore"):
        th_db = (10.0 * np.log10(th.combined)).astype(np.float32)
    # R = |(x, y)| (the persons walk on the floor: z = 0)
    ranges = np.hypot(truth_xy_m[:, 0], truth_xy_m[:, 1])
    cuts = [
        micro_doppler(rd[None], ranges[i : i + 1], radar).power_db[0] for i in range(len(ranges))
    ]
    person_db = np.array(cuts, dtype=np.float32).reshape(len(ranges), rd.shape[1])
    return th_db, person_db
