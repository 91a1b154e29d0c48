"""TI mmWave demo output over UART (the Demo Visualizer's ``.dat`` logs, raw serial dumps).

Reader (streaming, bounded memory) and writer of the packet stream every TI mmWave demo sends on
its data UART: a magic word, a frame header, then type-length-value (TLV) items. Byte layouts
(all little-endian) from TI's documentation, cited in ``docs/real-data.md``:

* the mmWave SDK demo's ``MmwDemo_output_message_header`` — mmWave SDK "Demo output" doxygen
  page and TI's *Understanding the UART Data Output Format* (radar toolbox 3.00.00.05);
* the people-tracking (3D people counting) demo's TLVs 1010/1011/1012/1020/1021 — the same TI
  page, section "People tracking";
* the xWRL6432 low-power SDK 5 demo's ``MMWDEMO_OUTPUT_EXT_MSG_*`` TLVs (301 …) — the MMWAVE-L
  SDK 5 motion and presence detection demo documentation, section 13.

Frame header, 40 bytes (SDK >= 2 on xWR16xx/18xx/68xx, SDK 5 on xWRL6432) or 36 bytes (SDK
1.x/2.x on xWR14xx, which has no ``subFrameNumber``)::

    magic u16[4] = 0x0102 0x0304 0x0506 0x0708   (bytes 02 01 04 03 06 05 08 07)
    version u32, totalPacketLen u32 (whole packet, header included, padded to 32 bytes),
    platform u32, frameNumber u32, timeCpuCycles u32, numDetectedObj u32, numTLVs u32,
    [subFrameNumber u32]

TLV header: ``type u32, length u32`` (length of the payload that follows, in bytes).

Which header a packet has is decided by its structure, not by trust in one field: the packet's
TLVs must tile it exactly (each TLV inside ``totalPacketLen``, the last one ending within the
32-byte padding). Both header lengths are tried, the one the platform and version suggest first
(``0xA1443`` with SDK major < 3: 36 bytes). Likewise the detected-points TLV (type 1) is the
SDK 1.x/2.x Q-format form when its length is ``4 + 12·n`` with ``n`` its own descriptor count,
and the SDK >= 3 float form when it is ``16·numDetectedObj``.

Damage is survived, counted and reported (:class:`UartReport`): a packet that does not tile
(bytes lost inside it, a cut, a false magic word) is skipped and the reader resynchronises on
the next magic word; gaps in ``frameNumber`` count dropped frames; unknown TLV types are
skipped and counted by type. What cannot be read at all (empty file, no magic word) raises one
:class:`~core.errors.InputError` naming the file and the byte offset.
"""

from __future__ import annotations

import math
import os
import struct
from collections import Counter
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import NamedTuple, Protocol, TypeVar

import numpy as np

from core.config import RadarConfig
from core.errors import InputError
from core.files import atomic_open
from core.pointcloud import PointCloud

#: The sync word that starts every packet: u16 0x0102, 0x0304, 0x0506, 0x0708, little-endian.
MAGIC = bytes.fromhex("0201040306050807")
#: Packets are padded to a multiple of this many bytes.
PACKET_ALIGN = 32
#: TLV header: type u32, length u32.
TLV_HEADER_BYTES = 8
#: The largest packet accepted; a longer ``totalPacketLen`` is damage (heat maps of a 256 x 64
#: range-Doppler map are 32 KiB; 16 MiB leaves room for any documented TLV).
MAX_PACKET_BYTES = 16 * 1024**2
#: The most TLVs one packet may claim.
MAX_TLVS = 256
#: Bytes read from a file per step; memory stays O(CHUNK + one packet).
CHUNK_BYTES = 1 << 20

_U32 = struct.Struct("<I")
_HDR36 = struct.Struct("<Q7I")
_HDR40 = struct.Struct("<Q8I")
_TLV = struct.Struct("<2I")

#: Platform codes of devices whose SDK 1.x/2.x header has no sub-frame number.
PLATFORMS_WITHOUT_SUBFRAME = (0xA1443,)

HEADER_36 = np.dtype(
    [
        ("magic", "<u8"),
        ("version", "<u4"),
        ("total_len", "<u4"),
        ("platform", "<u4"),
        ("frame_number", "<u4"),
        ("time_cpu_cycles", "<u4"),
        ("n_detected", "<u4"),
        ("n_tlvs", "<u4"),
    ]
)
HEADER_40 = np.dtype(HEADER_36.descr + [("subframe", "<u4")])
TLV_HEADER = np.dtype([("type", "<u4"), ("length", "<u4")])

# ---- TLV types (TI's names) -------------------------------------------------------------------
DETECTED_POINTS = 1
RANGE_PROFILE = 2
NOISE_PROFILE = 3
AZIMUTH_STATIC_HEAT_MAP = 4
RANGE_DOPPLER_HEAT_MAP = 5
STATS = 6
DETECTED_POINTS_SIDE_INFO = 7
AZIMUTH_ELEVATION_STATIC_HEAT_MAP = 8
TEMPERATURE_STATS = 9
EXT_DETECTED_POINTS = 301  # SDK 5 xWRL6432: compressed Cartesian points
EXT_RANGE_PROFILE_MAJOR = 302
EXT_RANGE_PROFILE_MINOR = 303
EXT_RANGE_AZIMUTH_MAJOR = 304
EXT_RANGE_AZIMUTH_MINOR = 305
EXT_STATS = 306
EXT_PRESENCE_INFO = 307
EXT_TARGET_LIST = 308
EXT_TARGET_INDEX = 309
SPHERICAL_POINTS = 1000
TARGET_LIST_3D = 1010
TARGET_INDEX = 1011
TARGET_HEIGHT = 1012
COMPRESSED_POINTS = 1020
PRESENCE_INDICATION = 1021

