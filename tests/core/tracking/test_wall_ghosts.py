"""Predicted wall ghosts (the room tracker with known walls): the ghost geometry against numbers
derived by hand, and a constructed ghost group at a confirmed track's predicted ghost is not
confirmed while the same group away from it is; without walls nothing changes."""

import math

import numpy as np
import pytest

from core.errors import InputError
from core.scene.room import Room, Wall
from core.tracking.params import TrackerParams
from core.tracking.room import room_points, run_room_tracker
from core.tracking.zones import Zones
from core.walls import ghost_points, ghost_points_xy, wall_lines

T = 0.1
ROOM = TrackerParams(
    mode="room", static_velocity=0.02, body_sigma=0.3, body_velocity_sigma=0.5,
    alloc_points=5.0, alloc_snr=60.0, alloc_distance=0.6, alloc_velocity=0.6, ghost_gap=0.5,
    ghost_bearing=0.25, ghost_velocity=0.5, static_time=60.0, ghost_radius=0.5,
)  # fmt: skip
#: one wall along x = 3 m (beside the person)
SIDE_WALL = (3.0, 0.0, 3.0, 8.0)


def _ghosts(x, y, segments):
    lines = wall_lines(np.array(segments, dtype=float))
    out = np.zeros((3 * len(lines), 2))
    return out[: ghost_points_xy(x, y, lines, out)]


def test_ghost_points_of_one_wall_by_hand():
    # S = (3, 4), wall y = 6: image S' = (3, 8); |S| = 5, |S'| = √73; half path (5 + √73) / 2
    g = _ghosts(3.0, 4.0, [(-5.0, 6.0, 5.0, 6.0)])
    half = (5.0 + math.sqrt(73.0)) / 2
    np.testing.assert_allclose(g[0], (half * 0.6, half * 0.8), atol=1e-12)  # back from S
    np.testing.assert_allclose(
        g[1], (half * 3 / math.sqrt(73.0), half * 8 / math.sqrt(73.0)), atol=1e-12
    )  # back by the wall, along S'
    np.testing.assert_allclose(g[2], (3.0, 8.0), atol=1e-12)  # double bounce: S' itself
    # a person straight ahead of a wall behind: all three on the boresight, at 6, 6 and 8 m
    np.testing.assert_allclose(_ghosts(0.0, 4.0, [(-5.0, 6.0, 5.0, 6.0)]), [[0, 6], [0, 6], [0, 8]])
    # the side wall x = 3 and S = (1, 3): S' = (5, 3), half path (√10 + √34) / 2
    g = _ghosts(1.0, 3.0, [SIDE_WALL])
    half = (math.sqrt(10.0) + math.sqrt(34.0)) / 2
    np.testing.assert_allclose(g[1], np.array([5.0, 3.0]) * half / math.sqrt(34.0), atol=1e-12)


def test_ghost_points_with_height_by_hand():
    """A point 3 m below the radar at slant range 5 m straight ahead: ground range 4 m; in the
    wall y = 6 its image lies at ground range 8 m, slant √(64 + 9) = √73 m; the single bounce
    is seen at (5 + √73)/2, the double bounce at √73, all on the boresight."""
    lines = wall_lines(np.array([(-5.0, 6.0, 5.0, 6.0)]))
    out = np.zeros((3, 2))
    assert ghost_points(0.0, 5.0, -3.0, lines, out) == 3
    half = (5.0 + math.sqrt(73.0)) / 2
    np.testing.assert_allclose(out, [[0, half], [0, half], [0, math.sqrt(73.0)]], atol=1e-12)
    # off the boresight: S = (3, 4) in the tracker's frame at h = 1.5: S_g = (3, 4) ρ/5,
    # ρ = √(25 − 2.25); image (S_gx, 12 − S_gy); every point keeps its leg's bearing
    rho = math.sqrt(25.0 - 2.25)
    gx, gy = 3.0 * rho / 5.0, 4.0 * rho / 5.0
    ix, iy = gx, 12.0 - gy
    rs = math.sqrt(ix * ix + iy * iy + 2.25)
    half = (5.0 + rs) / 2
    u = np.array([ix, iy]) / math.hypot(ix, iy)
    assert ghost_points(3.0, 4.0, 1.5, lines, out) == 3
    np.testing.assert_allclose(out, [[0.6 * half, 0.8 * half], half * u, rs * u], atol=1e-12)
    # h = 0: the horizontal geometry, bit for bit
    rng = np.random.default_rng(0)
    a, b = np.zeros((3, 2)), np.zeros((3, 2))
    for x, y in rng.uniform(-4.0, 5.5, (50, 2)):
        assert ghost_points(x, y, 0.0, lines, a) == ghost_points_xy(x, y, lines, b)
        np.testing.assert_array_equal(a, b)


