"""A live TI mmWave sensor over its two serial ports (pyserial); no Qt.

- :mod:`~core.live.dialogue` — the ``.cfg`` sent line by line on the CLI port, TI's answers
  (``Done``, ``... is not recognized as a CLI command``, ``Error -N``, the prompt) checked
- :mod:`~core.live.link` — :class:`LiveLink`: the ports, the dialogue, the data port's bytes
  through the UART files' stream parser, each frame tracked; ``sensorStop`` on the way out
- :mod:`~core.live.recorder` — the data port's bytes unchanged in one file, put in place whole
- :mod:`~core.live.emulator` — a sensor on pseudo-terminals, with faults (tests, benchmarks)
"""

from core.live.dialogue import LinkError
from core.live.link import LinkSettings, LiveFrame, LiveLink, list_ports

__all__ = ["LinkError", "LinkSettings", "LiveFrame", "LiveLink", "list_ports"]
