"""The people table shows the run's several-person metrics as core computes them."""

from __future__ import annotations

import json

import numpy as np

from app import engine
from app.views.people_table import PeopleTable, frame_line, people_rows
from core.evaluation.people import people_run
from core.tracking import TrackerParams, run_tracker
from core.tracking.batch import ConfirmedTracks


def test_people_table_of_the_two_person_scene(qtbot) -> None:
    path = engine.ROOT / "resources" / "scenes" / "two_persons.json"
    scene = engine.scene_from_document(json.loads(path.read_text()), path.parent)
    frames = list(engine.simulate(scene))
    params = TrackerParams.default("cv")
    result = engine.track(frames, params, scene.radar.frame_period_s, key="k")
    people = result.people
    assert people is not None and len(people.persons) == 2
    # the engine's metrics are core's people_run on the same tracker run
    counts = np.array([len(f.cloud) for f in frames])
    z = np.concatenate([f.cloud.measurements() for f in frames])
    off = np.concatenate(([0], np.cumsum(counts)))
    res = run_tracker((z, off), params, scene.radar.frame_period_s, keep_tracks=True)
    truth = np.stack([f.truth_xy_m for f in frames])
    again = people_run(truth, ConfirmedTracks.from_frames(res.frames))
    np.testing.assert_allclose(people.frames.gospa_m, again.frames.gospa_m, atol=1e-9)
    assert [m.frames_present for m in people.persons] == [
        int(np.isfinite(truth[:, j]).all(axis=1).sum()) for j in range(2)
    ]
    # the widget shows one row per person with those numbers, and the frame's GOSPA
    table = PeopleTable()
    qtbot.addWidget(table)
    table.show_people(people, 10)
    assert table.table.rowCount() == 2
    rows = people_rows(people)
    for r in range(2):
        assert [table.table.item(r, c).text() for c in range(len(rows[r]))] == rows[r]
        assert rows[r][3] == str(people.persons[r].frames_present)
    assert f"GOSPA {people.frames.gospa_m[10]:.3f} m" in table.frame_label.text()
    assert table.frame_label.text() == frame_line(people, 10)


def test_people_table_without_persons_is_empty(qtbot) -> None:
    table = PeopleTable()
    qtbot.addWidget(table)
    table.show_people(None, 0)
    assert table.table.rowCount() == 0 and "GOSPA –" in table.frame_label.text()
