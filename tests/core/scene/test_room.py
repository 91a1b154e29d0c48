"""Rooms in scene files: walls, furniture and the sensor pose; bad rooms get one line naming the
field, exit 2 from the CLI; scenes without a room are unchanged."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from core.cli import main
from core.scene import Scene
from core.scene.room import DEFAULT_REFLECTION_DB, Room, SensorPose, Wall, parse_room
from tests.scenes import small_scene

BOX = [
    {"from_m": [-3.0, 0.0], "to_m": [3.0, 0.0], "reflection_db": -6.0},
    {"from_m": [3.0, 0.0], "to_m": [3.0, 8.0], "reflection_db": -6.0},
    {"from_m": [3.0, 8.0], "to_m": [-3.0, 8.0], "reflection_db": -3.0},
    {"from_m": [-3.0, 8.0], "to_m": [-3.0, 0.0]},
]


def room_scene(**room) -> dict:
    return {**small_scene(), **room}


def test_room_round_trip():
    d = room_scene(
        walls=BOX,
        sensor={"height_m": 2.0, "tilt_deg": 15.0},
        furniture=[
            {
                "x_m": 1.5,
                "y_m": 4.0,
                "width_m": 0.8,
                "depth_m": 0.6,
                "height_m": 0.75,
                "rcs_dbsm": 5.0,
            }
        ],
    )
    scene = Scene.from_dict(d)
    assert scene.room is not None
    # a wall without a loss gets the default, the loss fitted to a real recording (rooms-02)
    assert [w.reflection_db for w in scene.room.walls] == [-6.0, -6.0, -3.0, DEFAULT_REFLECTION_DB]
    assert DEFAULT_REFLECTION_DB == -33.0
    assert scene.room.sensor == SensorPose(height_m=2.0, tilt_deg=15.0)
    again = Scene.from_json_text(scene.to_json())
    assert again.room == scene.room
    assert not scene.is_planar


def test_scene_without_room_writes_no_room_keys():
    scene = Scene.from_dict(small_scene())
    assert scene.room is None
    assert not {"walls", "furniture", "sensor"} & set(scene.to_dict())


@pytest.mark.parametrize(
    ("room", "needle"),
    [
        ({"walls": [{"from_m": [1.0, 2.0], "to_m": [1.0, 2.0]}]}, "walls[0].from_m/to_m"),
        ({"walls": [{**BOX[0], "reflection_db": 1.5}]}, "walls[0].reflection_db"),
        ({"walls": [{"from_m": [0.0, 1.0]}]}, "walls[0]: missing key 'to_m'"),
        ({"walls": [{"from_m": [0.0, 1.0], "to_m": [2.0]}]}, "walls[0].to_m"),
        ({"walls": [{**BOX[0], "colour": "red"}]}, "walls[0]: unknown key"),
        (
            {
                "walls": [
                    {
                        **w,
                        "from_m": [w["from_m"][0], w["from_m"][1] + 1],
                        "to_m": [w["to_m"][0], w["to_m"][1] + 1],
                    }
                    for w in BOX
                ]
            },
            "sensor: the radar at (0, 0) lies outside",
        ),
        ({"sensor": {"height_m": -1.0}}, "sensor.height_m"),
        ({"sensor": {"tilt_deg": 120.0}}, "sensor.tilt_deg"),
        ({"furniture": [{"x_m": 1.0, "y_m": 2.0, "width_m": 0.0}]}, "furniture[0].width_m"),
        ({"furniture": [{"x_m": 1.0}]}, "furniture[0]: missing key 'y_m'"),
    ],
)
def test_bad_room_one_line_exit_2(tmp_path, capsys, room, needle):
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(room_scene(**room)))
    out = tmp_path / "out.npz"
    capsys.readouterr()
    code = main(["simulate", "--scene", str(path), "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2, err
    assert len(err.splitlines()) == 1, err
    assert needle in err and "scene.json" in err, err
    assert not out.exists()


def test_sensor_inside_rooms():
    # mounted on a wall, inside a closed room, in a corridor of two open walls
    parse_room({"walls": BOX})
    parse_room(
        {
            "walls": [
                {
                    **w,
                    "from_m": [w["from_m"][0], w["from_m"][1] - 1],
                    "to_m": [w["to_m"][0], w["to_m"][1] - 1],
                }
                for w in BOX
            ]
        }
    )
    parse_room(
        {
            "walls": [
                {"from_m": [-1.0, 0.0], "to_m": [-1.0, 20.0]},
                {"from_m": [1.0, 0.0], "to_m": [1.0, 20.0]},
            ]
        }
    )
    # open walls enclose nothing: a lone wall anywhere is a room
    parse_room({"walls": [{"from_m": [2.0, 1.0], "to_m": [4.0, 20.0]}]})


def test_absorbing_wall_is_null_in_json():
    room = parse_room(
        {"walls": [{"from_m": [-3.0, 0.0], "to_m": [-3.0, 8.0], "reflection_db": None}]}
    )
    assert room.walls[0].reflection_db == -math.inf
    assert room.to_dict()["walls"][0]["reflection_db"] is None


def test_absorbing_wall_reads_minus_infinity():
    room = parse_room(
        {"walls": [{"from_m": [-3.0, 0.0], "to_m": [-3.0, 8.0], "reflection_db": -math.inf}]}
    )
    assert room.walls[0].reflection == 0.0
    assert not room.has_multipath


def test_sensor_pose_transform_round_trip_and_boresight():
    pose = SensorPose(height_m=2.0, tilt_deg=15.0)
    t = math.radians(15.0)
    # a point straight along the tilted boresight, 4 m away, is on the sensor's +y axis
    room_pt = pose.position_m + 4.0 * np.array([0.0, math.cos(t), -math.sin(t)])
    sensor_pt, v = pose.to_sensor(room_pt[None], np.array([[0.0, 1.0, 0.0]]))
    np.testing.assert_allclose(sensor_pt, [[0.0, 4.0, 0.0]], atol=1e-12)
    # a horizontal velocity gets a component towards +z' of sin(t)
    np.testing.assert_allclose(v, [[0.0, math.cos(t), math.sin(t)]], atol=1e-12)
    pts = np.random.default_rng(1).normal(size=(20, 3))
    back = pose.to_room(pose.to_sensor(pts, pts)[0])
    np.testing.assert_allclose(back, pts, atol=1e-12)


def test_furniture_rcs_split_sums_to_the_piece():
    room = Room(walls=(Wall(from_m=(-3.0, 0.0), to_m=(3.0, 0.0)),))
    room = parse_room({"furniture": [{"x_m": 1.0, "y_m": 3.0, "rcs_dbsm": 5.0}]})
    pos, rcs = room.furniture_scatterers()
    assert pos.shape == (5, 3)
    assert 10 * np.log10(np.sum(10 ** (rcs / 10))) == pytest.approx(5.0)
    np.testing.assert_allclose(pos.mean(axis=0), [1.0, 3.0, 0.75])