# ---- payload layouts --------------------------------------------------------------------------
#: SDK >= 3 ``DPIF_PointCloudCartesian``: x, y, z in m, velocity (radial) in m/s.
POINT_FLOAT = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("v", "<f4")])
#: SDK 1.x/2.x ``MmwDemo_output_message_dataObjDescr``, then that many ``MmwDemo_detectedObj``.
Q_DESCRIPTOR = np.dtype([("n", "<u2"), ("q", "<u2")])
POINT_Q = np.dtype(
    [
        ("range_idx", "<u2"),
        ("doppler_idx", "<i2"),
        ("peak", "<u2"),
        ("x", "<i2"),
        ("y", "<i2"),
        ("z", "<i2"),
    ]
)
#: ``DPIF_PointCloudSideInfo``: SNR and noise in units of 0.1 dB.
SIDE_INFO = np.dtype([("snr", "<i2"), ("noise", "<i2")])
#: SDK 5 ``MmwDemo_output_message_point_unit`` then ``..._UARTpoint`` per point.
EXT_UNIT = np.dtype(
    [
        ("xyz_unit", "<f4"),
        ("doppler_unit", "<f4"),
        ("snr_unit", "<f4"),
        ("noise_unit", "<f4"),
        ("n_major", "<u2"),
        ("n_minor", "<u2"),
    ]
)
EXT_POINT = np.dtype(
    [("x", "<i2"), ("y", "<i2"), ("z", "<i2"), ("doppler", "<i2"), ("snr", "u1"), ("noise", "u1")]
)
#: People tracking: ``pointUnit`` then compressed spherical points.
COMPRESSED_UNIT = np.dtype(
    [
        ("elevation_unit", "<f4"),
        ("azimuth_unit", "<f4"),
        ("doppler_unit", "<f4"),
        ("range_unit", "<f4"),
        ("snr_unit", "<f4"),
    ]
)
COMPRESSED_POINT = np.dtype(
    [
        ("elevation", "i1"),
        ("azimuth", "i1"),
        ("doppler", "<i2"),
        ("range", "<u2"),
        ("snr", "<u2"),
    ]
)
SPHERICAL_POINT = np.dtype(
    [("range", "<f4"), ("azimuth", "<f4"), ("elevation", "<f4"), ("doppler", "<f4")]
)
#: ``trackerProc_Target`` (3D): id, position, velocity, acceleration, error covariance 4x4,
#: gating gain, confidence.
TARGET_3D = np.dtype(
    [
        ("tid", "<u4"),
        ("pos", "<f4", (3,)),
        ("vel", "<f4", (3,)),
        ("acc", "<f4", (3,)),
        ("ec", "<f4", (16,)),
        ("g", "<f4"),
        ("confidence", "<f4"),
    ]
)
TARGET_HEIGHT_ITEM = np.dtype([("tid", "<u4"), ("max_z", "<f4"), ("min_z", "<f4")])
STATS_ITEM = np.dtype(
    [
        ("inter_frame_processing_time", "<u4"),
        ("transmit_output_time", "<u4"),
        ("inter_frame_processing_margin", "<u4"),
        ("inter_chirp_processing_margin", "<u4"),
        ("active_frame_cpu_load", "<u4"),
        ("inter_frame_cpu_load", "<u4"),
    ]
)
TEMPERATURE_ITEM = np.dtype([("valid", "<i4"), ("time_ms", "<u4"), ("temperature", "<u2", (10,))])

#: Auxiliary TLVs kept as arrays on :class:`UartFrame` (``extras``): type -> (name, dtype).
AUX_TLVS: dict[int, tuple[str, np.dtype]] = {
    RANGE_PROFILE: ("range_profile", np.dtype("<u2")),
    NOISE_PROFILE: ("noise_profile", np.dtype("<u2")),
    AZIMUTH_STATIC_HEAT_MAP: ("range_azimuth_heat_map", np.dtype("<i2")),  # (imag, real) pairs
    RANGE_DOPPLER_HEAT_MAP: ("range_doppler_heat_map", np.dtype("<u2")),
    STATS: ("stats", STATS_ITEM),
    AZIMUTH_ELEVATION_STATIC_HEAT_MAP: ("azimuth_elevation_heat_map", np.dtype("<i2")),
    TEMPERATURE_STATS: ("temperature", TEMPERATURE_ITEM),
    EXT_RANGE_PROFILE_MAJOR: ("range_profile_major", np.dtype("<u4")),
    EXT_RANGE_PROFILE_MINOR: ("range_profile_minor", np.dtype("<u4")),
    EXT_RANGE_AZIMUTH_MAJOR: ("range_azimuth_major", np.dtype("<u4")),
    EXT_RANGE_AZIMUTH_MINOR: ("range_azimuth_minor", np.dtype("<u4")),
    EXT_STATS: ("ext_stats", np.dtype("u1")),
    EXT_PRESENCE_INFO: ("presence_info", np.dtype("u1")),
    EXT_TARGET_LIST: ("targets", TARGET_3D),
    EXT_TARGET_INDEX: ("target_index", np.dtype("u1")),
    TARGET_LIST_3D: ("targets", TARGET_3D),
    TARGET_INDEX: ("target_index", np.dtype("u1")),
    TARGET_HEIGHT: ("target_height", TARGET_HEIGHT_ITEM),
    PRESENCE_INDICATION: ("presence", np.dtype("<u4")),
}
POINT_TLVS = (
    DETECTED_POINTS,
    DETECTED_POINTS_SIDE_INFO,
    EXT_DETECTED_POINTS,
    SPHERICAL_POINTS,
    COMPRESSED_POINTS,
)
KNOWN_TLVS = frozenset((*POINT_TLVS, *AUX_TLVS))

