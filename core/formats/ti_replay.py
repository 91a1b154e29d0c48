"""TI Industrial Visualizer replay files: reader and writer.

The Industrial Visualizer (TI radar toolbox, ``tools/visualizers/Applications_Visualizer``)
records what it parsed when "Save data" is ticked: every 100 frames a JSON file
``binData/<date>/replay_<N>.json``::

    {"cfg": [the .cfg lines sent to the device], "demo": "<demo name>", "device": "<xWR6843…>",
     "data": [{"frameData": {"frameNum": int, "pointCloud": [[x, y, z, doppler, snr, noise,
               track index], …], "numDetectedPoints": int, "trackData": […], …},
               "timestamp": ms since the epoch}, …]}

``pointCloud`` rows are Cartesian (the visualizer converts spherical TLVs), x/y/z in m, Doppler
in m/s, SNR and noise as the demo reports them (dB in the out-of-box demos); columns past the
fourth are optional. A replay is one such file or a folder of them (read in ``N`` order).
JSON cannot be streamed through :func:`core.files.read_json`; each file is bounded by the input
size limit and the visualizer writes 100 frames per file.
"""

from __future__ import annotations

import json
import re
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from core.config import PAPER_RADAR, RadarConfig
from core.errors import InputError
from core.files import read_json, write_text_atomic
from core.formats.recording import Recording, frames_from_numbers, points_to_cloud
from core.pointcloud import PointCloud

#: File names the visualizer writes.
REPLAY_NAME = re.compile(r"^replay_(\d+)\.json$")
#: ``frameNum`` is the firmware's 32-bit frame counter.
FRAME_NUMBER_END = 2**32
#: Columns of a ``pointCloud`` row: x, y, z, Doppler required; SNR, noise, track index optional.
POINT_COLUMNS = ("x", "y", "z", "doppler", "snr", "noise", "track")


def sniff(head: bytes, path: Path) -> bool:
    if path.is_dir():
        return any(REPLAY_NAME.match(p.name) for p in path.iterdir())
    text = head.lstrip()
    return text.startswith(b"{") and b'"data"' in head and (b'"frameData"' in head or b"[]" in head)


def replay_files(path: Path) -> list[Path]:
    """The replay files of ``path`` (a file, or a folder of ``replay_N.json`` in ``N`` order)."""
    if not path.is_dir():
        return [path]
    files = sorted(
        (p for p in path.iterdir() if REPLAY_NAME.match(p.name)),
        key=lambda p: int(REPLAY_NAME.match(p.name).group(1)),  # type: ignore[union-attr]
    )
    if not files:
        raise InputError("no replay_N.json files in this folder", str(path))
    return files


def _frames_of(doc: object, src: str) -> tuple[list, list]:
    if not isinstance(doc, dict):
        raise InputError("a replay file must hold a JSON object", src)
    data = doc.get("data")
    if not isinstance(data, list):
        raise InputError("'data' must be a list of frames", src)
    cfg = doc.get("cfg", [])
    if isinstance(cfg, str):
        cfg = cfg.splitlines()
    if not isinstance(cfg, list) or not all(isinstance(c, str) for c in cfg):
        raise InputError("'cfg' must be a list of text lines", src)
    return data, cfg


def _frame_points(item: object, k: int, src: str) -> tuple[int, np.ndarray]:
    where = f"data[{k}]"
    if not isinstance(item, dict) or not isinstance(item.get("frameData"), dict):
        raise InputError(f"{where} must be an object with 'frameData'", src)
    fd = item["frameData"]
    fn = fd.get("frameNum")
    if isinstance(fn, bool) or not isinstance(fn, int) or not 0 <= fn < FRAME_NUMBER_END:
        raise InputError(
            f"{where}.frameData.frameNum must be an integer in [0, 2^32), got {str(fn)[:40]}", src
        )
    pc = fd.get("pointCloud", [])
    if not isinstance(pc, list):
        raise InputError(f"{where}.frameData.pointCloud must be a list of rows", src)
    n = fd.get("numDetectedPoints", len(pc))
    if isinstance(n, bool) or not isinstance(n, int) or not 0 <= n <= len(pc):
        raise InputError(
            f"{where}.frameData.numDetectedPoints must be an integer in [0, {len(pc)}], got {n!r}",
            src,
        )
    rows = pc[:n]
    for i, row in enumerate(rows):
        if (
            not isinstance(row, list)
            or not 4 <= len(row) <= len(POINT_COLUMNS)
            or not all(isinstance(c, int | float) and not isinstance(c, bool) for c in row)
        ):
            raise InputError(
                f"{where}.frameData.pointCloud[{i}] must be 4 to {len(POINT_COLUMNS)} numbers "
                f"({', '.join(POINT_COLUMNS)})",
                src,
            )
    a = np.full((len(rows), 5), np.nan)
    for i, row in enumerate(rows):
        m = min(len(row), 5)
        try:
            a[i, :m] = [float(c) for c in row[:m]]  # float(): an int beyond int64 is fine
        except OverflowError:
            raise InputError(
                f"{where}.frameData.pointCloud[{i}] holds a number beyond the float range", src
            ) from None
    return fn, a


