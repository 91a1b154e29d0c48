"""Room scenes in the app: the walls and furniture drawn, stop waypoints edited."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from app.engine.scenes import room_outline, scene_info
from core.scene import Scene

SCENES = Path(__file__).parents[2] / "resources" / "scenes"


def test_room_outline_has_every_wall_and_furniture_footprint() -> None:
    scene = Scene.from_json(SCENES / "room_office.json")
    xy = room_outline(scene.room)
    pieces = np.split(xy, np.flatnonzero(np.isnan(xy[:, 0])))
    pieces = [p[~np.isnan(p[:, 0])] for p in pieces if np.any(~np.isnan(p[:, 0]))]
    assert len(pieces) == len(scene.room.walls) + len(scene.room.furniture)
    for wall, piece in zip(scene.room.walls, pieces):
        assert np.array_equal(piece, [wall.from_m, wall.to_m])
    for f, piece in zip(scene.room.furniture, pieces[len(scene.room.walls) :]):
        # a closed rectangle of the footprint's width and depth around its centre
        assert np.array_equal(piece[0], piece[-1]) and len(piece) == 5
        assert np.ptp(piece[:, 0]) == pytest.approx(f.width_m, abs=1e-12)
        assert np.ptp(piece[:, 1]) == pytest.approx(f.depth_m, abs=1e-12)
        assert np.allclose(piece[:4].mean(axis=0), [f.x_m, f.y_m])
    assert scene_info(scene).room_outline_xy_m.shape == xy.shape
    # the open field has none
    assert room_outline(None).shape == (0, 2)


def test_stop_waypoints_show_and_edit_with_their_hold(qtbot) -> None:
    from app.panels.scene_panel import XYTable
    from app.views.top_view import TopView

    view = TopView()
    qtbot.addWidget(view)
    rows = [[2.0, 4.7, 0.0, 25.0], [2.1, 4.6, 0.3]]
    view.set_waypoints(rows)  # a stop row has four numbers: it once failed to unpack
    assert [(i.pos().x(), i.pos().y()) for i in view._waypoint_items] == [(2.0, 4.7), (2.1, 4.6)]
    table = XYTable(["x", "y", "speed", "hold"], "t", n_optional=1)
    qtbot.addWidget(table)
    table.set_rows(rows)
    assert table.rows() == rows  # the blank hold cell ends the row: a plain waypoint again


def test_seated_stop_shows_and_keeps_its_posture_on_a_drag(qtbot) -> None:
    from app.views.top_view import TopView

    view = TopView()
    qtbot.addWidget(view)
    scene = Scene.from_json(SCENES / "room_office.json")
    rows = scene.to_dict()["persons"][0]["trajectory"]["waypoints"]
    assert rows[0][4] == "sit"  # the person at the desk sits
    view.set_waypoints(rows)  # a "sit" row once failed: float("sit")
    assert [(i.pos().x(), i.pos().y()) for i in view._waypoint_items] == [(2.0, 4.7), (2.1, 4.6)]
    got = []
    view.waypoints_moved.connect(got.append)
    view._waypoint_items[0].setPos(2.2, 4.8)
    view._on_waypoint_dragged()
    assert got == [[[2.2, 4.8, 0.0, 25.0, "sit"], [2.1, 4.6, 0.3]]]
