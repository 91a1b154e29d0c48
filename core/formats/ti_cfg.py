"""TI mmWave SDK CLI configuration (``.cfg``) files: reader and writer of :class:`RadarConfig`.

A ``.cfg`` is the list of CLI commands the TI mmWave SDK demo sends to the device
(``channelCfg``, ``profileCfg``, ``chirpCfg``, ``frameCfg``, ...). :func:`read_ti_cfg` builds a
:class:`~core.config.RadarConfig` from it, naming file, line and field of a malformed command;
:func:`write_ti_cfg` writes the inverse.
"""

from __future__ import annotations

import math
import os
from collections.abc import Collection
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from core.config import (
    ChainConfig,
    DbCfarSettings,
    OobSettings,
    PeopleCountingSettings,
    RaCfarSettings,
    RadarConfig,
)
from core.errors import InputError
from core.files import read_text, write_text_atomic

#: IWR6843ISK antenna layout in units of lambda/2: TX -> (azimuth, elevation), RX -> azimuth.
ISK_TX_POSITIONS = ((0, 0), (2, 1), (4, 0))
ISK_RX_AZIMUTH = (0, 1, 2, 3)
#: The device's maximum TX power; ``profileCfg`` carries a back-off from it in dB.
TI_MAX_TX_POWER_DBM = 12.0

#: Field names of the commands the reader needs (TI mmWave SDK user guide order).
TI_COMMAND_FIELDS: dict[str, tuple[str, ...]] = {
    "channelCfg": ("rxChannelEn", "txChannelEn", "cascading"),
    "adcCfg": ("numADCBits", "adcOutputFmt"),
    "profileCfg": (
        "profileId",
        "startFreq",
        "idleTime",
        "adcStartTime",
        "rampEndTime",
        "txOutPower",
        "txPhaseShifter",
        "freqSlopeConst",
        "txStartTime",
        "numAdcSamples",
        "digOutSampleRate",
        "hpfCornerFreq1",
        "hpfCornerFreq2",
        "rxGain",
    ),
    "chirpCfg": (
        "chirpStartIdx",
        "chirpEndIdx",
        "profileId",
        "startFreqVar",
        "freqSlopeVar",
        "idleTimeVar",
        "adcStartTimeVar",
        "txEnable",
    ),
    "adcbufCfg": ("subFrameIdx", "adcOutputFmt", "sampleSwap", "chanInterleave", "chirpThreshold"),
    "frameCfg": (
        "chirpStartIdx",
        "chirpEndIdx",
        "numLoops",
        "numFrames",
        "framePeriodicity",
        "triggerSelect",
        "frameTriggerDelay",
    ),
}
#: Fields that must be integers (the rest are decimal numbers).
_TI_INT_FIELDS = {
    "rxChannelEn",
    "txChannelEn",
    "cascading",
    "numADCBits",
    "adcOutputFmt",
    "profileId",
    "txOutPower",
    "txPhaseShifter",
    "numAdcSamples",
    "hpfCornerFreq1",
    "hpfCornerFreq2",
    "rxGain",
    "chirpStartIdx",
    "chirpEndIdx",
    "txEnable",
    "numLoops",
    "numFrames",
    "triggerSelect",
    "subFrameIdx",
    "sampleSwap",
    "chanInterleave",
    "chirpThreshold",
}


@dataclass(frozen=True, slots=True, kw_only=True)
class TiCommand:
    """One line of a TI ``.cfg`` file: command name, raw arguments and 1-based line number."""

    name: str
    args: tuple[str, ...]
    line: int


def parse_ti_cfg(text: str, source: str = "<cfg>") -> list[TiCommand]:
    """Split a TI CLI configuration into commands; ``%`` starts a comment line.

    Unknown commands are kept (and ignored by :func:`radar_from_ti_commands`).
    """
    commands = []
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("%"):
            continue
        name, *args = line.split()
        commands.append(TiCommand(name=name, args=tuple(args), line=number))
    return commands


def _fields(
    cmd: TiCommand, source: str, names: tuple[str, ...], int_fields: Collection[str]
) -> dict[str, float | int]:
    """The leading fields ``names`` of a TI command, converted (integers where ``int_fields``
    names them, finite numbers otherwise); a missing or malformed field is one
    :class:`InputError` naming file, line and field."""
    where = f"{source}:{cmd.line}"
    if len(cmd.args) < len(names):
        missing = names[len(cmd.args)]
        raise InputError(
            f"{cmd.name} needs {len(names)} fields, got {len(cmd.args)} "
            f"(field {len(cmd.args) + 1} {missing!r} missing)",
            where,
        )
    out: dict[str, float | int] = {}
    for i, (name, text) in enumerate(zip(names, cmd.args), start=1):
        try:
            value = int(text, 0) if name in int_fields else float(text)
        except ValueError:
            kind = "an integer" if name in int_fields else "a number"
            raise InputError(
                f"{cmd.name} field {i} {name!r}: expected {kind}, got {text!r}", where
            ) from None
        if isinstance(value, float) and not math.isfinite(value):
            raise InputError(f"{cmd.name} field {i} {name!r}: not finite, got {text!r}", where)
        out[name] = value
    return out