def read(path: Path, radar: RadarConfig | None) -> Recording:
    """Read a replay file or folder; the radar from ``radar`` (``--cfg``), else from the
    replay's own ``cfg`` lines, else the paper's (noted)."""
    numbers: list[int] = []
    arrays: list[np.ndarray] = []
    cfg_lines: list[str] = []
    notes: list[str] = []
    meta: dict = {}
    files = replay_files(path)
    for f in files:
        doc = read_json(f, what="replay file")
        data, cfg = _frames_of(doc, str(f))
        if cfg and not cfg_lines:
            cfg_lines = cfg
        for key in ("demo", "device"):
            if isinstance(doc.get(key), str) and key not in meta:
                meta[key] = doc[key]
        for k, item in enumerate(data):
            fn, a = _frame_points(item, k, str(f))
            numbers.append(fn)
            arrays.append(a)
    if not arrays:
        raise InputError("the replay holds no frames", str(path))
    cfg_radar = radar
    if cfg_radar is None and cfg_lines:
        from core.formats.ti_cfg import parse_ti_cfg, radar_from_ti_commands

        try:
            cfg_radar = radar_from_ti_commands(
                parse_ti_cfg("\n".join(cfg_lines), f"{path} (cfg)"), f"{path} (cfg)"
            )
        except InputError as exc:
            notes.append(f"the replay's own cfg was not usable ({exc}); the paper radar assumed")
    if cfg_radar is None:
        cfg_radar = PAPER_RADAR
        if not cfg_lines:
            notes.append("no cfg in the replay and no --cfg: the paper radar assumed")
    pts = np.concatenate(arrays)
    cloud, keep = points_to_cloud(pts[:, 0], pts[:, 1], pts[:, 2], pts[:, 3], pts[:, 4])
    counts = np.array([len(a) for a in arrays], dtype=np.int64)
    if not keep.all():
        owner = np.repeat(np.arange(len(counts)), counts)
        counts = np.bincount(owner[keep], minlength=len(counts))
        notes.append(f"{int((~keep).sum())} points with non-finite values dropped")
    slot, t_s, trajectory, n_filled = frames_from_numbers(
        np.asarray(numbers), cfg_radar.frame_period_s
    )
    frame_counts = np.bincount(slot, weights=counts, minlength=len(t_s)).astype(np.int64)
    gaps = int(np.sum(np.clip(np.diff(np.asarray(numbers)) - 1, 0, None)))
    notes.insert(
        0,
        f"{path}: {len(arrays)} frames from {len(files)} file(s), {gaps} dropped "
        f"(frame-number gaps)",
    )
    if n_filled:
        notes.append(f"{n_filled} empty frames inserted for missing frame numbers")
    return Recording(
        format="replay",
        cloud=cloud,
        counts=frame_counts,
        t_s=t_s,
        trajectory=trajectory,
        radar=cfg_radar,
        notes=tuple(notes),
        meta=meta,
    )


def replay_document(
    clouds: Sequence[PointCloud], radar: RadarConfig, *, t0_ms: float = 0.0
) -> dict:
    """Point clouds (one per frame) as the visualizer's replay document (one file, all frames)."""
    from core.formats.ti_cfg import ti_cfg_text

    frames = []
    for k, c in enumerate(clouds):
        rows = np.column_stack(
            (
                c.x_m,
                c.y_m,
                c.z_m,
                c.radial_velocity_mps,
                c.snr_db,
                np.zeros(len(c)),
                np.full(len(c), 255.0),
            )
        ).astype(np.float32)
        frames.append(
            {
                "frameData": {
                    "error": 0,
                    "frameNum": k + 1,
                    "pointCloud": rows.astype(np.float64).tolist(),
                    "numDetectedPoints": len(c),
                },
                "timestamp": t0_ms + k * radar.frame_period_s * 1e3,
            }
        )
    return {
        "cfg": ti_cfg_text(radar).splitlines(),
        "demo": "RadarTune simulation",
        "device": "xWR6843",
        "data": frames,
    }


def write(
    path: Path, clouds: Sequence[PointCloud], radar: RadarConfig, variant: str | None
) -> list[Path]:
    """Write the clouds as one replay JSON file (values rounded to float32, as the device's)."""
    doc = replay_document(clouds, radar)
    write_text_atomic(path, json.dumps(doc, indent=1))
    return [path]
