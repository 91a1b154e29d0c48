"""DCA1000 raw ADC captures in and out of the exact chain.

- :func:`dataset_from_capture`: a ``.bin`` and the TI ``.cfg`` that made it, streamed frame by
  frame through the exact chain's processing half (:func:`core.simulation.frame.process_cube`:
  range FFT, static clutter removal, Doppler FFT, CFAR, angles, point cloud) into a data set;
- :func:`write_capture`: a scene's ADC samples as the exact chain synthesises them (signal plus
  receiver noise, before the range window), quantised to int16, written in the DCA1000 layout
  with the matching ``.cfg``.

The layout itself is :mod:`core.formats.dca1000`. These two live in the pipeline because they run
the radar chain, which the formats layer sits below (see docs/decisions/inputs-03-dca1000.md).
"""

from __future__ import annotations

import dataclasses
import os
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np

from core.config import DEFAULT_PROCESSING, ProcessingSettings, RadarConfig
from core.dataset import Dataset
from core.errors import InputError
from core.files import check_output_path, printable, write_text_atomic
from core.formats.dca1000 import (
    CAPTURE_FORMAT,
    Capture,
    CaptureLayout,
    iter_capture_frames,
    open_capture,
    write_capture_frames,
)
from core.formats.recording import Recording, read_truth_csv, to_dataset
from core.formats.ti_cfg import adc_format, parse_ti_cfg, read_ti_capture_cfg, ti_cfg_text
from core.limits import MAX_DATASET_FRAMES
from core.pipeline.frames import frame_inputs
from core.pipeline.plan import plan
from core.pointcloud import POINT_FIELDS, PointCloud
from core.scene import Scene

#: Receiver noise of written captures: standard deviation of I (and of Q) in ADC counts. The
#: 16-bit range then holds a sample 20 log10(32767 / (8 sqrt 2)) = 69 dB above the noise, and the
#: rounding adds 1/12 count² to 64: 0.006 dB.
ADC_NOISE_RMS_COUNTS = 8.0
#: ``adcbufCfg`` of the SDK configurations ``ti_cfg_text`` writes (sampleSwap 1: Q before I) and
#: of written captures (sampleSwap 0: I before Q, TI's documented DCA1000 order).
SDK_ADCBUF_CFG = "adcbufCfg -1 0 1 1 1"
CAPTURE_ADCBUF_CFG = "adcbufCfg -1 0 0 1 1"

NoteCallback = Callable[[str], None]


class CaptureWarning(UserWarning):
    """Something in a capture was skipped (a partial frame) or altered (clipped samples)."""


def _warn(message: str) -> None:
    warnings.warn(message, CaptureWarning, stacklevel=3)


# ---- reading ------------------------------------------------------------------------------------


def open_capture_with_cfg(
    bin_path: str | os.PathLike, cfg_path: str | os.PathLike
) -> tuple[RadarConfig, Capture]:
    """The radar of ``cfg_path`` and the capture checked against its layout (one InputError
    line naming both files on a mismatch)."""
    radar, adc = read_ti_capture_cfg(cfg_path)
    try:
        layout = CaptureLayout.from_radar(radar, adc)
    except InputError as exc:
        raise InputError(exc.message, printable(str(cfg_path))) from None
    return radar, open_capture(bin_path, layout, cfg_path=cfg_path)


def capture_settings(
    radar: RadarConfig, capture: Capture, settings: ProcessingSettings | None = None
) -> ProcessingSettings:
    """The processing settings for a capture: ``settings`` (default: the chain's), detections
    limited to the unambiguous half of the range bins for real-only samples."""
    s = DEFAULT_PROCESSING if settings is None else settings
    if not capture.layout.adc.complex_samples:
        # real sampling: bins N/2..N-1 mirror bins 1..N/2-1, unique ranges up to Fs c / (4 S)
        half = 0.5 * radar.max_range_m
        if s.max_range_m > half:
            if s.min_range_m >= half:
                raise InputError(
                    f"min_range_m={s.min_range_m!r} is beyond the {half:.3g} m a real-sampled "
                    "capture can measure"
                )
            s = dataclasses.replace(s, max_range_m=half)
    return s


def iter_capture_clouds(
    radar: RadarConfig,
    capture: Capture,
    *,
    settings: ProcessingSettings | None = None,
    elevation: bool | None = None,
) -> Iterator[PointCloud]:
    """Each whole frame of a capture through the exact chain's processing half.

    ``elevation``: estimate elevation (default: when the virtual array can).
    """
    from core.simulation.frame import process_cube  # the radar chain: heavy import

    s = capture_settings(radar, capture, settings)
    el = radar.has_elevation if elevation is None else bool(elevation)
    for cube in iter_capture_frames(capture):
        yield process_cube(cube, radar, settings=s, elevation=el).point_cloud


