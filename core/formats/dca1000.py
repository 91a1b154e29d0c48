"""DCA1000EVM raw ADC captures (``.bin``): the sample layout, a streaming reader and a writer.

The DCA1000EVM capture card records the LVDS stream of an xWR16xx / xWR18xx / IWR6843 device
as little-endian 16-bit words, with no header (TI, *mmWave Radar Device ADC Raw Data Capture*,
SWRA581B, section "xWR16xx and IWR6843 with DCA1000 data format"; TI, *DCA1000EVM Data Capture
Card User's Guide*, SPRUIJ4). Chirps follow each other in transmit order, each chirp holds the
enabled receivers one after the other, each receiver its ``N`` samples:

- complex samples (two LVDS lanes): groups of four words ``I(n) I(n+1) Q(n) Q(n+1)``, ``n``
  even; with ``adcbufCfg`` sampleSwap 1 the Q pair comes first;
- real samples: the ``N`` words in order.

So one frame is ``[loop, TX slot, RX, sample]`` in the file, and the radar cube RadarTune
processes is ``[virtual channel = slot * n_rx + rx, loop, sample]``. With 12- or 14-bit ADCs the
words are not sign-extended (SWRA581B's MATLAB reader subtracts ``2**bits`` above the largest
positive value); this reader does the same.

The reader streams: one frame is read into a reused buffer at a time (``readinto``), so memory
stays bounded by a frame whatever the capture's size.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from core.config import RadarConfig
from core.errors import InputError
from core.files import atomic_open, printable
from core.formats.ti_cfg import AdcFormat

#: Bytes per ADC word.
WORD_BYTES = 2
#: 16-bit complex samples, I before Q: TI's documented DCA1000 layout.
COMPLEX_16BIT = AdcFormat()


#: The format's name in the table of recording formats (:data:`core.recordings.FORMATS`).
CAPTURE_FORMAT = "dca1000"


@dataclass(frozen=True, slots=True, kw_only=True)
class CaptureLayout:
    """The shape of one frame of a DCA1000 capture.

    Parameters
    ----------
    n_loops, n_tx, n_rx, n_samples
        Loops per frame, TX slots (chirps) per loop, enabled receivers, ADC samples per chirp.
    adc
        How samples are coded (complex or real, I/Q order, bits).
    """

    n_loops: int
    n_tx: int
    n_rx: int
    n_samples: int
    adc: AdcFormat = COMPLEX_16BIT

    def __post_init__(self) -> None:
        for name in ("n_loops", "n_tx", "n_rx", "n_samples"):
            value = getattr(self, name)
            if not (isinstance(value, int) and value > 0):
                raise InputError(f"{name} must be a positive integer, got {name}={value!r}")
        if self.adc.complex_samples and self.n_samples % 2:
            raise InputError(
                "complex DCA1000 captures hold samples in pairs per LVDS lane: numAdcSamples "
                f"must be even, got n_samples={self.n_samples}"
            )

    @classmethod
    def from_radar(cls, radar: RadarConfig, adc: AdcFormat = COMPLEX_16BIT) -> CaptureLayout:
        """The layout a capture made with ``radar``'s configuration has."""
        return cls(
            n_loops=radar.n_loops,
            n_tx=radar.n_tx,
            n_rx=radar.n_rx,
            n_samples=radar.n_samples,
            adc=adc,
        )

    @property
    def chirp_words(self) -> int:
        """16-bit words per chirp: ``n_rx * n_samples`` (times 2 for complex samples)."""
        return self.n_rx * self.n_samples * (2 if self.adc.complex_samples else 1)

    @property
    def chirp_bytes(self) -> int:
        return self.chirp_words * WORD_BYTES

    @property
    def frame_words(self) -> int:
        """16-bit words per frame: ``n_loops * n_tx`` chirps."""
        return self.n_loops * self.n_tx * self.chirp_words

    @property
    def frame_bytes(self) -> int:
        return self.frame_words * WORD_BYTES

    @property
    def cube_shape(self) -> tuple[int, int, int]:
        """``(virtual channels, loops, samples)`` of one frame's cube."""
        return (self.n_tx * self.n_rx, self.n_loops, self.n_samples)


