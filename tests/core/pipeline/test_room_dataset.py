"""`radartune dataset --room`: the paper's trajectories in a room, keyed apart in the cache."""

from __future__ import annotations

import json

import numpy as np

from core.cli import main
from core.pipeline.cache import dataset_key, in_room
from core.scene import paper_scenes
from core.scene.room import Room

WALLS = [
    {"from_m": [-9.0, 0.0], "to_m": [9.0, 0.0]},
    {"from_m": [9.0, 0.0], "to_m": [9.0, 10.5]},
    {"from_m": [9.0, 10.5], "to_m": [-9.0, 10.5]},
    {"from_m": [-9.0, 10.5], "to_m": [-9.0, 0.0]},
]


def test_room_changes_the_cache_key_not_the_trajectories(tmp_path):
    path = tmp_path / "room.json"
    path.write_text(json.dumps({"walls": WALLS, "sensor": {"height_m": 2.0, "tilt_deg": 10}}))
    room = Room.from_json(path)
    scenes = paper_scenes(0, 3)
    roomed = in_room(scenes, room)
    assert in_room(scenes, None) is scenes
    assert all(s.room == room for s in roomed)
    for a, b in zip(scenes, roomed):
        np.testing.assert_array_equal(
            a.persons[0].trajectory.position_m, b.persons[0].trajectory.position_m
        )
        assert a.seed == b.seed
    assert dataset_key(scenes, fidelity="exact", seed=0) != dataset_key(
        roomed, fidelity="exact", seed=0
    )


def test_dataset_in_a_room_has_path_orders(tmp_path, capsys):
    path = tmp_path / "room.json"
    # the absorbing far wall: null in JSON
    walls = [dict(w) for w in WALLS]
    walls[2]["reflection_db"] = None
    path.write_text(json.dumps({"walls": walls}))
    out = tmp_path / "ds.npz"
    code = main(
        [
            "dataset",
            "--out",
            str(out),
            "--trajectories",
            "1",
            "--room",
            str(path),
            "--person-model",
            "point",
            "--no-cache",
            "--jobs",
            "1",
        ]
    )
    assert code == 0
    text = capsys.readouterr().out
    assert "from wall bounces" in text and "0.0 % of the persons' positions lie outside" in text
    from core.dataset import Dataset

    ds = Dataset.load(out)
    assert ds.path_order is not None and set(np.unique(ds.path_order)) <= {-1, 0, 1, 2}


def test_bad_room_file_one_line_exit_2(tmp_path, capsys):
    path = tmp_path / "room.json"
    path.write_text(json.dumps({"walls": [{**WALLS[0], "reflection_db": 3.0}]}))
    out = tmp_path / "ds.npz"
    capsys.readouterr()
    code = main(["dataset", "--out", str(out), "--trajectories", "1", "--room", str(path)])
    err = capsys.readouterr().err
    assert code == 2 and len(err.splitlines()) == 1, err
    assert "room.json" in err and "walls[0].reflection_db" in err
    assert not out.exists()
    path.write_text(json.dumps({"doors": []}))
    code = main(["dataset", "--out", str(out), "--trajectories", "1", "--room", str(path)])
    err = capsys.readouterr().err
    assert code == 2 and "unknown key" in err and len(err.splitlines()) == 1