#: Point formats the writer produces (``--sdk`` of ``radartune export``).
WRITE_FORMATS = ("sdk3", "sdk2", "sdk1-xwr14", "sdk5", "tracking")


@dataclass(frozen=True, slots=True, kw_only=True)
class UartPoints:
    """Detected points of one packet, every array ``(n,)`` float64 in SI units.

    ``x_m, y_m, z_m`` Cartesian (radar at the origin, +y boresight); ``velocity_mps`` radial,
    positive away; ``snr_db`` and ``noise_db`` (NaN where the packet carries none).
    """

    x_m: np.ndarray
    y_m: np.ndarray
    z_m: np.ndarray
    velocity_mps: np.ndarray
    snr_db: np.ndarray
    noise_db: np.ndarray

    def __len__(self) -> int:
        return len(self.x_m)

    @classmethod
    def empty(cls) -> UartPoints:
        z = np.zeros(0)
        return cls(x_m=z, y_m=z, z_m=z, velocity_mps=z, snr_db=z, noise_db=z)


@dataclass(frozen=True, slots=True, kw_only=True)
class UartFrame:
    """One packet: header fields, its points, and the auxiliary TLVs as arrays.

    ``generation``: ``"sdk1-2 (36-byte header)"``, ``"sdk2+ (40-byte header)"``; ``point_format``:
    which TLV carried the points (``"float"``, ``"q"``, ``"ext"``, ``"spherical"``,
    ``"compressed"``, ``""`` when none). ``offset``: byte offset of the magic word in the stream.
    """

    offset: int
    version: int
    platform: int
    frame_number: int
    subframe: int
    time_cpu_cycles: int
    header_bytes: int
    point_format: str
    points: UartPoints
    extras: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def sdk_version(self) -> str:
        v = self.version
        return f"{v >> 24 & 0xFF}.{v >> 16 & 0xFF}.{v >> 8 & 0xFF}.{v & 0xFF}"


@dataclass(slots=True)
class UartReport:
    """What a read met: counts for the one-line summary the CLI prints."""

    source: str = "<stream>"
    n_bytes: int = 0
    n_frames: int = 0
    n_damaged: int = 0  # packets skipped because they did not tile (resynchronised after)
    n_dropped: int = 0  # frames missing from the frameNumber sequence
    n_truncated: int = 0  # a last packet cut by the end of the stream
    bytes_skipped: int = 0  # bytes between packets that belonged to no packet
    unknown_tlvs: Counter = field(default_factory=Counter)
    generations: Counter = field(default_factory=Counter)

    def summary(self) -> str:
        unknown = (
            ", unknown TLV types skipped: "
            + ", ".join(f"{t} x{n}" for t, n in sorted(self.unknown_tlvs.items()))
            if self.unknown_tlvs
            else ""
        )
        gens = ", ".join(f"{g} x{n}" for g, n in sorted(self.generations.items()))
        return (
            f"{self.source}: {self.n_frames} frames ({gens or 'none'}), {self.n_dropped} dropped "
            f"(frame-number gaps), {self.n_damaged} damaged packets skipped, "
            f"{self.n_truncated} cut at the end, {self.bytes_skipped} bytes outside packets"
            f"{unknown}"
        )


# ---- reading ----------------------------------------------------------------------------------
def _file_chunks(path: Path, chunk_bytes: int) -> Iterator[bytes]:
    try:
        fh = open(path, "rb")  # noqa: SIM115 - closed in the finally below
    except OSError as exc:
        raise InputError(f"cannot read ({exc.strerror or exc})", str(path)) from None
    try:
        while chunk := fh.read(chunk_bytes):
            yield chunk
    finally:
        fh.close()


def iter_uart_frames(
    source: str | os.PathLike | Iterable[bytes],
    *,
    radar: RadarConfig | None = None,
    report: UartReport | None = None,
    chunk_bytes: int = CHUNK_BYTES,
    name: str | None = None,
) -> Iterator[UartFrame]:
    """Yield every readable packet of a UART log, streaming.

    Parameters
    ----------
    source
        A file path, or an iterable of ``bytes`` chunks (any sizes; e.g. a serial port reader).
    radar
        The configuration the log was recorded with; needed only for SDK 1.x/2.x Q-format
        points, whose velocity is a Doppler bin index (``v = idx · Δv``).
    report
        Filled in as the stream is read (counts of frames, damage, unknown TLVs).
    chunk_bytes
        Bytes read per step from a file.
    name
        The name used in messages (default: the path, or ``"<stream>"``).

    Raises
    ------
    InputError
        An empty stream, no magic word anywhere, or Q-format points without ``radar``; one line
        naming the file and the byte offset.
    """
    rep = report if report is not None else UartReport()
    src = name or (str(source) if isinstance(source, str | os.PathLike) else "<stream>")

    def parse(packet: bytes, offset: int) -> UartFrame | None:
        return _parse_packet(packet, offset, radar, rep, src)

    return _iter_packets(source, parse, rep, src, chunk_bytes)


def iter_raw_packets(
    source: str | os.PathLike | Iterable[bytes],
    *,
    radar: RadarConfig | None = None,
    report: UartReport | None = None,
    chunk_bytes: int = CHUNK_BYTES,
    name: str | None = None,
) -> Iterator[RawPacket]:
    """:func:`iter_uart_frames` for bulk import: the same packets, checks and counts, each as a
    :class:`RawPacket` (float points left as bytes to decode all at once)."""
    rep = report if report is not None else UartReport()
    src = name or (str(source) if isinstance(source, str | os.PathLike) else "<stream>")

    def parse(packet: bytes, offset: int) -> RawPacket | None:
        return parse_packet_raw(packet, offset, radar, rep, src)

    return _iter_packets(source, parse, rep, src, chunk_bytes)