def _sign_extend(words: np.ndarray, n_bits: int) -> np.ndarray:
    """Words of an ``n_bits`` ADC as signed values (int32); 16 bits: unchanged."""
    x = words.astype(np.int32)
    if n_bits < 16:
        # two's complement of n_bits: values above 2^(n-1) - 1 are x - 2^n
        x &= (1 << n_bits) - 1
        x[x >= 1 << (n_bits - 1)] -= 1 << n_bits
    return x


def decode_frame(words: np.ndarray, layout: CaptureLayout) -> np.ndarray:
    """One frame's words as the radar cube.

    Parameters
    ----------
    words
        ``(layout.frame_words,)`` int16, in file order.

    Returns
    -------
    numpy.ndarray
        ``[virtual channel (slot * n_rx + rx), loop, sample]`` complex64 in ADC counts (real
        captures: imaginary part 0).
    """
    lay = layout
    n_v, n_l, n = lay.cube_shape
    out = np.empty(lay.cube_shape, dtype=np.complex64)
    parts = out.view(np.float32).reshape(lay.n_tx, lay.n_rx, n_l, n, 2)
    w = words if lay.adc.n_bits == 16 else _sign_extend(words, lay.adc.n_bits)
    if not lay.adc.complex_samples:
        # file [loop, slot, rx, sample] -> cube [slot, rx, loop, sample]
        real = w.reshape(n_l, lay.n_tx, lay.n_rx, n).transpose(1, 2, 0, 3)
        parts[..., 0] = real
        parts[..., 1] = 0.0
        return out
    # [loop, slot, rx, sample pair, lane (I or Q pair), sample within the pair]
    g = w.reshape(n_l, lay.n_tx, lay.n_rx, n // 2, 2, 2)
    i_lane, q_lane = (1, 0) if lay.adc.iq_swap else (0, 1)
    for part, lane in ((0, i_lane), (1, q_lane)):
        # [loop, slot, rx, n] -> [slot, rx, loop, n]
        parts[..., part] = (
            g[:, :, :, :, lane, :].reshape(n_l, lay.n_tx, lay.n_rx, n).transpose(1, 2, 0, 3)
        )
    return out


def encode_frame(i: np.ndarray, q: np.ndarray | None, layout: CaptureLayout) -> np.ndarray:
    """One frame's cube as the words a DCA1000 records (inverse of :func:`decode_frame`).

    Parameters
    ----------
    i, q
        ``[virtual channel, loop, sample]`` int16 in-phase and quadrature parts (``q`` None
        for a real-only layout).

    Returns
    -------
    numpy.ndarray
        ``(layout.frame_words,)`` int16 in file order.
    """
    lay = layout
    n_v, n_l, n = lay.cube_shape
    for name, a in (("i", i), ("q", q)):
        if a is not None and (a.shape != lay.cube_shape or a.dtype != np.int16):
            raise ValueError(f"{name} must be int16 {lay.cube_shape}, got {a.dtype} {a.shape}")
    if not lay.adc.complex_samples:
        if q is not None:
            raise ValueError("a real-only layout has no quadrature part")
        # cube [slot, rx, loop, n] -> file [loop, slot, rx, n]
        return np.ascontiguousarray(
            i.reshape(lay.n_tx, lay.n_rx, n_l, n).transpose(2, 0, 1, 3)
        ).reshape(-1)
    if q is None:
        raise ValueError("a complex layout needs the quadrature part")
    out = np.empty((n_l, lay.n_tx, lay.n_rx, n // 2, 2, 2), dtype=np.int16)
    i_lane, q_lane = (1, 0) if lay.adc.iq_swap else (0, 1)
    for a, lane in ((i, i_lane), (q, q_lane)):
        out[:, :, :, :, lane, :] = a.reshape(lay.n_tx, lay.n_rx, n_l, n // 2, 2).transpose(
            2, 0, 1, 3, 4
        )
    return out.reshape(-1)


@dataclass(frozen=True, slots=True, kw_only=True)
class Capture:
    """An opened DCA1000 capture: whole frames and what was left over.

    ``trailing_bytes``: bytes after the last whole frame (a frame cut short, dropped).
    """

    path: Path
    layout: CaptureLayout
    n_frames: int
    trailing_bytes: int

    @property
    def dropped_note(self) -> str | None:
        """One line about the dropped partial frame, or None when the capture ends on a frame."""
        if not self.trailing_bytes:
            return None
        return (
            f"{printable(str(self.path))}: the last {self.trailing_bytes} bytes "
            f"({self.trailing_bytes // self.layout.chirp_bytes} of "
            f"{self.layout.n_loops * self.layout.n_tx} chirps) are a partial frame: dropped"
        )


def open_capture(
    bin_path: str | os.PathLike, layout: CaptureLayout, *, cfg_path: str | os.PathLike = "<cfg>"
) -> Capture:
    """Check a capture's size against the layout its ``.cfg`` describes.

    The file must hold at least one frame and a whole number of chirps; whole chirps after the
    last whole frame are a partial frame (reported by :attr:`Capture.dropped_note`, dropped).

    Raises
    ------
    InputError
        One line naming both files and the sizes: an empty or missing file, less than one
        frame, or a size that is not a whole number of the cfg's chirps.
    """
    p = Path(bin_path)
    src = printable(str(p))
    cfg = printable(str(cfg_path))
    try:
        is_file, size = p.is_file(), p.stat().st_size
    except (OSError, ValueError) as exc:
        raise InputError(f"cannot read capture ({type(exc).__name__})", src) from None
    if not is_file:
        raise InputError("capture is not a file", src)
    lay = layout
    if size == 0:
        raise InputError("empty capture (0 bytes)", src)
    if size < lay.frame_bytes or size % lay.chirp_bytes:
        raise InputError(
            f"capture of {size} bytes does not match {cfg}: "
            f"{lay.frame_bytes} bytes a frame ({lay.n_loops} loops x {lay.n_tx} chirps x "
            f"{lay.n_rx} RX x {lay.n_samples} {'complex' if lay.adc.complex_samples else 'real'}"
            f" samples x 16 bit), {lay.chirp_bytes} bytes a chirp",
            src,
        )
    return Capture(
        path=p,
        layout=lay,
        n_frames=size // lay.frame_bytes,
        trailing_bytes=size % lay.frame_bytes,
    )


def iter_raw_frames(capture: Capture) -> Iterator[np.ndarray]:
    """The whole frames' words, one frame at a time.

    Yields
    ------
    numpy.ndarray
        ``(frame_words,)`` int16 in file order; the same buffer is reused for every frame (copy
        it to keep it).
    """
    buf = np.empty(capture.layout.frame_words, dtype="<i2")
    view = buf.data.cast("B")
    src = printable(str(capture.path))
    try:
        with open(capture.path, "rb") as fh:
            for _ in range(capture.n_frames):
                if fh.readinto(view) != capture.layout.frame_bytes:
                    raise InputError("capture shrank while it was read", src)
                yield buf
    except OSError as exc:
        raise InputError(f"cannot read capture ({type(exc).__name__})", src) from None


def iter_capture_frames(capture: Capture) -> Iterator[np.ndarray]:
    """The whole frames as radar cubes ``[virtual channel, loop, sample]`` complex64 (counts)."""
    for words in iter_raw_frames(capture):
        yield decode_frame(words, capture.layout)


def write_capture_frames(
    path: str | os.PathLike,
    frames: Iterable[tuple[np.ndarray, np.ndarray | None]],
    layout: CaptureLayout,
) -> Path:
    """Write frames as a DCA1000 ``.bin`` (atomically: nothing is left on failure).

    ``frames``: ``(i, q)`` int16 cubes ``[virtual channel, loop, sample]`` per frame, consumed
    one at a time (``q`` None for a real-only layout).
    """
    with atomic_open(path, "wb") as fh:
        for i, q in frames:
            fh.write(encode_frame(i, q, layout).astype("<i2", copy=False).tobytes())
    return Path(path)
