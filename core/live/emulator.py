"""A TI mmWave sensor emulated on two pseudo-terminals: the CLI port and the data port.

For tests and benchmarks without hardware. :class:`SensorEmulator` opens two pseudo-terminal
pairs (``os.openpty``); a client (pyserial, :class:`core.live.link.LiveLink`) opens their slave
ends (:attr:`SensorEmulator.cli_port`, :attr:`SensorEmulator.data_port`) as it would the
sensor's two UARTs. The emulator answers the CLI as TI's mmWave SDK demo does (the line echoed,
then ``Done``, ``'<name>' is not recognized as a CLI command`` or ``Error -N``, then the prompt
``mmwDemo:/>``; see :mod:`core.live.dialogue`) and, between ``sensorStart`` and
``sensorStop``, streams a capture's packets on the data port, one every frame period
(``frameCfg``'s ``framePeriodicity``, or :attr:`Faults.frame_period_s`).

Faults (:class:`Faults`): garbage bytes before a packet, a packet cut short (the next one follows
at once), both ports closed (the device unplugged) after a number of packets, an ``Error -1``
answer to a named command. Every byte written to the data port is kept in :attr:`sent`.
"""

from __future__ import annotations

import fcntl
import os
import select
import struct
import termios
import threading
import time
import tty
from dataclasses import dataclass

from core.errors import InputError
from core.formats import ti_uart

#: Commands of TI's out-of-box and people-counting demos the emulator accepts with ``Done``.
KNOWN_COMMANDS = frozenset(
    (
        "sensorStop sensorStart flushCfg dfeDataOutputMode channelCfg adcCfg adcbufCfg profileCfg "
        "chirpCfg frameCfg advFrameCfg subFrameCfg lowPower guiMonitor cfarCfg multiObjBeamForming "
        "calibDcRangeSig clutterRemoval aoaFovCfg cfarFovCfg compRangeBiasAndRxChanPhase "
        "measureRangeBiasAndRxChanPhase extendedMaxVelocity CQRxSatMonitor CQSigImgMonitor "
        "analogMonitor lvdsStreamCfg bpmCfg calibData dynamicRACfarCfg staticRACfarCfg "
        "dynamicRangeAngleCfg dynamic2DAngleCfg staticRangeAngleCfg antGeometry0 antGeometry1 "
        "antPhaseRot fovCfg trackingCfg boundaryBox staticBoundaryBox presenceBoundaryBox "
        "sensorPosition gatingParam stateParam allocationParam maxAcceleration fineMotionCfg "
        "baudRate"
    ).split()
)
PROMPT = b"mmwDemo:/>"


@dataclass(frozen=True, slots=True, kw_only=True)
class Faults:
    """What goes wrong, by packet index (0-based, counted from ``sensorStart``); None: never.

    ``garbage_before``: ``garbage_bytes`` bytes (no magic word in them) sent before that packet;
    ``cut``: that packet sent only up to ``cut_fraction`` of its length, the next one at once;
    ``vanish_after``: both ports closed once that many packets are sent and read;
    ``error_on``: the CLI answers ``Error -1`` to that command name;
    ``frame_period_s``: overrides the cfg's frame period.
    """

    garbage_before: int | None = None
    garbage_bytes: int = 37
    cut: int | None = None
    cut_fraction: float = 0.5
    vanish_after: int | None = None
    error_on: str | None = None
    frame_period_s: float | None = None

    def __post_init__(self) -> None:
        if self.garbage_bytes <= 0:
            raise InputError(f"garbage_bytes must be > 0, got {self.garbage_bytes=}")
        if not 0.0 < self.cut_fraction < 1.0:
            raise InputError(f"cut_fraction must be in (0, 1), got {self.cut_fraction=}")
        if self.frame_period_s is not None and not self.frame_period_s > 0:
            raise InputError(f"frame_period_s must be > 0, got {self.frame_period_s=}")


def split_packets(stream: bytes) -> list[bytes]:
    """A UART capture cut into its packets (each from one magic word to the next)."""
    starts = []
    i = stream.find(ti_uart.MAGIC)
    while i >= 0:
        starts.append(i)
        i = stream.find(ti_uart.MAGIC, i + 1)
    if not starts:
        raise InputError("no TI UART packet in the capture (no magic word)")
    return [stream[a:b] for a, b in zip(starts, starts[1:] + [len(stream)])]


def _garbage(n: int) -> bytes:
    # a repeating pattern that holds no magic word (no 0x02 0x01 pair)
    return bytes((0xA5 + 7 * k) & 0xFF or 0x33 for k in range(n)).replace(b"\x02\x01", b"\x02\x11")


