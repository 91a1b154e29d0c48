"""bench trackers: ghost tracks on constructed frames, the scores of each tracker kind, the room
the transfer bench walks the paper's trajectories in, and the quick run end to end."""

import json
from types import SimpleNamespace

import numpy as np
import pytest

from core.benchmarks import trackers, transfer
from core.tracking.synthetic import synthetic_dataset


def test_ghost_tracks_on_constructed_frames() -> None:
    # frame 0: a direct point at (0, 3), a wall-bounce point at (2, 5);
    # frame 1: one direct point at (1, 4)
    ds = SimpleNamespace(
        x_m=np.array([0.0, 2.0, 1.0]),
        y_m=np.array([3.0, 5.0, 4.0]),
        path_order=np.array([0, 1, 0], dtype=np.int8),
        frame_offsets=np.array([0, 2, 3]),
    )
    nan = np.nan
    xy = np.array(
        [
            # the person's track; a false track 0.1 m from the bounce; a false track far away
            [[0.0, 3.1], [2.1, 5.0], [6.0, 6.0]],
            # a false track on the direct point: no ghost
            [[1.0, 4.2], [nan, nan], [nan, nan]],
        ]
    )
    est = SimpleNamespace(frame_index=np.array([0, 1]), tracks=SimpleNamespace(xy=xy))
    fm = SimpleNamespace(gospa_track=np.array([[0], [-1]]))
    np.testing.assert_array_equal(trackers.ghost_tracks(ds, est, fm), [1, 0])
    # the far track is no ghost however large the radius, as long as its nearest point is direct
    np.testing.assert_array_equal(trackers.ghost_tracks(ds, est, fm, radius_m=0.05), [0, 0])
    no_paths = SimpleNamespace(**{**vars(ds), "path_order": None})
    np.testing.assert_array_equal(trackers.ghost_tracks(no_paths, est, fm), [0, 0])


def test_sim_scores_of_a_walker_with_truth() -> None:
    ds = synthetic_dataset(3, 1, classes="a", n_frames=120)
    est = trackers.run_tracker("paper", trackers.default_params("paper"), ds)
    s = trackers.sim_scores(ds, est)
    assert set(s) == set(trackers.SIM_FIGURES)
    assert 0.8 < s["right_count"] <= 1.0
    assert s["gospa_m"] < 1.0
    assert min(s["localisation_m2"], s["missed_m2"], s["false_m2"]) >= 0.0
    assert s["ghost_tracks_per_frame"] == 0.0  # no path_order: nothing came over a wall
    assert s["ghost_tracks_per_frame"] <= s["false_tracks_per_frame"]


@pytest.mark.parametrize("kind", ["paper", "room", "gtrack"])
def test_recording_scores_of_each_kind(kind, walker_and_reference) -> None:
    walker, reference = walker_and_reference("a")
    s = trackers.rec_scores(walker, reference, kind, trackers.default_params(kind))
    assert set(s) == set(trackers.REC_FIGURES)
    assert 0.0 <= s["walker_right_count"] <= 1.0
    assert 0.0 <= s["pc3_same_count"] <= 1.0
    # GOSPA (c = 2 m, p = 2) of one reference position against nothing is sqrt(2) m at most
    assert 0.0 <= s["pc3_gospa_m"] <= np.sqrt(2.0) + 1e-9
    if kind == "paper":  # one point a person: the paper's tracker follows the walker
        assert s["walker_right_count"] > 0.8 and s["pc3_gospa_m"] < 0.6


def test_the_hall_holds_every_paper_trajectory() -> None:
    from core.scene import paper_scenes
    from core.scene.room import inside_walls, parse_room

    room = parse_room(transfer.HALL)
    for scene in paper_scenes(0, 35):
        xy = scene.persons[0].trajectory.position_m[:, :2]
        assert np.all(inside_walls(room.walls, xy)), scene


@pytest.mark.slow
def test_quick_run(tmp_path, monkeypatch) -> None:
    monkeypatch.setenv("RADARTUNE_REAL", str(tmp_path / "none"))
    monkeypatch.delenv("RADARTUNE_REAL_DATA", raising=False)
    monkeypatch.chdir(tmp_path)
    r = trackers.run(quick=True)
    json.dumps(r)
    assert r["recordings"] == {} and "no part (b)" in r["notes"][0]
    assert list(r["simulated_rooms"]) == [name for name, _, _ in trackers.TRACKERS]
    for name, _kind, source in trackers.TRACKERS:
        row = r["simulated_rooms"][name]
        assert len(row["per_study"]) == (len(r["study_seeds"]) if source == "tuned" else 1)
        for per_set in row["per_study"]:
            for s in per_set:
                assert 0.0 <= s["right_count"] <= 1.0
                assert s["ghost_tracks_per_frame"] <= s["false_tracks_per_frame"]
                assert 0.0 <= s["gospa_m"] <= 2.0 * 3  # c = 2 m, at most three people a scene
    assert (tmp_path / r["plot"]).is_file()
    assert "IPDA tuned" in trackers.summary(r)
