"""gtrack over a :class:`core.dataset.Dataset`: every trajectory from scratch, as the paper's
tracker (:func:`core.tracking.track_dataset`), so the same evaluation applies."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from core.dataset import Dataset
from core.tracking.batch import ConfirmedTracks, DatasetEstimates, record_frame
from core.tracking.gtrack.params import GtrackParams
from core.tracking.gtrack.tracker import GtrackResult, run_gtrack
from core.tracking.results import TrackRecord

__all__ = ["dataset_points", "gtrack_dataset"]


def dataset_points(dataset: Dataset) -> np.ndarray:
    """(P, 5) ``[r, az, el, vr, snr]`` of a data set's points, SNR as a linear power ratio."""
    return np.column_stack(
        [
            dataset.range_m,
            dataset.azimuth_rad,
            dataset.elevation_rad,
            dataset.radial_velocity_mps,
            10.0 ** (np.asarray(dataset.snr_db, dtype=float) / 10.0),
        ]
    )


def gtrack_dataset(
    dataset: Dataset,
    params: GtrackParams,
    *,
    trajectories: Sequence[int] | None = None,
    engine: str = "numba",
    with_tracks: bool = False,
) -> tuple[DatasetEstimates, list[GtrackResult]]:
    """Run gtrack on every selected trajectory; estimates as :func:`core.tracking.track_dataset`
    (ACTIVE tracks are the confirmed ones, the estimate the ACTIVE track with most points).
    ``engine``: ``"numba"`` (compiled, default) or ``"numpy"`` (the readable form);
    ``with_tracks``: keep every live track of every frame in the estimates' ``record`` (in
    gtrack's own state layout), for the tracks file and the scores without positions."""
    from core.errors import InputError

    if engine == "numba":
        from core.tracking.gtrack.compiled import run_gtrack_compiled as run
    elif engine == "numpy":
        run = run_gtrack
    else:
        raise InputError(f"engine must be 'numba' or 'numpy', got engine={engine!r}")
    k_all = dataset.n_trajectories
    sel = np.arange(k_all) if trajectories is None else np.asarray(trajectories, dtype=np.int64)
    pts = dataset_points(dataset)
    f_off, t_off = dataset.frame_offsets, dataset.trajectory_offsets
    results = []
    for k in sel:
        a, b = int(t_off[k]), int(t_off[k + 1])
        results.append(run(pts[f_off[a] : f_off[b]], f_off[a : b + 1] - f_off[a], params))
    frames = [ft for res in results for ft in res.frames]
    n = len(frames)
    cap = params.max_tracks
    est_xy = np.full((n, 2), np.nan)
    has = np.zeros(n, dtype=bool)
    conf_xy = np.full((n, cap, 2), np.nan)
    n_conf = np.zeros(n, dtype=np.int64)
    n_tr = np.zeros(n, dtype=np.int64)
    # every live track of every frame (gtrack's own state layout), as the paper's tracker
    # records it for the tracks file and the scores without positions
    rec = TrackRecord.allocate(n if with_tracks else 0, cap, 3 * params.dims)
    for f, ft in enumerate(frames):
        if with_tracks:
            record_frame(rec, f, ft)
        xy = ft.state[ft.confirmed, :2]
        n_conf[f], n_tr[f] = len(xy), len(ft)
        conf_xy[f, : min(len(xy), cap)] = xy[:cap]
        if ft.estimate >= 0:
            est_xy[f], has[f] = ft.state[ft.estimate, :2], True
    lengths = [len(r.frames) for r in results]
    return (
        DatasetEstimates(
            trajectories=sel,
            frame_index=np.concatenate(
                [np.arange(t_off[k], t_off[k + 1]) for k in sel] or [np.zeros(0)]
            ).astype(np.int64),
            offsets=np.concatenate(([0], np.cumsum(lengths))).astype(np.int64),
            estimate_xy=est_xy,
            has_estimate=has,
            estimate_psi=np.full(n, np.nan),
            confirmed_xy=conf_xy,
            n_confirmed=n_conf,
            n_tracks=n_tr,
            model="ca",
            tracks=ConfirmedTracks.from_frames(frames),
            record=rec._replace(n_tracks=n_tr.copy()) if with_tracks else None,
        ),
        results,
    )
