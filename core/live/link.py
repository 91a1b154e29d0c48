"""A live TI mmWave sensor: its two serial ports, its ``.cfg``, its frames tracked as they arrive.

:class:`LiveLink` opens the CLI port (115 200 baud) and the data port (921 600 baud, or the
``.cfg``'s ``baudRate``), sends the ``.cfg`` line by line (:func:`core.live.dialogue.send_cfg`:
the first line the sensor rejects ends it, named), then reads the data port in chunks and hands
them to the same streaming parser that reads UART log files
(:func:`core.formats.ti_uart.iter_uart_frames`): damaged packets and garbage between packets are
skipped and counted the same way, and frame-number gaps count dropped frames. Every chunk is
written unchanged to the recording (:class:`core.live.recorder.Recorder`) before it is parsed.
Each frame's points are tracked at once, frame by frame (:func:`stream_tracker`: the paper's
IPDA, :class:`core.tracking.tracker.StreamTracker`, or gtrack,
:class:`core.tracking.gtrack.tracker.GtrackTracker`, as the parameters say) and yielded as a
:class:`LiveFrame`.

Frames are placed on the frame grid the importer uses
(:func:`core.formats.recording.frames_from_numbers`): a gap of up to
:data:`~core.formats.recording.MAX_FILLED_GAP_FRAMES` frame numbers advances the tracker over
that many empty frames; a frame number going back, or a longer gap, starts a new run (a new
tracker). So the tracks of a live run are those ``radartune import`` + the readable
tracker give on its recording.

:meth:`LiveLink.close` sends ``sensorStop`` on the CLI port (when it is still there), closes the
ports and puts the recording in place — however the link ended. A port that vanishes (a read or
write that fails: the device unplugged) or a data port silent for ``silence_timeout_s`` raises
one :class:`~core.live.dialogue.LinkError`.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from core.config import RadarConfig
from core.errors import InputError
from core.files import read_text
from core.formats import ti_uart
from core.formats.recording import MAX_FILLED_GAP_FRAMES, points_to_cloud
from core.formats.ti_cfg import TiCommand, parse_ti_cfg, radar_from_ti_commands
from core.live.dialogue import (
    ANSWER_TIMEOUT_S,
    CLI_BAUD,
    LinkError,
    Port,
    data_baud,
    read_answer,
    send_cfg,
)
from core.live.recorder import Recorder
from core.pointcloud import PointCloud
from core.tracking.gtrack import GtrackParams
from core.tracking.params import TrackerParams
from core.tracking.results import FrameTracks
from core.tracking.tracker import StreamTracker

#: Seconds the data port's read waits for a byte before the loop looks at the stop flag.
READ_TIMEOUT_S = 0.02
#: Default seconds without a byte on the data port after which the sensor counts as gone.
SILENCE_TIMEOUT_S = 5.0


@dataclass(frozen=True, slots=True, kw_only=True)
class LinkSettings:
    """Where the sensor is and how to talk to it.

    ``data_baud`` None: the ``.cfg``'s ``baudRate`` line, else 921 600.
    """

    cli_port: str
    data_port: str
    cfg: str
    cli_baud: int = CLI_BAUD
    data_baud: int | None = None
    silence_timeout_s: float = SILENCE_TIMEOUT_S
    answer_timeout_s: float = ANSWER_TIMEOUT_S

    def __post_init__(self) -> None:
        for name in ("cli_port", "data_port", "cfg"):
            if not getattr(self, name):
                raise InputError(f"{name} must be given, got {getattr(self, name)!r}")
        if self.cli_port == self.data_port:
            raise InputError(
                f"cli_port and data_port must be two ports, got {self.cli_port!r} for both"
            )
        if self.cli_baud <= 0:
            raise InputError(f"cli_baud must be > 0, got {self.cli_baud=}")
        if self.data_baud is not None and self.data_baud <= 0:
            raise InputError(f"data_baud must be > 0, got {self.data_baud=}")
        if not self.silence_timeout_s > 0:
            raise InputError(f"silence_timeout_s must be > 0, got {self.silence_timeout_s=}")
        if not self.answer_timeout_s > 0:
            raise InputError(f"answer_timeout_s must be > 0, got {self.answer_timeout_s=}")


@dataclass(frozen=True, slots=True, kw_only=True)
class LiveFrame:
    """One frame as it arrived, tracked.

    ``index``: the frame's place on the frame grid since the link started (what ``radartune
    import`` of the recording calls its frame); ``t_s`` = index x frame period; ``received_s``:
    ``time.perf_counter()`` when the chunk holding the frame's last byte was read;
    ``n_dropped``, ``n_damaged``: the stream's counts so far.
    """

    index: int
    frame_number: int
    t_s: float
    cloud: PointCloud
    tracks: FrameTracks
    received_s: float
    n_dropped: int
    n_damaged: int


class _GtrackStream:
    """gtrack fed one frame at a time (its tracker keeps its state between frames)."""

    def __init__(self, params: GtrackParams, frame_period_s: float) -> None:
        from core.limits import FRAME_PERIOD_RANGE_S
        from core.tracking.gtrack.tracker import GtrackTracker

        lo, hi = FRAME_PERIOD_RANGE_S
        if lo <= frame_period_s <= hi:  # the cfg's frame period is the data's
            params = replace(params, frame_period_s=frame_period_s)
        self._tracker = GtrackTracker(params)

    def step(self, cloud: PointCloud) -> FrameTracks:
        snr = 10.0 ** (np.asarray(cloud.snr_db, dtype=float) / 10.0)
        ft, _, _ = self._tracker.step(
            cloud.range_m, cloud.azimuth_rad, cloud.elevation_rad, cloud.radial_velocity_mps, snr
        )
        return ft


class _IpdaStream:
    def __init__(self, params: TrackerParams, frame_period_s: float) -> None:
        self._tracker = StreamTracker(params, frame_period_s)

    def step(self, cloud: PointCloud) -> FrameTracks:
        return self._tracker.step(cloud.measurements())


def stream_tracker(
    params: TrackerParams | GtrackParams, frame_period_s: float
) -> _IpdaStream | _GtrackStream:
    """A tracker fed one frame at a time, ``.step(cloud) -> FrameTracks``: the paper's IPDA
    (``TrackerParams`` of the paper mode) or gtrack (``GtrackParams``); each gives, frame by
    frame, what its batch run (:func:`~core.tracking.run_tracker`,
    :func:`~core.tracking.gtrack.run_gtrack`) gives over the whole run. The room mode has no
    frame-by-frame form yet: one :class:`~core.errors.InputError`."""
    if isinstance(params, GtrackParams):
        return _GtrackStream(params, frame_period_s)
    if params.mode != "paper":
        raise InputError(
            f"the live link tracks with the paper tracker or gtrack, not the {params.mode} mode "
            "(it has no frame-by-frame form yet): track the recording afterwards"
        )
    return _IpdaStream(params, frame_period_s)


def open_serial(port: str, baud: int, what: str) -> Port:
    """Open ``port`` with pyserial (8N1, no flow control); one line naming it if it cannot."""
    import serial

    try:
        return serial.Serial(port=port, baudrate=baud, timeout=READ_TIMEOUT_S, write_timeout=2.0)
    except (serial.SerialException, OSError, ValueError) as exc:
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise LinkError(f"cannot open the {what} at {baud} baud ({reason})", port) from None


def list_ports() -> list[tuple[str, str]]:
    """Serial ports pyserial finds: ``(device, description)``, TI's XDS110 ports first."""
    from serial.tools import list_ports as lp

    ports = [(p.device, p.description or "") for p in lp.comports()]
    return sorted(ports, key=lambda p: ("XDS110" not in p[1], p[0]))


