"""Point cloud: the radar chain's per-frame output, struct-of-arrays."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Ground-truth labels in ``PointCloud.source`` besides person indices (>= 0).
SOURCE_CLUTTER = -1
SOURCE_OTHER = -2
#: ``PointCloud.path_order`` of clutter and noise points (else the number of wall bounces).
PATH_CLUTTER = -1

POINT_FIELDS = (
    "range_m",
    "azimuth_rad",
    "elevation_rad",
    "radial_velocity_mps",
    "snr_db",
    "x_m",
    "y_m",
    "z_m",
)


@dataclass(frozen=True, slots=True, kw_only=True)
class PointCloud:
    """Detections of one frame; every array has shape ``(n_points,)``.

    ``source`` is the ground-truth label: the index of the person the point came from,
    ``-1`` for clutter, ``-2`` for noise or sidelobe detections that match no reflector.
    ``path_order`` (int8, optional: ``None`` where the simulation had no room): the number of
    wall bounces of the path the point came from (0 direct, 1 or 2), ``-1`` for clutter or
    noise (:data:`PATH_CLUTTER`).
    """

    range_m: np.ndarray
    azimuth_rad: np.ndarray
    elevation_rad: np.ndarray
    radial_velocity_mps: np.ndarray
    snr_db: np.ndarray
    x_m: np.ndarray
    y_m: np.ndarray
    z_m: np.ndarray
    source: np.ndarray
    path_order: np.ndarray | None = None

    def __post_init__(self) -> None:
        n = len(self.range_m)
        for name in (*POINT_FIELDS, "source"):
            if np.shape(getattr(self, name)) != (n,):
                raise ValueError(f"PointCloud.{name} must have shape ({n},)")
        if self.path_order is not None and np.shape(self.path_order) != (n,):
            raise ValueError(f"PointCloud.path_order must have shape ({n},)")

    def __len__(self) -> int:
        return len(self.range_m)

    @classmethod
    def empty(cls) -> PointCloud:
        z = np.zeros(0)
        return cls(**{f: z for f in POINT_FIELDS}, source=np.zeros(0, dtype=np.int32))

    @classmethod
    def concatenate(cls, clouds: list[PointCloud]) -> PointCloud:
        if not clouds:
            return cls.empty()
        kw = {f: np.concatenate([getattr(c, f) for c in clouds]) for f in POINT_FIELDS}
        order = None
        if any(c.path_order is not None for c in clouds):
            order = np.concatenate(
                [
                    np.full(len(c), PATH_CLUTTER, dtype=np.int8)
                    if c.path_order is None
                    else np.asarray(c.path_order, dtype=np.int8)
                    for c in clouds
                ]
            )
        return cls(
            **kw,
            source=np.concatenate([c.source for c in clouds]).astype(np.int32),
            path_order=order,
        )

    def measurements(self) -> np.ndarray:
        """Tracker measurements ``z = [r, az, vr]``, shape ``(n_points, 3)``, float64."""
        return np.column_stack((self.range_m, self.azimuth_rad, self.radial_velocity_mps)).astype(
            np.float64
        )