def test_no_ghost_where_the_bounce_is_not_specular():
    # the reflection point t S' (t = d_R / (d_R + d_S) = 6 / 8) of S = (3, 4) in y = 6 is
    # (2.25, 6): outside a wall from x = 2.5 to 5, inside one from 2 to 5
    assert len(_ghosts(3.0, 4.0, [(2.5, 6.0, 5.0, 6.0)])) == 0
    assert len(_ghosts(3.0, 4.0, [(2.0, 6.0, 5.0, 6.0)])) == 3
    # S behind the wall's line (the radar on the other side): no bounce
    assert len(_ghosts(0.0, 7.0, [(-5.0, 6.0, 5.0, 6.0)])) == 0


def test_room_wall_segments_leave_absorbers_out():
    room = Room(
        walls=(
            Wall(from_m=(-3.0, 0.0), to_m=(-3.0, 8.0)),
            Wall(from_m=(3.0, 0.0), to_m=(3.0, 8.0), reflection_db=-math.inf),
        )
    )
    assert room.wall_segments() == ((-3.0, 0.0, -3.0, 8.0),)
    with pytest.raises(InputError, match=r"walls\[0\]"):
        Zones(walls=((0.0, 1.0, 2.0),))


def cloud(cx, cy, *, n=8, vx=0.0, vy=0.0, snr=15.0, spread=0.1):
    a = 2 * np.pi * np.arange(n) / n
    x, y = cx + spread * np.cos(a), cy + spread * np.sin(a)
    r = np.hypot(x, y)
    return room_points(r, np.arctan2(x, y), (x * vx + y * vy) / r, x, y, np.ones(n),
                       np.full(n, snr))  # fmt: skip


def _person_and_wall_ghost(shift=(0.0, 0.0), n_f=40, start=5):
    """A person walking along y at x = 1 and, from frame ``start``, a weaker group at the
    person's predicted ghost back by the side wall (plus ``shift``), moving with the mirrored
    velocity (the same here: the wall is parallel to the walk)."""
    frames = []
    for f in range(n_f):
        px, py = 1.0, 2.0 + 0.5 * f * T
        person = cloud(px, py, vy=0.5, snr=20.0)
        if f < start:
            frames.append(person)
            continue
        gx, gy = _ghosts(px, py, [SIDE_WALL])[1] + np.asarray(shift)
        frames.append(np.vstack([person, cloud(gx, gy, n=6, vy=0.5, snr=12.0)]))
    return frames


