"""``radartune import`` / ``export`` for TI UART logs: :mod:`core.formats.ti_uart` packets as a
:class:`~core.formats.recording.Recording`, and a simulated run as a log plus its ``.cfg``.

Per-packet work is a few ``numpy.frombuffer`` views; the conversion to range, angles and the
data set's float64 arrays is done once for the whole log (``radartune bench import``).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path

import numpy as np

from core.config import PAPER_RADAR, RadarConfig
from core.errors import InputError
from core.formats import ti_uart
from core.formats.recording import (
    Recording,
    frames_from_numbers,
    point_tracks_from_indices,
    points_to_cloud,
)
from core.limits import MAX_DATASET_FRAMES
from core.pointcloud import PointCloud

#: Point formats ``radartune export --format uart --variant`` writes (default first).
VARIANTS = ti_uart.WRITE_FORMATS


def sniff(head: bytes, path: Path) -> bool:
    """A UART log has the magic word in its first bytes (a log may start mid-packet)."""
    return ti_uart.MAGIC in head


def read(
    path: Path, radar: RadarConfig | None, *, chunks: Iterable[bytes] | None = None
) -> Recording:
    """Read a UART log (or, with ``chunks``, an iterable of byte chunks named ``path``)."""
    report = ti_uart.UartReport()
    cfg = radar if radar is not None else PAPER_RADAR
    raw: list[bytes] = []  # float points (TLV 1, SDK >= 3) of the packets decoded in bulk
    raw_side: list[bytes] = []
    decoded: list[tuple[int, ti_uart.UartPoints]] = []  # (packet index, points) of the rest
    numbers: list[int] = []
    counts: list[int] = []
    extras: set[str] = set()
    # TI's own tracks: (packet index, targets), (packet index, target index bytes)
    targets: list[tuple[int, np.ndarray]] = []
    target_index: list[tuple[int, np.ndarray]] = []
    source = chunks if chunks is not None else path
    for k, pk in enumerate(
        ti_uart.iter_raw_packets(source, radar=radar, report=report, name=str(path))
    ):
        numbers.append(pk.frame_number)
        if k >= MAX_DATASET_FRAMES:
            # the data set could not hold it: stop here rather than fill memory first
            raise InputError(
                f"more than {MAX_DATASET_FRAMES} packets (the data-set limit of frames) within "
                f"the first {report.n_bytes} bytes; split the log",
                str(path),
            )
        if pk.points is None:
            n = len(pk.float_points) // ti_uart.POINT_FLOAT.itemsize
            raw.append(pk.float_points)
            # no side info: a marker per point that decodes to NaN (no SNR)
            raw_side.append(pk.side_info or _NO_SIDE * n)
        else:
            n = len(pk.points)
            decoded.append((k, pk.points))
        counts.append(n)
        if pk.extras:
            extras.update(pk.extras)
        if pk.targets is not None and len(pk.targets):
            targets.append((k, pk.targets))
        if pk.target_index is not None:
            target_index.append((k, pk.target_index))
    pkt_counts = np.asarray(counts, dtype=np.int64)
    x, y, z, v, snr = _assemble(raw, raw_side, decoded, pkt_counts)
    point_track = point_tracks_from_indices(pkt_counts, target_index)[0] if target_index else None
    cloud, keep = points_to_cloud(x, y, z, v, snr)
    if not keep.all():
        # points with a non-finite coordinate or velocity are dropped (counted)
        packet_of_point = np.repeat(np.arange(len(pkt_counts)), pkt_counts)
        pkt_counts = np.bincount(packet_of_point[keep], minlength=len(pkt_counts))
    slot, t_s, trajectory, n_filled = frames_from_numbers(np.asarray(numbers), cfg.frame_period_s)
    frame_counts = np.bincount(slot, weights=pkt_counts, minlength=len(t_s)).astype(np.int64)
    notes = [report.summary()]
    if n_filled:
        notes.append(f"{n_filled} empty frames inserted for missing frame numbers")
    if not keep.all():
        notes.append(f"{int((~keep).sum())} points with non-finite values dropped")
    if radar is None:
        notes.append(
            f"no --cfg: frame period {cfg.frame_period_s * 1e3:g} ms and radar of the paper assumed"
        )
    kept = {"targets", "target_index"}
    if extras - kept:
        notes.append(
            "auxiliary TLVs read and not kept in the data set: " + ", ".join(sorted(extras - kept))
        )
    ref_tracks = _ref_tracks(targets, slot)
    if ref_tracks is not None:
        notes.append(
            f"TI's own tracks kept as the reference layer: {len(ref_tracks['frame'])} track rows "
            f"of {len(np.unique(ref_tracks['track_id']))} track ids"
        )
    return Recording(
        format="uart",
        cloud=cloud,
        counts=frame_counts,
        t_s=t_s,
        trajectory=trajectory,
        radar=cfg,
        notes=tuple(notes),
        meta={
            "frames_read": report.n_frames,
            "dropped_frames": report.n_dropped,
            "damaged_packets": report.n_damaged,
            "unknown_tlvs": {str(k): v for k, v in report.unknown_tlvs.items()},
        },
        ref_tracks=ref_tracks,
        ref_point_track=point_track[keep] if point_track is not None else None,
    )


def _ref_tracks(targets: list[tuple[int, np.ndarray]], slot: np.ndarray) -> dict | None:
    """TLV 1010 / 308 records as reference-layer rows (frame = the packet's output frame)."""
    if not targets:
        return None
    t = np.concatenate([a for _, a in targets])
    frame = np.concatenate([np.full(len(a), slot[k], dtype=np.int64) for k, a in targets])
    pos = t["pos"].astype(np.float64)
    vel = t["vel"].astype(np.float64)
    return {
        "frame": frame,
        "track_id": t["tid"].astype(np.int64),
        "x_m": pos[:, 0],
        "y_m": pos[:, 1],
        "z_m": pos[:, 2],
        "vx_mps": vel[:, 0],
        "vy_mps": vel[:, 1],
    }


#: Side info of a packet without TLV 7: the most negative int16, read back as "no SNR".
_NO_SIDE = np.array([(-32768, -32768)], ti_uart.SIDE_INFO).tobytes()


def _assemble(
    raw: list[bytes],
    raw_side: list[bytes],
    decoded: list[tuple[int, ti_uart.UartPoints]],
    counts: np.ndarray,
) -> tuple[np.ndarray, ...]:
    """x, y, z, v, SNR of every point in packet order: the bulk-decoded float packets and the
    individually decoded ones interleaved back by packet index."""
    pts = np.frombuffer(b"".join(raw), ti_uart.POINT_FLOAT)
    side = np.frombuffer(b"".join(raw_side), ti_uart.SIDE_INFO)
    # snr in 0.1 dB steps; the "absent" marker as NaN
    snr = np.where(side["snr"] == -32768, np.nan, side["snr"] * 0.1)
    cols = [pts["x"], pts["y"], pts["z"], pts["v"], snr]
    if not decoded:
        return tuple(np.asarray(c, dtype=np.float64) for c in cols)
    total = int(counts.sum())
    out = [np.empty(total) for _ in range(5)]
    starts = np.concatenate(([0], np.cumsum(counts)))
    is_bulk = np.ones(len(counts), dtype=bool)
    is_bulk[[k for k, _ in decoded]] = False
    bulk_rows = np.repeat(is_bulk, counts)
    for o, c in zip(out, cols):
        o[bulk_rows] = c
    for k, p in decoded:
        s = slice(starts[k], starts[k + 1])
        for o, c in zip(out, (p.x_m, p.y_m, p.z_m, p.velocity_mps, p.snr_db)):
            o[s] = c
    return tuple(out)


def write(
    path: Path, clouds: Sequence[PointCloud], radar: RadarConfig, variant: str | None
) -> list[Path]:
    """Write point clouds (one per frame) as a UART log and its ``.cfg`` next to it."""
    from core.formats.ti_cfg import write_ti_cfg

    fmt = variant or VARIANTS[0]
    ti_uart.write_uart_log(path, clouds, fmt=fmt, radar=radar)
    cfg = path.with_suffix(".cfg")
    write_ti_cfg(radar, cfg, comment=f"written by radartune export with {path.name}")
    return [path, cfg]
