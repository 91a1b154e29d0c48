"""What the tracker returns: the result types shared by the readable tracker
(:mod:`core.tracking.tracker`) and the compiled kernel (:mod:`core.tracking.kernel`).

- :class:`FrameTracks` — every live track after one frame (struct of arrays)
- :class:`TrackerResult` — the output of :func:`core.tracking.run_tracker` over F frames
- :class:`TrackRecord` — every live track of every frame as the compiled kernel records it
  (preallocated, fixed number of slots per frame)
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

__all__ = ["FrameTracks", "TrackerResult", "TrackRecord"]


@dataclass(frozen=True, slots=True, kw_only=True)
class FrameTracks:
    """Every live track after one frame (struct of arrays, n tracks, state dimension d).

    Attributes
    ----------
    ids
        Track ids (n,), increasing with birth.
    state
        States (n, d): [x, y, vx, vy(, ax, ay)] in m, m/s, m/s².
    covariance
        Covariances (n, d, d).
    psi
        Existence probabilities (n,).
    confirmed
        Status (n,) bool: True confirmed, False tentative.
    gate_center_xy
        Centre of each track's gate in x–y (m), (n, 2): the predicted position (for a track
        born in this frame: its initial position).
    gate_shape_xy
        Gate ellipse in x–y (n, 2, 2): the points d with dᵀ G⁻¹ d ≤ 1, G = γ·J S_ra Jᵀ, where
        S_ra is the (r, az) block of S and J = ∂(x, y)/∂(r, az) (the gate's projection on the
        r–az plane, linearised into x–y).
    birth_frame
        Frame (index within the run) in which each track was born (n,), int64.
    n_associated
        (n,) int64 number m_τ of measurements inside each track's gate in this frame (νᵢᵀ S⁻¹ νᵢ
        ≤ γ), the measurements that took part in its (J)IPDA update; 0 for a track born in this
        frame.
    nis
        (n,) normalised innovation squared of this frame's update, ε = ν̃ᵀ S⁻¹ ν̃ with
        ν̃ = Σᵢ βᵢ νᵢ the combined (PDA) innovation over the m_τ gated measurements (βᵢ the
        association probabilities given existence, as in the state update x = x⁻ + K ν̃) and
        S = H P⁻ Hᵀ + R the predicted innovation covariance (unitless); NaN when no measurement
        was gated and for a track born in this frame.
    estimate
        Index into these arrays of the single-person estimate, or −1.
    height_m
        (n,) height of each track (m, the mean z of its latest group of points), room mode
        only (None in the paper mode).
    ghost
        (n,) bool, the track is a ghost candidate (neither confirmed nor counted), room mode
        only (None in the paper mode).
    """

    ids: np.ndarray
    state: np.ndarray
    covariance: np.ndarray
    psi: np.ndarray
    confirmed: np.ndarray
    gate_center_xy: np.ndarray
    gate_shape_xy: np.ndarray
    birth_frame: np.ndarray
    n_associated: np.ndarray
    nis: np.ndarray
    estimate: int = -1
    height_m: np.ndarray | None = None
    ghost: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.ids)


@dataclass(frozen=True, slots=True, kw_only=True)
class TrackerResult:
    """Tracker output over F frames.

    Attributes
    ----------
    estimate_xy
        Single-person estimate position (F, 2) in m, NaN where no track is confirmed.
    has_estimate
        (F,) bool, a confirmed track exists.
    estimate_id
        (F,) id of the estimate track, −1 when none.
    estimate_psi
        (F,) ψ of the estimate track, NaN when none.
    estimate_state, estimate_covariance
        (F, d) and (F, d, d) of the estimate track, NaN when none.
    confirmed_xy
        (F, max_tracks, 2) positions of all confirmed tracks, NaN-padded.
    n_tracks, n_confirmed
        (F,) live and confirmed track counts.
    frames
        Every track per frame (:class:`FrameTracks`), or None when ``keep_tracks=False``.
    """

    estimate_xy: np.ndarray
    has_estimate: np.ndarray
    estimate_id: np.ndarray
    estimate_psi: np.ndarray
    estimate_state: np.ndarray
    estimate_covariance: np.ndarray
    confirmed_xy: np.ndarray
    n_tracks: np.ndarray
    n_confirmed: np.ndarray
    frames: tuple[FrameTracks, ...] | None = field(default=None, repr=False)

    @property
    def n_frames(self) -> int:
        return len(self.has_estimate)


class TrackRecord(NamedTuple):
    """Every live track of every output frame, as the kernel recorded it (F frames, cap slots).

    A :class:`typing.NamedTuple` (immutable like the frozen dataclasses) so that the compiled
    kernel takes it as one argument and writes into its arrays.

    Slot ``t < n_tracks[f]`` of frame f holds the t-th live track in the tracker's order (the
    order of :class:`FrameTracks`); the other slots are unspecified.

    Attributes
    ----------
    n_tracks
        (F,) live tracks per frame.
    ids
        (F, cap) int64 track ids (per trajectory, increasing with birth).
    state, covariance
        (F, cap, d) and (F, cap, d, d): [x, y, vx, vy(, ax, ay)] in m, m/s, m/s².
    psi
        (F, cap) existence probability ψ.
    confirmed
        (F, cap) bool status: True confirmed, False tentative.
    birth_frame
        (F, cap) int64 frame (index within the trajectory) in which the track was born.
    gate_center_xy, gate_shape_xy
        (F, cap, 2) and (F, cap, 2, 2): the gate in x–y (see :class:`FrameTracks`), from the
        predicted covariance of the frame (for a newborn track: P₀).
    n_associated, nis
        (F, cap) int64 and float: gated measurements and NIS of the frame's update (see
        :class:`FrameTracks`).
    estimate
        (F,) slot of the single-person estimate, −1 when no track is confirmed.
    """

    n_tracks: np.ndarray
    ids: np.ndarray
    state: np.ndarray
    covariance: np.ndarray
    psi: np.ndarray
    confirmed: np.ndarray
    birth_frame: np.ndarray
    gate_center_xy: np.ndarray
    gate_shape_xy: np.ndarray
    n_associated: np.ndarray
    nis: np.ndarray
    estimate: np.ndarray

    @classmethod
    def allocate(cls, n_frames: int, cap: int, d: int) -> TrackRecord:
        """Preallocated arrays for ``n_frames`` frames of ``cap`` tracks (0, 0: recording off)."""
        return cls(
            n_tracks=np.zeros(n_frames, dtype=np.int64),
            ids=np.full((n_frames, cap), -1, dtype=np.int64),
            state=np.full((n_frames, cap, d), np.nan),
            covariance=np.full((n_frames, cap, d, d), np.nan),
            psi=np.full((n_frames, cap), np.nan),
            confirmed=np.zeros((n_frames, cap), dtype=np.bool_),
            birth_frame=np.full((n_frames, cap), -1, dtype=np.int64),
            gate_center_xy=np.full((n_frames, cap, 2), np.nan),
            gate_shape_xy=np.full((n_frames, cap, 2, 2), np.nan),
            n_associated=np.full((n_frames, cap), -1, dtype=np.int64),
            nis=np.full((n_frames, cap), np.nan),
            estimate=np.full(n_frames, -1, dtype=np.int64),
        )

    def frames(
        self, height_m: np.ndarray | None = None, ghost: np.ndarray | None = None
    ) -> tuple[FrameTracks, ...]:
        """The recorded frames as :class:`FrameTracks` (views into the arrays); ``height_m`` and
        ``ghost`` ``(F, cap)``: the room mode's per-track height and ghost flag."""
        return tuple(
            FrameTracks(
                ids=self.ids[f, :n],
                state=self.state[f, :n],
                covariance=self.covariance[f, :n],
                psi=self.psi[f, :n],
                confirmed=self.confirmed[f, :n],
                gate_center_xy=self.gate_center_xy[f, :n],
                gate_shape_xy=self.gate_shape_xy[f, :n],
                birth_frame=self.birth_frame[f, :n],
                n_associated=self.n_associated[f, :n],
                nis=self.nis[f, :n],
                estimate=int(self.estimate[f]),
                height_m=None if height_m is None else height_m[f, :n],
                ghost=None if ghost is None else ghost[f, :n],
            )
            for f, n in enumerate(self.n_tracks.tolist())
        )