class _Packet(Protocol):
    @property
    def frame_number(self) -> int: ...
    @property
    def header_bytes(self) -> int: ...
    @property
    def point_format(self) -> str: ...


P = TypeVar("P", bound=_Packet)


def _iter_packets(
    source: str | os.PathLike | Iterable[bytes],
    parse: Callable[[bytes, int], P | None],
    rep: UartReport,
    src: str,
    chunk_bytes: int = CHUNK_BYTES,
) -> Iterator[P]:
    """Find, check and hand each packet to ``parse``; resynchronise and count as documented
    in the module docstring. Memory: one chunk plus one packet."""
    chunks: Iterable[bytes]
    if isinstance(source, str | os.PathLike):
        chunks = _file_chunks(Path(source), chunk_bytes)
    else:
        chunks = source
    rep.source = src
    buf = b""  # immutable: a packet is one slice (one copy); a refill joins the rest and a chunk
    pos = 0  # read position in buf
    base = 0  # stream offset of buf[0]
    last_frame: int | None = None
    eof = False
    it = iter(chunks)
    generations: Counter = Counter()

    def more() -> bool:
        """Append the next chunk (dropping what was consumed first); False at the end."""
        nonlocal eof, pos, base, buf
        if eof:
            return False
        for chunk in it:
            if chunk:
                base += pos
                buf = buf[pos:] + bytes(chunk)
                pos = 0
                rep.n_bytes += len(chunk)
                return True
        eof = True
        return False

    while True:
        i = buf.find(MAGIC, pos)
        if i < 0:
            # keep the last 7 bytes: a magic word may straddle two chunks
            keep_from = max(pos, len(buf) - (len(MAGIC) - 1))
            rep.bytes_skipped += keep_from - pos
            pos = keep_from
            if not more():
                rep.bytes_skipped += len(buf) - pos
                break
            continue
        rep.bytes_skipped += i - pos
        pos = i
        while len(buf) - pos < HEADER_40.itemsize and more():
            pass
        if len(buf) - pos < HEADER_36.itemsize:
            rep.n_truncated += 1
            rep.bytes_skipped += len(buf) - pos
            break
        (total,) = _U32.unpack_from(buf, pos + 12)
        if not HEADER_36.itemsize <= total <= MAX_PACKET_BYTES:
            rep.n_damaged += 1
            rep.bytes_skipped += 1
            pos += 1
            continue
        while len(buf) - pos < total and more():
            pass
        if len(buf) - pos < total:
            # cut by the end of the stream, or a false length: look for a later magic word
            nxt = buf.find(MAGIC, pos + 1)
            if nxt < 0:
                rep.n_truncated += 1
                rep.bytes_skipped += len(buf) - pos
                break
            rep.n_damaged += 1
            rep.bytes_skipped += nxt - pos
            pos = nxt
            continue
        packet = buf[pos : pos + total]
        frame = parse(packet, base + pos)
        # a packet followed at once by the next magic word cannot have swallowed its start;
        # otherwise look for a magic word inside it (bytes lost near its end)
        following = buf[pos + total : pos + total + len(MAGIC)]
        inner = -1 if following == MAGIC else packet.find(MAGIC, 1)
        if frame is None or inner > 0:
            # damaged (bytes lost inside it, or it swallowed the next packet): resync
            rep.n_damaged += 1
            step = inner if inner > 0 else 1
            rep.bytes_skipped += step
            pos += step
            continue
        pos += total
        if last_frame is not None and frame.frame_number > last_frame + 1:
            rep.n_dropped += frame.frame_number - last_frame - 1
        last_frame = frame.frame_number
        rep.n_frames += 1
        generations[frame.header_bytes, frame.point_format] += 1
        yield frame
    for (hb, fmt), n in generations.items():
        rep.generations[f"{hb}-byte header, {fmt or 'no'} points"] += n

    if rep.n_bytes == 0:
        raise InputError("empty file: no bytes to read", f"{src}:0")
    if rep.n_frames == 0:
        raise InputError(
            "no TI UART packet found (no magic word 02 01 04 03 06 05 08 07 followed by a "
            f"readable frame header in {rep.n_bytes} bytes)",
            f"{src}:0",
        )


def _header_candidates(packet: bytes) -> tuple[struct.Struct, ...]:
    """The header layouts to try, the likelier first (platform and SDK major)."""
    version, _, platform = struct.unpack_from("<3I", packet, 8)
    if platform in PLATFORMS_WITHOUT_SUBFRAME and (version >> 24) < 3:
        return (_HDR36, _HDR40)
    return (_HDR40, _HDR36)


def _tlv_walk(packet: bytes, start: int, n_tlvs: int) -> list[tuple[int, int, int]] | None:
    """``(type, payload offset, payload length)`` of ``n_tlvs`` TLVs from ``start`` when they
    tile the packet (the last one ending in the final padding, < 32 bytes), else None."""
    total = len(packet)
    if n_tlvs > MAX_TLVS:
        return None
    out = []
    pos = start
    for _ in range(n_tlvs):
        if pos + TLV_HEADER_BYTES > total:
            return None
        t, n = _TLV.unpack_from(packet, pos)
        pos += TLV_HEADER_BYTES
        if n > total - pos:
            return None
        out.append((t, pos, n))
        pos += n
    if total - pos >= PACKET_ALIGN:
        return None
    return out


