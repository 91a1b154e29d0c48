"""The CLI-port dialogue with a TI mmWave sensor: a ``.cfg`` sent line by line, each answer checked.

TI's mmWave SDK demos (and the people-counting firmware built on them) read one command a line on
their CLI UART (115 200 baud, 8N1). The firmware echoes the line, runs the command and answers
``Done``, or an error line — ``'<name>' is not recognized as a CLI command`` for an unknown
command, ``Error -N`` (N the demo's error code) when the command's handler refuses it — and then
prints its prompt ``mmwDemo:/>`` (mmWave SDK user guide, section "CLI"; the demo's
``CLI_task``). Lines that inform (``Ignored: Sensor is already stopped``, ``Debug: ...``) may
come before ``Done``.

:func:`send_cfg` sends every command of a parsed ``.cfg`` (comments and blank lines are not
sent), waits for the prompt after each and stops at the first line the sensor rejects, raising one
:class:`LinkError` that names the file, line and the sensor's answer.
"""

from __future__ import annotations

import re
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Protocol

from core.errors import InputError
from core.formats.ti_cfg import TiCommand

#: The prompt the demo prints when it is ready for the next line.
PROMPT = b"mmwDemo:/>"
#: The answer to a command that was accepted.
DONE = "Done"
#: Baud rate of the CLI port (mmWave SDK user guide).
CLI_BAUD = 115_200
#: Default baud rate of the data port (mmWave SDK user guide; a ``.cfg`` may set another with
#: ``baudRate``, see :func:`data_baud`).
DATA_BAUD = 921_600
#: Seconds to wait for the prompt after a line (``sensorStart`` takes the longest: it configures
#: the RF front end and runs its calibration, well under a second on an IWR6843).
ANSWER_TIMEOUT_S = 3.0

_ERROR_LINE = re.compile(r"(is not recognized as a CLI command|^\s*Error\b.*)", re.IGNORECASE)


class LinkError(InputError):
    """The link to the sensor failed: a rejected line, no answer, a port that vanished."""


class Port(Protocol):
    """What the link needs of a serial port (``serial.Serial`` has it)."""

    def write(self, data: bytes, /) -> int | None: ...
    def read(self, size: int = 1, /) -> bytes: ...
    @property
    def in_waiting(self) -> int: ...
    def reset_input_buffer(self) -> None: ...
    def close(self) -> None: ...


@dataclass(frozen=True, slots=True, kw_only=True)
class Answer:
    """The sensor's answer to one line: the lines it printed before the prompt (the echo left
    out) and whether it accepted the command."""

    command: str
    lines: tuple[str, ...]
    accepted: bool

    @property
    def error(self) -> str:
        """The error line (or, with none, what was printed instead of ``Done``)."""
        for line in self.lines:
            if _ERROR_LINE.search(line):
                return line.strip()
        return "; ".join(self.lines) or "no answer before the prompt"


def classify(command: str, text: str) -> Answer:
    """The answer to ``command`` from the text read up to the prompt (prompt excluded).

    Accepted when a line says ``Done`` and none is an error line (``... is not recognized as a CLI
    command``, ``Error ...``); the echo of the command is left out of the lines.
    """
    lines = []
    for raw in text.replace("\r", "\n").split("\n"):
        line = raw.strip()
        if not line or line == command.strip():
            continue
        if line.startswith(PROMPT.decode()):
            line = line[len(PROMPT) :].strip()
            if not line or line == command.strip():
                continue
        lines.append(line)
    errors = [ln for ln in lines if _ERROR_LINE.search(ln)]
    accepted = not errors and DONE in lines
    return Answer(command=command, lines=tuple(lines), accepted=accepted)


def read_answer(
    port: Port, command: str, *, timeout_s: float = ANSWER_TIMEOUT_S, port_name: str = "CLI port"
) -> Answer:
    """Read from ``port`` until the prompt (or ``timeout_s``) and classify the answer."""
    buf = b""
    deadline = time.monotonic() + timeout_s
    while True:
        try:
            chunk = port.read(max(1, port.in_waiting))
        except (OSError, ValueError) as exc:  # serial.SerialException is an OSError
            raise LinkError(f"{port_name} vanished while waiting for the answer ({exc})") from None
        buf += chunk
        # the prompt ends the answer; the echo of the line may itself follow a prompt
        end = buf.rfind(PROMPT)
        if end >= 0:
            answer = classify(command, _text(buf[:end]))
            if answer.lines:  # more than the echo: the answer is complete
                return answer
        if time.monotonic() > deadline:
            text = _text(buf)
            answer = classify(command, text.split(PROMPT.decode())[0] if end >= 0 else text)
            if answer.accepted:
                return answer
            got = " ".join(text.split())[-120:] or "nothing"
            raise LinkError(
                f"no answer from the sensor to {command!r} within {timeout_s:g} s "
                f"(got: {got!r}); is this the CLI port (not the data port), at its baud rate "
                f"({CLI_BAUD} by default)?"
            )


def _text(b: bytes) -> str:
    return b.decode("ascii", "replace")


def send_cfg(
    port: Port,
    commands: Sequence[TiCommand],
    source: str,
    *,
    timeout_s: float = ANSWER_TIMEOUT_S,
    on_answer: Callable[[TiCommand, Answer], None] | None = None,
) -> list[Answer]:
    """Send ``commands`` one line each and check every answer.

    Raises
    ------
    LinkError
        At the first rejected line (``"<source>:<line>: the sensor rejected 'cmd ...': Error
        -1"``), or when no prompt follows a line within ``timeout_s``.
    """
    answers = []
    try:
        port.reset_input_buffer()
    except (OSError, ValueError) as exc:
        raise LinkError(f"CLI port unusable ({exc})") from None
    for cmd in commands:
        line = " ".join((cmd.name, *cmd.args))
        try:
            port.write(line.encode("ascii", "replace") + b"\n")
        except (OSError, ValueError) as exc:
            raise LinkError(f"CLI port vanished while sending {line!r} ({exc})") from None
        try:
            answer = read_answer(port, line, timeout_s=timeout_s)
        except LinkError as exc:
            raise LinkError(exc.message, f"{source}:{cmd.line}") from None
        if on_answer is not None:
            on_answer(cmd, answer)
        if not answer.accepted:
            raise LinkError(
                f"the sensor rejected {line!r}: {answer.error} (no line after it was sent)",
                f"{source}:{cmd.line}",
            )
        answers.append(answer)
    return answers


def data_baud(commands: Sequence[TiCommand], default: int = DATA_BAUD) -> int:
    """The data port's baud rate: a ``baudRate N`` line of the ``.cfg`` (the low-power SDK's
    command), else ``default``."""
    for cmd in commands:
        if cmd.name == "baudRate" and cmd.args:
            try:
                value = int(cmd.args[0])
            except ValueError:
                raise InputError(
                    f"baudRate field 1: expected an integer, got {cmd.args[0]!r}",
                    f"line {cmd.line}",
                ) from None
            if value <= 0:
                raise InputError(f"baudRate field 1: must be > 0, got {value}", f"line {cmd.line}")
            return value
    return default