@pytest.mark.parametrize("engine", ["numpy", "numba"])
def test_a_group_at_the_predicted_ghost_is_not_confirmed(engine):
    walls = Zones(walls=(SIDE_WALL,))
    frames = _person_and_wall_ghost()
    # the bearing rule alone does not catch it: ~1.0 rad from the person
    g = _ghosts(1.0, 2.5, [SIDE_WALL])[1]
    assert abs(math.atan2(g[0], g[1]) - math.atan2(1.0, 2.5)) > ROOM.ghost_bearing
    res = run_room_tracker(frames, ROOM, T, walls, engine=engine)
    assert res.n_tracks[8:].min() == 2  # both groups are tracked
    assert res.n_confirmed[2:].max() == 1
    last = res.frames[-1]
    ghost = np.argmax(last.state[:, 0])  # the group by the wall (x ≈ 2.5)
    assert last.ghost[ghost] and not last.confirmed[ghost]
    assert last.confirmed[1 - ghost] and not last.ghost[1 - ghost]
    # without walls it is confirmed and counted, and the run equals the one without the field
    bare = run_room_tracker(frames, ROOM, T, Zones(), engine=engine)
    assert bare.n_confirmed[-1] == 2
    none = run_room_tracker(frames, ROOM, T, None, engine=engine)
    np.testing.assert_array_equal(bare.n_confirmed, none.n_confirmed)
    np.testing.assert_array_equal(bare.estimate_xy, none.estimate_xy)
    # the same group 1.5 m nearer the radar (beyond r_ghost of every predicted point): counted
    away = run_room_tracker(_person_and_wall_ghost(shift=(0.0, -1.5)), ROOM, T, walls,
                            engine=engine)  # fmt: skip
    assert away.n_confirmed[-1] == 2
    # 0.3 m off the prediction: a ghost within r_ghost = 0.5 m, counted with r_ghost = 0.2 m
    off = _person_and_wall_ghost(shift=(0.0, 0.3))
    wide = run_room_tracker(off, ROOM, T, walls, engine=engine)
    narrow_params = TrackerParams.from_dict(ROOM.to_dict() | {"ghost_radius": 0.2})
    narrow = run_room_tracker(off, narrow_params, T, walls, engine=engine)
    assert wide.n_confirmed[-1] == 1 and narrow.n_confirmed[-1] == 2


def test_track_command_room_file(tmp_path, capsys):
    import json

    from core.cli import main
    from core.tracking.synthetic import circling_paths, room_dataset

    data = tmp_path / "room.npz"
    room_dataset(*circling_paths(1, 30), seed=2).save(data)
    room = tmp_path / "room.json"
    room.write_text(json.dumps({"walls": [{"from_m": [3.0, 0.0], "to_m": [3.0, 8.0]}]}))
    out = tmp_path / "t.json"
    args = ["track", "--data", str(data), "--room", str(room), "--out", str(out)]
    assert main([*args, "--mode", "room"]) == 0 and out.exists()
    out.unlink()
    capsys.readouterr()
    # the walls need the room mode; a bad room file is one line naming the field, exit 2
    assert main(args) == 2 and "--room needs the room mode" in capsys.readouterr().err
    room.write_text(json.dumps({"walls": [{"from_m": [3.0, 0.0], "to_m": [3.0]}]}))
    assert main([*args, "--mode", "room"]) == 2
    err = capsys.readouterr().err
    assert "room.json" in err and "walls[0].to_m" in err and not out.exists()


def _as_dataset(frames, scene: dict):
    """Room frames ((m, 7) :data:`core.tracking.groups.COLUMNS`) as a one-trajectory data set
    with the given scene JSON."""
    import json

    from core.dataset import Dataset
    from core.pointcloud import PointCloud

    clouds = [
        PointCloud(
            range_m=z[:, 0],
            azimuth_rad=z[:, 1],
            elevation_rad=np.arctan2(z[:, 5], z[:, 0]),
            radial_velocity_mps=z[:, 2],
            snr_db=z[:, 6],
            x_m=z[:, 3],
            y_m=z[:, 4],
            z_m=z[:, 5],
            source=np.zeros(len(z), dtype=np.int32),
        )  # fmt: skip
        for z in frames
    ]
    n_f = len(frames)
    return Dataset.from_frames(
        clouds=clouds, trajectory=np.zeros(n_f, dtype=np.int64), truth_t_s=np.arange(n_f) * T,
        truth_xy_m=np.zeros((n_f, 1, 2)), truth_v_mps=np.zeros((n_f, 1, 2)),
        trajectory_class=["drawn"], scene_json=json.dumps(scene),
        radar_json=json.dumps({"frame_period_s": T}),
    )  # fmt: skip


