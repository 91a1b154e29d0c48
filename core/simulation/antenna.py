"""Antenna gain, eq. (1): one seeded random realisation per simulated radar."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from core.config import RadarConfig

#: Azimuth grid of eq. (1): -90 deg ... 90 deg in 1 deg steps.
GRID_DEG = np.arange(-90.0, 91.0, 1.0)
#: Shape constant of eq. (1), per degree (0.01309 ~ 0.75 pi / 180).
SHAPE_PER_DEG = 0.01309
#: Variance of the random term of eq. (1), dB².
GAIN_VARIANCE_DB2 = 0.09


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class AntennaGain:
    """TX and RX antenna gain ``Gt(theta) = Gr(theta)`` over azimuth, eq. (1).

    Attributes
    ----------
    grid_deg
        ``(n_grid,)`` azimuths in degrees, increasing.
    table_db
        ``(n_grid,)`` gain in dB at ``grid_deg``; its maximum is ``Gmax``.
    """

    grid_deg: np.ndarray
    table_db: np.ndarray

    @classmethod
    def draw(cls, radar: RadarConfig, rng: np.random.Generator) -> AntennaGain:
        """One realisation of eq. (1).

        ``G(theta) = 20 log10(cos(0.01309 theta) + 0.01) + N(0, 0.09)`` (theta in degrees),
        ``Gt = Gr = Gmax + G(theta) - max G``.
        """
        # G(theta) = 20 log10(cos(0.01309 theta) + 0.01) + N(0, 0.09)
        g = 20 * np.log10(np.cos(SHAPE_PER_DEG * GRID_DEG) + 0.01) + rng.normal(
            0.0, np.sqrt(GAIN_VARIANCE_DB2), GRID_DEG.size
        )
        # Gt = Gr = Gmax + G - max G
        return cls(grid_deg=GRID_DEG.copy(), table_db=radar.antenna_gain_db + g - g.max())

    @classmethod
    def ideal(cls, radar: RadarConfig) -> AntennaGain:
        """Constant gain ``Gt = Gr = Gmax`` at every azimuth (for tests and link budgets)."""
        return cls(grid_deg=GRID_DEG.copy(), table_db=np.full(GRID_DEG.size, radar.antenna_gain_db))

    def gain_db(self, azimuth_rad: np.ndarray) -> np.ndarray:
        """Gain in dB at ``azimuth_rad`` (any shape), linear interpolation in the table."""
        return np.interp(np.degrees(azimuth_rad), self.grid_deg, self.table_db)
