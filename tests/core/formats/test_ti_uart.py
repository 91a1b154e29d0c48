"""TI UART TLV stream: every header generation and point TLV built byte by byte from TI's
documented layouts (not with the module's writer), round trips through the writer to the
formats' precision, resynchronisation after damage, and streaming in bounded memory."""

from __future__ import annotations

import math
import struct
import tracemalloc

import numpy as np
import pytest

from core.config import PAPER_RADAR
from core.errors import InputError
from core.formats import ti_uart
from core.formats.recording import frames_from_numbers
from core.formats.ti_uart_import import read as read_log
from core.pointcloud import PointCloud

MAGIC = struct.pack("<4H", 0x0102, 0x0304, 0x0506, 0x0708)


def tlv(t: int, payload: bytes) -> bytes:
    # TLV header: type u32, length u32 (payload bytes)
    return struct.pack("<2I", t, len(payload)) + payload


def packet(
    tlvs: list[bytes],
    *,
    frame: int,
    n_det: int,
    version: int = 0x03050000,
    platform: int = 0xA6843,
    subframe: int | None = 0,
    pad: bool = True,
) -> bytes:
    """Header (40 bytes with sub-frame number, 36 without) + TLVs + padding to 32 bytes."""
    body = b"".join(tlvs)
    hlen = 36 if subframe is None else 40
    total = hlen + len(body)
    if pad:
        total = -(-total // 32) * 32
    fields = [version, total, platform, frame, 123456, n_det, len(tlvs)]
    if subframe is not None:
        fields.append(subframe)
    head = MAGIC + struct.pack(f"<{len(fields)}I", *fields)
    return head + body + bytes(total - hlen - len(body))


def frames_of(data: bytes, **kw):
    report = ti_uart.UartReport()
    frames = list(ti_uart.iter_uart_frames([data], report=report, **kw))
    return frames, report


# ---- header generations -----------------------------------------------------------------------
def test_sdk3_float_points_and_side_info() -> None:
    pts = [(0.5, 2.0, 0.1, -0.75), (-1.25, 4.0, 0.0, 1.5)]
    p1 = b"".join(struct.pack("<4f", *p) for p in pts)
    p7 = struct.pack("<4h", 123, 456, -5, 300)  # snr, noise in 0.1 dB
    frames, rep = frames_of(packet([tlv(1, p1), tlv(7, p7)], frame=7, n_det=2))
    (f,) = frames
    assert (f.header_bytes, f.point_format, f.frame_number, f.subframe) == (40, "float", 7, 0)
    assert f.sdk_version == "3.5.0.0"
    np.testing.assert_array_equal(f.points.x_m, [0.5, -1.25])
    np.testing.assert_array_equal(f.points.velocity_mps, [-0.75, 1.5])
    np.testing.assert_allclose(f.points.snr_db, [12.3, -0.5])
    np.testing.assert_allclose(f.points.noise_db, [45.6, 30.0])
    assert rep.n_frames == 1 and rep.n_damaged == 0 and not rep.unknown_tlvs


def q_points(q: int, objs: list[tuple[int, int, int, int, int, int]]) -> bytes:
    # descriptor {u16 numDetetedObj, u16 xyzQFormat}, then {u16 rangeIdx, i16 dopplerIdx,
    # u16 peakVal, i16 x, i16 y, i16 z} per object
    return struct.pack("<2H", len(objs), q) + b"".join(struct.pack("<Hh4h", *o)[:12] for o in objs)


@pytest.mark.parametrize(
    ("platform", "subframe", "version", "hlen"),
    [
        (0xA1443, None, 0x01020000, 36),
        (0xA1443, None, 0x02010000, 36),
        (0xA1642, 0, 0x02010000, 40),
    ],
)
def test_sdk1_sdk2_q_format(platform, subframe, version, hlen) -> None:
    q = 8
    objs = [(10, 3, 500, 256, 1024, -64), (20, -2, 900, -512, 768, 0)]
    data = packet(
        [tlv(1, q_points(q, objs))],
        frame=1,
        n_det=2,
        version=version,
        platform=platform,
        subframe=subframe,
    )
    (f,), _ = frames_of(data, radar=PAPER_RADAR)
    assert (f.header_bytes, f.point_format) == (hlen, "q")
    # x = value / 2^Q
    np.testing.assert_array_equal(f.points.x_m, [1.0, -2.0])
    np.testing.assert_array_equal(f.points.y_m, [4.0, 3.0])
    np.testing.assert_array_equal(f.points.z_m, [-0.25, 0.0])
    # v = Doppler index x velocity resolution
    dv = PAPER_RADAR.velocity_resolution_mps
    np.testing.assert_allclose(f.points.velocity_mps, [3 * dv, -2 * dv])
    # level = 20·log10(peakVal), peakVal the angle-FFT peak's amplitude
    np.testing.assert_allclose(f.points.snr_db, 20 * np.log10([500, 900]))


def test_q_format_without_cfg_is_one_line() -> None:
    data = packet(
        [tlv(1, q_points(8, [(1, 1, 1, 1, 1, 1)]))],
        frame=1,
        n_det=1,
        version=0x02010000,
        platform=0xA1443,
        subframe=None,
    )
    with pytest.raises(InputError, match=r"<stream>:0: SDK 1.x/2.x points .*--cfg"):
        frames_of(data)


def test_header_generation_is_decided_by_structure() -> None:
    """A 36-byte header from a platform that usually sends 40 (and the reverse) still reads."""
    pts = struct.pack("<4f", 1.0, 2.0, 3.0, 0.5)
    odd36 = packet([tlv(1, pts)], frame=3, n_det=1, platform=0xA6843, subframe=None)
    odd40 = packet([tlv(1, pts)], frame=4, n_det=1, platform=0xA1443, version=0x02000000)
    frames, rep = frames_of(odd36 + odd40)
    assert [f.header_bytes for f in frames] == [36, 40]
    assert rep.n_damaged == 0


def test_sdk5_ext_points() -> None:
    # units {f32 xyz, doppler, snr, noise; u16 numDetectedPoints[2]}, then per point
    # {i16 x, y, z, doppler; u8 snr, noise}
    unit = struct.pack("<4f2H", 0.001, 0.01, 0.5, 0.25, 1, 1)
    pts = struct.pack("<4h2B", 1500, 2500, -100, -70, 40, 8) + struct.pack(
        "<4h2B", -300, 900, 0, 25, 10, 12
    )
    (f,), _ = frames_of(
        packet([tlv(301, unit + pts)], frame=9, n_det=2, version=0x05040000, platform=0x6432)
    )
    assert f.point_format == "ext"
    np.testing.assert_allclose(f.points.x_m, [1.5, -0.3], rtol=1e-6)
    np.testing.assert_allclose(f.points.velocity_mps, [-0.7, 0.25], rtol=1e-6)
    np.testing.assert_allclose(f.points.snr_db, [20.0, 5.0])
    np.testing.assert_allclose(f.points.noise_db, [2.0, 3.0])


def test_people_tracking_tlvs() -> None:
    # 1020: units {elevation, azimuth, doppler, range, snr} then {i8 el, i8 az, i16 doppler,
    # u16 range, u16 snr}; 1010: targets of 112 bytes; 1011: u8 per point; 1021: u32
    unit = struct.pack("<5f", 0.01, 0.01, 0.05, 0.0025, 0.04)
    pts = struct.pack("<2bh2H", 0, 50, -10, 1200, 500)
    target = struct.pack("<I27f", 5, 0.1, 2.9, 1.0, *([0.0] * 24))
    data = packet(
        [tlv(1020, unit + pts), tlv(1010, target), tlv(1011, b"\x05"), tlv(1021, b"\x01\0\0\0")],
        frame=2,
        n_det=1,
    )
    (f,), rep = frames_of(data)
    assert f.point_format == "compressed"
    r, az = 1200 * 0.0025, 50 * 0.01
    # x = r cos(el) sin(az), y = r cos(el) cos(az)
    np.testing.assert_allclose(
        [f.points.x_m[0], f.points.y_m[0]], [r * math.sin(az), r * math.cos(az)], rtol=1e-6
    )
    np.testing.assert_allclose(f.points.velocity_mps, [-0.5], rtol=1e-6)
    # TI: "Range detection SNR, linear": 500 x 0.04 = 20, 13.01 dB
    np.testing.assert_allclose(f.points.snr_db, [10 * math.log10(20.0)], rtol=1e-6)
    assert f.extras["targets"]["tid"][0] == 5
    np.testing.assert_allclose(f.extras["targets"]["pos"][0], [0.1, 2.9, 1.0], rtol=1e-6)
    assert f.extras["target_index"].tolist() == [5] and f.extras["presence"].tolist() == [1]
    assert not rep.unknown_tlvs


def test_auxiliary_tlvs_are_kept_as_arrays() -> None:
    profile = np.arange(64, dtype="<u2").tobytes()
    stats = struct.pack("<6I", 1, 2, 3, 4, 5, 6)
    temp = struct.pack("<iI10H", 1, 99, *range(10))
    rd = np.ones(16 * 8, dtype="<u2").tobytes()
    data = packet(
        [tlv(2, profile), tlv(3, profile), tlv(5, rd), tlv(6, stats), tlv(9, temp)],
        frame=1,
        n_det=0,
    )
    (f,), _ = frames_of(data)
    assert len(f.points) == 0
    np.testing.assert_array_equal(f.extras["range_profile"], np.arange(64))
    assert f.extras["stats"]["active_frame_cpu_load"][0] == 5
    assert f.extras["temperature"]["temperature"][0].tolist() == list(range(10))
    assert f.extras["range_doppler_heat_map"].shape == (128,)


# ---- damage -----------------------------------------------------------------------------------
def log(n: int = 6, n_pts: int = 3) -> list[bytes]:
    out = []
    for k in range(n):
        pts = b"".join(struct.pack("<4f", 0.1 * k, 1.0 + i, 0.0, 0.2) for i in range(n_pts))
        out.append(packet([tlv(1, pts)], frame=100 + k, n_det=n_pts))
    return out


def test_unknown_tlv_is_skipped_and_counted() -> None:
    pts = struct.pack("<4f", 1.0, 2.0, 0.0, 0.1)
    data = packet([tlv(4242, b"abcd" * 3), tlv(1, pts), tlv(4242, b"")], frame=1, n_det=1)
    (f,), rep = frames_of(data)
    assert len(f.points) == 1 and rep.unknown_tlvs == {4242: 2}
    assert "unknown TLV types skipped: 4242 x2" in rep.summary()


def test_cut_mid_frame_at_the_end() -> None:
    pk = log()
    data = b"".join(pk)[: -len(pk[-1]) // 2]
    frames, rep = frames_of(data)
    assert [f.frame_number for f in frames] == [100, 101, 102, 103, 104]
    assert rep.n_truncated == 1 and rep.n_damaged == 0


def test_bytes_lost_in_the_middle() -> None:
    pk = log()
    hurt = pk[2][:50] + pk[2][60:]  # 10 bytes lost inside packet 2 (frame 102)
    frames, rep = frames_of(b"".join([*pk[:2], hurt, *pk[3:]]))
    assert [f.frame_number for f in frames] == [100, 101, 103, 104, 105]
    assert rep.n_damaged >= 1 and rep.n_dropped == 1


def test_wrong_magic_word_and_junk_between_packets() -> None:
    pk = log()
    bad = b"\x02\x01\x04\x03\x06\x05\x08\x09" + pk[1][8:]
    frames, rep = frames_of(b"garbage" + pk[0] + bad + b"\xff" * 5 + b"".join(pk[2:]))
    assert [f.frame_number for f in frames] == [100, 102, 103, 104, 105]
    assert rep.n_dropped == 1 and rep.bytes_skipped == 7 + len(pk[1]) + 5


def test_a_lying_length_swallowing_the_next_packet_is_refused() -> None:
    pk = log()
    liar = bytearray(pk[1])
    struct.pack_into("<I", liar, 12, len(pk[1]) + len(pk[2]))  # claims the next packet too
    frames, rep = frames_of(b"".join([pk[0], bytes(liar), *pk[2:]]))
    assert [f.frame_number for f in frames] == [100, 102, 103, 104, 105]


def test_empty_and_no_magic_are_one_line(tmp_path) -> None:
    empty = tmp_path / "empty.dat"
    empty.write_bytes(b"")
    with pytest.raises(InputError, match=r"empty.dat:0: empty file"):
        list(ti_uart.iter_uart_frames(empty))
    junk = tmp_path / "junk.dat"
    junk.write_bytes(bytes(range(256)) * 10)
    with pytest.raises(InputError, match=r"junk.dat:0: no TI UART packet found"):
        list(ti_uart.iter_uart_frames(junk))


# ---- streaming --------------------------------------------------------------------------------
def test_streams_a_multi_megabyte_log_in_bounded_memory() -> None:
    """A ~8 MB log fed in 4 KiB chunks by a generator: every packet is read, and the reader's
    own allocations stay a small multiple of one chunk plus one packet, not the log."""
    pk = log(n=1, n_pts=30)[0]
    n_packets = 8_000_000 // len(pk)

    def chunks():
        block = pk * 8
        for _ in range(n_packets // 8):
            for i in range(0, len(block), 4096):
                yield block[i : i + 4096]

    tracemalloc.start()
    n = 0
    for f in ti_uart.iter_uart_frames(chunks()):
        n += len(f.points)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert n == (n_packets // 8) * 8 * 30
    assert peak < 1_000_000  # the log is 8 MB


# ---- writer round trips -----------------------------------------------------------------------
def cloud(rng: np.random.Generator, n: int) -> PointCloud:
    r = rng.uniform(0.5, 12.0, n)
    az = rng.uniform(-1.0, 1.0, n)
    el = rng.uniform(-0.3, 0.3, n)
    x, y, z = r * np.cos(el) * np.sin(az), r * np.cos(el) * np.cos(az), r * np.sin(el)
    return PointCloud(
        range_m=r,
        azimuth_rad=az,
        elevation_rad=el,
        radial_velocity_mps=rng.uniform(-2.5, 2.5, n),
        snr_db=rng.uniform(5, 40, n),
        x_m=x,
        y_m=y,
        z_m=z,
        source=np.zeros(n, dtype=np.int32),
    )


@pytest.mark.parametrize("fmt", ti_uart.WRITE_FORMATS)
def test_round_trip_to_the_formats_precision(fmt) -> None:
    rng = np.random.default_rng(4)
    clouds = [cloud(rng, n) for n in (0, 1, 17, 40)]
    data = b"".join(
        ti_uart.encode_frame(c, 10 + k, fmt=fmt, radar=PAPER_RADAR) for k, c in enumerate(clouds)
    )
    assert len(data) % 32 == 0
    frames, rep = frames_of(data, radar=PAPER_RADAR)
    assert [f.frame_number for f in frames] == [10, 11, 12, 13] and rep.n_damaged == 0
    lsb = ti_uart.quantisation_step(fmt, PAPER_RADAR)
    for c, f in zip(clouds, frames):
        p = f.points
        assert len(p) == len(c)
        if fmt == "sdk3":  # float32 on the wire: exact to float32
            for a, b in (
                (p.x_m, c.x_m),
                (p.y_m, c.y_m),
                (p.z_m, c.z_m),
                (p.velocity_mps, c.radial_velocity_mps),
            ):
                np.testing.assert_array_equal(a, np.float32(b))
            np.testing.assert_allclose(p.snr_db, c.snr_db, atol=0.05 + 1e-9)  # 0.1 dB steps
        elif fmt == "tracking":
            rr = np.sqrt(np.asarray(p.x_m) ** 2 + np.asarray(p.y_m) ** 2 + np.asarray(p.z_m) ** 2)
            assert np.all(np.abs(rr - c.range_m) <= lsb["range_m"] / 2 + 1e-6)
            az = np.arctan2(p.x_m, p.y_m)
            assert np.all(np.abs(az - c.azimuth_rad) <= lsb["azimuth_rad"] / 2 + 1e-6)
            assert np.all(
                np.abs(p.velocity_mps - c.radial_velocity_mps) <= lsb["velocity_mps"] / 2 + 1e-6
            )
            # linear SNR in steps of snr_unit: within half a step, in dB
            lin = 10 ** (c.snr_db / 10)
            half = ti_uart.COMPRESSED_UNITS["snr_unit"] / 2
            bound = 10 * np.log10(lin / (lin - half)) + 1e-6  # rounding down: the larger
            in_range = lin < 65535 * ti_uart.COMPRESSED_UNITS["snr_unit"]
            assert np.all(np.abs(p.snr_db - c.snr_db)[in_range] <= bound[in_range])
        else:  # integer formats: within half a step (round to nearest), float32 units aside
            for a, b in ((p.x_m, c.x_m), (p.y_m, c.y_m), (p.z_m, c.z_m)):
                assert np.all(np.abs(a - b) <= lsb["xyz_m"] / 2 * (1 + 1e-6))
            assert np.all(
                np.abs(p.velocity_mps - c.radial_velocity_mps)
                <= lsb["velocity_mps"] / 2 * (1 + 1e-6)
            )
            if fmt != "sdk5":  # peakVal: an integer amplitude, 20·log10 of it the level
                amp = 10 ** (c.snr_db / 20)
                bound = 20 * np.log10(amp / (amp - 0.5)) + 1e-6  # rounding down: the larger
                assert np.all(np.abs(p.snr_db - c.snr_db) <= bound)


def test_import_inserts_empty_frames_for_gaps_and_splits_runs(tmp_path) -> None:
    slot, t, traj, filled = frames_from_numbers(np.array([5, 6, 8, 8, 9, 2, 3]), 0.1)
    assert slot.tolist() == [0, 1, 3, 3, 4, 5, 6]
    assert traj.tolist() == [0, 0, 0, 0, 0, 1, 1] and filled == 1
    np.testing.assert_allclose(t, np.arange(7) * 0.1)
    rng = np.random.default_rng(0)
    c = cloud(rng, 5)
    data = b"".join(ti_uart.encode_frame(c, k) for k in (1, 2, 4))
    rec = read_log(tmp_path / "x.dat", None, chunks=[data])
    assert rec.counts.tolist() == [5, 5, 0, 5]
    assert "1 dropped" in rec.notes[0]


def test_a_log_longer_than_the_data_set_limit_stops_early(tmp_path, monkeypatch) -> None:
    """The importer refuses at the limit instead of reading (and holding) the whole log."""
    import core.formats.ti_uart_import as imp

    monkeypatch.setattr(imp, "MAX_DATASET_FRAMES", 3)
    data = b"".join(log(n=6))
    with pytest.raises(InputError, match=r"more than 3 packets .*split the log"):
        read_log(tmp_path / "long.dat", None, chunks=[data])
