"""Point-cloud CSV files as recordings: the vendor CSV of TI's people-counting firmware, the
out-of-box CSV of public gait and activity data sets, and any other CSV with a column map.

* ``people-csv`` (header ``time,fN,type,...``): one row per record of a frame, ``fN`` the frame
  number, ``time`` the host time stamp (``YYYY-MM-DD hh:mm:ss.ffffff``). Rows ``v6``: one point
  (elevation, azimuth in rad, then Doppler in m/s and range in m in an order that depends on the
  library version, then SNR (linear) and x, y, z in m); rows ``v7``: one of TI's tracks (the
  header names the columns: ``posX, posY, posZ, velX, velY, ..., tid``); rows ``v8``: the
  firmware's target index of the previous frame's points (a quoted list).
* ``oob-csv`` (header ``Frame #,# Obj,X,Y,Z,Doppler,Intensity[, y, m, d, h, m, s]``): one row
  per point; a frame without points is one placeholder row with ``# Obj`` 1 and
  X = Y = Z = Doppler = 0.
* ``csv``: any CSV with a header line, read through a column map (``frame=...,x=...,y=...``).

Frame numbers go through :func:`core.formats.recording.frames_from_numbers` (gaps filled with
empty frames, a restart or long gap starts a new run); the frame period comes from the time
stamps. Numbers are parsed in bulk by NumPy's C reader; a bad cell is then located by a slow
pass that names its line and column. See ``docs/real-data.md``.
"""

from __future__ import annotations

import dataclasses
import io
import math
import re
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from core.config import PAPER_RADAR, RadarConfig
from core.errors import InputError
from core.files import decode_utf8, read_bytes
from core.formats.recording import (
    Recording,
    frames_from_numbers,
    point_tracks_from_indices,
    points_to_cloud,
)
from core.formats.ti_uart import linear_snr_db, peak_db
from core.limits import FRAME_PERIOD_RANGE_S

#: Names of the three CSV rows of :data:`core.recordings.FORMATS`.
PEOPLE_CSV = "people-csv"
OOB_CSV = "oob-csv"
MAPPED_CSV = "csv"
#: First header cells of the vendor CSV of TI's people-counting firmware.
PEOPLE_HEADER = ("time", "fn", "type")
#: First header cells of the out-of-box CSV (lower case, stripped).
OOB_HEADER = ("frame #", "# obj", "x", "y", "z", "doppler")
#: Keys of a column map: required, then optional.
MAP_REQUIRED = ("frame", "x", "y")
MAP_OPTIONAL = ("z", "doppler", "snr", "time")
#: Candidate steps of the vendor CSV's SNR (``snr · snrUnit``), largest first; see
#: :func:`_unsigned_snr`.
SNR_UNITS = (1.0, 0.5, 0.25, 0.125, 0.1, 0.05, 0.04, 0.025, 0.02, 0.01)


def _first_line(head: bytes) -> str:
    line = head.split(b"\n", 1)[0].lstrip(b"\xef\xbb\xbf").rstrip(b"\r")
    return line.decode("latin-1")


def _cells(line: str) -> list[str]:
    return [c.strip().lower() for c in line.split(",")]


def sniff_people(head: bytes, path: Path) -> bool:
    return tuple(_cells(_first_line(head))[:3]) == PEOPLE_HEADER


def sniff_oob(head: bytes, path: Path) -> bool:
    return tuple(_cells(_first_line(head))[:6]) == OOB_HEADER


# ---- shared -----------------------------------------------------------------------------------
def _read_text(path: Path, what: str) -> str:
    """The file's text; anything but ASCII digits in a number field (``1_0``, Arabic-Indic
    digits) is refused here, before any number is parsed (Python's ``float`` takes both)."""
    text = decode_utf8(read_bytes(path, what=what), str(path), what=what)
    if not text.isascii():
        k = next(i for i, ch in enumerate(text) if not ch.isascii())
        line = text.count("\n", 0, k) + 1
        raise InputError(
            f"a {what} holds ASCII text only, got {text[k]!r} (U+{ord(text[k]):04X})",
            f"{path}:{line}",
        )
    return text


def _split_header(text: str, path: Path) -> tuple[str, str]:
    header, _, body = text.partition("\n")
    if not body.strip():
        raise InputError("the file holds a header line and no data rows", f"{path}:1")
    return header.rstrip("\r"), body


