"""The processing panel: fidelity level, the chain's settings as it runs them, timings."""

from __future__ import annotations

from app import engine
from core.config import DEFAULT_PROCESSING


def test_panel_shows_the_chain_settings_and_switches_fidelity(window, qtbot, monkeypatch) -> None:
    panel = window.processing_panel
    assert [panel.fidelity.itemData(i) for i in range(panel.fidelity.count())] == [
        "exact",
        "fast",
        "measurement",
    ]
    window.scene_model.set_document(dict(engine.PAPER_SCENE_DOCUMENT))
    window._scene_timer.stop()
    rc, dc = DEFAULT_PROCESSING.range_cfar, DEFAULT_PROCESSING.doppler_cfar
    text = panel.settings_labels["range_cfar"].text()
    assert text.startswith(f"{rc.method.upper()} · {rc.n_train} train / {rc.n_guard} guard")
    assert f"P_fa {rc.pfa:g}" in text
    assert f"P_fa {dc.pfa:g}" in panel.settings_labels["doppler_cfar"].text()
    # detections are limited to the scene's area of interest (10 m)
    assert panel.settings_labels["ranges"].text() == f"{DEFAULT_PROCESSING.min_range_m:g} … 10 m"

    levels = []
    real = window.engine.simulate

    def simulate(scene, *, fidelity="exact"):
        levels.append(fidelity)
        return real(scene, fidelity=fidelity)

    monkeypatch.setattr(window.engine, "simulate", simulate)
    panel.fidelity.setCurrentIndex(panel.fidelity.findData("measurement"))
    assert window.sim.fidelity == "measurement"
    qtbot.waitUntil(lambda: window.cache.complete, timeout=120000)
    assert levels == ["measurement"]
    window.redraw()
    window._t_timing_shown = 0.0
    window._update_fps()
    assert panel.timing_labels["chain"].text().endswith(" ms")
    assert panel.timing_labels["draw"].text().endswith(" ms")
    # the measurement level runs both halves in one kernel: no split to show
    assert panel.timing_labels["synthesis"].text() == "–"
    assert panel.timing_labels["processing"].text() == "–"
    # the exact level runs them apart: each half shown, and they make up the chain's time
    panel.fidelity.setCurrentIndex(panel.fidelity.findData("exact"))
    qtbot.waitUntil(lambda: window.cache.complete and len(window.cache) > 2, timeout=120000)
    window._t_timing_shown = 0.0
    window._update_fps()
    ft = window.sim.frame_timing_ms
    assert ft.n_frames >= 1 and 0 < ft.synthesis and 0 < ft.processing and ft.other >= 0
    assert abs(ft.synthesis + ft.processing + ft.other - ft.total) < 1e-9 * ft.total
    for key in ("synthesis", "processing", "other"):
        assert panel.timing_labels[key].text().endswith(" ms")


def test_frame_timing_parts_add_up_to_the_total_over_the_same_frames(qtbot) -> None:
    from app.panels.processing_panel import ProcessingPanel
    from app.workers import frame_timing

    # (whole frame, synthesis, processing) s; the first frame (kernel compilation) left out
    rows = [(9.0, 5.0, 3.0), (0.030, 0.012, 0.015), (0.050, 0.020, 0.024), (0.040, 0.016, 0.021)]
    ft = frame_timing(rows)
    assert ft.n_frames == 3
    assert abs(ft.total - 40.0) < 1e-9
    assert abs(ft.synthesis - 16.0) < 1e-9 and abs(ft.processing - 20.0) < 1e-9
    assert abs(ft.other - 4.0) < 1e-9
    # a level without the split: the total alone
    whole = frame_timing([(0.010, float("nan"), float("nan"))] * 3)
    assert abs(whole.total - 10.0) < 1e-9 and all(
        v != v for v in (whole.synthesis, whole.processing, whole.other)
    )
    assert frame_timing([]).n_frames == 0

    panel = ProcessingPanel(["exact"])
    qtbot.addWidget(panel)
    panel.show_timing(frame=ft, track_ms=1.0, draw_ms=2.0, sim_fps=20.0, draw_fps=30)
    keys = ("chain", "synthesis", "processing", "other")
    shown = {k: panel.timing_labels[k].text() for k in keys}
    assert shown == {
        "chain": "40.0 ms",
        "synthesis": "16.0 ms",
        "processing": "20.0 ms",
        "other": "4.0 ms",
    }


def test_the_worker_times_each_frame_whole_with_its_parts() -> None:
    import time
    from types import SimpleNamespace

    from app.workers import SimulationWorker, frame_timing

    class Engine:
        """Frames that take 20 ms each, of which the chain reports 8 ms + 6 ms."""

        def simulate(self, scene, *, fidelity="exact"):
            for i in range(4):
                time.sleep(0.020)
                yield SimpleNamespace(index=i, synthesis_s=0.008, processing_s=0.006)

    worker = SimulationWorker(Engine(), scene=None, generation=0)
    got = []
    worker.frame_ready.connect(lambda _g, f: got.append(f.index))
    worker.run()  # in this thread: the loop alone
    assert got == [0, 1, 2, 3] and len(worker.frame_times_s) == 4
    ft = frame_timing(worker.frame_times_s)
    assert abs(ft.synthesis - 8.0) < 1e-9 and abs(ft.processing - 6.0) < 1e-9
    assert ft.total >= 20.0 and abs(ft.other - (ft.total - 14.0)) < 1e-9
