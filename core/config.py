"""Radar configuration (SPEC §1) with the paper's defaults; derived values are properties."""

from __future__ import annotations

import dataclasses
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

from core.errors import InputError
from core.files import read_text, write_text_atomic
from core.limits import MAX_CUBE_SAMPLES

SPEED_OF_LIGHT_MPS = 299_792_458.0
BOLTZMANN_J_PER_K = 1.380649e-23

#: IWR6843ISK virtual array, channel index = tx * 4 + rx, positions in units of lambda/2.
ISK_AZIMUTH_POSITIONS = (0, 1, 2, 3, 2, 3, 4, 5, 4, 5, 6, 7)
ISK_ELEVATION_POSITIONS = (0, 0, 0, 0, 1, 1, 1, 1, 0, 0, 0, 0)


@dataclass(frozen=True, slots=True, kw_only=True)
class RadarConfig:
    """FMCW TDM-MIMO radar configuration. SI units throughout.

    The defaults are the paper's (TI IWR6843 class). Derived values (resolutions, limits,
    wavelength) are properties computed from the fields, never stored.
    """

    start_frequency_hz: float = 60e9
    ramp_time_s: float = 50.5e-6
    idle_time_s: float = 7e-6
    bandwidth_hz: float = 3.099e9
    n_tx: int = 3
    n_rx: int = 4
    n_loops: int = 32
    n_samples: int = 256
    sample_rate_hz: float = 5.9e6
    frame_period_s: float = 0.080
    tx_power_dbm: float = 12.0
    antenna_gain_db: float = 12.0
    receiver_gain_db: float = 36.0
    noise_figure_db: float = 12.0
    receiver_bandwidth_hz: float = 5.9e6
    temperature_k: float = 290.0
    impedance_ohm: float = 50.0
    #: TX antenna of each chirp slot within one loop (TDM order), e.g. (0, 1, 2).
    tx_order: tuple[int, ...] = (0, 1, 2)
    #: Virtual channel positions in units of lambda/2, channel index = slot * n_rx + rx.
    azimuth_positions: tuple[int, ...] = ISK_AZIMUTH_POSITIONS
    elevation_positions: tuple[int, ...] = ISK_ELEVATION_POSITIONS
    name: str = field(default="paper", compare=False)

    def __post_init__(self) -> None:
        positive = (
            "start_frequency_hz",
            "ramp_time_s",
            "bandwidth_hz",
            "n_tx",
            "n_rx",
            "n_loops",
            "n_samples",
            "sample_rate_hz",
            "frame_period_s",
            "receiver_bandwidth_hz",
            "temperature_k",
            "impedance_ohm",
        )
        for name in positive:
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
                raise InputError(f"{name} must be a positive number, got {name}={value!r}")
        if self.idle_time_s < 0:
            raise InputError(f"idle_time_s must be >= 0, got idle_time_s={self.idle_time_s!r}")
        if len(self.tx_order) != self.n_tx:
            raise InputError(
                f"tx_order must list one TX per chirp slot ({self.n_tx}), got {self.tx_order!r}"
            )
        n_virtual = self.n_tx * self.n_rx
        for name in ("azimuth_positions", "elevation_positions"):
            if len(getattr(self, name)) != n_virtual:
                raise InputError(
                    f"{name} must have n_tx*n_rx={n_virtual} entries, "
                    f"got {len(getattr(self, name))}"
                )
        cube = n_virtual * self.n_loops * self.n_samples
        if cube > MAX_CUBE_SAMPLES:
            raise InputError(
                f"n_tx*n_rx*n_loops*n_samples = {cube} samples a frame exceeds the limit "
                f"{MAX_CUBE_SAMPLES}"
            )
        if self.chirp_period_s * self.n_tx * self.n_loops > self.frame_period_s:
            raise InputError(
                "frame_period_s is shorter than the chirps of one frame "
                f"({self.chirp_period_s * self.n_tx * self.n_loops:.6g} s), "
                f"got frame_period_s={self.frame_period_s!r}"
            )

    # ---- derived values -------------------------------------------------------------------
    @property
    def wavelength_m(self) -> float:
        """lambda = c / Fc."""
        return SPEED_OF_LIGHT_MPS / self.start_frequency_hz

    @property
    def slope_hz_per_s(self) -> float:
        """S = BW / Tc."""
        return self.bandwidth_hz / self.ramp_time_s

    @property
    def chirp_period_s(self) -> float:
        """Tchirp = Tc + Tidle."""
        return self.ramp_time_s + self.idle_time_s

    @property
    def n_virtual(self) -> int:
        return self.n_tx * self.n_rx

    @property
    def range_resolution_m(self) -> float:
        """Range bin spacing c*Fs / (2*S*Nadc)."""
        return SPEED_OF_LIGHT_MPS * self.sample_rate_hz / (2 * self.slope_hz_per_s * self.n_samples)

    @property
    def max_range_m(self) -> float:
        """Fs*c / (2*S) (complex sampling)."""
        return self.sample_rate_hz * SPEED_OF_LIGHT_MPS / (2 * self.slope_hz_per_s)

    @property
    def max_velocity_mps(self) -> float:
        """Maximum unambiguous radial speed lambda / (4*Ntx*Tchirp)."""
        return self.wavelength_m / (4 * self.n_tx * self.chirp_period_s)

    @property
    def velocity_resolution_mps(self) -> float:
        """Doppler bin spacing lambda / (2*Ntx*Nc*Tchirp)."""
        return self.wavelength_m / (2 * self.n_tx * self.n_loops * self.chirp_period_s)

    @property
    def noise_power_w(self) -> float:
        """Input-referred noise power per sample k*T*F*Be."""
        return (
            BOLTZMANN_J_PER_K
            * self.temperature_k
            * 10 ** (self.noise_figure_db / 10)
            * self.receiver_bandwidth_hz
        )

    @property
    def has_elevation(self) -> bool:
        """True when the virtual array has elements at more than one elevation."""
        return len(set(self.elevation_positions)) > 1

    def derived(self) -> dict[str, float | int]:
        """Derived values as a plain dict (for ``radartune radar --json`` and the GUI)."""
        return {
            "wavelength_m": self.wavelength_m,
            "slope_hz_per_s": self.slope_hz_per_s,
            "chirp_period_s": self.chirp_period_s,
            "range_resolution_m": self.range_resolution_m,
            "max_range_m": self.max_range_m,
            "max_velocity_mps": self.max_velocity_mps,
            "velocity_resolution_mps": self.velocity_resolution_mps,
            "n_tx": self.n_tx,
            "n_rx": self.n_rx,
            "n_virtual": self.n_virtual,
            "n_loops": self.n_loops,
            "n_samples": self.n_samples,
            "frame_period_s": self.frame_period_s,
        }

    def to_dict(self) -> dict:
        """All fields as JSON-ready values."""
        out = {}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            out[f.name] = list(value) if isinstance(value, tuple) else value
        return out

    @classmethod
    def from_dict(cls, data: dict, source: str | None = None) -> RadarConfig:
        """Build from a dict of fields; unknown keys are an error naming them."""
        known = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(data) - known)
        if unknown:
            raise InputError(
                f"unknown radar field(s) {unknown}; expected some of {sorted(known)}", source
            )
        kwargs = {k: tuple(v) if isinstance(v, list) else v for k, v in data.items()}
        try:
            return cls(**kwargs)
        except InputError as exc:
            raise InputError(exc.message, source) from None
        except TypeError as exc:
            raise InputError(str(exc), source) from None


