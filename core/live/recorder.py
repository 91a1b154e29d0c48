"""The recording of a live link: the data port's bytes, unchanged, in one file.

The bytes are what TI's tools log from the data port (the mmWave Demo Visualizer's and the
Industrial Visualizer's ``.dat`` UART logs), so ``radartune import`` and TI's tools read the file
as any UART log. The file is written under a temporary name beside the target and renamed to it
when the link ends — however it ends: stopped, a frame limit reached, Ctrl-C, a port that
vanished — so the file is whole up to the last byte that arrived and no reader ever sees half of
it. (A process killed outright leaves the temporary ``.NAME.*.tmp`` file with the bytes so far.)
"""

from __future__ import annotations

import os
from contextlib import ExitStack
from pathlib import Path

from core.files import atomic_open


class Recorder:
    """Appends chunks to ``path``'s temporary file; :meth:`close` puts it in place."""

    def __init__(self, path: str | os.PathLike) -> None:
        self.path = Path(path)
        self.n_bytes = 0
        self._stack = ExitStack()
        self._fh = self._stack.enter_context(atomic_open(self.path, "wb"))
        self._closed = False

    def write(self, chunk: bytes) -> None:
        self._fh.write(chunk)
        self.n_bytes += len(chunk)

    def close(self) -> Path:
        """Flush, sync and rename the file into place (once; later calls do nothing)."""
        if not self._closed:
            self._closed = True
            self._stack.close()  # atomic_open's success path: fsync, chmod, os.replace
        return self.path