def _require(
    cond: bool,
    cmd: TiCommand,
    names: tuple[str, ...],
    field_name: str,
    message: str,
    source: str,
) -> None:
    if not cond:
        index = names.index(field_name) + 1
        raise InputError(
            f"{cmd.name} field {index} {field_name!r}: {message}", f"{source}:{cmd.line}"
        )


def _ti_fields(cmd: TiCommand, source: str) -> dict[str, float | int]:
    return _fields(cmd, source, TI_COMMAND_FIELDS[cmd.name], _TI_INT_FIELDS)


def _ti_require(cond: bool, cmd: TiCommand, field_name: str, message: str, source: str) -> None:
    _require(cond, cmd, TI_COMMAND_FIELDS[cmd.name], field_name, message, source)


def radar_from_ti_commands(
    commands: list[TiCommand], source: str = "<cfg>", name: str = "ti", *, real_ok: bool = False
) -> RadarConfig:
    """Build a :class:`RadarConfig` from parsed TI commands (see :func:`read_ti_cfg`).

    ``real_ok``: accept real-only sampling (``adcCfg`` format 0; raw ADC captures) instead of
    refusing it; the configuration is then the complex one's (see :func:`adc_format`).
    """
    known = {c.name: c for c in commands if c.name in TI_COMMAND_FIELDS and c.name != "chirpCfg"}
    for needed in ("channelCfg", "profileCfg", "chirpCfg", "frameCfg"):
        if needed != "chirpCfg" and needed not in known:
            raise InputError(f"missing command {needed!r}", source)
    chirps = [c for c in commands if c.name == "chirpCfg"]
    if not chirps:
        raise InputError("missing command 'chirpCfg'", source)
    ch_cmd, pr_cmd, fr_cmd = known["channelCfg"], known["profileCfg"], known["frameCfg"]
    ch = _ti_fields(ch_cmd, source)
    pr = _ti_fields(pr_cmd, source)
    fr = _ti_fields(fr_cmd, source)
    if "adcCfg" in known:
        adc_cmd = known["adcCfg"]
        adc = _ti_fields(adc_cmd, source)
        _ti_require(
            adc["adcOutputFmt"] in ((0, 1, 2) if real_ok else (1, 2)),
            adc_cmd,
            "adcOutputFmt",
            f"only complex sampling (1 or 2) is supported, got {adc['adcOutputFmt']}",
            source,
        )

    rx_mask, tx_mask = int(ch["rxChannelEn"]), int(ch["txChannelEn"])
    _ti_require(
        0 < rx_mask < 16, ch_cmd, "rxChannelEn", f"mask 1..15 expected, got {rx_mask}", source
    )
    _ti_require(
        0 < tx_mask < 8, ch_cmd, "txChannelEn", f"mask 1..7 expected, got {tx_mask}", source
    )
    rx_enabled = [r for r in range(4) if rx_mask >> r & 1]

    for fname in ("startFreq", "rampEndTime", "freqSlopeConst", "digOutSampleRate"):
        _ti_require(pr[fname] > 0, pr_cmd, fname, f"must be > 0, got {pr[fname]}", source)
    for fname in ("idleTime", "txOutPower"):
        _ti_require(pr[fname] >= 0, pr_cmd, fname, f"must be >= 0, got {pr[fname]}", source)
    _ti_require(
        pr["numAdcSamples"] > 0,
        pr_cmd,
        "numAdcSamples",
        f"must be > 0, got {pr['numAdcSamples']}",
        source,
    )

    # chirp index -> TX mask
    tx_of_chirp: dict[int, int] = {}
    for c in chirps:
        cf = _ti_fields(c, source)
        start, end, mask = int(cf["chirpStartIdx"]), int(cf["chirpEndIdx"]), int(cf["txEnable"])
        _ti_require(
            mask in (1, 2, 4),
            c,
            "txEnable",
            f"one TX per chirp (mask 1, 2 or 4) expected, got {mask}",
            source,
        )
        _ti_require(mask & tx_mask == mask, c, "txEnable", "TX not enabled in channelCfg", source)
        _ti_require(end >= start >= 0, c, "chirpEndIdx", f"must be >= {start}, got {end}", source)
        for idx in range(start, end + 1):
            tx_of_chirp[idx] = mask.bit_length() - 1
    first, last = int(fr["chirpStartIdx"]), int(fr["chirpEndIdx"])
    _ti_require(
        last >= first >= 0, fr_cmd, "chirpEndIdx", f"must be >= {first}, got {last}", source
    )
    for idx in range(first, last + 1):
        _ti_require(
            idx in tx_of_chirp, fr_cmd, "chirpEndIdx", f"chirp {idx} has no chirpCfg", source
        )
    tx_order = tuple(tx_of_chirp[idx] for idx in range(first, last + 1))
    _ti_require(
        fr["numLoops"] > 0, fr_cmd, "numLoops", f"must be > 0, got {fr['numLoops']}", source
    )
    _ti_require(
        fr["framePeriodicity"] > 0,
        fr_cmd,
        "framePeriodicity",
        f"must be > 0, got {fr['framePeriodicity']}",
        source,
    )

    az = tuple(ISK_TX_POSITIONS[t][0] + ISK_RX_AZIMUTH[r] for t in tx_order for r in rx_enabled)
    el = tuple(ISK_TX_POSITIONS[t][1] for t in tx_order for _ in rx_enabled)
    geometry = antenna_geometry(commands, source, len(az))
    if geometry is not None:
        az, el = geometry
    ramp_s = pr["rampEndTime"] / 1e6
    sample_rate_hz = pr["digOutSampleRate"] * 1000.0
    # BW = S * Tc, rounded to 1 Hz (TI quantises the slope far more coarsely)
    bandwidth_hz = float(round(pr["freqSlopeConst"] * 1e12 * ramp_s))
    try:
        return RadarConfig(
            start_frequency_hz=pr["startFreq"] * 1e9,
            ramp_time_s=ramp_s,
            idle_time_s=pr["idleTime"] / 1e6,
            bandwidth_hz=bandwidth_hz,
            n_tx=len(tx_order),
            n_rx=len(rx_enabled),
            n_loops=int(fr["numLoops"]),
            n_samples=int(pr["numAdcSamples"]),
            sample_rate_hz=sample_rate_hz,
            frame_period_s=fr["framePeriodicity"] / 1000.0,
            tx_power_dbm=TI_MAX_TX_POWER_DBM - tx_backoff_db(int(pr["txOutPower"]), tx_order),
            receiver_gain_db=float(int(pr["rxGain"]) & 0x3F),
            receiver_bandwidth_hz=sample_rate_hz,
            tx_order=tx_order,
            azimuth_positions=az,
            elevation_positions=el,
            name=name,
        )
    except InputError as exc:
        raise InputError(exc.message, source) from None


