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
from typing import TYPE_CHECKING

from core.config import RadarConfig
from core.errors import InputError
from core.formats import pointcloud_csv, ti_replay, ti_uart, ti_uart_import
from core.formats.dca1000 import CAPTURE_FORMAT
from core.formats.recording import Recording
from core.formats.ti_cfg import read_ti_cfg
from core.pointcloud import PointCloud

if TYPE_CHECKING:
    from core.scene import Scene


@dataclass(frozen=True, slots=True, kw_only=True)
class FileFormat:
    """One row of :data:`FORMATS`.

    ``sniff(head, path)``: True when a file whose first bytes are ``head`` is in this format.
    ``read(path, cfg)``: the :class:`Recording` (``cfg``: the TI ``.cfg`` given with ``--cfg``,
    or None).
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
    read: Callable[[Path, Path | None], Recording]
    write: Callable[[Path, Sequence[PointCloud], RadarConfig, str | None], list[Path]] | None = None
    variants: tuple[str, ...] = ()
    write_scene: Callable[..., list[Path]] | None = None


def _uart_row() -> FileFormat:
    return FileFormat(
        name="uart",
        description="TI mmWave demo UART stream (Demo Visualizer .dat, serial dumps), every SDK",
        suffixes=(".dat", ".bin", ".uart", ".log"),
        sniff=ti_uart_import.sniff,
        read=lambda path, cfg: ti_uart_import.read(path, _radar(cfg)),
        write=ti_uart_import.write,
        variants=ti_uart_import.VARIANTS,
    )


def _replay_row() -> FileFormat:
    return FileFormat(
        name="replay",
        description="TI Industrial Visualizer replay (replay_N.json, or a folder of them)",
        suffixes=(".json",),
        sniff=ti_replay.sniff,
        read=lambda path, cfg: ti_replay.read(path, _radar(cfg)),
        write=ti_replay.write,
    )


def _radar(cfg: Path | None) -> RadarConfig | None:
    return read_ti_cfg(cfg) if cfg is not None else None


def _read_capture(path: Path, cfg: Path | None) -> Recording:
    if cfg is None:
        raise InputError(
            "a DCA1000 capture holds raw ADC samples only: give --cfg, the TI .cfg it was "
            "captured with",
            str(path),
        )

    from core.pipeline.capture import recording_from_capture  # the radar chain: heavy import

    # the partial-frame note is among the recording's notes, which the caller prints: no warning
    return recording_from_capture(path, cfg, note=lambda line: None)


def _write_capture(
    path: Path, scene: Scene, *, seed: int | None, fidelity: str, variant: str | None
) -> list[Path]:

    if fidelity != "exact":
        raise InputError(
            f"--fidelity must be exact for dca1000 (the ADC samples are the exact chain's), "
            f"got {fidelity!r}"
        )
    from core.pipeline.capture import write_capture  # the radar chain: heavy import

    return write_capture(scene, path, seed=seed)


def _dca1000_row() -> FileFormat:
    return FileFormat(
        name=CAPTURE_FORMAT,
        description="TI DCA1000 raw ADC capture (.bin) with the TI .cfg that made it, processed "
        "by RadarTune's own chain",
        suffixes=(".bin",),
        # raw samples carry no signature: a .bin without the UART magic word (tried first)
        sniff=lambda head, path: path.suffix.lower() == ".bin" and ti_uart.MAGIC not in head,
        read=_read_capture,
        write_scene=_write_capture,
    )


def _csv_rows() -> tuple[FileFormat, ...]:
    return (
        FileFormat(
            name=pointcloud_csv.PEOPLE_CSV,
            description="vendor CSV of TI's people-counting firmware (header time,fN,type; rows "
            "v6 points, v7 TI's tracks, v8 point-to-track indices)",
            suffixes=(".csv",),
            sniff=pointcloud_csv.sniff_people,
            read=lambda path, cfg: pointcloud_csv.read_people(path, _radar(cfg)),
        ),
        FileFormat(
            name=pointcloud_csv.OOB_CSV,
            description="out-of-box CSV (Frame #,# Obj,X,Y,Z,Doppler,Intensity[, date and time])",
            suffixes=(".csv",),
            sniff=pointcloud_csv.sniff_oob,
            read=lambda path, cfg: pointcloud_csv.read_oob(path, _radar(cfg)),
        ),
        FileFormat(
            name=pointcloud_csv.MAPPED_CSV,
            description="any point-cloud CSV with a header, read through --columns "
            "frame=...,x=...,y=...[,z=,doppler=,snr=,time=]",
            suffixes=(".csv",),
            # never detected: a plain CSV says nothing about which column is what
            sniff=lambda head, path: False,
            read=lambda path, cfg: pointcloud_csv.read_mapped(path, _radar(cfg), None),
        ),
    )


#: name -> row, in the order auto-detection tries them.
FORMATS: dict[str, FileFormat] = {
    row.name: row for row in (_uart_row(), _replay_row(), _dca1000_row(), *_csv_rows())
}

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
    path: str | os.PathLike,
    *,
    fmt: str | None,
    cfg: str | os.PathLike | None,
    columns: str | None = None,
) -> Recording:
    """Read ``path`` as format ``fmt`` (None: detected); ``columns``: the column map of a plain
    CSV (``frame=...,x=...,y=...``; implies ``--format csv``)."""
    path = Path(path)
    if columns is not None:
        if fmt not in (None, pointcloud_csv.MAPPED_CSV):
            raise InputError(f"--columns goes with --format csv, not --format {fmt}")
        colmap = pointcloud_csv.parse_column_map(columns)
        if not path.exists():
            raise InputError("no such file", str(path))
        return pointcloud_csv.read_mapped(path, _radar(None if cfg is None else Path(cfg)), colmap)
    if not path.exists():
        raise InputError("no such file", str(path))
    if fmt is None:
        row = detect_format(path)
    elif fmt in FORMATS:
        row = FORMATS[fmt]
    else:
        raise InputError(f"--format must be one of {list(FORMATS)}, got {fmt!r}")
    return row.read(path, None if cfg is None else Path(cfg))
