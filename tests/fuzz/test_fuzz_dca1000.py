"""Fuzz the DCA1000 reader: generated cfg edits, cut, grown and corrupted captures. The promise:
a data set or one InputError line, never another exception."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from core.errors import InputError
from core.formats.dca1000 import CaptureLayout, write_capture_frames
from core.formats.ti_cfg import read_ti_capture_cfg
from core.pipeline.capture import dataset_from_capture
from tests.fuzz.conftest import FUZZ_SETTINGS

#: A small capture's cfg: 2 TX x 2 RX, 8 loops, 32 complex samples (1 KiB a chirp... a frame
#: of 8 x 2 chirps).
BASE_CFG = """channelCfg 3 5 0
adcCfg 2 1
adcbufCfg -1 0 1 1 1
profileCfg 0 60 7 6 50 0 0 40 1 32 5000 0 0 30
chirpCfg 0 0 0 0 0 0 0 1
chirpCfg 1 1 0 0 0 0 0 4
frameCfg 0 1 8 0 50 1 0
"""
COMMANDS = ["channelCfg", "adcCfg", "adcbufCfg", "profileCfg", "chirpCfg", "frameCfg"]
words = st.one_of(
    st.sampled_from(["0", "1", "2", "3", "4", "-1", "16", "32", "31", "x", "1e9", "nan", "0x7"]),
    st.integers(-(2**31), 2**31).map(str),
)


def _frames(n_frames: int) -> bytes:
    with tempfile.TemporaryDirectory() as tmp:
        cfg = Path(tmp) / "c.cfg"
        cfg.write_text(BASE_CFG)
        radar, adc = read_ti_capture_cfg(cfg)
        layout = CaptureLayout.from_radar(radar, adc)
        rng = np.random.default_rng(0)
        cubes = [
            tuple(rng.integers(-300, 300, layout.cube_shape).astype(np.int16) for _ in range(2))
            for _ in range(n_frames)
        ]
        path = write_capture_frames(Path(tmp) / "c.bin", cubes, layout)
        return path.read_bytes()


BASE_BIN = _frames(2)


def _check(cfg_text: str, data: bytes) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        cfg = Path(tmp) / "c.cfg"
        cfg.write_text(cfg_text, encoding="utf-8", errors="surrogatepass")
        capture = Path(tmp) / "c.bin"
        capture.write_bytes(data)
        try:
            ds = dataset_from_capture(capture, cfg, note=lambda _: None)
        except InputError as exc:
            assert "\n" not in str(exc) and "Traceback" not in str(exc)
            return
        assert ds.n_frames >= 1
        assert np.all(np.isfinite(ds.range_m)) and np.all(np.isfinite(ds.snr_db))


@FUZZ_SETTINGS
@given(
    cut=st.integers(0, len(BASE_BIN) + 4096),
    flips=st.lists(st.tuples(st.integers(0, len(BASE_BIN) - 1), st.integers(0, 255)), max_size=8),
    extreme=st.booleans(),
)
def test_cut_grown_and_corrupted_captures(cut: int, flips: list, extreme: bool) -> None:
    """Any length (empty, partial frames, extra bytes) and any sample values."""
    data = bytearray(BASE_BIN)
    if extreme:  # full-scale samples everywhere
        data = bytearray(np.full(len(data) // 2, -32768, dtype="<i2").tobytes())
    for pos, value in flips:
        data[pos] = value
    data = data[:cut] if cut <= len(data) else data + bytes(cut - len(data))
    _check(BASE_CFG, bytes(data))


@FUZZ_SETTINGS
@given(
    edits=st.lists(
        st.tuples(st.sampled_from([*COMMANDS, "x"]), st.lists(words, max_size=16)),
        min_size=1,
        max_size=3,
    )
)
def test_generated_cfg_commands(edits: list) -> None:
    """The capture's cfg with commands replaced or added with generated fields."""
    lines = BASE_CFG.splitlines()
    for name, ws in edits:
        line = " ".join([name, *ws])
        hits = [i for i, ln in enumerate(lines) if ln.startswith(name + " ")]
        if hits:
            lines[hits[0]] = line
        else:
            lines.append(line)
    _check("\n".join(lines) + "\n", BASE_BIN)
