"""Clutter reflectors (SPEC §2): a Poisson number per frame, uniform over the AOI.

Each clutter reflector is a point whose post-processing SNR is uniform in 15–30 dB (its RCS is
found later with ``core.simulation.rcs_for_snr_db``, which needs the antenna realisation) and
whose radial velocity is uniform over ``±v_max`` with ``|v| >= 2`` velocity bins, so that static
clutter removal keeps it. Clutter goes through the whole radar chain; it is never added to the
point cloud directly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from core.config import RadarConfig
from core.scene.aoi import AOI

CLUTTER_SNR_DB = (15.0, 30.0)
MIN_CLUTTER_SPEED_BINS = 2.0


@dataclass(frozen=True, slots=True, kw_only=True)
class ClutterDraw:
    """Clutter reflectors of one frame.

    Attributes
    ----------
    position_m
        ``[x, y]``, shape ``(N, 2)``, m (z = 0).
    radial_velocity_mps
        Shape ``(N,)``, m/s; the velocity vector points along the line of sight.
    snr_db
        Target post-processing SNR per virtual channel, shape ``(N,)``, dB.
    """

    position_m: np.ndarray
    radial_velocity_mps: np.ndarray
    snr_db: np.ndarray

    def __len__(self) -> int:
        return len(self.snr_db)

    @property
    def velocity_mps(self) -> np.ndarray:
        """``v = vr · p/|p|``, shape ``(N, 2)``, m/s."""
        r = np.hypot(self.position_m[:, 0], self.position_m[:, 1])
        return self.position_m / r[:, None] * self.radial_velocity_mps[:, None]


def expected_clutter_count(aoi: AOI, density_per_m2: float) -> float:
    """Mean number of clutter reflectors per frame, ``λ · area(AOI)``."""
    return density_per_m2 * aoi.area_m2


def draw_clutter(
    aoi: AOI, density_per_m2: float, radar: RadarConfig, rng: np.random.Generator
) -> ClutterDraw:
    """Draw the clutter reflectors of one frame.

    Parameters
    ----------
    aoi
        Where the reflectors are placed (uniform over its area).
    density_per_m2
        λ, m⁻²; the count is Poisson with mean ``λ · area(AOI)``.
    radar
        Gives ``v_max`` and the velocity bin ``Δv``.
    rng
        The only source of randomness.
    """
    n = int(rng.poisson(expected_clutter_count(aoi, density_per_m2)))
    pos = aoi.sample_uniform(n, rng)
    v_max = radar.max_velocity_mps
    v_min = MIN_CLUTTER_SPEED_BINS * radar.velocity_resolution_mps
    # |v| uniform in [v_min, v_max), sign uniform: uniform over ±v_max without the centre
    speed = rng.uniform(v_min, v_max, n)
    sign = np.where(rng.random(n) < 0.5, -1.0, 1.0)
    snr = rng.uniform(*CLUTTER_SNR_DB, n)
    return ClutterDraw(position_m=pos, radial_velocity_mps=sign * speed, snr_db=snr)
