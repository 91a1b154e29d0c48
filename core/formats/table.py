"""The one table of recording formats ``radartune import`` / ``export`` know.

Each row (:class:`FileFormat`): a name, how to recognise a file (``sniff``), how to read it into
a :class:`~core.formats.recording.Recording` and, where supported, how to write a simulated
scene in it. A new format is a new row in :data:`FORMATS` (see ``docs/real-data.md``).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from core.config import RadarConfig
from core.errors import InputError
from core.formats import ti_replay, ti_uart_import
from core.formats.recording import Recording
from core.pointcloud import PointCloud


@dataclass(frozen=True, slots=True, kw_only=True)
class FileFormat:
    """One row of :data:`FORMATS`.

    ``sniff(head, path)``: True when a file whose first bytes are ``head`` is in this format.
    ``read(path, radar)``: the :class:`Recording` (``radar`` from ``--cfg`` or None).
    ``write(path, clouds, radar, variant)``: the files written for a simulated scene's point
    clouds, one per frame (the data file and its ``.cfg``), or None when the format cannot be
    written; ``variants``: the values ``--variant`` accepts (first: the default).
    ``write_scene(path, scene, *, seed, fidelity, variant)``: for formats that need more than
    point clouds (a DCA1000 capture needs the ADC samples): writes from the scene itself;
    ``radartune export`` calls it instead of simulating and calling ``write``.
    """

    name: str
    description: str
    suffixes: tuple[str, ...]
    sniff: Callable[[bytes, Path], bool]
    read: Callable[[Path, RadarConfig | None], Recording]
    write: Callable[[Path, Sequence[PointCloud], RadarConfig, str | None], list[Path]] | None = None
    variants: tuple[str, ...] = ()
    write_scene: Callable[..., list[Path]] | None = None


def _uart_row() -> FileFormat:
    return FileFormat(
        name="uart",
        description="TI mmWave demo UART stream (Demo Visualizer .dat, serial dumps), every SDK",
        suffixes=(".dat", ".bin", ".uart", ".log"),
        sniff=ti_uart_import.sniff,
        read=ti_uart_import.read,
        write=ti_uart_import.write,
        variants=ti_uart_import.VARIANTS,
    )


def _replay_row() -> FileFormat:
    return FileFormat(
        name="replay",
        description="TI Industrial Visualizer replay (replay_N.json, or a folder of them)",
        suffixes=(".json",),
        sniff=ti_replay.sniff,
        read=ti_replay.read,
        write=ti_replay.write,
    )


#: name -> row, in the order auto-detection tries them. The DCA1000 reader adds its row here.
FORMATS: dict[str, FileFormat] = {row.name: row for row in (_uart_row(), _replay_row())}

#: Bytes read from the start of a file to recognise its format.
SNIFF_BYTES = 1 << 16


def detect_format(path: Path) -> FileFormat:
    """The format of ``path`` (first by content, then by suffix); one line if none fits."""
    if path.is_dir():
        head = b""
    else:
        try:
            with open(path, "rb") as fh:
                head = fh.read(SNIFF_BYTES)
        except OSError as exc:
            raise InputError(f"cannot read ({exc.strerror or exc})", str(path)) from None
        if not head:
            raise InputError("empty file: no bytes to read", f"{path}:0")
    for row in FORMATS.values():
        if row.sniff(head, path):
            return row
    raise InputError(
        f"format not recognised (none of {', '.join(FORMATS)} fits its first bytes); give --format",
        str(path),
    )


def read_recording(
    path: str | os.PathLike, *, fmt: str | None, radar: RadarConfig | None
) -> Recording:
    path = Path(path)
    if not path.exists():
        raise InputError("no such file", str(path))
    if fmt is None:
        row = detect_format(path)
    elif fmt in FORMATS:
        row = FORMATS[fmt]
    else:
        raise InputError(f"--format must be one of {list(FORMATS)}, got {fmt!r}")
    return row.read(path, radar)