PAPER_RADAR = RadarConfig()


# ---- processing settings ------------------------------------------------------------------------

#: Window names understood by :func:`core.processing.window`.
WINDOWS = ("rect", "hann", "hamming", "blackman")
#: CFAR variants: cell averaging, smallest-of and greatest-of cell averaging.
CFAR_METHODS = ("ca", "caso", "cago")


@dataclass(frozen=True, slots=True, kw_only=True)
class CfarSettings:
    """One CFAR stage (along range or along Doppler).

    Parameters
    ----------
    method
        ``"ca"`` (cell averaging over both sides), ``"caso"`` (smallest of the two sides) or
        ``"cago"`` (greatest of the two sides).
    n_train, n_guard
        Training and guard cells on each side of the cell under test.
    pfa
        Design false-alarm probability of this stage, in (0, 1).
    cyclic
        Wrap around the axis (Doppler) instead of using one side at the edges (range).
    """

    method: str = "caso"
    n_train: int = 8
    n_guard: int = 4
    pfa: float = 1e-4
    cyclic: bool = False

    def __post_init__(self) -> None:
        if self.method not in CFAR_METHODS:
            raise InputError(f"method must be one of {CFAR_METHODS}, got method={self.method!r}")
        if not (isinstance(self.n_train, int) and self.n_train >= 1):
            raise InputError(f"n_train must be an integer >= 1, got n_train={self.n_train!r}")
        if not (isinstance(self.n_guard, int) and self.n_guard >= 0):
            raise InputError(f"n_guard must be an integer >= 0, got n_guard={self.n_guard!r}")
        if not (isinstance(self.pfa, int | float) and 0.0 < self.pfa < 1.0):
            raise InputError(f"pfa must be in (0, 1), got pfa={self.pfa!r}")

    def to_dict(self) -> dict:
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}

    @classmethod
    def from_dict(cls, data: dict, source: str | None = None) -> CfarSettings:
        return _from_dict(cls, data, source)


#: SPEC §3 defaults (the TI SDK's): CASO along range, cyclic CA along Doppler.
RANGE_CFAR = CfarSettings(method="caso", n_train=8, n_guard=4, pfa=1e-4, cyclic=False)
DOPPLER_CFAR = CfarSettings(method="ca", n_train=4, n_guard=2, pfa=1e-3, cyclic=True)