def parse_numbers(
    lines: str | Sequence[str],
    n_cols: int,
    src: str,
    names: Sequence[str],
    line_numbers: Sequence[int] | None = None,
    first_line: int = 2,
) -> np.ndarray:
    """``(rows, n_cols)`` float64 of comma-separated number rows, every cell finite.

    The bulk parse is NumPy's C reader (plain ASCII decimal numbers only); on any failure a
    row-by-row pass names the first bad ``line`` and field (``names``) with one
    :class:`InputError`. ``line_numbers``: the file line of each row when ``lines`` is a list
    of selected rows; otherwise rows are consecutive lines from ``first_line``, blank lines
    skipped.
    """
    body = lines if isinstance(lines, str) else "\n".join(lines)
    try:
        a = np.loadtxt(io.StringIO(body), delimiter=",", dtype=np.float64, ndmin=2, comments=None)
    except ValueError:
        a = None
    if (
        a is not None
        and a.shape[1:] == (n_cols,)
        and len(a)
        and np.isfinite(a).all()
        and "_" not in body
    ):
        return a
    if a is not None and a.size == 0 and not body.strip():
        return np.zeros((0, n_cols))
    _locate_bad_cell(body, n_cols, src, names, line_numbers, first_line)
    raise InputError("unreadable numbers", src)  # not reached: the slow pass names the cell


def _locate_bad_cell(
    body: str,
    n_cols: int,
    src: str,
    names: Sequence[str],
    line_numbers: Sequence[int] | None,
    first_line: int,
) -> None:
    row = -1
    for k, raw in enumerate(body.split("\n")):
        line = raw.rstrip("\r")
        if line_numbers is None:
            if not line.strip():
                continue
            where = f"{src}:{first_line + k}"
        else:
            row += 1
            where = f"{src}:{line_numbers[row]}" if row < len(line_numbers) else src
        cells = line.split(",")
        if len(cells) != n_cols:
            raise InputError(
                f"expected {n_cols} fields ({', '.join(names)}), got {len(cells)}", where
            )
        for name, c in zip(names, cells):
            s = c.strip()
            bad = not s or "_" in s or not s.isascii()
            if not bad:
                try:
                    v = float(s)
                except ValueError:
                    bad = True
                else:
                    if not math.isfinite(v):
                        raise InputError(f"{name} must be finite, got {s[:40]!r}", where)
            if bad:
                raise InputError(f"{name} must be a number, got {s[:40]!r}", where)


_BLANK_LINE = re.compile(r"(^|\n)[ \t\r]*(\n|$)")


def _row_lines(body: str, n_rows: int, first_line: int = 2) -> np.ndarray:
    """The file line of each data row of ``body`` (blank lines are skipped by the parser)."""
    b = body.rstrip("\r\n")
    maybe_blank = b.startswith(("\n", "\r")) or "\n\n" in b or "\n\r\n" in b
    if not maybe_blank and ("\n " in b or "\n\t" in b or b[:1] in (" ", "\t")):
        maybe_blank = bool(_BLANK_LINE.search(b))  # whitespace-only lines: rare, slow check
    if not maybe_blank:
        return np.arange(n_rows, dtype=np.int64) + first_line
    lines = [k for k, ln in enumerate(body.split("\n"), start=first_line) if ln.strip()]
    return np.asarray(lines[:n_rows], dtype=np.int64)


def _check_times(t: np.ndarray, src: str, lines: np.ndarray, field: str) -> None:
    back = np.flatnonzero(np.diff(t) < 0)
    if len(back):
        k = int(back[0]) + 1
        raise InputError(
            f"{field} goes backwards ({t[k]:.6f} s after {t[k - 1]:.6f} s)", f"{src}:{lines[k]}"
        )