def tx_backoff_db(code: int, tx_order: tuple[int, ...]) -> float:
    """The TX power back-off of ``profileCfg``'s txOutPower field, dB.

    The field packs one back-off code per transmitter, 1 dB per step (TI mmWave link API,
    ``rlProfileCfg_t.txOutPowerBackoffCode``: TX0 in bits 7:0, TX1 in 15:8, TX2 in 23:16; TI's
    people-counting files write 394758 = 0x060606, 6 dB on each); a value below 256 is the
    same back-off for every transmitter as before. The mean over the transmitters used.
    """
    if code < 256:
        return float(code)
    return float(np.mean([(code >> (8 * t)) & 0xFF for t in set(tx_order)]))


def read_ti_cfg(path: str | os.PathLike) -> RadarConfig:
    """Read a :class:`RadarConfig` from a TI mmWave SDK CLI configuration (``.cfg``) file.

    Uses ``channelCfg`` (RX/TX masks), ``profileCfg`` (start frequency, idle and ramp time, TX
    back-off from 12 dBm, slope, sample count and rate, RX gain), ``chirpCfg`` (the TX of each
    chirp slot), ``frameCfg`` (chirps per loop, loops, frame period) and ``adcCfg`` (complex
    sampling). The bandwidth is slope x ramp end time; the receiver noise bandwidth is the
    complex sampling rate; the virtual array is the IWR6843ISK layout for the enabled antennas.
    Fields the format does not carry (antenna gain, noise figure, temperature, impedance) keep
    their defaults. Unknown commands are ignored.

    Raises
    ------
    InputError
        Naming the file, line number and field of a malformed known command.
    """
    p = Path(path)
    text = read_text(p, what="TI configuration")
    return radar_from_ti_commands(parse_ti_cfg(text, str(p)), str(p), name=p.stem)


#: ``adcCfg`` numADCBits code -> bits per sample (TI mmWave SDK user guide).
ADC_BITS = {0: 12, 1: 14, 2: 16}


@dataclass(frozen=True, slots=True, kw_only=True)
class AdcFormat:
    """How the ADC samples of a raw capture are coded (``adcCfg`` and ``adcbufCfg``).

    Parameters
    ----------
    complex_samples
        Complex (I and Q) samples; False: real-only (``adcCfg`` format 0, ``adcbufCfg`` 1).
    iq_swap
        ``adcbufCfg`` sampleSwap 1 ("Q in LSB, I in MSB"): Q is stored before I.
    n_bits
        Significant bits per 16-bit word (12, 14 or 16; ``adcCfg`` numADCBits 0, 1, 2).
    """

    complex_samples: bool = True
    iq_swap: bool = False
    n_bits: int = 16