def _parse_packet(
    packet: bytes, offset: int, radar: RadarConfig | None, rep: UartReport, src: str
) -> UartFrame | None:
    """The packet under the header layout that tiles it with the fewest unknown TLV types
    (the platform's usual layout first, accepted at once when every TLV type is known)."""
    best: tuple[int, UartFrame, Counter] | None = None
    for hdr in _header_candidates(packet):
        if len(packet) < hdr.size:
            continue
        fields = hdr.unpack_from(packet, 0)
        _, version, _, platform, frame_number, cycles, n_detected, n_tlvs = fields[:8]
        tlvs = _tlv_walk(packet, hdr.size, n_tlvs)
        if tlvs is None:
            continue
        try:
            points, fmt, extras, unknown = _decode_tlvs(packet, tlvs, n_detected, version, radar)
        except _Undecodable:
            continue
        except _NeedsRadar:
            raise InputError(
                "SDK 1.x/2.x points carry Doppler bin indices; give the .cfg the log was "
                "recorded with (--cfg) to scale them to m/s",
                f"{src}:{offset}",
            ) from None
        frame = UartFrame(
            offset=offset,
            version=version,
            platform=platform,
            frame_number=frame_number,
            subframe=fields[8] if len(fields) > 8 else 0,
            time_cpu_cycles=cycles,
            header_bytes=hdr.size,
            point_format=fmt,
            points=points,
            extras=extras,
        )
        n_unknown = sum(unknown.values())
        if best is None or n_unknown < best[0]:
            best = (n_unknown, frame, unknown)
        if n_unknown == 0:
            break
    if best is None:
        return None
    if best[2]:
        rep.unknown_tlvs.update(best[2])
    return best[1]


class RawPacket(NamedTuple):
    """A packet as the fast import path keeps it: float points (SDK >= 3 TLV 1) and their side
    info (TLV 7) as raw bytes, joined and decoded once for the whole log; any other point format
    decoded (``points``)."""

    frame_number: int
    header_bytes: int
    point_format: str
    float_points: bytes
    side_info: bytes
    points: UartPoints | None
    extras: tuple[str, ...]
    #: The firmware's own tracks (TLV 1010 / 308, :data:`TARGET_3D` records) and target index
    #: (TLV 1011 / 309, one byte per point of the previous frame), when the packet has them.
    targets: np.ndarray | None = None
    target_index: np.ndarray | None = None


#: TLV types whose payload the fast path checks by length only.
_AUX_SIZES = {t: dt.itemsize for t, (_, dt) in AUX_TLVS.items()}
_OTHER_POINT_TLVS = frozenset((EXT_DETECTED_POINTS, COMPRESSED_POINTS, SPHERICAL_POINTS))


def parse_packet_raw(
    packet: bytes, offset: int, radar: RadarConfig | None, rep: UartReport, src: str
) -> RawPacket | None:
    """:func:`_parse_packet` for the importer: the same header choice and checks, without
    building arrays for the common SDK >= 3 float packet (see :class:`RawPacket`)."""
    for hdr in _header_candidates(packet):
        if len(packet) < hdr.size:
            continue
        fields = hdr.unpack_from(packet, 0)
        version, n_detected, n_tlvs = fields[1], fields[6], fields[7]
        tlvs = _tlv_walk(packet, hdr.size, n_tlvs)
        if tlvs is None:
            continue
        float_points = side = b""
        names: list[str] = []
        targets = target_index = None
        simple = True
        for t, off, n in tlvs:
            if t == DETECTED_POINTS:
                if n != POINT_FLOAT.itemsize * n_detected or _is_q(
                    packet, off, n, n_detected, version
                ):
                    simple = False
                    break
                float_points = packet[off : off + n]
            elif t == DETECTED_POINTS_SIDE_INFO:
                if n != SIDE_INFO.itemsize * n_detected:
                    simple = False
                    break
                side = packet[off : off + n]
            elif t in _AUX_SIZES:
                if n % _AUX_SIZES[t]:
                    simple = False
                    break
                names.append(AUX_TLVS[t][0])
                if t in (TARGET_LIST_3D, EXT_TARGET_LIST):
                    targets = _records(packet, off, n, TARGET_3D).copy()
                elif t in (TARGET_INDEX, EXT_TARGET_INDEX):
                    target_index = _records(packet, off, n, np.dtype("u1")).copy()
            else:  # other point formats, unknown types: the full decoder
                simple = False
                break
        if simple and (float_points or not side):
            return RawPacket(
                fields[4],
                hdr.size,
                "float" if float_points else "",
                float_points,
                side,
                None,
                tuple(names),
                targets,
                target_index,
            )
        break
    frame = _parse_packet(packet, offset, radar, rep, src)
    if frame is None:
        return None
    return RawPacket(
        frame.frame_number,
        frame.header_bytes,
        frame.point_format,
        b"",
        b"",
        frame.points,
        tuple(frame.extras),
        frame.extras.get("targets"),
        frame.extras.get("target_index"),
    )


class _Undecodable(Exception):
    """A TLV's length does not fit its documented layout under this header interpretation."""


class _NeedsRadar(Exception):
    pass