class LiveLink:
    """A sensor behind two serial ports (see the module docstring).

    Use: ``link.start()`` (ports opened, ``.cfg`` sent), iterate ``link.frames()``, then
    ``link.close()`` (in a ``finally``). ``stop()`` may be called from another thread: the frame
    iterator ends at its next read. A closed link can be started again (reconnect).

    ``opener(port, baud, what)`` opens a port (default :func:`open_serial`).
    """

    def __init__(
        self,
        settings: LinkSettings,
        params: TrackerParams | GtrackParams | None = None,
        *,
        record: str | Path | None = None,
        opener: Callable[[str, int, str], Port] = open_serial,
    ) -> None:
        self.settings = settings
        self.params = params if params is not None else TrackerParams.default("cv")
        stream_tracker(self.params, 0.05)  # a tracker the link cannot run: said now, in one line
        self.record_path = Path(record) if record is not None else None
        self._opener = opener
        text = read_text(Path(settings.cfg), what="TI configuration")
        self.commands: list[TiCommand] = parse_ti_cfg(text, settings.cfg)
        if not self.commands:
            raise InputError("no command to send (only comments or blank lines)", settings.cfg)
        self.radar: RadarConfig = radar_from_ti_commands(
            self.commands, settings.cfg, name=Path(settings.cfg).stem
        )
        self.data_baud = settings.data_baud or data_baud(self.commands)
        self.notes: list[str] = []
        if not any(c.name == "sensorStart" for c in self.commands):
            last = self.commands[-1].line + 1
            self.commands.append(TiCommand(name="sensorStart", args=(), line=last))
            self.notes.append(f"{settings.cfg} has no sensorStart line: sent one after its last")
        self.report = ti_uart.UartReport()
        self.n_frames = 0
        self._stop = threading.Event()
        self._cli: Port | None = None
        self._data: Port | None = None
        self._recorder: Recorder | None = None
        self._started = False
        self._cli_lost = False
        self._last_chunk_s = 0.0

    # ---- life cycle -------------------------------------------------------------------------
    def start(self) -> None:
        """Open both ports and the recording, send the ``.cfg``; raises :class:`LinkError`."""
        s = self.settings
        self._stop.clear()
        self.report = ti_uart.UartReport()
        self.n_frames = 0
        self._cli_lost = False
        self._cli = self._opener(s.cli_port, s.cli_baud, "CLI port")
        self._data = self._opener(s.data_port, self.data_baud, "data port")
        try:
            self._data.reset_input_buffer()
        except (OSError, ValueError) as exc:
            raise LinkError(f"data port unusable ({exc})", s.data_port) from None
        self._started = True  # from here on, close() sends sensorStop
        try:
            send_cfg(self._cli, self.commands, s.cfg, timeout_s=s.answer_timeout_s)
        except LinkError as exc:
            if "vanished" in exc.message:
                self._cli_lost = True
            raise
        # after the sensor took the cfg: a rejected cfg leaves no recording behind (the bytes
        # sent since sensorStart wait in the port's buffer and are recorded first)
        if self.record_path is not None:
            self._recorder = Recorder(self.record_path)

    def stop(self) -> None:
        """Ask the frame iterator to end (thread-safe); :meth:`close` does the rest."""
        self._stop.set()

    @property
    def stopping(self) -> bool:
        return self._stop.is_set()

    def close(self) -> Path | None:
        """``sensorStop`` (if the sensor was started and its CLI port is still there), both ports
        closed, the recording put in place (returned). Never raises for a vanished port."""
        stopped_sensor = False
        if self._started and self._cli is not None and not self._cli_lost:
            try:
                self._cli.write(b"sensorStop\n")
                read_answer(self._cli, "sensorStop", timeout_s=1.0)
                stopped_sensor = True
            except (LinkError, OSError, ValueError):
                pass
        if self._started and not stopped_sensor:
            self.notes.append("sensorStop could not be sent (CLI port gone or silent)")
        for port in (self._cli, self._data):
            if port is not None:
                try:
                    port.close()
                except (OSError, ValueError):
                    pass
        self._cli = self._data = None
        self._started = False
        path = None
        if self._recorder is not None:
            path = self._recorder.close()
            self._recorder = None
        return path

    @property
    def recorded_bytes(self) -> int:
        return self._recorder.n_bytes if self._recorder is not None else 0

    # ---- data -------------------------------------------------------------------------------
    def _chunks(self) -> Iterator[bytes]:
        """The data port's bytes as they arrive, each chunk recorded first; ends on stop()."""
        port = self._data
        if port is None:
            raise LinkError("the link is not started", self.settings.data_port)
        last = time.monotonic()
        n_bytes = 0
        while not self._stop.is_set():
            try:
                chunk = port.read(max(1, port.in_waiting))
            except (OSError, ValueError) as exc:  # serial.SerialException is an OSError
                reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
                raise LinkError(
                    f"the data port vanished after {n_bytes} bytes and {self.n_frames} frames "
                    f"({reason})",
                    self.settings.data_port,
                ) from None
            now = time.monotonic()
            if chunk:
                self._last_chunk_s = time.perf_counter()
                last = now
                n_bytes += len(chunk)
                if self._recorder is not None:
                    self._recorder.write(chunk)
                yield chunk
            elif now - last > self.settings.silence_timeout_s:
                raise LinkError(
                    f"no data for {self.settings.silence_timeout_s:g} s after {n_bytes} bytes "
                    f"and {self.n_frames} frames (sensor stopped, or not the data port?)",
                    self.settings.data_port,
                )

    def frames(self) -> Iterator[LiveFrame]:
        """Each frame as it arrives, tracked (see the module docstring)."""
        period = self.radar.frame_period_s
        tracker = stream_tracker(self.params, period)
        index = -1
        id_shift = next_id = 0
        last_number: int | None = None
        empty = PointCloud.empty()
        it = ti_uart.iter_uart_frames(
            self._chunks(), radar=self.radar, report=self.report, name=self.settings.data_port
        )
        try:
            for uf in it:
                fn = uf.frame_number
                d = 1 if last_number is None else fn - last_number
                if 1 < d <= MAX_FILLED_GAP_FRAMES + 1:
                    # frames lost on the way: the tracker predicts over them (as on import)
                    for _ in range(d - 1):
                        tracker.step(empty)
                    index += d
                elif d == 1:
                    index += 1
                else:  # the sensor restarted (number back) or a long gap: a new run
                    tracker = stream_tracker(self.params, period)
                    id_shift = next_id
                    index += 1
                last_number = fn
                p = uf.points
                cloud, _ = points_to_cloud(p.x_m, p.y_m, p.z_m, p.velocity_mps, p.snr_db)
                tracks = tracker.step(cloud)
                if len(tracks):
                    # ids unique over the link: a new run's ids follow the last run's
                    tracks = replace(tracks, ids=tracks.ids + id_shift)
                    next_id = max(next_id, int(tracks.ids.max()) + 1)
                self.n_frames += 1
                yield LiveFrame(
                    index=index,
                    frame_number=fn,
                    t_s=index * period,
                    cloud=cloud,
                    tracks=tracks,
                    received_s=self._last_chunk_s,
                    n_dropped=self.report.n_dropped,
                    n_damaged=self.report.n_damaged,
                )
        except LinkError:
            raise
        except InputError:
            # the parser's "no packet in the stream" at the end: only an error if not stopped
            if not self._stop.is_set():
                raise