def adc_format(commands: list[TiCommand], source: str = "<cfg>") -> AdcFormat:
    """The :class:`AdcFormat` of parsed TI commands.

    Without ``adcCfg``: 16-bit complex; without ``adcbufCfg``: I before Q (TI's documented
    DCA1000 layout). ``adcbufCfg`` is read with (SDK 2 and later) or without (SDK 1) its
    subFrameIdx field. Interleaved channels (chanInterleave 0, xWR14xx) are refused: that layout
    is not the one the DCA1000 records for xWR16xx/18xx/68xx.
    """
    known = {c.name: c for c in commands}
    n_bits, complex_samples = 16, True
    if "adcCfg" in known:
        cmd = known["adcCfg"]
        adc = _ti_fields(cmd, source)
        code = int(adc["numADCBits"])
        _ti_require(code in ADC_BITS, cmd, "numADCBits", f"0, 1 or 2 expected, got {code}", source)
        fmt = int(adc["adcOutputFmt"])
        _ti_require(fmt in (0, 1, 2), cmd, "adcOutputFmt", f"0, 1 or 2 expected, got {fmt}", source)
        n_bits, complex_samples = ADC_BITS[code], fmt != 0
    iq_swap = False
    if "adcbufCfg" in known:
        cmd = known["adcbufCfg"]
        if len(cmd.args) == 4:  # SDK 1.x: no subFrameIdx
            cmd = TiCommand(name=cmd.name, args=("-1", *cmd.args), line=cmd.line)
        buf = _ti_fields(cmd, source)
        fmt, swap = int(buf["adcOutputFmt"]), int(buf["sampleSwap"])
        _ti_require(fmt in (0, 1), cmd, "adcOutputFmt", f"0 or 1 expected, got {fmt}", source)
        _ti_require(
            (fmt == 0) == complex_samples,
            cmd,
            "adcOutputFmt",
            f"{'real' if fmt else 'complex'} disagrees with adcCfg's "
            f"{'complex' if complex_samples else 'real'} samples",
            source,
        )
        _ti_require(swap in (0, 1), cmd, "sampleSwap", f"0 or 1 expected, got {swap}", source)
        _ti_require(
            int(buf["chanInterleave"]) == 1,
            cmd,
            "chanInterleave",
            f"only non-interleaved channels (1) are supported, got {buf['chanInterleave']}",
            source,
        )
        iq_swap = swap == 1
    return AdcFormat(complex_samples=complex_samples, iq_swap=iq_swap, n_bits=n_bits)


def read_ti_capture_cfg(path: str | os.PathLike) -> tuple[RadarConfig, AdcFormat]:
    """The radar and the ADC sample format of the ``.cfg`` that made a raw ADC capture.

    As :func:`read_ti_cfg`, but real-only sampling is accepted (its format says so).
    """
    p = Path(path)
    text = read_text(p, what="TI configuration")
    commands = parse_ti_cfg(text, str(p))
    radar = radar_from_ti_commands(commands, str(p), name=p.stem, real_ok=True)
    return radar, adc_format(commands, str(p))


def ti_cfg_text(radar: RadarConfig, comment: str = "") -> str:
    """The TI CLI commands that configure ``radar`` (inverse of :func:`read_ti_cfg`).

    Only IWR6843ISK-layout arrays with one TX per chirp slot can be written.
    """
    slope_mhz_per_us = radar.slope_hz_per_s / 1e12
    rx_mask = (1 << radar.n_rx) - 1
    tx_mask = 0
    for t in radar.tx_order:
        tx_mask |= 1 << t
    lines = [f"% {line}" for line in comment.splitlines()] if comment else []
    lines += [
        "% RadarTune: TI mmWave SDK CLI configuration",
        "sensorStop",
        "flushCfg",
        "dfeDataOutputMode 1",
        f"channelCfg {rx_mask} {tx_mask} 0",
        "adcCfg 2 1",
        "adcbufCfg -1 0 1 1 1",
        "profileCfg "
        + " ".join(
            [
                "0",
                f"{radar.start_frequency_hz / 1e9:.10g}",
                f"{radar.idle_time_s * 1e6:.10g}",
                "6",
                f"{radar.ramp_time_s * 1e6:.10g}",
                f"{max(0, round(TI_MAX_TX_POWER_DBM - radar.tx_power_dbm)):d}",
                "0",
                f"{slope_mhz_per_us:.12g}",
                "0",
                f"{radar.n_samples:d}",
                f"{radar.sample_rate_hz / 1000.0:.10g}",
                "0",
                "0",
                f"{round(radar.receiver_gain_db):d}",
            ]
        ),
    ]
    for slot, tx in enumerate(radar.tx_order):
        lines.append(f"chirpCfg {slot} {slot} 0 0 0 0 0 {1 << tx}")
    lines += [
        f"frameCfg 0 {radar.n_tx - 1} {radar.n_loops} 0 {radar.frame_period_s * 1000:.10g} 1 0",
        "lowPower 0 0",
        "guiMonitor -1 1 1 0 0 0 1",
        "sensorStart",
    ]
    return "\n".join(lines) + "\n"


def write_ti_cfg(radar: RadarConfig, path: str | os.PathLike, comment: str = "") -> None:
    """Write ``radar`` as a TI ``.cfg`` file (atomically: temporary name, then rename)."""
    write_text_atomic(path, ti_cfg_text(radar, comment))


