"""Area of interest (AOI): the annular sector the radar watches (SPEC §2)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from core.config import (
    PAPER_MAX_AZIMUTH_DEG,
    PAPER_MAX_RANGE_M,
    PAPER_MIN_RANGE_M,
    sector_area_m2,
)
from core.errors import InputError


@dataclass(frozen=True, slots=True, kw_only=True)
class AOI:
    """Annular sector ``min_range_m <= r <= max_range_m``, ``|az| <= max_azimuth_deg`` (defaults:
    the paper's area, :data:`core.config.PAPER_MIN_RANGE_M` and its neighbours).

    Radar at the origin, boresight along +y, ``az = atan2(x, y)``.
    """

    min_range_m: float = PAPER_MIN_RANGE_M
    max_range_m: float = PAPER_MAX_RANGE_M
    max_azimuth_deg: float = PAPER_MAX_AZIMUTH_DEG

    def __post_init__(self) -> None:
        for name in ("min_range_m", "max_range_m", "max_azimuth_deg"):
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value)):
                raise InputError(f"aoi.{name} must be a finite number, got {name}={value!r}")
        if not 0 <= self.min_range_m < self.max_range_m:
            raise InputError(
                "aoi must have 0 <= min_range_m < max_range_m, got "
                f"min_range_m={self.min_range_m!r}, max_range_m={self.max_range_m!r}"
            )
        if not 0 < self.max_azimuth_deg <= 90:
            raise InputError(
                "aoi.max_azimuth_deg must be in (0, 90], "
                f"got max_azimuth_deg={self.max_azimuth_deg!r}"
            )

    @property
    def max_azimuth_rad(self) -> float:
        return math.radians(self.max_azimuth_deg)

    @property
    def area_m2(self) -> float:
        """Sector area in m² (:func:`core.config.sector_area_m2`; 104.46 m² for the paper)."""
        return sector_area_m2(self.min_range_m, self.max_range_m, self.max_azimuth_deg)

    @property
    def centre_m(self) -> np.ndarray:
        """A point in the middle of the AOI, on boresight, shape (2,) ``[x, y]``."""
        return np.array([0.0, 0.5 * (self.min_range_m + self.max_range_m)])

    def contains(self, xy_m: np.ndarray, margin_m: float = 0.0) -> np.ndarray:
        """Whether points lie inside the AOI shrunk by ``margin_m``.

        Parameters
        ----------
        xy_m
            Positions, shape ``(..., 2)`` as ``[x, y]`` in m.
        margin_m
            Distance (m) the point must keep from the range limits and the azimuth edges.

        Returns
        -------
        numpy.ndarray
            Boolean array of shape ``xy_m.shape[:-1]``.
        """
        xy = np.asarray(xy_m, dtype=np.float64)
        x, y = xy[..., 0], xy[..., 1]
        r = np.hypot(x, y)
        az = np.arctan2(x, y)
        inside = (r >= self.min_range_m + margin_m) & (r <= self.max_range_m - margin_m)
        # distance from the azimuth edge line: r * sin(az_max - |az|)
        edge = r * np.sin(self.max_azimuth_rad - np.abs(az))
        return inside & (np.abs(az) <= self.max_azimuth_rad) & (edge >= margin_m)

    def sample_uniform(self, n: int, rng: np.random.Generator) -> np.ndarray:
        """Draw ``n`` points uniformly over the AOI area.

        Range by inverse CDF of ``p(r) ∝ r``, azimuth uniform.

        Returns
        -------
        numpy.ndarray
            Positions ``[x, y]`` in m, shape ``(n, 2)``.
        """
        u = rng.random(n)
        # r = sqrt(r_min^2 + u (r_max^2 - r_min^2))
        r = np.sqrt(self.min_range_m**2 + u * (self.max_range_m**2 - self.min_range_m**2))
        az = rng.uniform(-self.max_azimuth_rad, self.max_azimuth_rad, n)
        return np.column_stack((r * np.sin(az), r * np.cos(az)))

    def to_dict(self) -> dict:
        return {
            "min_range_m": self.min_range_m,
            "max_range_m": self.max_range_m,
            "max_azimuth_deg": self.max_azimuth_deg,
        }
