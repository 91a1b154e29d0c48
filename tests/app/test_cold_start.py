"""Cold start: the readable numpy tracker draws the overlay until the compiled kernel is ready,
then the scene is re-tracked with the kernel; both give the same tracks."""

from __future__ import annotations

import threading

import numpy as np

from app import engine
from app.models import FrameCache, TrackerParamsModel, TrackingModel
from app.workers import TrackingController


class ColdEngine(engine.Engine):
    """The real engine whose kernel 'compiles' until the test releases it."""

    def __init__(self) -> None:
        self.release = threading.Event()
        self.ready = False

    def tracker_compiled(self) -> bool:
        return self.ready

    def warm_up_tracker(self) -> float:
        self.release.wait(60)
        self.ready = True
        return 1.5


def test_numpy_tracker_until_compiled_then_the_kernel(qtbot, long_scene_frames) -> None:
    scene, frames = long_scene_frames
    eng = ColdEngine()
    cache = FrameCache()
    cache.clear(expected=len(frames), truth_paths=[])
    for f in frames:
        cache.append(f)
    cache.mark_complete()
    tracking = TrackingModel()
    ctl = TrackingController(eng, cache, TrackerParamsModel(eng), tracking)
    compiled = []
    ctl.compiled.connect(compiled.append)
    ctl.start_warm_up()
    ctl.request()
    qtbot.waitUntil(lambda: tracking.result is not None and ctl.idle, timeout=120000)
    first = tracking.result
    assert first.engine == "numpy" and not compiled
    eng.release.set()
    qtbot.waitUntil(lambda: bool(compiled) and ctl.n_runs >= 2 and ctl.idle, timeout=120000)
    assert compiled == [1.5]
    second = tracking.result
    assert second.engine == "numba"
    # the same tracks to round-off: ids and confirmation equal, positions to 1e-9 m
    assert len(first.frames) == len(second.frames) == len(frames)
    for a, b in zip(first.frames, second.frames):
        np.testing.assert_array_equal(a.track_id, b.track_id)
        np.testing.assert_array_equal(a.confirmed, b.confirmed)
        np.testing.assert_allclose(a.xy_m, b.xy_m, atol=1e-9)
    np.testing.assert_allclose(first.running_loss, second.running_loss, rtol=1e-9)
    ctl.wait()