#: TI's tracker lines (3-D people counting demo; docs/tracking/gtrack.md cites the syntax):
#: command -> its fields in order, (name, int or float). Extra trailing fields (a later SDK's
#: ``trackingCfg`` boresight filter flag) are kept as they are when lines are rewritten.
TRACKER_COMMAND_FIELDS: dict[str, tuple[tuple[str, type], ...]] = {
    "trackingCfg": (
        ("enable", int),
        ("paramSet", int),
        ("maxNumPoints", int),
        ("maxNumTracks", int),
        ("maxRadialVelocity", float),
        ("radialVelocityResolution", float),
        ("deltaT", float),
    ),
    "sensorPosition": (("sensorHeight", float), ("azimuthTilt", float), ("elevationTilt", float)),
    **{
        box: tuple((n, float) for n in ("xMin", "xMax", "yMin", "yMax", "zMin", "zMax"))
        for box in ("boundaryBox", "staticBoundaryBox", "presenceBoundaryBox")
    },
    "gatingParam": (
        ("gain", float),
        ("widthLimit", float),
        ("depthLimit", float),
        ("heightLimit", float),
        ("velocityLimit", float),
    ),
    "stateParam": (
        ("det2actThre", int),
        ("det2freeThre", int),
        ("active2freeThre", int),
        ("static2freeThre", int),
        ("exit2freeThre", int),
        ("sleep2freeThre", int),
    ),
    "allocationParam": (
        ("snrThre", float),
        ("snrThreObscured", float),
        ("velocityThre", float),
        ("pointsThre", int),
        ("maxDistanceThre", float),
        ("maxVelThre", float),
    ),
    "maxAcceleration": (("maxAccelX", float), ("maxAccelY", float), ("maxAccelZ", float)),
}


def tracker_fields(
    commands: list[TiCommand], source: str = "<cfg>"
) -> dict[str, tuple[TiCommand, tuple[float | int, ...]]]:
    """The tracker lines of parsed TI commands, each field converted (int or finite number).

    A line given twice: the last one counts (as on the device). Raises :class:`InputError`
    naming file, line and field of a missing or malformed field.
    """
    out: dict[str, tuple[TiCommand, tuple[float | int, ...]]] = {}
    for cmd in commands:
        spec = TRACKER_COMMAND_FIELDS.get(cmd.name)
        if spec is None:
            continue
        where = f"{source}:{cmd.line}"
        if len(cmd.args) < len(spec):
            missing = spec[len(cmd.args)][0]
            raise InputError(
                f"{cmd.name} needs {len(spec)} fields, got {len(cmd.args)} "
                f"(field {len(cmd.args) + 1} {missing!r} missing)",
                where,
            )
        values: list[float | int] = []
        for i, ((name, kind), text) in enumerate(zip(spec, cmd.args), start=1):
            try:
                value: float | int = int(text, 10) if kind is int else float(text)
            except ValueError:
                what = "an integer" if kind is int else "a number"
                raise InputError(
                    f"{cmd.name} field {i} {name!r}: expected {what}, got {text!r}", where
                ) from None
            if isinstance(value, float) and not math.isfinite(value):
                raise InputError(f"{cmd.name} field {i} {name!r}: not finite, got {text!r}", where)
            values.append(value)
        out[cmd.name] = (cmd, tuple(values))
    return out


def replace_tracker_lines(text: str, lines: dict[str, str]) -> str:
    """``text`` with each tracker line of ``lines`` (command -> full line) put in place.

    Every other line is kept as it was (comments, blank lines, line order). An existing line is
    replaced where it stands, keeping its extra trailing fields; a line ``text`` lacks goes
    before ``sensorStart`` (or at the end).
    """
    out: list[str] = []
    done: set[str] = set()
    for raw in text.splitlines():
        stripped = raw.strip()
        name = stripped.split()[0] if stripped and not stripped.startswith("%") else ""
        if name in lines:
            old = stripped.split()[1:]
            extra = old[len(TRACKER_COMMAND_FIELDS[name]) :]
            out.append(" ".join([lines[name], *extra]))
            done.add(name)
        elif name == "sensorStart":
            out += [lines[n] for n in lines if n not in done]
            done.update(lines)
            out.append(raw)
        else:
            out.append(raw)
    out += [lines[n] for n in lines if n not in done]
    return "\n".join(out) + "\n"


# ---- chain lines: which detection chain a .cfg runs, and its settings ---------------------------