@dataclass(frozen=True, slots=True, kw_only=True)
class ProcessingSettings:
    """Settings of the processing chain (SPEC §3). SI units.

    Parameters
    ----------
    range_window, doppler_window
        Window before the range / Doppler FFT: one of :data:`WINDOWS` (Hann by default).
    static_clutter_removal
        Subtract the mean over loops per range bin and virtual channel.
    range_cfar, doppler_cfar
        The two CFAR stages; a cell is detected only if it passes both.
    cfar_noise_model
        Let the CFAR thresholds account for window-correlated cells and the noise notch that
        static clutter removal leaves around zero Doppler (otherwise: independent cells).
    peak_grouping
        Keep only detections that are local maxima of the range-Doppler map (3 x 3, Doppler
        cyclic).
    min_range_m, max_range_m
        Detections are reported only between these ranges (default 0.3 m to the AOI's 10 m).
    angle_fft_size
        Zero-padded length of the azimuth FFT over the azimuth row of the virtual array.
    """

    range_window: str = "hann"
    doppler_window: str = "hann"
    static_clutter_removal: bool = True
    range_cfar: CfarSettings = RANGE_CFAR
    doppler_cfar: CfarSettings = DOPPLER_CFAR
    cfar_noise_model: bool = True
    peak_grouping: bool = True
    min_range_m: float = 0.3
    max_range_m: float = 10.0
    angle_fft_size: int = 64

    def __post_init__(self) -> None:
        for name in ("range_window", "doppler_window"):
            if getattr(self, name) not in WINDOWS:
                raise InputError(f"{name} must be one of {WINDOWS}, got {getattr(self, name)!r}")
        for name in ("range_cfar", "doppler_cfar"):
            if not isinstance(getattr(self, name), CfarSettings):
                raise InputError(f"{name} must be CfarSettings, got {getattr(self, name)!r}")
        if not (math.isfinite(self.min_range_m) and self.min_range_m >= 0):
            raise InputError(f"min_range_m must be >= 0, got min_range_m={self.min_range_m!r}")
        if not (math.isfinite(self.max_range_m) and self.max_range_m > self.min_range_m):
            raise InputError(
                f"max_range_m must be > min_range_m={self.min_range_m!r}, "
                f"got max_range_m={self.max_range_m!r}"
            )
        n = self.angle_fft_size
        if not (isinstance(n, int) and n >= 8 and n & (n - 1) == 0):
            raise InputError(f"angle_fft_size must be a power of two >= 8, got {n!r}")

    def to_dict(self) -> dict:
        out = {}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            out[f.name] = value.to_dict() if isinstance(value, CfarSettings) else value
        return out

    @classmethod
    def from_dict(cls, data: dict, source: str | None = None) -> ProcessingSettings:
        data = dict(data)
        for name in ("range_cfar", "doppler_cfar"):
            if isinstance(data.get(name), dict):
                data[name] = CfarSettings.from_dict(data[name], source)
        return _from_dict(cls, data, source)


def _from_dict(cls, data: dict, source: str | None):
    known = {f.name for f in dataclasses.fields(cls)}
    unknown = sorted(set(data) - known)
    if unknown:
        raise InputError(
            f"unknown {cls.__name__} field(s) {unknown}; expected some of {sorted(known)}", source
        )
    try:
        return cls(**data)
    except InputError as exc:
        raise InputError(exc.message, source) from None
    except TypeError as exc:
        raise InputError(str(exc), source) from None


# ---- TI mmWave SDK .cfg ----------------------------------------------------------------------

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


def _ti_fields(cmd: TiCommand, source: str) -> dict[str, float | int]:
    names = TI_COMMAND_FIELDS[cmd.name]
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
            value = int(text, 0) if name in _TI_INT_FIELDS else float(text)
        except ValueError:
            kind = "an integer" if name in _TI_INT_FIELDS else "a number"
            raise InputError(
                f"{cmd.name} field {i} {name!r}: expected {kind}, got {text!r}", where
            ) from None
        if isinstance(value, float) and not math.isfinite(value):
            raise InputError(f"{cmd.name} field {i} {name!r}: not finite, got {text!r}", where)
        out[name] = value
    return out


def _ti_require(cond: bool, cmd: TiCommand, field_name: str, message: str, source: str) -> None:
    if not cond:
        index = TI_COMMAND_FIELDS[cmd.name].index(field_name) + 1
        raise InputError(
            f"{cmd.name} field {index} {field_name!r}: {message}", f"{source}:{cmd.line}"
        )


def radar_from_ti_commands(
    commands: list[TiCommand], source: str = "<cfg>", name: str = "ti"
) -> RadarConfig:
    """Build a :class:`RadarConfig` from parsed TI commands (see :func:`read_ti_cfg`)."""
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
            adc["adcOutputFmt"] in (1, 2),
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
            tx_power_dbm=TI_MAX_TX_POWER_DBM - pr["txOutPower"],
            receiver_gain_db=float(int(pr["rxGain"]) & 0x3F),
            receiver_bandwidth_hz=sample_rate_hz,
            tx_order=tx_order,
            azimuth_positions=az,
            elevation_positions=el,
            name=name,
        )
    except InputError as exc:
        raise InputError(exc.message, source) from None


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


#: The SPEC §3 processing defaults (module-level singleton for argument defaults).
DEFAULT_PROCESSING = ProcessingSettings()
