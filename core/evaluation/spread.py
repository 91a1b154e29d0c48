"""Spread of the measurements around the truth: how far the person-labelled points of a data set
lie from the person (a property of the radar chain, independent of the tracker)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from core.dataset import Dataset

__all__ = ["PointSpread", "person_point_spread"]


@dataclass(frozen=True, slots=True, kw_only=True)
class PointSpread:
    """Measurement spread of the person-labelled points of a data set (SI units).

    ``rms_position_m``: RMS of |p − x_gt| (x-y plane) over the points whose ``source`` is a
    person; ``median_position_m``, ``p90_position_m`` its percentiles; ``rms_range_m`` and
    ``rms_cross_range_m`` its components along and across the line of sight;
    ``rms_radial_velocity_mps``: RMS of v_r − v_gt·r̂; ``points_per_frame``: mean number of
    person points per frame with at least one.
    """

    n_points: int
    points_per_frame: float
    rms_position_m: float
    median_position_m: float
    p90_position_m: float
    rms_range_m: float
    rms_cross_range_m: float
    rms_radial_velocity_mps: float

    def to_dict(self) -> dict[str, float]:
        return {k: getattr(self, k) for k in self.__slots__}


def person_point_spread(dataset: Dataset) -> PointSpread:
    """Error of the person-labelled points against the person's true position and velocity.

    Parameters
    ----------
    dataset
        A simulated data set; a point with ``source = i >= 0`` came from person ``i``.

    Returns
    -------
    PointSpread
        Spread over all person points of all frames (m, m/s).
    """
    sel = np.flatnonzero(dataset.source >= 0)
    if sel.size == 0:
        raise ValueError("the data set has no person-labelled points")
    f = dataset.frame[sel]
    person = dataset.source[sel]
    truth = dataset.truth_xy_m[f, person]  # (P, 2) m
    v_truth = dataset.truth_v_mps[f, person]  # (P, 2) m/s
    d = np.stack([dataset.x_m[sel], dataset.y_m[sel]], axis=1) - truth  # (P, 2) m
    # r̂ = x_gt / |x_gt|: line of sight to the true position
    u = truth / np.linalg.norm(truth, axis=1, keepdims=True)
    e_range = np.sum(d * u, axis=1)
    e_cross = d[:, 0] * u[:, 1] - d[:, 1] * u[:, 0]
    # v_r,gt = v_gt · r̂
    e_vr = dataset.radial_velocity_mps[sel] - np.sum(v_truth * u, axis=1)
    e = np.hypot(d[:, 0], d[:, 1])
    _, per_frame = np.unique(f, return_counts=True)
    return PointSpread(
        n_points=int(sel.size),
        points_per_frame=float(per_frame.mean()),
        rms_position_m=float(np.sqrt(np.mean(e**2))),
        median_position_m=float(np.median(e)),
        p90_position_m=float(np.percentile(e, 90)),
        rms_range_m=float(np.sqrt(np.mean(e_range**2))),
        rms_cross_range_m=float(np.sqrt(np.mean(e_cross**2))),
        rms_radial_velocity_mps=float(np.sqrt(np.mean(e_vr**2))),
    )