def _frame_grid(
    numbers: np.ndarray, times: np.ndarray | None, radar: RadarConfig | None, src: str, what: str
) -> tuple[np.ndarray, np.ndarray, np.ndarray, RadarConfig, list[str]]:
    """Rows (frame number, host time) on the frame grid.

    Returns the slot of each row, the frame times ``t_s`` (s from the first frame: host time
    stamps; frames inserted for missing numbers interpolated between their neighbours), the run
    of each frame, the radar (``radar`` or the paper's, with the frame period measured from the
    time stamps) and notes.
    """
    notes: list[str] = []
    slot, t_grid, trajectory, n_filled = frames_from_numbers(numbers, 1.0)
    period = None
    if times is not None and len(times):
        first = np.flatnonzero(np.concatenate(([True], np.diff(slot) != 0)))
        frame_t = np.full(len(t_grid), np.nan)
        frame_t[slot[first]] = times[first]
        period = _measured_period(numbers[first], times[first], trajectory[slot[first]], src)
        have = np.isfinite(frame_t)
        idx = np.arange(len(frame_t))
        t_s = np.interp(idx, idx[have], frame_t[have]) - frame_t[have][0]
    if radar is None:
        base = PAPER_RADAR
        assumed = "no --cfg: the paper radar assumed"
    else:
        base = radar
        assumed = ""
    if period is None:
        cfg = base
        t_s = t_grid * cfg.frame_period_s
        notes.append(
            f"no time stamps that give a frame period: {cfg.frame_period_s * 1e3:g} ms "
            + ("from --cfg" if radar is not None else "of the paper radar assumed")
        )
    else:
        if radar is not None and abs(period - radar.frame_period_s) > 0.1 * radar.frame_period_s:
            notes.append(
                f"the time stamps give a frame period of {period * 1e3:.1f} ms, the --cfg "
                f"{radar.frame_period_s * 1e3:g} ms: the time stamps' is used"
            )
        try:
            cfg = dataclasses.replace(base, frame_period_s=period)
        except ValueError as exc:
            raise InputError(
                f"the time stamps' frame period does not fit the radar: {exc}", src
            ) from None
        notes.append(
            f"frame period {period * 1e3:.1f} ms from the time stamps"
            + (f"; {assumed}" if assumed else "")
        )
    if n_filled:
        notes.append(f"{n_filled} empty frames inserted for missing frame numbers")
    n_runs = int(trajectory[-1]) + 1 if len(trajectory) else 0
    if n_runs > 1:
        notes.append(f"{n_runs} runs (frame numbers restart or jump by more than 100)")
    return slot, t_s, trajectory, cfg, notes


def _measured_period(
    numbers: np.ndarray, times: np.ndarray, run: np.ndarray, src: str
) -> float | None:
    """The frame period of the longest run: its time span over its frame-number span (robust to
    the jitter of host time stamps, which arrive in bursts); None if no run spans two frames."""
    best = None
    for r in np.unique(run):
        sel = run == r
        span = int(numbers[sel][-1] - numbers[sel][0])
        if span >= 1 and (best is None or span > best[0]):
            best = (span, float(times[sel][-1] - times[sel][0]))
    if best is None:
        return None
    period = best[1] / best[0]
    lo, hi = FRAME_PERIOD_RANGE_S
    if not lo <= period <= hi:
        raise InputError(
            f"the time stamps give a frame period of {period:.3g} s over {best[0]} frames, "
            f"outside [{lo:g}, {hi:g}] s (all equal, or in the wrong unit?)",
            src,
        )
    return period


def _recording(
    fmt: str,
    x: np.ndarray,
    y: np.ndarray,
    z: np.ndarray,
    v: np.ndarray,
    snr_db: np.ndarray,
    row_slot: np.ndarray,
    t_s: np.ndarray,
    trajectory: np.ndarray,
    radar: RadarConfig,
    notes: list[str],
    meta: dict,
) -> Recording:
    cloud, keep = points_to_cloud(x, y, z, v, snr_db)
    counts = np.bincount(row_slot[keep], minlength=len(t_s)).astype(np.int64)
    return Recording(
        format=fmt,
        cloud=cloud,
        counts=counts,
        t_s=t_s,
        trajectory=trajectory,
        radar=radar,
        notes=tuple(notes),
        meta=meta,
    )


