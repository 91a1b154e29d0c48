"""The scene editor with several people: add up to eight, select, remove; each person
drawn in its own colour, the selected one wider; the list shows the same colours."""

from __future__ import annotations

import json

from app import engine
from app.person_colours import person_colour
from core.limits import MAX_PERSONS


def test_editor_adds_selects_removes_and_colours_persons(window) -> None:
    window.scene_model.set_document(dict(engine.PAPER_SCENE_DOCUMENT))
    window._scene_timer.stop()
    panel, view, model = window.scene_panel, window.top_view, window.scene_model
    while model.n_persons < MAX_PERSONS:
        (panel.add_wp_button if model.n_persons % 2 else panel.add_class_button).click()
    window._scene_timer.stop()
    assert model.n_persons == MAX_PERSONS == panel.person_list.count()
    assert not panel.add_class_button.isEnabled() and not panel.add_wp_button.isEnabled()
    # eight colours, all different, in the list and on the paths
    colours = {person_colour(k) for k in range(MAX_PERSONS)}
    assert len(colours) == MAX_PERSONS
    for k in range(MAX_PERSONS):
        icon = panel.person_list.item(k).icon().pixmap(12, 12).toImage()
        assert icon.pixelColor(6, 6).getRgb()[:3] == person_colour(k)
        pen = view._person_paths[k].opts["pen"]
        assert pen.color().getRgb()[:3] == person_colour(k)
        x, _y = view._person_paths[k].getData()
        assert x is not None and len(x) > 1  # every person's path is drawn
    # selecting a person draws its path wider and shows its waypoints (person 3 is drawn)
    panel.person_list.setCurrentRow(3)
    assert model.selected_person == 3
    widths = [item.opts["pen"].widthF() for item in view._person_paths[:MAX_PERSONS]]
    assert widths[3] > max(w for k, w in enumerate(widths) if k != 3)
    assert len(view._waypoint_items) == 2
    # removing a person frees a slot; the paths follow
    panel.remove_button.click()
    window._scene_timer.stop()
    assert model.n_persons == MAX_PERSONS - 1 and panel.add_class_button.isEnabled()
    assert view._person_paths[MAX_PERSONS - 1].getData()[0] is None or (
        len(view._person_paths[MAX_PERSONS - 1].getData()[0]) == 0
    )


def test_study_data_set_of_a_two_person_scene_gives_finite_losses(tmp_path) -> None:
    """The GUI writes the scene on screen as the study's data set; on the shipped two-person
    scene every trial failed with a NaN loss. Person 0 is absent in some frames
    (NaN truth); the data set keeps every person and the loss is finite."""
    import json
    import math

    import numpy as np

    from core.dataset import Dataset
    from core.optimization.objective import TrackerLosses
    from core.tracking.space import defaults, tracker_params_dict

    path = engine.ROOT / "resources" / "scenes" / "two_persons.json"
    scene = engine.scene_from_document(json.loads(path.read_text()), path.parent)
    frames = list(engine.simulate(scene))
    ds = Dataset.load(engine.scene_dataset(frames, scene, tmp_path / "scene.npz"))
    assert ds.truth_xy_m.shape == (len(frames), 2, 2)
    assert np.isnan(ds.truth_xy_m).any()  # a person absent in some frames
    (score,) = TrackerLosses(ds).losses(tracker_params_dict(defaults("cv"), "cv"), [0])
    assert math.isfinite(score.loss) and score.loss > 0 and score.n_c > 0


def test_the_default_scene_is_the_paper_walk_with_a_walking_body() -> None:
    """Decision scene-07: the app starts with the paper's class-c walk, walked by the default
    person model; the scene file itself (no model: a point) is unchanged."""
    from core.scene.scene import DEFAULT_PERSON_MODEL

    doc = engine.paper_document()
    raw = json.loads(engine.PAPER_SCENE_FILE.read_text())
    assert [p["model"] for p in doc["persons"]] == [DEFAULT_PERSON_MODEL] == ["walking"]
    assert all("model" not in p for p in raw["persons"])
    assert [p["trajectory"] for p in doc["persons"]] == [p["trajectory"] for p in raw["persons"]]
    scene = engine.scene_from_document(doc, engine.PAPER_SCENE_FILE.parent)
    assert scene.persons[0].model == "walking"