def test_a_data_set_simulated_in_a_room_gives_the_room_mode_its_walls():
    """The walls a data set's scene carries reach the room mode without ``--room``: the
    constructed wall ghost is not counted, as with the walls given, and is without them; walls
    given win; a scene without walls (a recording) or scenes in different rooms give none."""
    from core.tracking import track_dataset
    from core.walls import scene_walls

    room = Room(walls=(Wall(from_m=SIDE_WALL[:2], to_m=SIDE_WALL[2:]),))
    # as the room reads it: absorbers left out
    mixed = Room(walls=(*room.walls, Wall(from_m=(-3.0, 0.5), to_m=(-3.0, 9.0),
                                          reflection_db=-math.inf)))  # fmt: skip
    assert scene_walls(mixed.to_dict()) == mixed.wall_segments() == (SIDE_WALL,)
    frames = _person_and_wall_ghost()
    in_room = _as_dataset(frames, {"persons": []} | room.to_dict())
    recording = _as_dataset(frames, {"imported": {"format": "people-csv"}})
    assert scene_walls(in_room.scene()) == (SIDE_WALL,)
    assert scene_walls(recording.scene()) == ()

    def run(d, **kw):
        e = track_dataset(d, ROOM, **kw)
        return e.n_confirmed, e.estimate_xy

    auto = run(in_room)
    assert auto[0][2:].max() == 1  # the ghost group is not counted
    for a, b in zip(auto, run(recording, zones=Zones(walls=(SIDE_WALL,))), strict=True):
        np.testing.assert_array_equal(a, b)
    bare = run(recording)
    assert bare[0][-1] == 2  # a recording has no walls: the ghost group is counted
    for a, b in zip(run(in_room, walls_from_scene=False), bare, strict=True):
        np.testing.assert_array_equal(a, b)
    # walls given win over the scene's: a wall far away predicts no ghost here
    far = Zones(walls=((-6.0, 0.5, -6.0, 9.0),))
    for a, b in zip(run(in_room, zones=far), run(recording, zones=far), strict=True):
        np.testing.assert_array_equal(a, b)
    assert run(in_room, zones=far)[0][-1] == 2
    # scenes in different rooms give none; in the same room, its walls
    other = Room(walls=(Wall(from_m=(-3.0, 0.5), to_m=(-3.0, 9.0)),))
    assert scene_walls([room.to_dict(), other.to_dict()]) == ()
    assert scene_walls([room.to_dict(), room.to_dict()]) == (SIDE_WALL,)
    # a sensor mounted 2 m up: the scene's z are heights above the floor, the room mode takes
    # the sensor's height from the scene, as when it is given with the walls
    from core.scene.room import SensorPose
    from core.walls import scene_sensor_height

    high = Room(walls=room.walls, sensor=SensorPose(height_m=2.0))
    assert scene_sensor_height(high.to_dict()) == 2.0 and scene_sensor_height({}) == 0.0
    mounted = _as_dataset(frames, {"persons": []} | high.to_dict())
    given = Zones(walls=(SIDE_WALL,), sensor_height_m=2.0)
    for a, b in zip(run(mounted), run(recording, zones=given), strict=True):
        np.testing.assert_array_equal(a, b)
    with pytest.raises(InputError, match="sensor_height_m"):
        Zones(sensor_height_m=math.nan)
    # a damaged scene: one line naming the wall
    for bad in ({"walls": [{"from_m": [3.0, 0.0]}]}, {"walls": [{"from_m": [3, 0], "to_m": "x"}]}):
        with pytest.raises(InputError, match=r"scene 0: walls\[0\]"):
            scene_walls(bad)
