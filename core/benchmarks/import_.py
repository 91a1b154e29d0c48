"""``radartune bench import``: how fast real recordings are read into a data set.

Figures, each against a reference measured in the same run (the machine is shared and noisy):

- ``uart``: MB/s of :func:`core.formats.ti_uart_import.read` (file → :class:`Recording`, every
  point converted) on a synthetic SDK 3.x log written to a temporary file: per packet 24 float
  points (TLV 1), their side info (TLV 7), a 256-bin range profile (TLV 2) and the statistics
  (TLV 6), about 1.1 kB a packet like an out-of-box demo at 80 ms; best of 3, by wall clock
  and by this process's CPU time (the machine is shared: the CPU figure is what the code
  costs). Target ≥ 50 MB/s (issue 16). Reference: a plain loop that only finds each packet and
  unpacks its points with :mod:`struct` (no checks, no resynchronisation, no arrays), on the
  first quarter of the same bytes; ``ratio`` = reference time / ours (> 1: ours faster).
- ``csv``: MB/s of the point-cloud CSV readers (:mod:`core.formats.pointcloud_csv`, file →
  :class:`Recording`) on generated files: an out-of-box CSV (24 points a frame, 13 columns with
  the date and time, numbers written to 5 decimals like the public gait recordings) and a
  people-counting vendor CSV (24 ``v6`` points, one ``v7`` track and one ``v8`` index per
  frame); best of 3 by wall clock and CPU time; target ≥ 20 MB/s; ``ratio_to_uart``: CPU MB/s
  over the UART reader's in the same run.
- ``dca1000``: a DCA1000 capture through the exact chain's processing half in frames/s against
  the exact chain's own frames/s on the same frames (:mod:`core.benchmarks.import_adc`).
"""

from __future__ import annotations

import os
import struct
import tempfile
import time
from pathlib import Path

import numpy as np

from core.benchmarks import import_adc
from core.formats import ti_uart
from core.formats.ti_uart_import import read
from core.pointcloud import PointCloud

#: Points per packet in the synthetic log (a few people and some clutter).
POINTS_PER_PACKET = 24
#: Range bins of the range profile TLV.
RANGE_BINS = 256