#: Fields of dynamicRACfarCfg and staticRACfarCfg (TI 3-D people counting).
_RA_CFAR_FIELDS = (
    "subFrameIdx",
    "cfarDiscardLeftRange",
    "cfarDiscardRightRange",
    "cfarDiscardLeftAngle",
    "cfarDiscardRightAngle",
    "refWinSizeRange",
    "refWinSizeAngle",
    "guardWinSizeRange",
    "guardWinSizeAngle",
    "rangeThre",
    "angleThre",
    "sidelobeThre",
    "enable2ndPass",
    "dynamicFlag",
)
#: Field names of the chain commands (TI mmWave SDK 3.x user guide for the out-of-box demo; TI's
#: 3-D people counting demo configuration guide for the rest). Only the leading fields listed
#: are read; a command may carry more.
TI_CHAIN_FIELDS: dict[str, tuple[str, ...]] = {
    "cfarCfg": (
        "subFrameIdx",
        "procDirection",
        "averageMode",
        "winLen",
        "guardLen",
        "noiseDiv",
        "cyclicMode",
        "thresholdScale",
        "peakGroupingEn",
    ),
    "cfarFovCfg": ("subFrameIdx", "procDirection", "min", "max"),
    "aoaFovCfg": (
        "subFrameIdx",
        "minAzimuthDeg",
        "maxAzimuthDeg",
        "minElevationDeg",
        "maxElevationDeg",
    ),
    "multiObjBeamForming": ("subFrameIdx", "enabled", "threshold"),
    "clutterRemoval": ("subFrameIdx", "enabled"),
    "dynamicRACfarCfg": _RA_CFAR_FIELDS,
    "staticRACfarCfg": _RA_CFAR_FIELDS,
    "dynamicRangeAngleCfg": (
        "subFrameIdx",
        "angleSearchStep",
        "rangeAngleDiagonalLoading",
        "rangeAngleEstMethod",
        "dopplerEstMethod",
    ),
    "dynamic2DAngleCfg": ("subFrameIdx", "elevSearchStep", "angleDiagonalLoading"),
    "staticRangeAngleCfg": (
        "subFrameIdx",
        "staticProcEnabled",
        "staticAzimStepDeciFactor",
        "staticElevStepDeciFactor",
    ),
    "fovCfg": ("subFrameIdx", "azimuthFovDeg", "elevationFovDeg"),
    "antGeometry0": tuple(f"virtAnt{i}" for i in range(12)),
    "antGeometry1": tuple(f"virtAnt{i}" for i in range(12)),
    "antPhaseRot": tuple(f"virtAnt{i}" for i in range(12)),
}
_CHAIN_INT_FIELDS = {
    "subFrameIdx",
    "procDirection",
    "averageMode",
    "winLen",
    "guardLen",
    "noiseDiv",
    "cyclicMode",
    "peakGroupingEn",
    "enabled",
    "cfarDiscardLeftRange",
    "cfarDiscardRightRange",
    "cfarDiscardLeftAngle",
    "cfarDiscardRightAngle",
    "refWinSizeRange",
    "refWinSizeAngle",
    "guardWinSizeRange",
    "guardWinSizeAngle",
    "enable2ndPass",
    "dynamicFlag",
    "rangeAngleEstMethod",
    "dopplerEstMethod",
    "staticProcEnabled",
    "staticAzimStepDeciFactor",
    "staticElevStepDeciFactor",
    *(f"virtAnt{i}" for i in range(12)),
}
#: Commands that select the people-counting chain; ``cfarCfg`` selects the out-of-box chain.
PEOPLE_COUNTING_COMMANDS = (
    "dynamicRACfarCfg",
    "staticRACfarCfg",
    "dynamicRangeAngleCfg",
    "dynamic2DAngleCfg",
    "staticRangeAngleCfg",
)
#: Commands that start, stop or route the sensor's output: no effect on the points.
TI_HOUSEKEEPING = frozenset(
    {
        "sensorStop",
        "sensorStart",
        "flushCfg",
        "dfeDataOutputMode",
        "lowPower",
        "guiMonitor",
        "lvdsStreamCfg",
        "adcbufCfg",
        "CQRxSatMonitor",
        "CQSigImgMonitor",
        "analogMonitor",
        "calibData",
        "measureRangeBiasAndRxChanPhase",
    }
)
#: Commands RadarTune reads into the radar or the chain; every other one a .cfg uses is named
#: as ignored (:attr:`ChainConfig.ignored`).
TI_READ_COMMANDS = frozenset(TI_COMMAND_FIELDS) | frozenset(TI_CHAIN_FIELDS) - {"antPhaseRot"}
_CFAR_MODES = {0: "ca", 1: "cago", 2: "caso"}


def _chain_fields(cmd: TiCommand, source: str) -> dict[str, float | int]:
    return _fields(cmd, source, TI_CHAIN_FIELDS[cmd.name], _CHAIN_INT_FIELDS)


def _chain_require(cond: bool, cmd: TiCommand, field_name: str, message: str, source: str) -> None:
    _require(cond, cmd, TI_CHAIN_FIELDS[cmd.name], field_name, message, source)


