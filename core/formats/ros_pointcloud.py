"""Point clouds of TI's ROS driver as ``rostopic echo`` text (e.g. the RadHAR recordings).

The ``ti_mmwave_rospkg`` driver publishes one message per detected point; ``rostopic echo``
prints each as a block of ``key: value`` lines ending in ``---``::

    header:
      seq: 1415037
      stamp:
        secs: 1561683490
        nsecs: 283427298
      frame_id: "ti_mmwave"
    point_id: 0
    x: 0.01171875
    ...
    intensity: 30.7627620697
    ---

``point_id: 0`` starts a new frame. The driver's axes are ROS's: ``x`` forward (the radar's
boresight), ``y`` to the left, ``z`` up. :func:`read_ros_pointcloud` turns them into
RadarTune's (``y`` along boresight, ``x`` to the right: ``x_m = -y_ros``, ``y_m = x_ros``).

The file is read line by line (it is never held in memory whole); a malformed block raises one
:class:`~core.errors.InputError` naming file, line and field.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from core.errors import InputError
from core.limits import MAX_DATASET_FRAMES, MAX_NPZ_ELEMENTS

#: Fields of one point block (besides ``header``), in the driver's order.
ROS_POINT_FIELDS = (
    "point_id",
    "x",
    "y",
    "z",
    "range",
    "velocity",
    "doppler_bin",
    "bearing",
    "intensity",
)
#: Indented lines of the ``header`` block: accepted, only ``secs`` and ``nsecs`` are kept.
_HEADER_KEYS = ("seq", "stamp", "secs", "nsecs", "frame_id")


@dataclass(frozen=True, slots=True, kw_only=True)
class RosPointCloud:
    """All points of a recording, struct-of-arrays in file order.

    Per point (length P): ``frame`` (index of its frame, from 0, non-decreasing), ``x_m``,
    ``y_m``, ``z_m`` (m, RadarTune axes: ``y`` boresight, ``x`` right), ``range_m`` (m),
    ``radial_velocity_mps`` (m/s, the driver's ``velocity``), ``intensity_db`` (the driver's
    ``intensity``: 10 log10 of the detection's peak power, dB, arbitrary reference).
    Per frame (length F): ``t_s`` (time stamp of its first point, s since the epoch).
    """

    frame: np.ndarray
    x_m: np.ndarray
    y_m: np.ndarray
    z_m: np.ndarray
    range_m: np.ndarray
    radial_velocity_mps: np.ndarray
    intensity_db: np.ndarray
    t_s: np.ndarray

    @property
    def n_frames(self) -> int:
        return len(self.t_s)

    @property
    def frame_offsets(self) -> np.ndarray:
        """Points of frame f are ``offsets[f]:offsets[f+1]``, shape (F+1,)."""
        return np.searchsorted(self.frame, np.arange(self.n_frames + 1)).astype(np.int64)


def iter_ros_points(path: str | os.PathLike) -> Iterator[tuple[int, dict[str, float]]]:
    """The point blocks of a ``rostopic echo`` file, one at a time.

    Yields
    ------
    line, point
        The line number of the block's ``---`` and a dict of the :data:`ROS_POINT_FIELDS` plus
        ``t_s`` (header stamp, s).

    Raises
    ------
    InputError
        ``file:line`` and the field of the first malformed line or incomplete block.
    """
    src = os.fspath(path)
    try:
        fh = open(src, "rb")  # noqa: SIM115 (closed in finally; a generator)
    except OSError as exc:
        raise InputError(f"cannot read point-cloud file: {exc.strerror}", src) from None
    try:
        block: dict[str, float] = {}
        secs = nsecs = None
        n = 0
        for n, raw in enumerate(fh, start=1):
            where = f"{src}:{n}"
            try:
                line = raw.decode("utf-8").rstrip("\r\n")
            except UnicodeDecodeError:
                raise InputError("not UTF-8 text", where) from None
            if not line.strip():
                continue
            if line == "---":
                missing = [k for k in ROS_POINT_FIELDS if k not in block]
                if missing:
                    raise InputError(f"point block without field(s) {missing}", where)
                if secs is None or nsecs is None:
                    raise InputError("point block without header stamp secs/nsecs", where)
                block["t_s"] = secs + 1e-9 * nsecs
                yield n, block
                block, secs, nsecs = {}, None, None
                continue
            key, sep, value = line.partition(":")
            name = key.strip()
            if not sep:
                raise InputError(f"expected 'key: value', got {line[:40]!r}", where)
            if key.startswith(" "):
                if name not in _HEADER_KEYS:
                    raise InputError(f"unknown header field {name!r}", where)
                if name in ("secs", "nsecs"):
                    stamp = _number(value, name, where)
                    if name == "secs":
                        secs = stamp
                    else:
                        nsecs = stamp
                continue
            if name == "header":
                continue
            if name not in ROS_POINT_FIELDS:
                raise InputError(
                    f"unknown field {name!r} (expected header or one of {list(ROS_POINT_FIELDS)})",
                    where,
                )
            if name in block:
                raise InputError(f"field {name!r} twice in one block (a '---' missing?)", where)
            block[name] = _number(value, name, where)
        if block:
            raise InputError("file ends inside a point block (no final '---')", f"{src}:{n}")
    finally:
        fh.close()


def read_ros_pointcloud(path: str | os.PathLike) -> RosPointCloud:
    """Read a ``rostopic echo`` point-cloud file (streaming) into one :class:`RosPointCloud`.

    ``point_id: 0`` starts a frame; within a frame the ids must increase.

    Raises
    ------
    InputError
        Malformed text (see :func:`iter_ros_points`), a ``point_id`` that does not increase, a
        file without points, or more frames or points than the limits allow.
    """
    src = os.fspath(path)
    cols: dict[str, list[float]] = {k: [] for k in ("x", "y", "z", "range", "velocity")}
    intensity: list[float] = []
    frame: list[int] = []
    t_s: list[float] = []
    last_id = -1
    for line, p in iter_ros_points(path):
        pid = p["point_id"]
        if pid != int(pid) or pid < 0:
            raise InputError(f"point_id must be an integer >= 0, got {pid}", f"{src}:{line}")
        if pid == 0:
            t_s.append(p["t_s"])
            if len(t_s) > MAX_DATASET_FRAMES:
                raise InputError(f"more than {MAX_DATASET_FRAMES} frames", f"{src}:{line}")
        elif not t_s or pid <= last_id:
            raise InputError(
                f"point_id {int(pid)} after {last_id}: ids must start at 0 and increase within "
                "a frame",
                f"{src}:{line}",
            )
        last_id = int(pid)
        frame.append(len(t_s) - 1)
        if len(frame) > MAX_NPZ_ELEMENTS:
            raise InputError(f"more than {MAX_NPZ_ELEMENTS} points", f"{src}:{line}")
        for k, v in cols.items():
            v.append(p[k])
        intensity.append(p["intensity"])
    if not frame:
        raise InputError("no point blocks in the file", src)
    return RosPointCloud(
        frame=np.asarray(frame, dtype=np.int64),
        x_m=-np.asarray(cols["y"]),
        y_m=np.asarray(cols["x"]),
        z_m=np.asarray(cols["z"]),
        range_m=np.asarray(cols["range"]),
        radial_velocity_mps=np.asarray(cols["velocity"]),
        intensity_db=np.asarray(intensity),
        t_s=np.asarray(t_s),
    )


def _number(value: str, name: str, where: str) -> float:
    """One finite number, or an :class:`InputError` naming the field."""
    text = value.strip()
    try:
        x = float(text)
    except ValueError:
        raise InputError(f"{name} must be a number, got {text[:40]!r}", where) from None
    if not np.isfinite(x):
        raise InputError(f"{name} must be finite, got {text[:40]!r}", where)
    return x