class SensorEmulator:
    """Two pseudo-terminals that behave as an IWR6843's CLI and data UARTs (module docstring).

    Use as a context manager, or :meth:`start` / :meth:`close`.
    """

    def __init__(self, capture: bytes, *, faults: Faults | None = None, loop: bool = False):
        self.packets = split_packets(capture)
        self.faults = faults or Faults()
        self.loop = loop
        self.sent = bytearray()
        self.commands: list[str] = []
        self.n_packets_sent = 0
        self.frame_period_s = 0.08
        self.streaming = threading.Event()
        self.stopped = threading.Event()  # sensorStop received after a sensorStart
        self.vanished = threading.Event()
        self._closing = threading.Event()
        self._lock = threading.Lock()
        self._cli_m, self._cli_s = os.openpty()
        self._data_m, self._data_s = os.openpty()
        for fd in (self._cli_s, self._data_s):
            tty.setraw(fd)
        self.cli_port = os.ttyname(self._cli_s)
        self.data_port = os.ttyname(self._data_s)
        self._threads: list[threading.Thread] = []
        self._session = 0  # sensorStart count: each start streams from the first packet
        #: perf_counter() at which each packet's last byte was written
        self.sent_at: list[float] = []

    def __enter__(self) -> SensorEmulator:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def start(self) -> None:
        for target in (self._cli_loop, self._data_loop):
            t = threading.Thread(target=target, daemon=True)
            t.start()
            self._threads.append(t)

    def close(self) -> None:
        self._closing.set()
        self.streaming.clear()
        for t in self._threads:
            t.join(timeout=2.0)
        with self._lock:
            for name in ("_cli_m", "_cli_s", "_data_m", "_data_s"):
                fd = getattr(self, name)
                if fd >= 0:
                    os.close(fd)
                    setattr(self, name, -1)

    # ---- CLI --------------------------------------------------------------------------------
    def _answer(self, line: str) -> bytes:
        name = line.split()[0] if line.split() else ""
        out = line.encode() + b"\r\n"
        if not name:
            return out + PROMPT
        self.commands.append(line)
        if self.faults.error_on is not None and name == self.faults.error_on:
            out += b"Error -1\r\n"
        elif name not in KNOWN_COMMANDS:
            out += f"'{name}' is not recognized as a CLI command\r\n".encode()
        else:
            if name == "frameCfg":
                args = line.split()
                if len(args) > 5 and self.faults.frame_period_s is None:
                    try:
                        self.frame_period_s = float(args[5]) / 1000.0
                    except ValueError:
                        pass
            if name == "sensorStart":
                self.stopped.clear()
                self._session += 1
                self.streaming.set()
            elif name == "sensorStop":
                if self.streaming.is_set():
                    self.stopped.set()
                else:
                    out += b"Ignored: Sensor is already stopped\r\n"
                self.streaming.clear()
            out += b"Done\r\n"
        return out + PROMPT

    def _cli_loop(self) -> None:
        buf = b""
        while not self._closing.is_set() and not self.vanished.is_set():
            try:
                r, _, _ = select.select([self._cli_m], [], [], 0.05)
            except (OSError, ValueError):
                return
            if not r:
                continue
            try:
                data = os.read(self._cli_m, 4096)
            except OSError:
                # no client has the slave open (EIO): wait for one
                time.sleep(0.02)
                continue
            buf += data
            while b"\n" in buf or b"\r" in buf:
                cut = min(i for i in (buf.find(b"\n"), buf.find(b"\r")) if i >= 0)
                line, buf = buf[:cut].decode("ascii", "replace").strip(), buf[cut + 1 :]
                if not line:
                    continue
                reply = self._answer(line)
                self._write(self._cli_m, reply)

    def _write(self, fd: int, data: bytes) -> None:
        view = memoryview(data)
        while view and not self.vanished.is_set():
            try:
                n = os.write(fd, view)
            except BlockingIOError:
                time.sleep(0.001)
                continue
            except OSError:
                return
            view = view[n:]

    # ---- data -------------------------------------------------------------------------------
    def _pending(self, fd: int) -> int:
        """Bytes written to the data port that its reader has not read yet."""
        buf = fcntl.ioctl(fd, termios.FIONREAD, b"\0\0\0\0")
        return int(struct.unpack("i", buf)[0])

    def _vanish(self) -> None:
        # wait until the client has read what was sent, so "what arrived" is all that was sent
        # (a pty passes written bytes on to the slave's queue a moment later, so wait first)
        time.sleep(0.1)
        deadline = time.monotonic() + 3.0
        while self._pending(self._data_s) and time.monotonic() < deadline:
            time.sleep(0.005)
        time.sleep(0.05)
        with self._lock:
            self.vanished.set()
            self.streaming.clear()
            for name in ("_cli_m", "_data_m"):
                fd = getattr(self, name)
                if fd >= 0:
                    os.close(fd)
                    setattr(self, name, -1)

    def _data_loop(self) -> None:
        f = self.faults
        k = 0  # packet index since sensorStart
        next_t = 0.0
        session = 0
        while not self._closing.is_set():
            if not self.streaming.wait(0.02):
                continue
            if session != self._session:
                session, k = self._session, 0
                next_t = time.perf_counter()
            if f.vanish_after is not None and k >= f.vanish_after:
                self._vanish()
                return
            if k >= len(self.packets) and not self.loop:
                self.streaming.wait(0.02)
                time.sleep(0.02)
                continue
            delay = next_t - time.perf_counter()
            if delay > 0:
                time.sleep(delay)
            if not self.streaming.is_set():
                continue
            packet = self.packets[k % len(self.packets)]
            if self.loop and k >= len(self.packets):
                packet = _renumber(packet, k + 1)
            out = b""
            if f.garbage_before == k:
                out += _garbage(f.garbage_bytes)
            if f.cut == k:
                out += packet[: max(1, int(len(packet) * f.cut_fraction))]
            else:
                out += packet
            self._write(self._data_m, out)
            self.sent += out
            self.sent_at.append(time.perf_counter())
            self.n_packets_sent += 1
            k += 1
            next_t += self.frame_period_s if f.cut != k - 1 else 0.0


def _renumber(packet: bytes, frame_number: int) -> bytes:
    """The packet with another frame number (header bytes 20..24), for a looped capture."""
    return packet[:20] + struct.pack("<I", frame_number & 0xFFFFFFFF) + packet[24:]
