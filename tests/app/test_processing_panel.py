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
    synth, proc = window.sim.ms_per_frame_halves
    assert 0 < synth and 0 < proc and synth + proc <= window.sim.ms_per_frame * 1.5
    assert panel.timing_labels["synthesis"].text().endswith(" ms")
    assert panel.timing_labels["processing"].text().endswith(" ms")
