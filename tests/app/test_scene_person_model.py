"""The scene editor offers the person model (point, blob, walking) and the walking body's height."""

from __future__ import annotations

from app import engine


def test_scene_panel_person_model_both_ways(window) -> None:
    window.scene_model.set_document(engine.PAPER_SCENE_DOCUMENT)
    panel, model = window.scene_panel, window.scene_model
    assert [panel.person_model.itemText(k) for k in range(3)] == ["point", "blob", "walking"]
    assert panel.person_model.currentText() == "point" and not panel.height.isEnabled()
    # widget -> model
    panel.person_model.setCurrentText("walking")
    person = model.document["persons"][0]
    assert person["model"] == "walking" and person["height_m"] == 1.75
    assert model.scene.persons[0].kind == "walking" and not model.scene.is_planar
    assert panel.height.isEnabled()
    panel.height.setValue(1.6)
    assert model.scene.persons[0].height_m == 1.6
    panel.person_model.setCurrentText("point")
    assert "model" not in model.document["persons"][0]
    assert "height_m" not in model.document["persons"][0]
    # model -> widget: a file with the former name shows the blob
    doc = model.document
    doc["persons"][0]["model"] = "extended"
    model.set_document(doc)
    assert panel.person_model.currentText() == "blob"
    assert model.document["persons"][0]["model"] == "extended"