def _records(packet: bytes, off: int, n: int, dtype: np.dtype) -> np.ndarray:
    if n % dtype.itemsize:
        raise _Undecodable
    return np.frombuffer(packet, dtype, count=n // dtype.itemsize, offset=off)


def _decode_tlvs(
    packet: bytes,
    tlvs: list[tuple[int, int, int]],
    n_detected: int,
    version: int,
    radar: RadarConfig | None,
) -> tuple[UartPoints, str, dict[str, np.ndarray], Counter]:
    points: UartPoints | None = None
    fmt = ""
    side: np.ndarray | None = None
    extras: dict[str, np.ndarray] = {}
    unknown: Counter = Counter()
    for t, off, n in tlvs:
        if t == DETECTED_POINTS:
            points, fmt = _detected_points(packet, off, n, n_detected, version, radar)
        elif t == DETECTED_POINTS_SIDE_INFO:
            side = _records(packet, off, n, SIDE_INFO)
        elif t == EXT_DETECTED_POINTS:
            points, fmt = _ext_points(packet, off, n), "ext"
        elif t == COMPRESSED_POINTS:
            points, fmt = _compressed_points(packet, off, n), "compressed"
        elif t == SPHERICAL_POINTS:
            p = _records(packet, off, n, SPHERICAL_POINT)
            nan = np.full(len(p), np.nan)
            points, fmt = (
                _from_spherical(p["range"], p["azimuth"], p["elevation"], p["doppler"], nan),
                "spherical",
            )
        elif t in AUX_TLVS:
            key, dtype = AUX_TLVS[t]
            if n % dtype.itemsize:
                raise _Undecodable
            extras[key] = np.frombuffer(packet, dtype, count=n // dtype.itemsize, offset=off).copy()
        else:
            unknown[t] += 1
    if points is None:
        points = UartPoints.empty()
    if side is not None:
        if len(side) != len(points):
            raise _Undecodable
        points = UartPoints(
            x_m=points.x_m,
            y_m=points.y_m,
            z_m=points.z_m,
            velocity_mps=points.velocity_mps,
            # snr, noise in 0.1 dB steps
            snr_db=side["snr"] * 0.1,
            noise_db=side["noise"] * 0.1,
        )
    return points, fmt, extras, unknown


def _is_q(packet: bytes, off: int, n: int, n_detected: int, version: int) -> bool:
    """Whether TLV 1 at ``off`` is the SDK 1.x/2.x Q-format form (see :func:`_detected_points`)."""
    if n < Q_DESCRIPTOR.itemsize:
        return False
    k, q = struct.unpack_from("<2H", packet, off)
    if not (n == Q_DESCRIPTOR.itemsize + k * POINT_Q.itemsize and q <= 15 and k == n_detected):
        return False
    return not (n == POINT_FLOAT.itemsize * n_detected and (version >> 24) >= 3)


def _detected_points(
    packet: bytes, off: int, n: int, n_detected: int, version: int, radar: RadarConfig | None
) -> tuple[UartPoints, str]:
    """Type 1: SDK 1.x/2.x Q-format (descriptor + 12-byte objects) or SDK >= 3 float.

    Q-format when the payload is exactly ``4 + 12·k`` bytes for the descriptor's own ``k`` (the
    header's count agreeing) and its Q is at most 15; float when it is ``16·numDetectedObj``;
    where both fit (one 16-byte point), the SDK major decides (< 3: Q-format).
    """
    if _is_q(packet, off, n, n_detected, version):
        k, q = struct.unpack_from("<2H", packet, off)
        p = np.frombuffer(packet, POINT_Q, count=k, offset=off + Q_DESCRIPTOR.itemsize)
        if k and radar is None:
            raise _NeedsRadar
        # value = integer / 2^Q (m); v = Doppler index · Δv
        scale = 1.0 / (1 << q)
        dv = radar.velocity_resolution_mps if radar is not None else 0.0
        nan = np.full(k, np.nan)
        return (
            UartPoints(
                x_m=p["x"] * scale,
                y_m=p["y"] * scale,
                z_m=p["z"] * scale,
                velocity_mps=p["doppler_idx"] * dv,
                snr_db=peak_db(p["peak"]),
                noise_db=nan,
            ),
            "q",
        )
    p = _records(packet, off, n, POINT_FLOAT)
    if n_detected != len(p):
        raise _Undecodable
    nan = np.full(len(p), np.nan)
    # float32 views; converted (and checked finite) once for the whole log by the importer
    return (
        UartPoints(
            x_m=p["x"], y_m=p["y"], z_m=p["z"], velocity_mps=p["v"], snr_db=nan, noise_db=nan
        ),
        "float",
    )


def peak_db(peak: np.ndarray) -> np.ndarray:
    """The level of SDK 1.x/2.x points in dB from their ``peakVal``: ``20·log10(peakVal)``.

    TI's SDK 1.x/2.x demos set ``peakVal`` to the magnitude of the angle-FFT peak,
    ``sqrt(max|X_az|² / (N_range·N_angle·N_Doppler))`` (xWR16xx DSP data path; the xWR14xx
    hardware accelerator's ``|X_az|`` directly), a linear amplitude: 20·log10 puts it on a dB
    scale. The packet carries no noise level, so this is the point's level above one FFT unit,
    not a signal-to-noise ratio (for SDK 3, TI gives ``peak dB = snr + noise``, both in the side
    info). ``peakVal`` 0 gives NaN (no level)."""
    a = np.asarray(peak, dtype=np.float64)
    with np.errstate(divide="ignore"):
        return np.where(a > 0, 20.0 * np.log10(np.where(a > 0, a, 1.0)), np.nan)


def linear_snr_db(snr: np.ndarray) -> np.ndarray:
    """The people-tracking demo's point SNR, which TI's output structure documents as linear
    (``Pcount3DDemo_output_message_point.snr``: "Range detection SNR, linear"), in dB:
    ``10·log10(snr)``; 0 (or less) gives NaN."""
    a = np.asarray(snr, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(a > 0, 10.0 * np.log10(np.where(a > 0, a, 1.0)), np.nan)


def _ext_points(packet: bytes, off: int, n: int) -> UartPoints:
    """Type 301 (SDK 5): units, then int16 x, y, z, Doppler and uint8 SNR, noise per point."""
    if n < EXT_UNIT.itemsize:
        raise _Undecodable
    u = np.frombuffer(packet, EXT_UNIT, count=1, offset=off)[0]
    p = _records(packet, off + EXT_UNIT.itemsize, n - EXT_UNIT.itemsize, EXT_POINT)
    if int(u["n_major"]) + int(u["n_minor"]) != len(p):
        raise _Undecodable
    units = [float(u[k]) for k in ("xyz_unit", "doppler_unit", "snr_unit", "noise_unit")]
    if not all(math.isfinite(x) for x in units):
        raise _Undecodable
    xyz, dop, snr, noise = units
    return UartPoints(
        x_m=p["x"] * xyz,
        y_m=p["y"] * xyz,
        z_m=p["z"] * xyz,
        velocity_mps=p["doppler"] * dop,
        snr_db=p["snr"] * snr,
        noise_db=p["noise"] * noise,
    )


def _compressed_points(packet: bytes, off: int, n: int) -> UartPoints:
    """Type 1020 (people tracking): units, then int8 elevation, azimuth, int16 Doppler, uint16
    range, SNR per point (spherical, TI's azimuth from boresight)."""
    if n < COMPRESSED_UNIT.itemsize:
        raise _Undecodable
    u = np.frombuffer(packet, COMPRESSED_UNIT, count=1, offset=off)[0]
    units = [float(u[k]) for k in COMPRESSED_UNITS]
    if not all(math.isfinite(x) for x in units):
        raise _Undecodable
    el_u, az_u, dop_u, r_u, snr_u = units
    p = _records(
        packet, off + COMPRESSED_UNIT.itemsize, n - COMPRESSED_UNIT.itemsize, COMPRESSED_POINT
    )
    return _from_spherical(
        p["range"] * r_u,
        p["azimuth"] * az_u,
        p["elevation"] * el_u,
        p["doppler"] * dop_u,
        linear_snr_db(p["snr"] * snr_u),
    )


def _from_spherical(
    r: np.ndarray, az: np.ndarray, el: np.ndarray, v: np.ndarray, snr: np.ndarray
) -> UartPoints:
    r, az, el = (np.asarray(a, dtype=np.float64) for a in (r, az, el))
    if not np.all(np.isfinite(r) & np.isfinite(az) & np.isfinite(el) & np.isfinite(v)):
        raise _Undecodable
    # x = r cos(el) sin(az), y = r cos(el) cos(az), z = r sin(el)
    return UartPoints(
        x_m=r * np.cos(el) * np.sin(az),
        y_m=r * np.cos(el) * np.cos(az),
        z_m=r * np.sin(el),
        velocity_mps=np.asarray(v, dtype=np.float64),
        snr_db=np.asarray(snr, dtype=np.float64),
        noise_db=np.full(len(r), np.nan),
    )


# ---- writing ----------------------------------------------------------------------------------
#: Q format of the SDK 1.x/2.x writer: 2^-9 m steps cover +/-64 m in int16.
WRITE_Q = 9
#: Units of the SDK 5 and people-tracking writers (chosen to cover a room at fine steps).
EXT_UNITS = {"xyz_unit": 2.0**-10, "doppler_unit": 2.0**-8, "snr_unit": 0.25, "noise_unit": 0.25}
COMPRESSED_UNITS = {
    "elevation_unit": math.pi / 2 / 127,
    "azimuth_unit": math.pi / 127,
    "doppler_unit": 2.0**-8,
    "range_unit": 2.0**-8,
    # linear SNR steps of 0.25: up to 16 383 (42 dB), 0.17 dB steps at 5 dB
    "snr_unit": 0.25,
}
#: Platform codes written in the header.
PLATFORM = {"xwr68xx": 0xA6843, "xwr14xx": 0xA1443, "xwrl6432": 0x6432}
#: SDK versions written in the header, per point format: major << 24 | minor << 16 | ...
WRITE_VERSION = {
    "sdk3": 0x03050000,
    "sdk2": 0x02010000,
    "sdk1-xwr14": 0x01020000,
    "sdk5": 0x05040000,
    "tracking": 0x03050000,
}


def encode_frame(
    cloud: PointCloud,
    frame_number: int,
    *,
    fmt: str = "sdk3",
    radar: RadarConfig | None = None,
    time_cpu_cycles: int = 0,
    extra_tlvs: Sequence[tuple[int, bytes]] = (),
) -> bytes:
    """One packet holding ``cloud`` in point format ``fmt`` (:data:`WRITE_FORMATS`), then the
    TLVs ``extra_tlvs`` (type, payload) as given (e.g. TI's tracks, 1010, and target index,
    1011).

    ``sdk3``: float points (type 1) and side info (type 7), 40-byte header, xWR68xx;
    ``sdk2``: Q9 points (type 1 with descriptor), 40-byte header (xWR16xx SDK 2.x);
    ``sdk1-xwr14``: the same points with the 36-byte xWR14xx header;
    ``sdk5``: type 301 (xWRL6432), 40-byte header; ``tracking``: type 1020, 40-byte header.
    ``radar`` is needed for the Q formats (the Doppler index is ``round(v / Δv)``).
    """
    n = len(cloud)
    x, y, z = (np.asarray(getattr(cloud, f), dtype=np.float64) for f in ("x_m", "y_m", "z_m"))
    v = np.asarray(cloud.radial_velocity_mps, dtype=np.float64)
    snr = np.asarray(cloud.snr_db, dtype=np.float64)
    tlvs: list[tuple[int, bytes]] = []
    platform = PLATFORM["xwr68xx"]
    if fmt == "sdk3":
        p = np.zeros(n, POINT_FLOAT)
        p["x"], p["y"], p["z"], p["v"] = x, y, z, v
        s = np.zeros(n, SIDE_INFO)
        s["snr"] = _clip_round(snr * 10, np.int16)
        tlvs += [(DETECTED_POINTS, p.tobytes()), (DETECTED_POINTS_SIDE_INFO, s.tobytes())]
    elif fmt in ("sdk2", "sdk1-xwr14"):
        if radar is None:
            raise InputError("the SDK 1.x/2.x point format needs the radar configuration")
        d = np.zeros(1, Q_DESCRIPTOR)
        d["n"], d["q"] = n, WRITE_Q
        p = np.zeros(n, POINT_Q)
        step = 2.0**WRITE_Q
        p["x"], p["y"], p["z"] = (_clip_round(a * step, np.int16) for a in (x, y, z))
        p["doppler_idx"] = _clip_round(v / radar.velocity_resolution_mps, np.int16)
        p["range_idx"] = _clip_round(
            np.asarray(cloud.range_m) / radar.range_resolution_m, np.uint16
        )
        # peakVal: the amplitude whose 20·log10 is the level (the reader's peak_db)
        p["peak"] = np.maximum(_clip_round(10.0 ** (snr / 20.0), np.uint16), 1)
        tlvs.append((DETECTED_POINTS, d.tobytes() + p.tobytes()))
        if fmt == "sdk1-xwr14":
            platform = PLATFORM["xwr14xx"]
    elif fmt == "sdk5":
        u = np.zeros(1, EXT_UNIT)
        for k, val in EXT_UNITS.items():
            u[k] = val
        u["n_major"] = n
        p = np.zeros(n, EXT_POINT)
        for k, a in (("x", x), ("y", y), ("z", z)):
            p[k] = _clip_round(a / EXT_UNITS["xyz_unit"], np.int16)
        p["doppler"] = _clip_round(v / EXT_UNITS["doppler_unit"], np.int16)
        p["snr"] = _clip_round(snr / EXT_UNITS["snr_unit"], np.uint8)
        tlvs.append((EXT_DETECTED_POINTS, u.tobytes() + p.tobytes()))
        platform = PLATFORM["xwrl6432"]
    elif fmt == "tracking":
        u = np.zeros(1, COMPRESSED_UNIT)
        for k, val in COMPRESSED_UNITS.items():
            u[k] = val
        p = np.zeros(n, COMPRESSED_POINT)
        p["elevation"] = _clip_round(
            np.asarray(cloud.elevation_rad) / COMPRESSED_UNITS["elevation_unit"], np.int8
        )
        p["azimuth"] = _clip_round(
            np.asarray(cloud.azimuth_rad) / COMPRESSED_UNITS["azimuth_unit"], np.int8
        )
        p["doppler"] = _clip_round(v / COMPRESSED_UNITS["doppler_unit"], np.int16)
        p["range"] = _clip_round(
            np.asarray(cloud.range_m) / COMPRESSED_UNITS["range_unit"], np.uint16
        )
        # the demo's SNR is linear (see linear_snr_db)
        p["snr"] = _clip_round(10.0 ** (snr / 10.0) / COMPRESSED_UNITS["snr_unit"], np.uint16)
        tlvs.append((COMPRESSED_POINTS, u.tobytes() + p.tobytes()))
    else:
        raise InputError(f"UART point format must be one of {list(WRITE_FORMATS)}, got {fmt!r}")
    tlvs += list(extra_tlvs)
    hdr_dtype = HEADER_36 if fmt == "sdk1-xwr14" else HEADER_40
    body = b"".join(np.array([(t, len(pl))], TLV_HEADER).tobytes() + pl for t, pl in tlvs)
    used = hdr_dtype.itemsize + len(body)
    total = -(-used // PACKET_ALIGN) * PACKET_ALIGN
    h = np.zeros(1, hdr_dtype)
    h["magic"] = int.from_bytes(MAGIC, "little")
    h["version"] = WRITE_VERSION[fmt]
    h["total_len"] = total
    h["platform"] = platform
    h["frame_number"] = frame_number
    h["time_cpu_cycles"] = time_cpu_cycles
    h["n_detected"] = n
    h["n_tlvs"] = len(tlvs)
    return h.tobytes() + body + bytes(total - used)


def _clip_round(a: np.ndarray, dtype: type) -> np.ndarray:
    info = np.iinfo(dtype)
    return np.clip(np.rint(np.asarray(a, dtype=np.float64)), info.min, info.max).astype(dtype)


def write_uart_log(
    path: str | os.PathLike,
    clouds: Iterable[PointCloud],
    *,
    fmt: str = "sdk3",
    radar: RadarConfig | None = None,
    first_frame: int = 1,
) -> Path:
    """Write one packet per point cloud (frame numbers from ``first_frame``), atomically."""
    path = Path(path)
    with atomic_open(path, "wb") as fh:
        for k, cloud in enumerate(clouds):
            fh.write(encode_frame(cloud, first_frame + k, fmt=fmt, radar=radar))
    return path


def quantisation_step(fmt: str, radar: RadarConfig | None = None) -> dict[str, float]:
    """The least significant bit of each written quantity (m, m/s) in point format ``fmt``:
    a round trip returns every value within half of it (plus float32 rounding)."""
    if fmt == "sdk3":
        return {"xyz_m": 0.0, "velocity_mps": 0.0}
    if fmt in ("sdk2", "sdk1-xwr14"):
        if radar is None:
            raise InputError("the SDK 1.x/2.x point format needs the radar configuration")
        return {"xyz_m": 2.0**-WRITE_Q, "velocity_mps": radar.velocity_resolution_mps}
    if fmt == "sdk5":
        return {"xyz_m": EXT_UNITS["xyz_unit"], "velocity_mps": EXT_UNITS["doppler_unit"]}
    if fmt == "tracking":
        return {
            "range_m": COMPRESSED_UNITS["range_unit"],
            "azimuth_rad": COMPRESSED_UNITS["azimuth_unit"],
            "elevation_rad": COMPRESSED_UNITS["elevation_unit"],
            "velocity_mps": COMPRESSED_UNITS["doppler_unit"],
        }
    raise InputError(f"UART point format must be one of {list(WRITE_FORMATS)}, got {fmt!r}")
