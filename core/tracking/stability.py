"""Numerical-stability sweep over the corners of the paper's search space (eq. 15).

Every corner (each optimised parameter at its lower or upper bound) tracks the same synthetic
paper-like scene (:data:`core.tracking.synthetic.PAPER_LIKE`: 2.1 clutter points a frame,
0.5–10 m, ±60°, one person walking a circle) for 300 frames with the compiled kernel in checking
mode: after every frame every live track must have a finite state, ψ ∈ [0, 1] and a symmetric
positive-definite covariance (Cholesky succeeds), and no output may be NaN or Inf except the
documented "no estimate" NaN.

CV has 12 optimised parameters: all 2¹² = 4096 corners. CA has 14 (2¹⁴ = 16 384 corners); a
seeded sample without replacement is run (2048 by default). The room mode adds its 12 rows
(2²⁴ CV corners): a seeded sample runs on the room scenes (:func:`room_scenes`).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from core.dataset import Dataset
from core.tracking.batch import dataset_frame_period_s, room_points_of
from core.tracking.kernel import track_frames
from core.tracking.params import TrackerParams
from core.tracking.room import track_room_arrays
from core.tracking.space import p0_names, search_space
from core.tracking.synthetic import (
    PAPER_LIKE,
    circling_paths,
    crossing_paths,
    people_dataset,
    room_dataset,
    synthetic_dataset,
)

__all__ = [
    "corner_names",
    "corner_params",
    "all_corners",
    "stability_scene",
    "multi_person_scenes",
    "room_scenes",
    "CornerReport",
    "sweep",
    "condition_number",
]


def corner_names(model: str, mode: str = "paper") -> list[str]:
    """Names of the optimised parameters of a model and mode, in search-space table order."""
    return [p.name for p in search_space(model, mode)]


def corner_params(model: str, bits: tuple[int, ...], mode: str = "paper", **fixed) -> TrackerParams:
    """The corner selected by ``bits`` (0 lower, 1 upper bound, in :func:`corner_names` order)."""
    values = {p.name: (p.low, p.high)[b] for p, b in zip(search_space(model, mode), bits)}
    p0 = tuple(values.pop(name) for name in p0_names(model))
    if mode != "paper":
        fixed = {"mode": mode, **fixed}
    return TrackerParams(model=model, p0=p0, **values, **fixed)


def all_corners(
    model: str, n_sample: int | None = None, seed: int = 0, mode: str = "paper"
) -> list[tuple[int, ...]]:
    """All corners of a model and mode, or a seeded sample of ``n_sample`` distinct ones."""
    k = len(corner_names(model, mode))
    if n_sample is None or n_sample >= 2**k:
        return list(itertools.product((0, 1), repeat=k))
    rng = np.random.default_rng(seed)
    picks = rng.choice(2**k, size=n_sample, replace=False) if k < 63 else None
    if picks is None:  # pragma: no cover  (no table has 63 rows)
        raise ValueError(f"{k} parameters: too many corners to sample")
    return [tuple(int(b) for b in np.binary_repr(int(p), width=k)) for p in sorted(picks)]


def stability_scene(n_frames: int = 300, seed: int = 0) -> Dataset:
    """The synthetic paper-like scene: one person walking a circle (r 3–7 m), 300 frames."""
    dt = PAPER_LIKE.frame_period_s
    speed, radius, centre = 1.2, 2.0, np.array([0.0, 5.0])
    phi = speed / radius * dt * np.arange(n_frames)
    pos = centre + radius * np.column_stack((np.cos(phi), np.sin(phi)))
    vel = speed * np.column_stack((-np.sin(phi), np.cos(phi)))
    return synthetic_dataset(seed, paths=[(pos, vel)])


def multi_person_scenes(n_frames: int = 300, seed: int = 0) -> dict[str, Dataset]:
    """Paper-like scenes of several people whose tracks share measurements: two crossing at
    90°, three crossing at 60° from each other, four circling a room (they keep crossing)."""
    two = crossing_paths(2, n_frames, spread_rad=math.pi / 2)
    three = crossing_paths(3, n_frames)
    four = circling_paths(4, n_frames)
    return {
        "2 people crossing": people_dataset(*two, seed=seed),
        "3 people crossing": people_dataset(*three, seed=seed + 1),
        "4 people circling": people_dataset(*four, seed=seed + 2),
    }


def room_scenes(n_frames: int = 300, seed: int = 0) -> dict[str, Dataset]:
    """Room scenes (:func:`core.tracking.synthetic.room_dataset`): one person walking a circle
    and four people circling (they keep crossing), 25 points a person, 10 moving and 40
    zero-Doppler clutter points a frame (150 points a frame with four people)."""
    one = circling_paths(1, n_frames)
    four = circling_paths(4, n_frames)
    return {
        "room, 1 person circling": room_dataset(*one, seed=seed),
        "room, 4 people circling": room_dataset(*four, seed=seed + 1),
    }


def _room_health(rec) -> tuple[int, int]:
    """(unhealthy track-frames, live tracks at most) of a room run's record: a live track must
    have a finite state, ψ in [0, 1] and a symmetric positive-definite covariance."""
    bad = 0
    for f, n in enumerate(rec.n_tracks.tolist()):
        for k in range(n):
            x, P, psi = rec.state[f, k], rec.covariance[f, k], rec.psi[f, k]
            ok = bool(np.all(np.isfinite(x)) and np.all(np.isfinite(P)) and 0 <= psi <= 1)
            if ok and not np.allclose(P, P.T, rtol=1e-9, atol=1e-12):
                ok = False
            if ok:
                try:
                    np.linalg.cholesky(P)
                except np.linalg.LinAlgError:
                    ok = False
            bad += not ok
    return bad, int(rec.n_tracks.max(initial=0))


@dataclass(frozen=True, slots=True, kw_only=True)
class CornerReport:
    """Result of a sweep: counts of corners and frames with problems."""

    model: str
    n_corners: int
    n_frames: int
    bad_corners: int
    bad_track_frames: int
    nonfinite_outputs: int
    max_tracks_seen: int
    failures: tuple[tuple[int, ...], ...]

    @property
    def ok(self) -> bool:
        return self.bad_corners == 0


def sweep(
    model: str,
    corners: list[tuple[int, ...]],
    dataset: Dataset | None = None,
    mode: str = "paper",
) -> CornerReport:
    """Run every corner on the scene; count unhealthy tracks and non-finite outputs (room
    mode: every live track of every frame checked from the run's record)."""
    ds = dataset if dataset is not None else stability_scene()
    period = dataset_frame_period_s(ds)
    z = ds.measurements()
    f_off, t_off = ds.frame_offsets, ds.trajectory_offsets
    sel = np.arange(ds.n_trajectories)
    bad_corners, bad_frames, nonfinite, max_tracks = 0, 0, 0, 0
    failures = []
    pts = room_points_of(ds) if mode == "room" else None
    for bits in corners:
        p = corner_params(model, bits, mode)
        if mode == "room":
            out = track_room_arrays(pts, f_off, t_off, sel, p, period, record=True)
            est_xy, has, est_psi, conf_xy, n_conf, n_tr, est_x, est_P, rec = out[:9]
            n_bad = np.array([_room_health(rec)[0]])
        else:
            out = track_frames(z, f_off, t_off, sel, p, period, check=True)
            est_xy, has, est_psi, conf_xy, n_conf, n_tr, est_x, est_P, n_bad = out
        # outputs must be finite wherever an estimate exists
        nf = int(
            np.sum(~np.isfinite(est_xy[has]))
            + np.sum(~np.isfinite(est_psi[has]))
            + np.sum(~np.isfinite(est_x[has]))
            + np.sum(~np.isfinite(est_P[has]))
        )
        valid = np.arange(conf_xy.shape[1])[None, :] < n_conf[:, None]
        nf += int(np.sum(~np.isfinite(conf_xy[valid])))
        bad = int(np.sum(n_bad))
        max_tracks = max(max_tracks, int(n_tr.max(initial=0)))
        if bad or nf:
            bad_corners += 1
            failures.append(bits)
        bad_frames += bad
        nonfinite += nf
    return CornerReport(
        model=model,
        n_corners=len(corners),
        n_frames=ds.n_frames,
        bad_corners=bad_corners,
        bad_track_frames=bad_frames,
        nonfinite_outputs=nonfinite,
        max_tracks_seen=max_tracks,
        failures=tuple(failures[:20]),
    )


def condition_number(P: np.ndarray) -> float:
    """Spectral condition number of a symmetric positive-definite matrix (inf if singular)."""
    w = np.linalg.eigvalsh(P)
    return float(w[-1] / w[0]) if w[0] > 0 else math.inf