# ---- out-of-box CSV -----------------------------------------------------------------------------
def read_oob(path: Path, radar: RadarConfig | None) -> Recording:
    """The out-of-box CSV; see the module docstring."""
    src = str(path)
    text = _read_text(path, "out-of-box CSV")
    header, body = _split_header(text, path)
    head = _cells(header)
    if tuple(head[:6]) != OOB_HEADER:
        raise InputError(
            f"the header must start with Frame #,# Obj,X,Y,Z,Doppler, got {header[:80]!r}",
            f"{src}:1",
        )
    extra = len(head) - 6
    if extra not in (0, 1, 7):
        raise InputError(
            "after Doppler the header must name Intensity and optionally the six date and time "
            f"columns (year, month, day, hour, minute, second), got {extra} more columns",
            f"{src}:1",
        )
    names = ["Frame #", "# Obj", "X", "Y", "Z", "Doppler", "Intensity"][: 6 + min(extra, 1)]
    names += ["year", "month", "day", "hour", "minute", "second"][: max(extra - 1, 0)]
    a = parse_numbers(body, len(head), src, names)
    n_rows = len(a)
    line_of_row = _row_lines(body, n_rows)
    fn = a[:, 0]
    bad = np.flatnonzero((fn != np.round(fn)) | (fn < 0) | (fn >= 2**53))
    if len(bad):
        raise InputError(
            f"Frame # must be an integer >= 0, got {fn[bad[0]]:g}", f"{src}:{line_of_row[bad[0]]}"
        )
    numbers = fn.astype(np.int64)
    times = None
    if extra == 7:
        times = _date_columns(a[:, 7:13], src, line_of_row)
        _check_times(times, src, line_of_row, "the date and time")
    placeholder = (a[:, 1] == 1) & (a[:, 2] == 0) & (a[:, 3] == 0) & (a[:, 4] == 0) & (a[:, 5] == 0)
    slot, t_s, trajectory, cfg, notes = _frame_grid(numbers, times, radar, src, "out-of-box CSV")
    pts = ~placeholder
    if extra >= 1:
        snr = peak_db(a[:, 6])
        notes.append(
            "SNR: 20·log10(Intensity), the linear peak value on a dB scale (the noise level is "
            "not in the file: it ranks points, it is not an SNR)"
        )
    else:
        snr = np.full(n_rows, np.nan)
    notes.insert(
        0,
        f"{src}: {n_rows} rows, {int(placeholder.sum())} placeholder rows of empty frames, "
        f"{int(pts.sum())} points",
    )
    return _recording(
        OOB_CSV,
        a[pts, 2],
        a[pts, 3],
        a[pts, 4],
        a[pts, 5],
        snr[pts],
        slot[pts],
        t_s,
        trajectory,
        cfg,
        notes,
        {"rows": n_rows},
    )


