"""Comparison with a recording's reference layer: TI's own tracks as the firmware reported them.

A recording without position truth can still be compared, frame by frame, with the tracker the
sensor ran: GOSPA (:func:`core.evaluation.metrics.gospa`, c = 1 m, p = 2, α = 2) between the
estimated positions and the reference tracks' positions of the frame, and the count difference
``n_estimated − n_reference``. Neither is an error against the truth: TI's tracker can be wrong
too; the figures say how far two trackers agree.

TI's positions are in the coordinates the firmware tracks in: with ``sensorPosition`` set in
the ``.cfg`` (height, tilt) they are world coordinates (y along the floor, z the height above
it), not the sensor's; compare like with like.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from core.dataset import Dataset
from core.evaluation.metrics import GOSPA_C_M, GOSPA_P, gospa

__all__ = ["ReferenceComparison", "compare_with_reference", "reference_positions"]


@dataclass(frozen=True, slots=True, kw_only=True)
class ReferenceComparison:
    """Per-frame agreement of F frames with the reference layer.

    ``gospa_m`` (F,) GOSPA in m; ``n_estimated``, ``n_reference`` (F,) the positions compared;
    ``count_difference`` (F,) ``n_estimated − n_reference``; ``c_m``, ``p`` the GOSPA cut-off
    and order.
    """

    gospa_m: np.ndarray
    n_estimated: np.ndarray
    n_reference: np.ndarray
    count_difference: np.ndarray
    c_m: float
    p: float

    @property
    def mean_gospa_m(self) -> float:
        return float(np.mean(self.gospa_m)) if len(self.gospa_m) else float("nan")

    @property
    def count_agreement(self) -> float:
        """Fraction of frames with as many estimated positions as reference tracks."""
        return float(np.mean(self.count_difference == 0)) if len(self.gospa_m) else float("nan")

    def to_dict(self) -> dict:
        return {
            "frames": len(self.gospa_m),
            "mean_gospa_m": self.mean_gospa_m,
            "count_agreement": self.count_agreement,
            "mean_abs_count_difference": float(np.mean(np.abs(self.count_difference)))
            if len(self.gospa_m)
            else float("nan"),
            "c_m": self.c_m,
            "p": self.p,
        }


def reference_positions(ds: Dataset) -> list[np.ndarray]:
    """Per frame, the ``(k, 2)`` x, y (m) of the reference tracks of that frame."""
    bounds = np.searchsorted(ds.ref_frame, np.arange(ds.n_frames + 1))
    xy = np.column_stack((ds.ref_x_m, ds.ref_y_m))
    return [xy[bounds[f] : bounds[f + 1]] for f in range(ds.n_frames)]


def compare_with_reference(
    ds: Dataset,
    est_frame: np.ndarray,
    est_xy: np.ndarray,
    *,
    c_m: float = GOSPA_C_M,
    p: float = GOSPA_P,
) -> ReferenceComparison:
    """GOSPA and count difference per frame between estimated positions and the reference layer.

    Parameters
    ----------
    ds
        A data set with a reference layer (:attr:`Dataset.has_reference`).
    est_frame
        ``(E,)`` the data set's frame index of each estimated position (e.g. each confirmed
        track row of ``radartune track --tracks``).
    est_xy
        ``(E, 2)`` the estimated x, y in m (rows with a non-finite value are left out).
    c_m, p
        GOSPA cut-off (m) and order.
    """
    if not ds.has_reference:
        raise ValueError("the data set has no reference layer (no tracks of the sensor's own)")
    est_frame = np.asarray(est_frame, dtype=np.int64).reshape(-1)
    est_xy = np.asarray(est_xy, dtype=np.float64).reshape(-1, 2)
    if len(est_frame) != len(est_xy):
        raise ValueError(
            f"est_frame and est_xy must have one row per position, got {len(est_frame)} and "
            f"{len(est_xy)}"
        )
    if len(est_frame) and (est_frame.min() < 0 or est_frame.max() >= ds.n_frames):
        raise ValueError(f"est_frame must index the {ds.n_frames} frames of the data set")
    keep = np.all(np.isfinite(est_xy), axis=1)
    est_frame, est_xy = est_frame[keep], est_xy[keep]
    order = np.argsort(est_frame, kind="stable")
    est_frame, est_xy = est_frame[order], est_xy[order]
    eb = np.searchsorted(est_frame, np.arange(ds.n_frames + 1))
    ref = reference_positions(ds)
    f = ds.n_frames
    g = np.empty(f)
    n_est = np.diff(eb)
    n_ref = np.array([len(r) for r in ref], dtype=np.int64)
    for k in range(f):
        g[k] = gospa(est_xy[eb[k] : eb[k + 1]], ref[k], c=c_m, p=p).distance_m
    return ReferenceComparison(
        gospa_m=g,
        n_estimated=n_est.astype(np.int64),
        n_reference=n_ref,
        count_difference=(n_est - n_ref).astype(np.int64),
        c_m=float(c_m),
        p=float(p),
    )
