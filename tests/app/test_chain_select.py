"""The radar panel selects the detection chain; a TI .cfg sets it with its own settings."""

from __future__ import annotations

import pytest

from app import engine


def test_chain_combo_and_cfg_set_the_simulated_chain(window, monkeypatch) -> None:
    from PySide6 import QtWidgets

    monkeypatch.setattr(
        QtWidgets.QMessageBox, "question", lambda *a, **k: QtWidgets.QMessageBox.Yes
    )
    window.scene_model.set_document(dict(engine.PAPER_SCENE_DOCUMENT))
    combo = window.radar_panel.chain_combo
    assert combo.currentText() == "paper" and window.sim.chain is None
    combo.setCurrentText("oob")
    assert window.radar_model.chain.name == "oob"
    assert window.sim.chain.name == "oob" and window.sim.chain.oob.range_cfar.method == "caso"
    # a people-counting .cfg: its radar, its chain with its settings (static detection on)
    cfg = engine.ROOT / "resources" / "radar" / "people_counting_isk_static.cfg"
    assert window.load_cfg(cfg), window.errors
    assert combo.currentText() == "people-counting"
    chain = window.sim.chain
    assert chain.name == "people-counting" and chain.people_counting.static_enabled
    assert window.radar_model.radar.n_loops == 96
    # choosing the same name again keeps the cfg's settings; paper goes back
    combo.setCurrentText("people-counting")
    assert window.sim.chain is chain
    combo.setCurrentText("paper")
    assert window.sim.chain.name == "paper"


@pytest.mark.slow
def test_engine_simulates_through_a_ti_chain() -> None:
    from core.config import default_chain

    doc = dict(engine.PAPER_SCENE_DOCUMENT)
    scene = engine.scene_from_document(doc, engine.ROOT)
    frames = engine.simulate(scene, chain=default_chain("oob"))
    first = next(iter(frames))
    assert first.rd_map_db is not None and first.ra_map_db is not None