def antenna_geometry(
    commands: list[TiCommand], source: str, n_virtual: int
) -> tuple[tuple[int, ...], tuple[int, ...]] | None:
    """Virtual positions from ``antGeometry0`` (azimuth index) and ``antGeometry1`` (elevation
    index), or None when the .cfg has neither (the IWR6843ISK layout then applies).

    TI lists each virtual antenna's position index (0, -1, -2, ...) in units of lambda/2 in
    chirp order; RadarTune's positions are ``-antGeometry0`` and ``antGeometry1 - min`` (the
    mapping that gives the ISK layout from TI's ISK lines, see core.config).
    """
    known = {c.name: c for c in commands if c.name in ("antGeometry0", "antGeometry1")}
    if not known:
        return None
    for needed in ("antGeometry0", "antGeometry1"):
        if needed not in known:
            raise InputError(f"{needed} missing (the other antGeometry line is given)", source)
    g0 = _chain_fields(known["antGeometry0"], source)
    g1 = _chain_fields(known["antGeometry1"], source)
    if n_virtual != 12:
        raise InputError(
            f"antGeometry0 lists 12 virtual antennas, the channel and chirp lines give {n_virtual}",
            f"{source}:{known['antGeometry0'].line}",
        )
    az = [-int(g0[f"virtAnt{i}"]) for i in range(12)]
    el = [int(g1[f"virtAnt{i}"]) for i in range(12)]
    az0, el0 = min(az), min(el)
    return tuple(a - az0 for a in az), tuple(e - el0 for e in el)


def _ra_cfar(cmd: TiCommand, source: str) -> RaCfarSettings:
    f = _chain_fields(cmd, source)
    try:
        return RaCfarSettings(
            discard_left_range=int(f["cfarDiscardLeftRange"]),
            discard_right_range=int(f["cfarDiscardRightRange"]),
            discard_left_angle=int(f["cfarDiscardLeftAngle"]),
            discard_right_angle=int(f["cfarDiscardRightAngle"]),
            ref_range=int(f["refWinSizeRange"]),
            ref_angle=int(f["refWinSizeAngle"]),
            guard_range=int(f["guardWinSizeRange"]),
            guard_angle=int(f["guardWinSizeAngle"]),
            range_threshold_db=float(f["rangeThre"]),
            angle_threshold_db=float(f["angleThre"]),
            sidelobe_threshold=float(f["sidelobeThre"]),
            second_pass=bool(f["enable2ndPass"]),
        )
    except InputError as exc:
        raise InputError(f"{cmd.name}: {exc.message}", f"{source}:{cmd.line}") from None


def _people_counting(known: dict[str, TiCommand], source: str) -> PeopleCountingSettings:
    kw: dict = {}
    for name in ("dynamicRACfarCfg", "staticRACfarCfg"):
        if name not in known:
            raise InputError(
                f"missing command {name!r} (the people-counting chain needs it)", source
            )
    kw["dynamic_cfar"] = _ra_cfar(known["dynamicRACfarCfg"], source)
    kw["static_cfar"] = _ra_cfar(known["staticRACfarCfg"], source)
    if "dynamicRangeAngleCfg" in known:
        cmd = known["dynamicRangeAngleCfg"]
        f = _chain_fields(cmd, source)
        _chain_require(f["angleSearchStep"] > 0, cmd, "angleSearchStep", "must be > 0", source)
        _chain_require(
            f["rangeAngleDiagonalLoading"] >= 0,
            cmd,
            "rangeAngleDiagonalLoading",
            "must be >= 0",
            source,
        )
        kw["angle_step_deg"] = float(f["angleSearchStep"])
        kw["diagonal_loading"] = float(f["rangeAngleDiagonalLoading"])
    if "dynamic2DAngleCfg" in known:
        cmd = known["dynamic2DAngleCfg"]
        f = _chain_fields(cmd, source)
        _chain_require(f["elevSearchStep"] > 0, cmd, "elevSearchStep", "must be > 0", source)
        _chain_require(
            f["angleDiagonalLoading"] >= 0, cmd, "angleDiagonalLoading", "must be >= 0", source
        )
        kw["elevation_step_deg"] = float(f["elevSearchStep"])
        kw["elevation_loading"] = float(f["angleDiagonalLoading"])
    if "staticRangeAngleCfg" in known:
        cmd = known["staticRangeAngleCfg"]
        f = _chain_fields(cmd, source)
        for name in ("staticAzimStepDeciFactor", "staticElevStepDeciFactor"):
            _chain_require(f[name] >= 1, cmd, name, f"must be >= 1, got {f[name]}", source)
        kw["static_enabled"] = bool(f["staticProcEnabled"])
        kw["static_azimuth_decimation"] = int(f["staticAzimStepDeciFactor"])
        kw["static_elevation_decimation"] = int(f["staticElevStepDeciFactor"])
    if "fovCfg" in known:
        cmd = known["fovCfg"]
        f = _chain_fields(cmd, source)
        _chain_require(
            1 <= f["azimuthFovDeg"] <= 90, cmd, "azimuthFovDeg", "must be in [1, 90]", source
        )
        _chain_require(
            0 <= f["elevationFovDeg"] <= 90, cmd, "elevationFovDeg", "must be in [0, 90]", source
        )
        kw["azimuth_fov_deg"] = float(f["azimuthFovDeg"])
        kw["elevation_fov_deg"] = float(f["elevationFovDeg"])
    try:
        return PeopleCountingSettings(**kw)
    except InputError as exc:
        raise InputError(exc.message, source) from None


