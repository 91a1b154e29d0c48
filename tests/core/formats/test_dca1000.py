"""DCA1000 capture layout (TI SWRA581B): word order, I/Q swap, real samples, ADC bits, sizes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from core.errors import InputError
from core.formats.dca1000 import (
    CaptureLayout,
    decode_frame,
    encode_frame,
    iter_capture_frames,
    open_capture,
    write_capture_frames,
)
from core.formats.ti_cfg import AdcFormat, adc_format, parse_ti_cfg, read_ti_capture_cfg

SMALL = CaptureLayout(n_loops=3, n_tx=2, n_rx=2, n_samples=4)


def _cube(layout: CaptureLayout, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    lim = np.iinfo(np.int16)
    i = rng.integers(lim.min, lim.max, layout.cube_shape, endpoint=True).astype(np.int16)
    q = rng.integers(lim.min, lim.max, layout.cube_shape, endpoint=True).astype(np.int16)
    return i, q


def test_complex_words_follow_ti_two_lane_order() -> None:
    """Chirp (loop m, slot k), then RX r, then groups ``I(n) I(n+1) Q(n) Q(n+1)``."""
    lay = SMALL
    n_v, n_l, n = lay.cube_shape
    v, m, s = np.meshgrid(np.arange(n_v), np.arange(n_l), np.arange(n), indexing="ij")
    i = (1000 * v + 100 * m + s).astype(np.int16)
    q = -i - 1
    words = encode_frame(i, q, lay)
    assert words.shape == (lay.frame_words,) == (3 * 2 * 2 * 4 * 2,)
    # the first chirp (m=0, k=0), RX 0: I0 I1 Q0 Q1 I2 I3 Q2 Q3
    assert words[:8].tolist() == [0, 1, -1, -2, 2, 3, -3, -4]
    # then RX 1 of that chirp (virtual channel 1)
    assert words[8:12].tolist() == [1000, 1001, -1001, -1002]
    # the second chirp is TX slot 1 of loop 0 (virtual channel 2), the third loop 1 slot 0
    assert words[16] == 2000 and words[32] == 100
    cube = decode_frame(words, lay)
    assert np.array_equal(cube.real, i) and np.array_equal(cube.imag, q)


def test_iq_swap_puts_q_pair_first() -> None:
    lay = CaptureLayout(n_loops=1, n_tx=1, n_rx=1, n_samples=2, adc=AdcFormat(iq_swap=True))
    i = np.array([[[5, 6]]], dtype=np.int16)
    q = np.array([[[7, 8]]], dtype=np.int16)
    assert encode_frame(i, q, lay).tolist() == [7, 8, 5, 6]
    assert decode_frame(np.array([7, 8, 5, 6], dtype=np.int16), lay)[0, 0].tolist() == [
        5 + 7j,
        6 + 8j,
    ]


@pytest.mark.parametrize("adc", [AdcFormat(), AdcFormat(iq_swap=True)])
def test_encode_decode_are_inverse(adc: AdcFormat) -> None:
    lay = CaptureLayout(n_loops=4, n_tx=3, n_rx=4, n_samples=8, adc=adc)
    i, q = _cube(lay, 3)
    cube = decode_frame(encode_frame(i, q, lay), lay)
    assert cube.dtype == np.complex64
    assert np.array_equal(cube.real, i) and np.array_equal(cube.imag, q)


def test_real_samples_in_order_with_zero_imaginary_part() -> None:
    lay = CaptureLayout(
        n_loops=2, n_tx=1, n_rx=2, n_samples=3, adc=AdcFormat(complex_samples=False)
    )
    assert lay.chirp_words == 6
    words = np.arange(12, dtype=np.int16)
    cube = decode_frame(words, lay)
    # loop 1, RX 1 starts at word (1 * 2 + 1) * 3 = 9
    assert cube[1, 1].real.tolist() == [9, 10, 11] and not cube.imag.any()
    assert np.array_equal(encode_frame(cube.real.astype(np.int16), None, lay), words)


@pytest.mark.parametrize("bits", [12, 14])
def test_narrow_adc_words_are_sign_extended(bits: int) -> None:
    lay = CaptureLayout(n_loops=1, n_tx=1, n_rx=1, n_samples=2, adc=AdcFormat(n_bits=bits))
    # -1 and -2**(bits-1) written without sign extension, 2**(bits-1) - 1 as is
    raw = [(1 << bits) - 1, 1 << (bits - 1), (1 << (bits - 1)) - 1, 0]
    cube = decode_frame(np.array(raw, dtype=np.uint16).view(np.int16), lay)
    assert cube[0, 0].real.tolist() == [-1, -(1 << (bits - 1))]
    assert cube[0, 0].imag.tolist() == [(1 << (bits - 1)) - 1, 0]


def test_odd_sample_count_refused_for_complex() -> None:
    with pytest.raises(InputError, match="must be even"):
        CaptureLayout(n_loops=1, n_tx=1, n_rx=1, n_samples=5)


def test_stream_reads_whole_frames_and_reports_partial(tmp_path: Path) -> None:
    i, q = _cube(SMALL, 1)
    frames = [(i, q), (q, i), (i, i)]
    path = write_capture_frames(tmp_path / "c.bin", frames, SMALL)
    assert path.stat().st_size == 3 * SMALL.frame_bytes
    # a capture stopped after two chirps of a fourth frame
    with path.open("ab") as fh:
        fh.write(b"\x01\x00" * 2 * SMALL.chirp_words)
    cap = open_capture(path, SMALL)
    assert (cap.n_frames, cap.trailing_bytes) == (3, 2 * SMALL.chirp_bytes)
    assert "2 of 6 chirps" in cap.dropped_note
    got = list(iter_capture_frames(cap))
    assert len(got) == 3
    for cube, (a, b) in zip(got, frames):
        assert np.array_equal(cube.real, a) and np.array_equal(cube.imag, b)


@pytest.mark.parametrize(
    ("size", "expected"),
    [
        (0, "empty capture"),
        (SMALL.frame_bytes - SMALL.chirp_bytes, "does not match"),
        (SMALL.frame_bytes + 6, "does not match"),
    ],
)
def test_size_mismatch_is_one_line_naming_both_files(
    tmp_path: Path, size: int, expected: str
) -> None:
    path = tmp_path / "c.bin"
    path.write_bytes(b"\0" * size)
    with pytest.raises(InputError, match=expected) as err:
        open_capture(path, SMALL, cfg_path=tmp_path / "c.cfg")
    msg = str(err.value)
    assert "\n" not in msg and "c.bin" in msg
    if size:
        assert "c.cfg" in msg and str(size) in msg and str(SMALL.frame_bytes) in msg


def test_missing_capture_is_input_error(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="cannot read capture"):
        open_capture(tmp_path / "absent.bin", SMALL)
    with pytest.raises(InputError, match="capture is not a file"):
        open_capture(tmp_path, SMALL)


CFG_HEAD = """channelCfg 15 5 0
profileCfg 0 77 7 6 62 0 0 60 1 128 2500 0 0 30
chirpCfg 0 0 0 0 0 0 0 1
chirpCfg 1 1 0 0 0 0 0 4
frameCfg 0 1 16 0 100 1 0
"""


@pytest.mark.parametrize(
    ("lines", "expected"),
    [
        ("adcCfg 2 1\nadcbufCfg -1 0 1 1 1\n", AdcFormat(iq_swap=True)),
        ("adcCfg 2 2\nadcbufCfg 0 0 1 1\n", AdcFormat(iq_swap=False)),  # SDK 1.x: no subframe
        ("adcCfg 0 0\nadcbufCfg -1 1 0 1 1\n", AdcFormat(complex_samples=False, n_bits=12)),
        ("", AdcFormat()),
    ],
)
def test_adc_format_from_cfg(tmp_path: Path, lines: str, expected: AdcFormat) -> None:
    path = tmp_path / "x.cfg"
    path.write_text(CFG_HEAD + lines)
    radar, adc = read_ti_capture_cfg(path)
    assert adc == expected
    assert (radar.n_tx, radar.n_rx, radar.n_loops, radar.n_samples) == (2, 4, 16, 128)


@pytest.mark.parametrize(
    ("lines", "field"),
    [
        ("adcCfg 3 1\n", "numADCBits"),
        ("adcCfg 2 3\n", "adcOutputFmt"),
        ("adcCfg 2 1\nadcbufCfg -1 1 0 1 1\n", "adcOutputFmt"),
        ("adcbufCfg -1 0 2 1 1\n", "sampleSwap"),
        ("adcbufCfg -1 0 0 0 1\n", "chanInterleave"),
        ("adcbufCfg -1 0 x 1 1\n", "sampleSwap"),
    ],
)
def test_wrong_sample_format_names_line_and_field(lines: str, field: str) -> None:
    text = CFG_HEAD + lines
    with pytest.raises(InputError, match=field) as err:
        adc_format(parse_ti_cfg(text, "x.cfg"), "x.cfg")
    assert f"x.cfg:{len(text.splitlines())}" in str(err.value)


@pytest.mark.slow
def test_one_gigabyte_capture_streams_in_bounded_memory(tmp_path: Path) -> None:
    """A 1 GiB capture (sparse: zeros) is read frame by frame; Python allocations stay within a
    few frames whatever the file's size."""
    import tracemalloc

    lay = CaptureLayout(n_loops=32, n_tx=3, n_rx=4, n_samples=256)
    path = tmp_path / "big.bin"
    n_frames = (1 << 30) // lay.frame_bytes
    with path.open("wb") as fh:
        fh.truncate(n_frames * lay.frame_bytes)
    cap = open_capture(path, lay)
    assert cap.n_frames == n_frames == 2730
    from core.formats.dca1000 import iter_raw_frames

    tracemalloc.start()
    try:
        seen = sum(1 for words in iter_raw_frames(cap) if words.shape == (lay.frame_words,))
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert seen == n_frames
    assert peak < 4 * lay.frame_bytes
