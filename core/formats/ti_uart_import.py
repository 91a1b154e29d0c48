"""``radartune import`` / ``export`` for TI UART logs: :mod:`core.formats.ti_uart` packets as a
:class:`~core.formats.recording.Recording`, and a simulated run as a log plus its ``.cfg``.

Per-packet work is a few ``numpy.frombuffer`` views; the conversion to range, angles and the
data set's float64 arrays is done once for the whole log (``radartune bench import``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from core.config import PAPER_RADAR, RadarConfig
from core.formats import ti_uart
from core.formats.recording import Recording, frames_from_numbers, points_to_cloud

#: Point formats ``radartune export --format uart --variant`` writes (default first).
VARIANTS = ti_uart.WRITE_FORMATS


def sniff(head: bytes, path: Path) -> bool:
    """A UART log has the magic word in its first bytes (a log may start mid-packet)."""
    return ti_uart.MAGIC in head


def read(path: Path, radar: RadarConfig | None, *, chunks=None) -> Recording:
    """Read a UART log (or, with ``chunks``, an iterable of byte chunks named ``path``)."""
    report = ti_uart.UartReport()
    cfg = radar if radar is not None else PAPER_RADAR
    parts: dict[str, list[np.ndarray]] = {k: [] for k in ("x", "y", "z", "v", "snr")}
    numbers: list[int] = []
    counts: list[int] = []
    extras: set[str] = set()
    source = chunks if chunks is not None else path
    for fr in ti_uart.iter_uart_frames(source, radar=radar, report=report, name=str(path)):
        p = fr.points
        parts["x"].append(p.x_m)
        parts["y"].append(p.y_m)
        parts["z"].append(p.z_m)
        parts["v"].append(p.velocity_mps)
        parts["snr"].append(p.snr_db)
        numbers.append(fr.frame_number)
        counts.append(len(p))
        if fr.extras:
            extras.update(fr.extras)
    cat = {k: np.concatenate(v) if v else np.zeros(0) for k, v in parts.items()}
    cloud, keep = points_to_cloud(cat["x"], cat["y"], cat["z"], cat["v"], cat["snr"])
    pkt_counts = np.asarray(counts, dtype=np.int64)
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
    if extras:
        notes.append(
            "auxiliary TLVs read and not kept in the data set: " + ", ".join(sorted(extras))
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
    )


def write(path: Path, run, radar: RadarConfig, variant: str | None) -> list[Path]:
    """Write a simulated run's point clouds as a UART log and its ``.cfg`` next to it."""
    from core.formats.ti_cfg import write_ti_cfg

    fmt = variant or VARIANTS[0]
    ti_uart.write_uart_log(path, run.clouds, fmt=fmt, radar=radar)
    cfg = path.with_suffix(".cfg")
    write_ti_cfg(radar, cfg, comment=f"written by radartune export with {path.name}")
    return [path, cfg]
