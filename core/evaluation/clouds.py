"""Point-cloud statistics of people: points per person per frame, spread and Doppler smear.

A *person-frame* is one person in one frame. Each person point belongs to one person-frame;
each person-frame has a reference position (the truth in a simulated data set, a rule's centre
in a real recording) whose range puts it in a range band. Per band (default 1-3, 3-6, 6-10 m):

- points per person-frame: mean, median, fraction of person-frames with none;
- spatial spread in x and y about the person-frame's cloud centroid: the pooled within-frame
  standard deviation

  .. math:: s_x^2 = \\frac{\\sum_j \\sum_i (x_{ij} - \\bar x_j)^2}{\\sum_j (n_j - 1)}

  over the person-frames ``j`` with ``n_j >= 2`` points (unbiased per frame, frames weighted by
  their points);
- spread about the reference: the RMS of ``x - x_ref`` and ``y - y_ref`` over all points (bias
  included), and the RMS distance of the cloud centroid from the reference;
- Doppler smear: the pooled within-frame standard deviation of the radial velocity (as above);
- SNR: the median over the points (dB), where the data has it.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from core.dataset import Dataset

#: Range bands of the statistics (m), ``[low, high)`` on the reference's range.
RANGE_BANDS_M = ((1.0, 3.0), (3.0, 6.0), (6.0, 10.0))


@dataclass(frozen=True, slots=True, kw_only=True)
class PersonPoints:
    """Person points assigned to person-frames.

    Attributes
    ----------
    owner
        Shape (P,), int: index of each point's person-frame, in ``0 .. N-1``.
    x_m, y_m, radial_velocity_mps
        Shape (P,): position (m, radar at the origin, ``y`` along boresight) and radial
        velocity (m/s) of each point.
    snr_db
        Shape (P,) or ``None`` when the data has no SNR.
    reference_xy_m
        Shape (N, 2): reference position of each person-frame (m), finite.
    reference_is_truth
        The reference is the ground truth (``False``: a rule's estimate, e.g. a real recording).
    """

    owner: np.ndarray
    x_m: np.ndarray
    y_m: np.ndarray
    radial_velocity_mps: np.ndarray
    snr_db: np.ndarray | None
    reference_xy_m: np.ndarray
    reference_is_truth: bool

    def __post_init__(self) -> None:
        p = np.shape(self.owner)
        names = (
            "x_m",
            "y_m",
            "radial_velocity_mps",
            *(("snr_db",) if self.snr_db is not None else ()),
        )
        for name in names:
            if np.shape(getattr(self, name)) != p:
                raise ValueError(f"PersonPoints.{name} must have the shape {p} of owner")
        ref = np.shape(self.reference_xy_m)
        if len(ref) != 2 or ref[1] != 2 or not np.all(np.isfinite(self.reference_xy_m)):
            raise ValueError(f"PersonPoints.reference_xy_m must be finite (N, 2), got {ref}")
        if len(self.owner) and not (0 <= np.min(self.owner) and np.max(self.owner) < ref[0]):
            raise ValueError(f"PersonPoints.owner must index the {ref[0]} person-frames")

    @property
    def n_person_frames(self) -> int:
        return len(self.reference_xy_m)


@dataclass(frozen=True, slots=True, kw_only=True)
class BandStatistics:
    """Cloud statistics of the person-frames whose reference range is in ``[low_m, high_m)``.

    Figures that need points the band does not have are NaN (e.g. ``spread_x_m`` with no
    person-frame of two points; ``rms_x_truth_m`` when the reference is not the truth).
    """

    low_m: float
    high_m: float
    person_frames: int
    points_mean: float
    points_median: float
    empty_fraction: float
    spread_x_m: float
    spread_y_m: float
    rms_x_ref_m: float
    rms_y_ref_m: float
    centroid_error_m: float
    doppler_std_mps: float
    snr_median_db: float
    reference_is_truth: bool

    def to_dict(self) -> dict:
        """JSON-ready (NaN becomes ``None``)."""
        return {
            k: (None if isinstance(v, float) and np.isnan(v) else v)
            for k, v in asdict(self).items()
        }


def cloud_statistics(
    points: PersonPoints, bands: tuple[tuple[float, float], ...] = RANGE_BANDS_M
) -> list[BandStatistics]:
    """Statistics of the person clouds per range band (see the module docstring).

    Parameters
    ----------
    points
        The person points and their person-frames.
    bands
        ``(low, high)`` range bands (m) of the person-frames' reference range.

    Returns
    -------
    list of BandStatistics
        One per band, in order.
    """
    n = points.n_person_frames
    owner = np.asarray(points.owner, dtype=np.int64)
    count = np.bincount(owner, minlength=n).astype(np.float64)
    ref = np.asarray(points.reference_xy_m, dtype=np.float64)
    ref_range = np.hypot(ref[:, 0], ref[:, 1])

    def centred(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Each point's deviation from its person-frame's mean, and the means (N,)."""
        mean = np.bincount(owner, weights=v, minlength=n) / np.maximum(count, 1)
        return v - mean[owner], mean

    dx, cx = centred(np.asarray(points.x_m, dtype=np.float64))
    dy, cy = centred(np.asarray(points.y_m, dtype=np.float64))
    dv, _ = centred(np.asarray(points.radial_velocity_mps, dtype=np.float64))
    ex = points.x_m - ref[owner, 0]
    ey = points.y_m - ref[owner, 1]

    out = []
    for lo, hi in bands:
        frames = (ref_range >= lo) & (ref_range < hi)
        in_band = frames[owner]
        pooled = in_band & (count[owner] >= 2)
        # s² = Σ_j Σ_i (x_ij − x̄_j)² / Σ_j (n_j − 1),  over person-frames with n_j ≥ 2
        dof = float(np.sum(count[frames & (count >= 2)] - 1))

        def pooled_std(d: np.ndarray, sel: np.ndarray = pooled, dof: float = dof) -> float:
            return float(np.sqrt(np.sum(d[sel] ** 2) / dof)) if dof > 0 else np.nan

        def rms(e: np.ndarray, sel: np.ndarray = in_band) -> float:
            return float(np.sqrt(np.mean(e[sel] ** 2))) if sel.any() else np.nan

        seen = frames & (count > 0)
        centroid_err = (
            float(np.sqrt(np.mean((cx[seen] - ref[seen, 0]) ** 2 + (cy[seen] - ref[seen, 1]) ** 2)))
            if seen.any()
            else np.nan
        )
        snr = np.nan
        if points.snr_db is not None and in_band.any():
            snr = float(np.median(points.snr_db[in_band]))
        c = count[frames]
        out.append(
            BandStatistics(
                low_m=float(lo),
                high_m=float(hi),
                person_frames=int(frames.sum()),
                points_mean=float(c.mean()) if len(c) else np.nan,
                points_median=float(np.median(c)) if len(c) else np.nan,
                empty_fraction=float(np.mean(c == 0)) if len(c) else np.nan,
                spread_x_m=pooled_std(dx),
                spread_y_m=pooled_std(dy),
                rms_x_ref_m=rms(ex),
                rms_y_ref_m=rms(ey),
                centroid_error_m=centroid_err,
                doppler_std_mps=pooled_std(dv),
                snr_median_db=snr,
                reference_is_truth=points.reference_is_truth,
            )
        )
    return out


def dataset_person_points(ds: Dataset) -> PersonPoints:
    """The person points of a simulated data set, by its ground-truth labels.

    A person-frame is a (frame, person) pair where the person is present (finite truth); its
    reference is the true position. A point is a person point when its ``source`` is a person
    index (>= 0); clutter and noise points are left out.
    """
    present = np.isfinite(ds.truth_xy_m[:, :, 0])  # (F, n_persons)
    index = np.full(present.shape, -1, dtype=np.int64)
    index[present] = np.arange(int(present.sum()))
    person = ds.source >= 0
    owner = index[ds.frame[person], ds.source[person]]
    keep = owner >= 0  # a label of a person absent from its frame cannot occur; guard anyway
    sel = np.flatnonzero(person)[keep]
    return PersonPoints(
        owner=owner[keep],
        x_m=ds.x_m[sel],
        y_m=ds.y_m[sel],
        radial_velocity_mps=ds.radial_velocity_mps[sel],
        snr_db=ds.snr_db[sel],
        reference_xy_m=ds.truth_xy_m[present],
        reference_is_truth=True,
    )


def rule_person_points(
    frame: np.ndarray,
    x_m: np.ndarray,
    y_m: np.ndarray,
    radial_velocity_mps: np.ndarray,
    n_frames: int,
    *,
    snr_db: np.ndarray | None = None,
    radius_m: float = 1.0,
) -> PersonPoints:
    """The person points of a one-person recording without truth, by a rule.

    Rule: the frame's reference is the median ``(x, y)`` of its moving points (radial velocity
    not 0); a frame without moving points keeps the last reference (the first frames take the
    first one). Every point within ``radius_m`` of its frame's reference is a person point.

    Parameters
    ----------
    frame
        Shape (P,), frame index of each point in ``0 .. n_frames-1``.
    x_m, y_m, radial_velocity_mps, snr_db
        Shape (P,): the points (``snr_db`` optional).
    n_frames
        Number of frames (one person-frame each).

    Returns
    -------
    PersonPoints
        ``reference_is_truth`` is False. Raises ``ValueError`` when no point moves.
    """
    frame = np.asarray(frame, dtype=np.int64)
    x = np.asarray(x_m, dtype=np.float64)
    y = np.asarray(y_m, dtype=np.float64)
    moving = np.asarray(radial_velocity_mps) != 0
    if not moving.any():
        raise ValueError("no moving point: the rule has no person to find")
    ref = np.full((n_frames, 2), np.nan)
    for f in np.unique(frame[moving]):
        sel = moving & (frame == f)
        ref[f] = np.median(x[sel]), np.median(y[sel])
    have = np.isfinite(ref[:, 0])
    last = np.where(have, np.arange(n_frames), -1)
    np.maximum.accumulate(last, out=last)
    last = np.where(last < 0, np.flatnonzero(have)[0], last)
    ref = ref[last]
    near = np.hypot(x - ref[frame, 0], y - ref[frame, 1]) <= radius_m
    return PersonPoints(
        owner=frame[near],
        x_m=x[near],
        y_m=y[near],
        radial_velocity_mps=np.asarray(radial_velocity_mps, dtype=np.float64)[near],
        snr_db=None if snr_db is None else np.asarray(snr_db, dtype=np.float64)[near],
        reference_xy_m=ref,
        reference_is_truth=False,
    )
