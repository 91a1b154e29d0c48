"""The gtrack side of ``radartune track`` and ``radartune export-cfg`` (TI's tracker lines)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from core.tracking.gtrack.params import GtrackParams

if TYPE_CHECKING:
    from core.dataset import Dataset
    from core.formats.tracks_csv import TrackRows
    from core.tracking import DatasetEstimates
    from core.tracking.gtrack.tracker import GtrackResult


def load_params(cfg: str | None, params: str | None) -> GtrackParams:
    """TI's defaults, then the tracker lines of ``cfg``, then the keys of the JSON ``params``."""
    from core.files import read_json, read_text
    from core.formats.ti_cfg import parse_ti_cfg
    from core.tracking.gtrack.params import params_from_cfg

    out = GtrackParams()
    if cfg:
        text = read_text(Path(cfg), what="TI configuration")
        out = params_from_cfg(parse_ti_cfg(text, cfg), cfg)
    if params:
        doc = read_json(Path(params), what="gtrack parameters")
        if isinstance(doc, dict):
            doc = {**out.to_dict(), **doc}
        out = GtrackParams.from_dict(doc, params)
    return out


def run_track(args: argparse.Namespace) -> int:
    """``radartune track --tracker gtrack``."""
    import time

    import numpy as np

    from core.dataset import Dataset
    from core.files import check_output_path, write_json_atomic
    from core.formats.recording import has_truth
    from core.tracking.gtrack.batch import gtrack_dataset

    for out_path, what in ((args.out, "--out"), (args.tracks, "--tracks")):
        if out_path:
            check_output_path(out_path, what=f"{what} file")
    if args.people is not None and args.people < 0:
        from core.errors import InputError

        raise InputError(f"--people must be >= 0, got {args.people}")
    params = load_params(getattr(args, "cfg", None), args.params)
    ds = Dataset.load(args.data)
    t0 = time.perf_counter()
    est, results = gtrack_dataset(ds, params, engine=args.engine, with_tracks=True)
    elapsed = time.perf_counter() - t0
    n = len(est.frame_index)
    active = est.n_confirmed
    print(
        f"{args.data}: gtrack ({params.dims}-D), {len(est.trajectories)} trajectories, {n} frames "
        f"tracked in {elapsed * 1e3:.1f} ms ({elapsed / max(n, 1) * 1e6:.0f} µs a frame); "
        f"ACTIVE tracks a frame: mean {float(np.mean(active)) if n else 0:.2f}, "
        f"max {int(active.max(initial=0))}; {int(np.sum(active > 0))} frames with one or more"
    )
    from core.cli.track_scores import per_frame, scores_without_positions

    # the NIS of gtrack's centroid update: one dof per measurement row ([r, az, (el,) vr])
    scores = scores_without_positions(ds, est, args.people, nis_dof=params.dims + 1)
    doc: dict = {
        "data": str(args.data),
        "tracker": "gtrack",
        "params": params.to_dict(),
        "elapsed_s": elapsed,
        "active_per_frame": active.tolist(),
        **per_frame(est),
        "without_positions": scores.to_dict(),
    }
    if has_truth(ds):
        from core.evaluation import evaluate

        ev = evaluate(ds, est)
        print(ev.format_table())
        doc.update(ev.to_dict())
    print("\n".join(scores.format_lines()))
    if args.tracks:
        from core.formats.tracks_csv import write_tracks_csv

        rows = gtrack_track_rows(ds, est, results, params.dims)
        write_tracks_csv(args.tracks, rows)
        print(f"written: {args.tracks} ({len(rows)} rows)")
    if args.out:
        write_json_atomic(Path(args.out), doc)
        print(f"written: {args.out}")
    return 0


def gtrack_track_rows(
    ds: Dataset, est: DatasetEstimates, results: list[GtrackResult], dims: int
) -> TrackRows:
    """The tracks file's rows (SPEC §7) of a gtrack run: every live track of every frame, ids
    shifted per trajectory past the largest of the runs before (unique over the file), status
    ``confirmed`` for ACTIVE, existence empty (gtrack has none), height from the 3-D state."""
    from core.formats.tracks_csv import TrackRows

    frame, ids, conf, state, z, n_pts, nis = [], [], [], [], [], [], []
    shift, row = 0, 0
    for res in results:
        largest = -1
        for ft in res.frames:
            g = int(est.frame_index[row])
            row += 1
            k = len(ft)
            frame += [g] * k
            ids.append(ft.ids + shift)
            conf.append(ft.confirmed)
            x = ft.state
            state.append(np.column_stack([x[:, 0], x[:, 1], x[:, dims], x[:, dims + 1]]))
            z.append(x[:, 2] if dims == 3 else np.zeros(k))
            n_pts.append(ft.n_associated)
            nis.append(ft.nis)
            largest = max(largest, int(ft.ids.max(initial=-1)))
        shift += largest + 1
    f = np.asarray(frame, dtype=np.int64)

    def cat(parts: list[np.ndarray], dtype: type, width: int = 0) -> np.ndarray:
        shape = (0, width) if width else (0,)
        return np.concatenate(parts).astype(dtype) if parts else np.zeros(shape, dtype)

    return TrackRows(
        frame=f,
        time_s=np.asarray(ds.truth_t_s, dtype=np.float64)[f],
        track_id=cat(ids, np.int64),
        confirmed=cat(conf, bool),
        state=cat(state, np.float64, 4),
        existence=np.full(len(f), np.nan),
        n_points=cat(n_pts, np.int64),
        nis=cat(nis, np.float64),
        height_m=cat(z, np.float64) if dims == 3 else None,
    )