def _oob(commands: list[TiCommand], source: str) -> OobSettings:
    kw: dict = {}
    cfar: dict[int, DbCfarSettings] = {}
    for cmd in commands:
        if cmd.name == "cfarCfg":
            f = _chain_fields(cmd, source)
            direction = int(f["procDirection"])
            _chain_require(
                direction in (0, 1),
                cmd,
                "procDirection",
                f"0 or 1 expected, got {direction}",
                source,
            )
            mode = int(f["averageMode"])
            _chain_require(
                mode in _CFAR_MODES, cmd, "averageMode", f"0, 1 or 2 expected, got {mode}", source
            )
            _chain_require(f["winLen"] >= 1, cmd, "winLen", "must be >= 1", source)
            _chain_require(f["guardLen"] >= 0, cmd, "guardLen", "must be >= 0", source)
            _chain_require(
                0 < f["thresholdScale"] <= 100,
                cmd,
                "thresholdScale",
                f"a threshold in dB in (0, 100] expected (SDK 3.x), got {f['thresholdScale']}",
                source,
            )
            cfar[direction] = DbCfarSettings(
                method=_CFAR_MODES[mode],
                n_train=int(f["winLen"]),
                n_guard=int(f["guardLen"]),
                threshold_db=float(f["thresholdScale"]),
                cyclic=bool(f["cyclicMode"]),
                peak_grouping=bool(f["peakGroupingEn"]),
            )
        elif cmd.name == "cfarFovCfg":
            f = _chain_fields(cmd, source)
            _chain_require(
                f["min"] < f["max"], cmd, "max", f"must be > min {f['min']}, got {f['max']}", source
            )
            if int(f["procDirection"]) == 0:
                kw["min_range_m"], kw["max_range_m"] = float(f["min"]), float(f["max"])
            else:
                kw["min_velocity_mps"], kw["max_velocity_mps"] = float(f["min"]), float(f["max"])
        elif cmd.name == "aoaFovCfg":
            f = _chain_fields(cmd, source)
            az = (float(f["minAzimuthDeg"]), float(f["maxAzimuthDeg"]))
            el = (float(f["minElevationDeg"]), float(f["maxElevationDeg"]))
            _chain_require(
                -90 <= az[0] < az[1] <= 90, cmd, "maxAzimuthDeg", f"bad interval {az}", source
            )
            _chain_require(
                -90 <= el[0] < el[1] <= 90, cmd, "maxElevationDeg", f"bad interval {el}", source
            )
            kw["azimuth_fov_deg"], kw["elevation_fov_deg"] = az, el
        elif cmd.name == "multiObjBeamForming":
            f = _chain_fields(cmd, source)
            _chain_require(0 < f["threshold"] <= 1, cmd, "threshold", "must be in (0, 1]", source)
            kw["multi_object_threshold"] = float(f["threshold"]) if f["enabled"] else None
        elif cmd.name == "clutterRemoval":
            f = _chain_fields(cmd, source)
            kw["static_clutter_removal"] = bool(f["enabled"])
    for direction, name in ((0, "range"), (1, "Doppler")):
        if direction not in cfar:
            raise InputError(
                f"missing cfarCfg for the {name} direction (procDirection {direction})", source
            )
    kw["range_cfar"], kw["doppler_cfar"] = cfar[0], cfar[1]
    try:
        return OobSettings(**kw)
    except InputError as exc:
        raise InputError(exc.message, source) from None


def chain_from_ti_commands(commands: list[TiCommand], source: str = "<cfg>") -> ChainConfig:
    """The detection chain a TI .cfg runs, with its settings and the commands it ignores.

    ``cfarCfg`` selects ``oob`` (TI's out-of-box demo), any of
    :data:`PEOPLE_COUNTING_COMMANDS` selects ``people-counting``, neither ``paper`` (the
    radar lines alone). Both kinds in one file is an error naming the first line of each.
    """
    oob = [c for c in commands if c.name == "cfarCfg"]
    people = [c for c in commands if c.name in PEOPLE_COUNTING_COMMANDS]
    if oob and people:
        raise InputError(
            f"{oob[0].name} (line {oob[0].line}) is the out-of-box chain's, "
            f"{people[0].name} (line {people[0].line}) the people-counting chain's: "
            "one chain per file",
            source,
        )
    ignored = tuple(
        sorted(
            {
                f"{c.name} (line {c.line})"
                for c in commands
                if c.name not in TI_READ_COMMANDS and c.name not in TI_HOUSEKEEPING
            },
            key=lambda t: int(t.rsplit("line ", 1)[1].rstrip(")")),
        )
    )
    if people:
        known = {c.name: c for c in commands if c.name in TI_CHAIN_FIELDS}
        pc = _people_counting(known, source)
        return ChainConfig(name="people-counting", people_counting=pc, ignored=ignored)
    if oob:
        return ChainConfig(name="oob", oob=_oob(commands, source), ignored=ignored)
    return ChainConfig(name="paper", ignored=ignored)


def read_ti_chain(path: str | os.PathLike) -> ChainConfig:
    """The detection chain of a TI .cfg file (:func:`chain_from_ti_commands`)."""
    p = Path(path)
    text = read_text(p, what="TI configuration")
    return chain_from_ti_commands(parse_ti_cfg(text, str(p)), str(p))