def recording_from_capture(
    bin_path: str | os.PathLike,
    cfg_path: str | os.PathLike,
    *,
    settings: ProcessingSettings | None = None,
    elevation: bool | None = None,
    note: NoteCallback | None = None,
) -> Recording:
    """A DCA1000 capture through the exact chain's processing half, as a one-run recording.

    Parameters
    ----------
    bin_path, cfg_path
        The capture and the TI ``.cfg`` that made it (:mod:`core.formats.dca1000` for the
        layout it implies).
    settings
        Processing settings (default: the chain's defaults, SPEC §3).
    elevation
        Estimate elevation (default: when the virtual array can).
    note
        Receives one line per thing skipped (a trailing partial frame); default: a
        :class:`CaptureWarning`. The line is also among the recording's ``notes``.

    Returns
    -------
    Recording
        Format ``"dca1000"``; frame ``f`` at ``f * frame_period_s``; the cfg's radar.

    Raises
    ------
    InputError
        One line: a malformed cfg (file, line, field), a capture whose size does not fit the cfg
        (both files, the sizes), more frames than a data set may hold.
    """
    radar, capture = open_capture_with_cfg(bin_path, cfg_path)
    if capture.n_frames > MAX_DATASET_FRAMES:
        raise InputError(
            f"{capture.n_frames} frames, more than the data-set limit {MAX_DATASET_FRAMES}",
            printable(str(bin_path)),
        )
    notes = []
    if capture.dropped_note:
        (note or _warn)(capture.dropped_note)
        notes.append(capture.dropped_note)
    clouds = list(iter_capture_clouds(radar, capture, settings=settings, elevation=elevation))
    clouds, dropped = _finite_points(clouds)
    if dropped:
        line = (
            f"{printable(str(bin_path))}: {dropped} points without a finite value dropped (a "
            f"noise estimate of 0); {_saturated_fraction(bin_path):.1%} of the capture's words "
            "are at full scale (-32768 or 32767): a saturated ADC, whose points are not to be "
            "trusted"
        )
        notes.append(line)
    counts = np.array([len(c) for c in clouds], dtype=np.int64)
    return Recording(
        format=CAPTURE_FORMAT,
        cloud=PointCloud.concatenate(clouds),
        counts=counts,
        t_s=np.arange(capture.n_frames) * radar.frame_period_s,
        trajectory=np.zeros(capture.n_frames, dtype=np.int64),
        radar=radar,
        notes=tuple(notes),
    )


def _finite_points(clouds: list[PointCloud]) -> tuple[list[PointCloud], int]:
    """The clouds without points holding a non-finite value (the SNR of a cell whose noise
    estimate is 0, as in a saturated capture), and how many were dropped."""
    out, dropped = [], 0
    for c in clouds:
        ok = np.ones(len(c), dtype=bool)
        for name in POINT_FIELDS:
            ok &= np.isfinite(getattr(c, name))
        if not ok.all():
            dropped += int((~ok).sum())
            c = PointCloud(**{f: getattr(c, f)[ok] for f in POINT_FIELDS}, source=c.source[ok])
        out.append(c)
    return out, dropped


def _saturated_fraction(bin_path: str | os.PathLike) -> float:
    """The fraction of the capture's 16-bit words at full scale."""
    words = np.memmap(bin_path, dtype="<i2", mode="r")
    if not len(words):
        return 0.0
    full = 0
    step = 1 << 22
    for k in range(0, len(words), step):
        w = np.asarray(words[k : k + step])
        full += int(np.count_nonzero((w == 32767) | (w == -32768)))
    return full / len(words)


def dataset_from_capture(
    bin_path: str | os.PathLike,
    cfg_path: str | os.PathLike,
    *,
    truth: str | os.PathLike | None = None,
    settings: ProcessingSettings | None = None,
    elevation: bool | None = None,
    note: NoteCallback | None = None,
) -> Dataset:
    """A DCA1000 capture as a data set (:func:`recording_from_capture`, then
    :func:`core.formats.recording.to_dataset`), with the truth CSV ``time_s,person,x_m,y_m``
    (:func:`core.formats.recording.read_truth_csv`; times from the first frame's start) if
    given; without it the data set has no persons."""
    rows = read_truth_csv(truth) if truth is not None else None
    rec = recording_from_capture(
        bin_path, cfg_path, settings=settings, elevation=elevation, note=note
    )
    return to_dataset(rec, truth=rows, source_name=printable(str(bin_path)))


# ---- writing ------------------------------------------------------------------------------------


