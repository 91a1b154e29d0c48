"""Workers end before their owner does: shutdown joins a simulation busy in one long step."""

from __future__ import annotations

import time
from types import SimpleNamespace

from PySide6 import QtCore

from app.models import FrameCache
from app.workers import SimulationController

#: Longer than the 5 s the simulation join used to give up after (a cold numba compile of the
#: first frame on a busy machine takes longer; then the window was destroyed under the thread).
BUSY_S = 5.5


class OneSlowFrameEngine:
    """Simulates one frame that takes ``BUSY_S`` and cannot be interrupted (like a compile)."""

    def scene_info(self, scene):
        return SimpleNamespace(n_frames=1, truth_paths=[])

    def simulate(self, scene, *, fidelity="exact"):
        time.sleep(BUSY_S)
        yield SimpleNamespace(index=0)


def test_wait_joins_a_worker_busy_past_the_old_time_out(qtbot) -> None:
    cache = FrameCache()
    sim = SimulationController(OneSlowFrameEngine(), cache)
    sim.start(scene=None)
    qtbot.waitUntil(lambda: sim.running, timeout=5000)
    t0 = time.perf_counter()
    assert sim.wait()
    elapsed = time.perf_counter() - t0
    assert not sim.running
    assert all(w.isFinished() for w in sim.findChildren(QtCore.QThread))
    assert elapsed >= BUSY_S - 1.0  # it really waited for the step in progress
    assert len(cache) == 0  # the frame of a stopped simulation is dropped, not cached
