"""The gtrack side of ``radartune track`` and ``radartune export-cfg`` (TI's tracker lines)."""

from __future__ import annotations

import argparse
from pathlib import Path

from core.tracking.gtrack.params import GtrackParams


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

    if args.out:
        check_output_path(args.out)
    params = load_params(getattr(args, "cfg", None), args.params)
    ds = Dataset.load(args.data)
    t0 = time.perf_counter()
    est, results = gtrack_dataset(ds, params, engine=args.engine)
    elapsed = time.perf_counter() - t0
    n = len(est.frame_index)
    active = est.n_confirmed
    print(
        f"{args.data}: gtrack ({params.dims}-D), {len(est.trajectories)} trajectories, {n} frames "
        f"tracked in {elapsed * 1e3:.1f} ms ({elapsed / max(n, 1) * 1e6:.0f} µs a frame); "
        f"ACTIVE tracks a frame: mean {float(np.mean(active)) if n else 0:.2f}, "
        f"max {int(active.max(initial=0))}; {int(np.sum(active > 0))} frames with one or more"
    )
    doc: dict = {
        "data": str(args.data),
        "tracker": "gtrack",
        "params": params.to_dict(),
        "elapsed_s": elapsed,
        "active_per_frame": active.tolist(),
    }
    if has_truth(ds):
        from core.evaluation import evaluate

        ev = evaluate(ds, est)
        print(ev.format_table())
        doc.update(ev.to_dict())
    if args.out:
        write_json_atomic(Path(args.out), doc)
        print(f"written: {args.out}")
    return 0
