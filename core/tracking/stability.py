"""Numerical-stability sweep over the corners of the paper's search space (eq. 15).

Every corner (each optimised parameter at its lower or upper bound) tracks the same synthetic
paper-like scene (:data:`core.tracking.synthetic.PAPER_LIKE`: 2.1 clutter points a frame,
0.5–10 m, ±60°, one person walking a circle) for 300 frames with the compiled kernel in checking
mode: after every frame every live track must have a finite state, ψ ∈ [0, 1] and a symmetric
positive-definite covariance (Cholesky succeeds), and no output may be NaN or Inf except the
documented "no estimate" NaN.

CV has 12 optimised parameters: all 2¹² = 4096 corners. CA has 14 (2¹⁴ = 16 384 corners); a
seeded sample without replacement is run (2048 by default).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from core.dataset import Dataset
from core.tracking.batch import dataset_frame_period_s
from core.tracking.kernel import track_frames
from core.tracking.params import TrackerParams
from core.tracking.space import p0_names, search_space
from core.tracking.synthetic import (
    PAPER_LIKE,
    circling_paths,
    crossing_paths,
    people_dataset,
    synthetic_dataset,
)

__all__ = [
    "corner_names",
    "corner_params",
    "all_corners",
    "stability_scene",
    "multi_person_scenes",
    "CornerReport",
    "sweep",
    "condition_number",
]


def corner_names(model: str) -> list[str]:
    """Names of the optimised parameters of a model, in search-space table order."""
    return [p.name for p in search_space(model)]


def corner_params(model: str, bits: tuple[int, ...], **fixed) -> TrackerParams:
    """The corner selected by ``bits`` (0 lower, 1 upper bound, in :func:`corner_names` order)."""
    values = {p.name: (p.low, p.high)[b] for p, b in zip(search_space(model), bits)}
    p0 = tuple(values.pop(name) for name in p0_names(model))
    return TrackerParams(model=model, p0=p0, **values, **fixed)


def all_corners(model: str, n_sample: int | None = None, seed: int = 0) -> list[tuple[int, ...]]:
    """All corners of a model, or a seeded sample of ``n_sample`` distinct ones."""
    k = len(corner_names(model))
    if n_sample is None or n_sample >= 2**k:
        return list(itertools.product((0, 1), repeat=k))
    rng = np.random.default_rng(seed)
    picks = rng.choice(2**k, size=n_sample, replace=False)
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
) -> CornerReport:
    """Run every corner on the scene; count unhealthy tracks and non-finite outputs."""
    ds = dataset if dataset is not None else stability_scene()
    period = dataset_frame_period_s(ds)
    z = ds.measurements()
    f_off, t_off = ds.frame_offsets, ds.trajectory_offsets
    sel = np.arange(ds.n_trajectories)
    bad_corners, bad_frames, nonfinite, max_tracks = 0, 0, 0, 0
    failures = []
    for bits in corners:
        p = corner_params(model, bits)
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
