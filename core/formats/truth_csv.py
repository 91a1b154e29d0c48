"""Ground truth of a recording as CSV: one row per person and time, ``time_s,person,x_m,y_m``.

A header line names the columns (in any order; other columns are ignored). Positions are linearly
interpolated to the frame times within each person's recorded span (NaN outside it: the person is
absent); the velocity is the slope of the segment a frame time falls in.
"""

from __future__ import annotations

import csv
import math
import os

import numpy as np

from core.errors import InputError
from core.files import printable, read_text
from core.limits import MAX_PERSONS

TRUTH_COLUMNS = ("time_s", "person", "x_m", "y_m")


def read_truth_rows(path: str | os.PathLike) -> dict[int, np.ndarray]:
    """The rows of a truth CSV per person id: ``(n, 3)`` float64 ``[t, x, y]``, time-sorted.

    Raises
    ------
    InputError
        Naming the file and line: a missing column, a value that is not a finite number, a
        negative or non-integer person id, a repeated time of one person, a person with fewer
        than two rows, more than :data:`~core.limits.MAX_PERSONS` persons.
    """
    src = printable(str(path))
    text = read_text(path, what="truth CSV")
    lines = text.splitlines()
    if not lines or not lines[0].strip():
        raise InputError(f"empty truth CSV: a header {','.join(TRUTH_COLUMNS)} expected", src)
    header = [h.strip() for h in next(csv.reader([lines[0]]))]
    missing = [c for c in TRUTH_COLUMNS if c not in header]
    if missing:
        raise InputError(f"truth CSV header lacks column(s) {missing}, got {header}", f"{src}:1")
    col = {c: header.index(c) for c in TRUTH_COLUMNS}
    rows: dict[int, list[tuple[float, float, float, int]]] = {}
    for number, fields in enumerate(csv.reader(lines[1:]), start=2):
        if not fields or all(not f.strip() for f in fields):
            continue
        where = f"{src}:{number}"
        if len(fields) < len(header):
            raise InputError(f"{len(header)} fields expected, got {len(fields)}", where)
        values = {}
        for c in ("time_s", "x_m", "y_m"):
            try:
                values[c] = float(fields[col[c]])
            except ValueError:
                raise InputError(f"{c}: a number expected, got {fields[col[c]]!r}", where) from None
            if not math.isfinite(values[c]):
                raise InputError(f"{c}: not finite, got {fields[col[c]]!r}", where)
        text_id = fields[col["person"]].strip()
        if not text_id.isdigit():
            raise InputError(f"person: an integer >= 0 expected, got {text_id!r}", where)
        rows.setdefault(int(text_id), []).append(
            (values["time_s"], values["x_m"], values["y_m"], number)
        )
        if len(rows) > MAX_PERSONS:
            raise InputError(f"more than {MAX_PERSONS} persons", where)
    out = {}
    for pid, items in sorted(rows.items()):
        items.sort()
        if len(items) < 2:
            raise InputError(
                f"person {pid} has one row: two or more needed", f"{src}:{items[0][3]}"
            )
        t = np.array([r[0] for r in items])
        dup = np.flatnonzero(np.diff(t) == 0)
        if dup.size:
            line = items[dup[0] + 1][3]
            raise InputError(f"person {pid} has time_s {t[dup[0]]!r} twice", f"{src}:{line}")
        out[pid] = np.array([r[:3] for r in items], dtype=np.float64)
    return out


def truth_at_frames(
    rows: dict[int, np.ndarray], frame_t_s: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Positions and velocities of the persons at the frame times.

    Parameters
    ----------
    rows
        :func:`read_truth_rows`'s output.
    frame_t_s
        ``(F,)`` frame times, s.

    Returns
    -------
    xy, v : numpy.ndarray
        ``(F, n_persons, 2)`` m and m/s, persons in id order; NaN where a frame time is outside
        a person's first and last row.
    """
    t = np.asarray(frame_t_s, dtype=np.float64)
    xy = np.full((len(t), len(rows), 2), np.nan)
    v = np.full_like(xy, np.nan)
    for k, tr in enumerate(rows.values()):
        ts, pos = tr[:, 0], tr[:, 1:]
        inside = (t >= ts[0]) & (t <= ts[-1])
        # segment j: ts[j] <= t <= ts[j + 1]
        j = np.clip(np.searchsorted(ts, t[inside], side="right") - 1, 0, len(ts) - 2)
        # p(t) = p_j + (t - t_j) (p_{j+1} - p_j) / (t_{j+1} - t_j)
        slope = (pos[j + 1] - pos[j]) / (ts[j + 1] - ts[j])[:, None]
        xy[inside, k] = pos[j] + (t[inside] - ts[j])[:, None] * slope
        v[inside, k] = slope
    return xy, v
