"""Point reflectors of one frame."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from core.errors import InputError


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class Scatterers:
    """Point reflectors of one frame (SI units, radar at the origin, boresight +y).

    Attributes
    ----------
    position_m
        ``(N, 3)`` x, y, z at the frame's first chirp.
    velocity_mps
        ``(N, 3)`` constant within the frame (targets move within the frame).
    rcs_dbsm
        ``(N,)`` radar cross-section.
    source
        ``(N,)`` int32: person index >= 0, -1 clutter or static reflector.
    """

    position_m: np.ndarray
    velocity_mps: np.ndarray
    rcs_dbsm: np.ndarray
    source: np.ndarray

    def __post_init__(self) -> None:
        n = np.shape(self.rcs_dbsm)
        if len(n) != 1:
            raise InputError(f"rcs_dbsm must have shape (N,), got {np.shape(self.rcs_dbsm)}")
        for name, shape in (
            ("position_m", (n[0], 3)),
            ("velocity_mps", (n[0], 3)),
            ("source", (n[0],)),
        ):
            if np.shape(getattr(self, name)) != shape:
                raise InputError(
                    f"{name} must have shape {shape}, got {np.shape(getattr(self, name))}"
                )
        for name in ("position_m", "velocity_mps", "rcs_dbsm"):
            if not np.all(np.isfinite(getattr(self, name))):
                raise InputError(f"{name} must be finite, got {getattr(self, name)!r}")
        if n[0] and np.any(np.linalg.norm(self.position_m, axis=1) <= 0):
            raise InputError("position_m: a scatterer sits at the radar (range 0)")

    def __len__(self) -> int:
        return len(self.rcs_dbsm)

    def take(self, index: np.ndarray) -> Scatterers:
        """The scatterers at ``index`` (a boolean mask or integer indices), in that order."""
        return Scatterers(
            position_m=self.position_m[index],
            velocity_mps=self.velocity_mps[index],
            rcs_dbsm=self.rcs_dbsm[index],
            source=self.source[index],
        )

    @classmethod
    def empty(cls) -> Scatterers:
        return cls(
            position_m=np.zeros((0, 3)),
            velocity_mps=np.zeros((0, 3)),
            rcs_dbsm=np.zeros(0),
            source=np.zeros(0, dtype=np.int32),
        )

    @classmethod
    def concatenate(cls, parts: list[Scatterers]) -> Scatterers:
        if not parts:
            return cls.empty()
        return cls(
            position_m=np.concatenate([p.position_m for p in parts]).reshape(-1, 3),
            velocity_mps=np.concatenate([p.velocity_mps for p in parts]).reshape(-1, 3),
            rcs_dbsm=np.concatenate([p.rcs_dbsm for p in parts]),
            source=np.concatenate([p.source for p in parts]).astype(np.int32),
        )

    @property
    def range_m(self) -> np.ndarray:
        """``(N,)`` range at the first chirp."""
        return np.linalg.norm(self.position_m, axis=1)

    @property
    def azimuth_rad(self) -> np.ndarray:
        """``(N,)`` az = atan2(x, y)."""
        return np.arctan2(self.position_m[:, 0], self.position_m[:, 1])

    @property
    def elevation_rad(self) -> np.ndarray:
        """``(N,)`` el = atan2(z, hypot(x, y))."""
        p = self.position_m
        return np.arctan2(p[:, 2], np.hypot(p[:, 0], p[:, 1]))

    @property
    def radial_velocity_mps(self) -> np.ndarray:
        """``(N,)`` vr = p . v / |p| (positive receding)."""
        return np.einsum("ij,ij->i", self.position_m, self.velocity_mps) / self.range_m

    @property
    def is_planar(self) -> bool:
        """True when every scatterer stays at z = 0."""
        return not (np.any(self.position_m[:, 2]) or np.any(self.velocity_mps[:, 2]))
