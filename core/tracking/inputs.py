"""What the tracker takes in, validated once for both engines (the readable
:mod:`core.tracking.tracker` and the compiled :mod:`core.tracking.kernel`).

- :func:`packed_frames` — the one validator of measurement frames: a sequence of (m_f, 3) arrays
  or a pair (z, frame_offsets) → one (P, 3) float64 array and its (F + 1,) offsets
- :func:`frame_slices` — the same frames as a list of (m_f, 3) arrays
- :class:`TrackerConstants` — matrices and thresholds derived once from the parameters and the
  frame period (which it validates)
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from core.errors import InputError
from core.tracking import gating, initiation
from core.tracking.models import process_noise, transition_matrix
from core.tracking.params import TrackerParams

__all__ = ["Frames", "packed_frames", "frame_slices", "TrackerConstants"]

#: Measurements per frame ``[r (m), az (rad), vr (m/s)]``: a sequence of (m_f, 3) arrays, or a
#: pair ``(z (P, 3), frame_offsets (F + 1,))``.
Frames = Sequence[np.ndarray] | tuple[np.ndarray, np.ndarray]


def _is_packed(frames) -> bool:
    return isinstance(frames, tuple) and len(frames) == 2 and np.ndim(frames[1]) == 1


def packed_frames(frames: Frames) -> tuple[np.ndarray, np.ndarray]:
    """Validate measurement frames and pack them into one array.

    Parameters
    ----------
    frames
        A sequence of (m_f, 3) arrays ``[r (m), az (rad), vr (m/s)]``, or a pair
        ``(z (P, 3), frame_offsets (F + 1,))`` with offsets rising from 0 to P.

    Returns
    -------
    z, frame_offsets
        (P, 3) float64 measurements sorted by frame and (F + 1,) int64 offsets.

    Raises
    ------
    InputError
        Offsets that do not rise from 0 to P, a frame that is not (m_f, 3), a measurement that
        is NaN or infinite.
    """
    if _is_packed(frames):
        z = np.asarray(frames[0], dtype=np.float64).reshape(-1, 3)
        f_off = np.asarray(frames[1], dtype=np.int64)
        if len(f_off) == 0 or f_off[0] != 0 or f_off[-1] != len(z) or np.any(np.diff(f_off) < 0):
            raise InputError(
                f"frame_offsets must rise from 0 to the {len(z)} measurements, "
                f"got {f_off[:3].tolist()}…{f_off[-2:].tolist()}"
            )
    else:
        zs = []
        for f, zf in enumerate(frames):
            zf = np.asarray(zf, dtype=np.float64)
            if zf.size % 3:
                raise InputError(f"measurements of frame {f} must be (m, 3), got {zf.shape}")
            zs.append(zf.reshape(-1, 3))
        counts = np.array([len(zf) for zf in zs], dtype=np.int64)
        z = np.concatenate(zs) if zs else np.zeros((0, 3))
        f_off = np.concatenate(([0], np.cumsum(counts))).astype(np.int64)
    if not np.all(np.isfinite(z)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(z), axis=1))[0])
        frame = int(np.searchsorted(f_off, bad, side="right") - 1)
        raise InputError(f"measurement {bad} (frame {frame}) contains NaN or Inf")
    return z, f_off


def frame_slices(frames: Frames) -> list[np.ndarray]:
    """The validated frames (:func:`packed_frames`) as a list of (m_f, 3) float64 arrays."""
    z, f_off = packed_frames(frames)
    return [z[f_off[f] : f_off[f + 1]] for f in range(len(f_off) - 1)]


@dataclass(frozen=True, slots=True, kw_only=True)
class TrackerConstants:
    """Matrices and thresholds derived once from the parameters and the frame period.

    ``F`` (d, d) transition, ``Q`` (d, d) process noise, ``R`` (3, 3) measurement noise, ``P0``
    (d, d) initial covariance, ``gamma`` the 3-D gate threshold, ``gamma2`` the 2-D merge
    threshold (also of the JIPDA tracker's velocity test), ``pdpg`` = P_D·P_G.
    """

    F: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    P0: np.ndarray
    gamma: float
    gamma2: float
    pdpg: float

    @classmethod
    def build(cls, params: TrackerParams, frame_period_s: float) -> TrackerConstants:
        if not (np.isfinite(frame_period_s) and frame_period_s > 0):
            raise InputError(f"frame_period_s must be positive, got {frame_period_s=}")
        return cls(
            F=transition_matrix(params.model, frame_period_s),
            Q=process_noise(params.model, frame_period_s, params.q_coeff),
            # R = diag(r11², r22², r33²)
            R=np.diag([params.r11**2, params.r22**2, params.r33**2]),
            P0=initiation.initial_covariance(params.p0),
            gamma=gating.gate_threshold(params.p_g, 3),
            gamma2=gating.gate_threshold(params.p_g, 2),
            pdpg=params.p_d * params.p_g,
        )