def _date_columns(d: np.ndarray, src: str, line_of_row: np.ndarray) -> np.ndarray:
    """Seconds since the first row's midnight from year, month, day, hour, minute, second."""
    ymd = d[:, 0] * 10000 + d[:, 1] * 100 + d[:, 2]
    hms = d[:, 3] * 3600.0 + d[:, 4] * 60.0 + d[:, 5]
    bad = np.flatnonzero(
        (d[:, :5] != np.round(d[:, :5])).any(axis=1)
        | (d[:, 1] < 1)
        | (d[:, 1] > 12)
        | (d[:, 2] < 1)
        | (d[:, 2] > 31)
        | (d[:, 3] < 0)
        | (d[:, 3] > 23)
        | (d[:, 4] < 0)
        | (d[:, 4] > 59)
        | (d[:, 5] < 0)
        | (d[:, 5] >= 61)
        | (d[:, 0] < 1)
        | (d[:, 0] > 9999)
    )
    if len(bad):
        k = int(bad[0])
        raise InputError(
            f"the date and time columns must be year, month, day, hour, minute, second, got "
            f"{', '.join(f'{v:g}' for v in d[k])}",
            f"{src}:{line_of_row[k]}",
        )
    uniq, inv = np.unique(ymd, return_inverse=True)
    days = np.empty(len(uniq))
    for i, u in enumerate(uniq):
        y, m, dd = int(u // 10000), int(u // 100 % 100), int(u % 100)
        try:
            days[i] = float(np.datetime64(f"{y:04d}-{m:02d}-{dd:02d}", "D").astype(np.int64))
        except ValueError:
            k = int(np.flatnonzero(inv == i)[0])
            raise InputError(f"no such date {y}-{m}-{dd}", f"{src}:{line_of_row[k]}") from None
    t = (days[inv] - days[inv[0]]) * 86400.0 + hms  # small numbers: no float64 rounding
    return t - t[0]


# ---- people-counting vendor CSV --------------------------------------------------------------
#: Names of the eight positional values of a ``v6`` row, in the 2023 library's order.
V6_NAMES = ("elevation", "azimuth", "range", "doppler", "snr", "x", "y", "z")


def read_people(path: Path, radar: RadarConfig | None) -> Recording:
    """The vendor CSV of TI's people-counting firmware; see the module docstring.

    TI's tracks (``v7``) and target indices (``v8``) are kept as the recording's
    ``ref_tracks`` and ``ref_point_track`` (the data set's reference layer).
    """
    src = str(path)
    text = _read_text(path, "people-counting CSV")
    header, body = _split_header(text, path)
    head = [c.strip() for c in header.split(",")]
    if tuple(c.lower() for c in head[:3]) != PEOPLE_HEADER:
        raise InputError(
            f"the header must start with time,fN,type, got {header[:80]!r}", f"{src}:1"
        )
    v7_names = head[3:]
    rows: dict[str, list[str]] = {"v6": [], "v7": [], "v8": []}
    lines: dict[str, list[int]] = {"v6": [], "v7": [], "v8": []}
    stamps: dict[str, list[str]] = {"v6": [], "v7": [], "v8": []}
    numbers: dict[str, list[str]] = {"v6": [], "v7": [], "v8": []}
    other = 0
    for k, raw in enumerate(body.split("\n"), start=2):
        line = raw.rstrip("\r")
        if not line.strip():
            continue
        parts = line.split(",", 3)
        if len(parts) < 4:
            raise InputError("expected time,fN,type and values", f"{src}:{k}")
        kind = parts[2].strip()
        if kind not in rows:
            other += 1
            continue
        rows[kind].append(parts[3])
        lines[kind].append(k)
        stamps[kind].append(parts[0])
        numbers[kind].append(parts[1])
    if not rows["v6"] and not rows["v7"]:
        raise InputError("no v6 (point) or v7 (track) rows", src)
    # frames: every row kind carries the frame number and time; points and tracks define frames
    all_kinds = ("v6", "v7", "v8")
    fn_text = [s for kd in all_kinds for s in numbers[kd]]
    fn_lines = np.array([n for kd in all_kinds for n in lines[kd]], dtype=np.int64)
    fn_all = _integers(fn_text, fn_lines, src, "fN")
    t_all = _timestamps([s for kd in all_kinds for s in stamps[kd]], fn_lines, src)
    order = np.argsort(fn_lines, kind="stable")  # file order
    fn_f, t_f, line_f = fn_all[order], t_all[order], fn_lines[order]
    _check_times(t_f, src, line_f, "time")
    slot_f, t_s, trajectory, cfg, notes = _frame_grid(fn_f, t_f, radar, src, "people-counting CSV")
    slot_all = np.empty_like(slot_f)
    slot_all[order] = slot_f
    bounds = np.cumsum([0] + [len(numbers[kd]) for kd in all_kinds])
    slot_of = {kd: slot_all[bounds[i] : bounds[i + 1]] for i, kd in enumerate(all_kinds)}

    # points
    p = parse_numbers(rows["v6"], 8, src, V6_NAMES, lines["v6"]) if rows["v6"] else np.zeros((0, 8))
    el, az, c2, c3, snr_raw, x, y, z = p.T
    r_xyz = np.sqrt(x * x + y * y + z * z)
    err_range_first = float(np.median(np.abs(c2 - r_xyz))) if len(p) else 0.0
    err_doppler_first = float(np.median(np.abs(c3 - r_xyz))) if len(p) else 0.0
    if err_range_first <= err_doppler_first:
        doppler, order_note = c3, "range before Doppler"
    else:
        doppler, order_note = c2, "Doppler before range"
    snr_lin, snr_note = _unsigned_snr(snr_raw)
    snr_db = linear_snr_db(snr_lin)
    notes.insert(
        0,
        f"{src}: {len(rows['v6'])} points (v6, {order_note} in this file), "
        f"{len(rows['v7'])} TI track rows (v7), {len(rows['v8'])} target-index rows (v8)"
        + (f", {other} rows of other types skipped" if other else ""),
    )
    notes.append("SNR: the firmware's linear SNR as 10·log10(snr)" + snr_note)

    ref = _tracks(rows["v7"], lines["v7"], v7_names, src)
    point_track, matched = _point_track(
        rows["v8"], lines["v8"], slot_of["v8"], slot_of["v6"], len(t_s), src
    )
    if rows["v8"]:
        notes.append(
            f"target indices: {matched} of {len(rows['v8'])} v8 rows match the previous frame's "
            "point count and label its points (the rest are not used)"
        )
    rec = _recording(
        PEOPLE_CSV, x, y, z, doppler, snr_db, slot_of["v6"], t_s, trajectory, cfg, notes, {}
    )
    return dataclasses.replace(
        rec,
        ref_tracks=None if ref is None else {"frame": slot_of["v7"], **ref},
        ref_point_track=point_track if rows["v8"] else None,
    )


def _integers(cells: list[str], lines: np.ndarray, src: str, field: str) -> np.ndarray:
    try:
        a = np.array(cells, dtype=np.int64) if cells else np.zeros(0, np.int64)
    except (ValueError, OverflowError):
        a = None
    if a is not None and all("_" not in c for c in cells):
        neg = np.flatnonzero(a < 0)
        if not len(neg):
            return a
        cells = [cells[int(neg[0])]]
        lines = lines[neg[:1]]
    for c, n in zip(cells, lines):
        s = c.strip()
        if not (s.isascii() and s.isdigit()):
            raise InputError(f"{field} must be an integer >= 0, got {s[:40]!r}", f"{src}:{n}")
    raise InputError(f"{field} must be an integer >= 0", src)


#: A host time stamp of the vendor CSV.
_STAMP = re.compile(r"^\d{4}-\d{2}-\d{2}[ T]\d{2}:\d{2}:\d{2}(\.\d{1,9})?$", re.ASCII)


def _timestamps(cells: list[str], lines: np.ndarray, src: str) -> np.ndarray:
    """Host time stamps ``YYYY-MM-DD hh:mm:ss[.ffffff]`` as seconds from the first."""
    uniq, inv = np.unique(np.array(cells, dtype=str), return_inverse=True)
    t = np.empty(len(uniq), dtype=np.int64)
    for i, s in enumerate(uniq):
        try:
            if not _STAMP.match(s.strip()):
                raise ValueError(s)
            t[i] = np.datetime64(s.strip().replace(" ", "T"), "us").astype(np.int64)
        except ValueError:
            k = int(np.flatnonzero(inv == i)[0])
            raise InputError(
                f"time must be a date and time YYYY-MM-DD hh:mm:ss.ffffff, got {s[:40]!r}",
                f"{src}:{lines[k]}",
            ) from None
    out = t[inv]
    # integer microseconds from the first stamp, then seconds (no float64 rounding of epochs)
    return (out - out[0]) * 1e-6 if len(out) else out.astype(np.float64)


def _unsigned_snr(snr: np.ndarray) -> tuple[np.ndarray, str]:
    """The firmware sends SNR as an unsigned 16-bit count times ``snrUnit``; some library
    versions read the count as signed, so counts above 32 767 arrive negative. The unit is the
    largest step of :data:`SNR_UNITS` on whose grid every value lies; a negative value is
    then ``+ 65536·unit``."""
    neg = snr < 0
    if not neg.any():
        return snr, ""
    for unit in SNR_UNITS:
        q = snr / unit
        if np.all(np.abs(q - np.round(q)) < 1e-3):
            fixed = np.where(neg, snr + 65536 * unit, snr)
            return fixed, (
                f"; {int(neg.sum())} negative SNR values read as unsigned "
                f"(+65536 × {unit:g}, the SNR step of this file)"
            )
    return np.where(neg, np.nan, snr), (
        f"; {int(neg.sum())} negative SNR values without a recognisable step: no SNR for them"
    )


#: Columns of a ``v7`` row kept in the reference layer (header name -> key).
V7_KEEP = {
    "tid": "track_id",
    "posX": "x_m",
    "posY": "y_m",
    "posZ": "z_m",
    "velX": "vx_mps",
    "velY": "vy_mps",
}


def _tracks(rows: list[str], lines: list[int], names: list[str], src: str) -> dict | None:
    if not rows:
        return None
    missing = [n for n in V7_KEEP if n not in names and n != "posZ"]
    if missing:
        raise InputError(f"the header does not name the v7 columns {missing}", f"{src}:1")
    a = parse_numbers(rows, len(names), src, names, lines)
    out: dict = {}
    for name, key in V7_KEEP.items():
        out[key] = a[:, names.index(name)] if name in names else np.zeros(len(a))
    tid = out["track_id"]
    bad = np.flatnonzero((tid != np.round(tid)) | (tid < 0) | (tid >= 2**31))
    if len(bad):
        raise InputError(
            f"tid must be an integer >= 0, got {tid[bad[0]]:g}", f"{src}:{lines[bad[0]]}"
        )
    out["track_id"] = tid.astype(np.int64)
    return out


def _point_track(
    rows: list[str],
    lines: list[int],
    v8_slot: np.ndarray,
    v6_slot: np.ndarray,
    n_frames: int,
    src: str,
) -> tuple[np.ndarray, int]:
    """Per point, the id of TI's track it was given to (-1: none), from the ``v8`` rows (see
    :func:`core.formats.recording.point_tracks_from_indices`)."""
    indices: list[tuple[int, np.ndarray]] = []
    for text, n, f in zip(rows, lines, v8_slot):
        s = text.strip().strip('"').strip()
        if not (s.startswith("[") and s.endswith("]")):
            raise InputError("a v8 row must hold a quoted list [i, j, ...]", f"{src}:{n}")
        inner = s[1:-1].strip()
        cells = [c.strip() for c in inner.split(",")] if inner else []
        if not all(c.isascii() and c.isdigit() for c in cells):
            raise InputError("a v8 list must hold integers >= 0", f"{src}:{n}")
        indices.append((int(f), np.array([int(c) for c in cells], dtype=np.int64)))
    counts = np.bincount(v6_slot, minlength=n_frames)
    return point_tracks_from_indices(counts, indices)


# ---- any CSV with a column map ---------------------------------------------------------------
def parse_column_map(spec: str) -> dict[str, str]:
    """``frame=Frame,x=X,y=Y[,z=...,doppler=...,snr=...,time=...]`` as a dict."""
    out: dict[str, str] = {}
    for part in spec.split(","):
        key, eq, col = part.partition("=")
        key, col = key.strip().lower(), col.strip()
        if not eq or not col:
            raise InputError(f"--columns entries must be key=column, got {part.strip()!r}")
        if key not in (*MAP_REQUIRED, *MAP_OPTIONAL):
            raise InputError(
                f"--columns key must be one of {', '.join((*MAP_REQUIRED, *MAP_OPTIONAL))}, got "
                f"{key!r}"
            )
        if key in out:
            raise InputError(f"--columns names {key!r} twice")
        out[key] = col
    missing = [k for k in MAP_REQUIRED if k not in out]
    if missing:
        raise InputError(f"--columns must map {', '.join(missing)}")
    return out


def read_mapped(path: Path, radar: RadarConfig | None, columns: dict[str, str] | None) -> Recording:
    """Any CSV whose header names the columns of ``columns`` (``time`` in s, SNR in dB; other
    columns ignored; every column must hold numbers)."""
    src = str(path)
    if not columns:
        raise InputError(
            "a plain CSV needs a column map: --columns frame=...,x=...,y=...[,z=,doppler=,snr=,"
            "time=]",
            src,
        )
    text = _read_text(path, "CSV")
    header, body = _split_header(text, path)
    head = [c.strip() for c in header.split(",")]
    where: dict[str, int] = {}
    for key, name in columns.items():
        if name not in head:
            raise InputError(
                f"--columns {key}={name}: no such column in the header ({', '.join(head)[:80]})",
                f"{src}:1",
            )
        where[key] = head.index(name)
    a = parse_numbers(body, len(head), src, head)
    line_of_row = _row_lines(body, len(a))
    fn = a[:, where["frame"]]
    bad = np.flatnonzero((fn != np.round(fn)) | (fn < 0) | (fn >= 2**53))
    if len(bad):
        raise InputError(
            f"{columns['frame']} (frame) must be an integer >= 0, got {fn[bad[0]]:g}",
            f"{src}:{line_of_row[bad[0]]}",
        )
    times = None
    if "time" in where:
        times = a[:, where["time"]] - a[0, where["time"]]
        _check_times(times, src, line_of_row, columns["time"])
    slot, t_s, trajectory, cfg, notes = _frame_grid(fn.astype(np.int64), times, radar, src, "CSV")
    n = len(a)

    def col(key: str) -> np.ndarray:
        return a[:, where[key]] if key in where else np.zeros(n)

    snr = a[:, where["snr"]] if "snr" in where else np.full(n, np.nan)
    notes.insert(0, f"{src}: {n} points through the column map")
    if "doppler" not in where:
        notes.append("no doppler column: radial velocity 0 for every point")
    return _recording(
        MAPPED_CSV,
        col("x"),
        col("y"),
        col("z"),
        col("doppler"),
        snr,
        slot,
        t_s,
        trajectory,
        cfg,
        notes,
        {},
    )