def synthetic_packet(k: int, rng: np.random.Generator) -> bytes:
    """One SDK 3.x packet: points, side info, range profile, statistics."""
    n = POINTS_PER_PACKET
    pts = np.zeros(n, ti_uart.POINT_FLOAT)
    pts["x"], pts["y"] = rng.uniform(-3, 3, n), rng.uniform(0.5, 8, n)
    pts["v"] = rng.uniform(-2, 2, n)
    side = np.zeros(n, ti_uart.SIDE_INFO)
    side["snr"] = rng.integers(50, 300, n)
    tlvs = [
        (ti_uart.DETECTED_POINTS, pts.tobytes()),
        (ti_uart.RANGE_PROFILE, rng.integers(0, 2**15, RANGE_BINS).astype("<u2").tobytes()),
        (ti_uart.STATS, bytes(ti_uart.STATS_ITEM.itemsize)),
        (ti_uart.DETECTED_POINTS_SIDE_INFO, side.tobytes()),
    ]
    body = b"".join(struct.pack("<2I", t, len(p)) + p for t, p in tlvs)
    total = -(-(40 + len(body)) // 32) * 32
    head = ti_uart.MAGIC + struct.pack("<8I", 0x03050004, total, 0xA6843, k, 0, n, len(tlvs), 0)
    return head + body + bytes(total - 40 - len(body))


def plain_read(data: bytes) -> int:
    """Reference: find each magic word, then unpack header, TLVs and every point with struct."""
    n_points = 0
    pos = data.find(ti_uart.MAGIC)
    while pos >= 0 and pos + 40 <= len(data):
        _, _, total, _, _, _, n_det, n_tlv, _ = struct.unpack_from("<Q8I", data, pos)
        off = pos + 40
        for _ in range(n_tlv):
            t, length = struct.unpack_from("<2I", data, off)
            off += 8
            if t == ti_uart.DETECTED_POINTS:
                for i in range(length // 16):
                    x, y, z, v = struct.unpack_from("<4f", data, off + 16 * i)
                    n_points += 1
            off += length
        pos = data.find(ti_uart.MAGIC, pos + total)
    return n_points


def synthetic_oob_csv(path: Path, n_frames: int, rng: np.random.Generator) -> None:
    """An out-of-box CSV of ``n_frames`` frames at 0.1 s, :data:`POINTS_PER_PACKET` points each."""
    n = POINTS_PER_PACKET
    fn = np.repeat(np.arange(1, n_frames + 1), n)
    t = 11.0 + (fn - 1) * 0.1
    rows = np.column_stack(
        (
            fn,
            np.full(len(fn), n),
            rng.uniform(-3, 3, len(fn)),
            rng.uniform(0.5, 8, len(fn)),
            rng.uniform(-1, 2, len(fn)),
            rng.uniform(-2, 2, len(fn)),
            rng.integers(150, 400, len(fn)),
            np.full(len(fn), 2019),
            np.full(len(fn), 7),
            np.full(len(fn), 13),
            np.full(len(fn), 11),
            (t // 60) % 60,
            t % 60,
        )
    )
    with open(path, "w") as fh:
        fh.write("Frame #,# Obj,X,Y,Z,Doppler,,y,m,d,h,m,s\n")
        np.savetxt(fh, rows, fmt="%d,%d,%.5f,%.5f,%.5f,%.5f,%d,%d,%d,%d,%d,%d,%.3f")


def synthetic_people_csv(path: Path, n_frames: int, rng: np.random.Generator) -> None:
    """A people-counting vendor CSV: per frame 24 ``v6`` points, one ``v7`` track, one ``v8``."""
    n = POINTS_PER_PACKET
    header = (
        "time,fN,type,posX,posY,posZ,velX,velY,velZ,accX,accY,accZ,"
        + ",".join(f"ec{i}" for i in range(16))
        + ",g,confi,tid\n"
    )
    lines = [header]
    for k in range(n_frames):
        stamp = f"2023-06-21 12:{27 + k // 600:02d}:{(k % 600) / 10:09.6f}"
        r = rng.uniform(0.5, 8, n)
        el, az = rng.uniform(-0.3, 0.3, n), rng.uniform(-1, 1, n)
        x, y, z = r * np.cos(el) * np.sin(az), r * np.cos(el) * np.cos(az), r * np.sin(el)
        pts = np.column_stack((el, az, r, rng.uniform(-2, 2, n), rng.uniform(4, 300, n), x, y, z))
        prefix = f"{stamp},{k + 1},v6,"
        lines.extend(prefix + ",".join(repr(float(v)) for v in row) + "\n" for row in pts)
        track = [1.0, 3.0, 1.0, 0.1, -0.2, 0, 0, 0, 0, *([0.0] * 16), 3.0, 0.99, 0]
        lines.append(f"{stamp},{k + 1},v7," + ",".join(map(str, track)) + "\n")
        lines.append(f'{stamp},{k + 1},v8,"[' + ", ".join(["255"] * n) + ']"\n')
    path.write_text("".join(lines))


def _best_of_3(fn, path: Path) -> tuple[float, float]:
    fn(path, None)  # warm up
    best = best_cpu = float("inf")
    for _ in range(3):
        t0, c0 = time.perf_counter(), time.process_time()
        fn(path, None)
        best = min(best, time.perf_counter() - t0)
        best_cpu = min(best_cpu, time.process_time() - c0)
    return best, best_cpu


def run_csv(quick: bool, uart_cpu_mb_per_s: float) -> dict:
    from core.formats.pointcloud_csv import read_oob, read_people

    rng = np.random.default_rng(27)
    out: dict = {}
    with tempfile.TemporaryDirectory(prefix="radartune-bench-csv-") as tmp:
        for name, make, reader, frames in (
            ("oob", synthetic_oob_csv, read_oob, 1_500 if quick else 12_000),
            ("people", synthetic_people_csv, read_people, 200 if quick else 1_600),
        ):
            path = Path(tmp) / f"{name}.csv"
            make(path, frames, rng)
            size = path.stat().st_size
            wall, cpu = _best_of_3(reader, path)
            out[name] = {
                "bytes": size,
                "frames": frames,
                "points": frames * POINTS_PER_PACKET,
                "seconds": wall,
                "cpu_seconds": cpu,
                "mb_per_s": size / wall / 1e6,
                "cpu_mb_per_s": size / cpu / 1e6,
                "ratio_to_uart": size / cpu / 1e6 / uart_cpu_mb_per_s,
            }
    out["target_mb_per_s"] = 20.0
    out["load_average_1min"] = os.getloadavg()[0]
    return out


def run(quick: bool = False) -> dict:
    rng = np.random.default_rng(16)
    n_unique = 256
    packets = b"".join(synthetic_packet(k, rng) for k in range(n_unique))
    repeats = 8 if quick else 64  # 8 / 64 x 256 packets: ~2.3 / ~18 MB
    with tempfile.TemporaryDirectory(prefix="radartune-bench-import-") as tmp:
        path = Path(tmp) / "log.dat"
        with open(path, "wb") as fh:
            for r in range(repeats):
                # renumber so that frames follow each other (no dropped-frame gaps)
                block = bytearray(packets)
                for k in range(n_unique):
                    struct.pack_into(
                        "<I", block, k * len(packets) // n_unique + 24, r * n_unique + k
                    )
                fh.write(block)
        size = path.stat().st_size
        read(path, None)  # warm up
        best = best_cpu = float("inf")
        for _ in range(3):
            t0, c0 = time.perf_counter(), time.process_time()
            rec = read(path, None)
            best = min(best, time.perf_counter() - t0)
            best_cpu = min(best_cpu, time.process_time() - c0)
        n_points = len(rec.cloud)
        data = path.read_bytes()[: 4 * len(packets)]
        t0 = time.process_time()
        plain_points = plain_read(data)
        t_plain = (time.process_time() - t0) * (size / len(data))
    assert isinstance(rec.cloud, PointCloud)
    return {
        "uart": {
            "bytes": size,
            "packets": repeats * n_unique,
            "points": n_points,
            "seconds": best,
            "cpu_seconds": best_cpu,
            "mb_per_s": size / best / 1e6,
            "cpu_mb_per_s": size / best_cpu / 1e6,
            "reference_cpu_mb_per_s": size / t_plain / 1e6,
            "reference_points_per_packet_checked": plain_points / (4 * n_unique),
            "ratio": t_plain / best_cpu,
            "load_average_1min": os.getloadavg()[0],
            "target_mb_per_s": 50.0,
        },
        "csv": run_csv(quick, size / best_cpu / 1e6),
        "dca1000": import_adc.run(quick),
    }


def summary(result: dict) -> str:
    u = result["uart"]
    d = result["dca1000"]
    return (
        f"UART log import: {u['cpu_mb_per_s']:.0f} MB/s of CPU time, {u['mb_per_s']:.0f} MB/s "
        f"wall clock at load {u['load_average_1min']:.1f} ({u['bytes'] / 1e6:.1f} MB, "
        f"{u['packets']} packets, {u['points']} points; target >= {u['target_mb_per_s']:.0f} "
        f"MB/s); a bare struct loop without checks: {u['reference_cpu_mb_per_s']:.0f} MB/s "
        f"(ratio {u['ratio']:.2f})\n"
        + "".join(
            f"{name} CSV import: {c['cpu_mb_per_s']:.0f} MB/s of CPU time, {c['mb_per_s']:.0f} "
            f"MB/s wall clock ({c['bytes'] / 1e6:.1f} MB, {c['points']} points; target >= "
            f"{result['csv']['target_mb_per_s']:.0f} MB/s); {c['ratio_to_uart']:.2f}x the UART "
            "reader's CPU MB/s\n"
            for name, c in result["csv"].items()
            if isinstance(c, dict)
        )
        + f"DCA1000 capture through the processing half: {d['capture_fps']:.0f} frames/s, "
        f"{d['capture_over_exact']:.2f}x the exact chain's {d['exact_fps']:.0f} frames/s in the "
        f"same run (CPU: {d['capture_over_exact_cpu']:.2f}x; goal >= 1x)"
    )