def adc_count_v(radar: RadarConfig) -> float:
    """Volts per ADC count of written captures: noise ``sigma_I = sigma_Q`` is
    :data:`ADC_NOISE_RMS_COUNTS` counts."""
    from core.simulation.link import noise_power_v2

    # sigma_I = sqrt(E|n|^2 / 2)
    return float(np.sqrt(noise_power_v2(radar) / 2.0)) / ADC_NOISE_RMS_COUNTS


def quantise(cube_v: np.ndarray, count_v: float) -> tuple[np.ndarray, np.ndarray, int]:
    """A complex cube in volts as int16 I and Q counts (rounded, saturated at the int16 range).

    Returns ``(i, q, n_clipped)``: the two int16 arrays of ``cube_v``'s shape and the number of
    parts that saturated.
    """
    lim = np.iinfo(np.int16)
    parts = []
    n_clipped = 0
    for x in (cube_v.real, cube_v.imag):
        c = np.rint(x / count_v)
        n_clipped += int(np.count_nonzero((c < lim.min) | (c > lim.max)))
        parts.append(np.clip(c, lim.min, lim.max).astype(np.int16))
    return parts[0], parts[1], n_clipped


def iter_adc_frames(
    scene: Scene, *, seed: int | None = None, count_v: float | None = None
) -> Iterator[tuple[np.ndarray, np.ndarray, int]]:
    """The exact chain's received ADC samples of each frame of ``scene``, quantised.

    Frame ``f``: the reflectors, antenna and noise generator :func:`core.pipeline.iter_frames`
    gives the exact simulator (:func:`core.pipeline.frames.frame_inputs`), the noise-free cube
    of :func:`core.simulation.baseband.synthesize_signal` plus the same receiver noise the exact
    chain adds (before its range window), in counts of ``count_v`` volts (default
    :func:`adc_count_v`).

    Yields
    ------
    (i, q, n_clipped)
        int16 ``[virtual channel, loop, sample]`` and the count of saturated parts.
    """
    from core.simulation.baseband import synthesize_signal
    from core.simulation.gaussian import add_complex_noise
    from core.simulation.link import noise_power_v2

    radar = scene.radar
    lsb = adc_count_v(radar) if count_v is None else count_v
    p = plan(scene, fidelity="exact")
    seed_ = scene.seed if seed is None else int(seed)
    for fi in frame_inputs(scene, p, seed_):
        cube = synthesize_signal(radar, fi.scatterers, fi.antenna)
        add_complex_noise(cube, noise_power_v2(radar), fi.rng)
        yield quantise(cube, lsb)


def write_capture(
    scene: Scene,
    out_path: str | os.PathLike,
    *,
    seed: int | None = None,
    note: NoteCallback | None = None,
) -> list[Path]:
    """Write a scene's simulated ADC samples as a DCA1000 capture and its TI ``.cfg``.

    Parameters
    ----------
    scene
        The scene (its radar must have an even number of ADC samples).
    out_path
        The ``.bin`` to write; the ``.cfg`` goes next to it with the suffix ``.cfg``.
    seed
        Seed of every random stream (default ``scene.seed``): the frames are the exact chain's.
    note
        Receives one line if samples saturated (default: a :class:`CaptureWarning`).

    Returns
    -------
    list[Path]
        ``[bin, cfg]``, each written atomically (nothing half-written on failure).
    """
    bin_path = check_output_path(out_path, what="capture")
    cfg_path = check_output_path(bin_path.with_suffix(".cfg"), what="capture cfg")
    if cfg_path == bin_path:
        raise InputError("the capture needs a suffix other than .cfg", printable(str(bin_path)))
    radar = scene.radar
    text = ti_cfg_text(
        radar,
        comment=f"DCA1000 capture {bin_path.name} written by RadarTune; I before Q as TI "
        "documents the DCA1000 layout (adcbufCfg sampleSwap 0)",
    )
    # I first: what TI's, mmWave Studio's and OpenRadar-style readers assume
    text = text.replace(f"\n{SDK_ADCBUF_CFG}\n", f"\n{CAPTURE_ADCBUF_CFG}\n")
    layout = CaptureLayout.from_radar(radar, adc_format(parse_ti_cfg(text)))
    clipped = [0]

    def frames() -> Iterator[tuple[np.ndarray, np.ndarray | None]]:
        for i, q, n in iter_adc_frames(scene, seed=seed):
            clipped[0] += n
            yield i, q

    write_capture_frames(bin_path, frames(), layout)
    write_text_atomic(cfg_path, text)
    if clipped[0]:
        (note or _warn)(
            f"{printable(str(bin_path))}: {clipped[0]} I/Q values saturated at the int16 range"
        )
    return [bin_path, cfg_path]
