"""Tracks out (SPEC §7): every live track of every frame as a CSV, for any data set."""

import csv
import io
import json

import numpy as np
import pytest

from core.cli import main
from core.formats.tracks_csv import TRACKS_HEADER, format_tracks_csv, track_rows
from core.tracking import TrackerParams, track_dataset
from core.tracking.synthetic import synthetic_dataset

HEADER = "frame,time_s,track_id,status,x_m,y_m,z_m,vx_mps,vy_mps,existence,n_points"


@pytest.fixture(scope="module")
def run():
    ds = synthetic_dataset(3, 1, classes="abc", n_frames=120)
    est = track_dataset(ds, TrackerParams.default("cv"), with_tracks=True)
    return ds, est


def _read(text: str) -> list[dict]:
    return list(csv.DictReader(io.StringIO(text)))


def test_header_and_rows_follow_the_tracker(run) -> None:
    ds, est = run
    text = format_tracks_csv(track_rows(ds, est))
    assert text.splitlines()[0] == HEADER == ",".join(TRACKS_HEADER)
    rows = _read(text)
    # one row per live track and frame; the confirmed ones are the tracker's confirmed count
    assert len(rows) == int(est.n_tracks.sum())
    frames = np.array([int(r["frame"]) for r in rows])
    conf = np.array([r["status"] == "confirmed" for r in rows])
    assert set(r["status"] for r in rows) <= {"confirmed", "tentative"}
    f_sel = est.frame_index
    np.testing.assert_array_equal(np.bincount(frames, minlength=ds.n_frames)[f_sel], est.n_tracks)
    np.testing.assert_array_equal(
        np.bincount(frames[conf], minlength=ds.n_frames)[f_sel], est.n_confirmed
    )
    # frame times are the data set's; z is empty (the tracker has no height)
    for r in rows[:50]:
        assert float(r["time_s"]) == pytest.approx(ds.truth_t_s[int(r["frame"])], abs=1e-4)
        assert r["z_m"] == ""
        assert 0.0 <= float(r["existence"]) <= 1.0 and int(r["n_points"]) >= 0


def test_confirmed_tracks_sit_on_the_person(run) -> None:
    ds, est = run
    r = track_rows(ds, est)
    # the single-person estimate is the confirmed track of highest existence: its row is there
    best = {}
    for i in np.flatnonzero(r.confirmed):
        f = int(r.frame[i])
        if f not in best or r.existence[i] > r.existence[best[f]]:
            best[f] = i
    rows = np.array(list(best.values()))
    est_xy = est.estimate_xy[np.searchsorted(est.frame_index, r.frame[rows])]
    np.testing.assert_allclose(r.state[rows, :2], est_xy, atol=5e-5)
    err = np.linalg.norm(r.state[rows, :2] - ds.truth_xy_m[r.frame[rows], 0], axis=1)
    assert np.median(err) < 0.5  # the tracker follows the synthetic walker


def test_ids_unique_over_runs_and_engines_agree(run) -> None:
    ds, est = run
    r = track_rows(ds, est)
    run_of = ds.trajectory[r.frame]
    # every run's ids come after those of the runs before it
    for k in range(1, ds.n_trajectories):
        assert r.track_id[run_of == k].min() > r.track_id[run_of < k].max()
    slow = track_rows(ds, track_dataset(ds, TrackerParams.default("cv"), with_tracks=True,
                                        engine="numpy"))  # fmt: skip
    np.testing.assert_array_equal(slow.track_id, r.track_id)
    np.testing.assert_array_equal(slow.confirmed, r.confirmed)
    np.testing.assert_array_equal(slow.n_points, r.n_points)
    np.testing.assert_allclose(slow.state, r.state, atol=1e-9)


def test_cli_writes_tracks_and_per_frame_counts(tmp_path, capsys) -> None:
    data = synthetic_dataset(0, 1, classes="ab", n_frames=80).save(tmp_path / "d.npz")
    tracks, out = tmp_path / "t.csv", tmp_path / "r.json"
    args = ["track", "--data", str(data), "--tracks", str(tracks), "--out", str(out)]
    assert main(args) == 0
    rows = _read(tracks.read_text())
    doc = json.loads(out.read_text())
    per = doc["per_frame"]
    assert len(per["frame"]) == len(per["confirmed"]) == len(per["tentative"])
    assert sum(per["confirmed"]) + sum(per["tentative"]) == len(rows)
    assert sum(per["confirmed"]) == sum(r["status"] == "confirmed" for r in rows)
    assert doc["without_positions"]["head_count"] == "truth"


def test_cli_bad_tracks_path_is_one_line_and_writes_nothing(tmp_path, capsys) -> None:
    data = synthetic_dataset(0, 1, classes="a", n_frames=60).save(tmp_path / "d.npz")
    folder = tmp_path / "sub"
    folder.mkdir()
    out = tmp_path / "r.json"
    code = main(["track", "--data", str(data), "--tracks", str(folder), "--out", str(out)])
    assert code == 2
    err = capsys.readouterr().err
    assert "--tracks" in err and err.count("\n") == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.npz", "sub"]


def test_room_mode_writes_each_track_height_where_points_carry_elevation() -> None:
    """z_m is the room tracker's height (the mean z of a track's latest group): points all at
    1.25 m give 1.2500 on every row; points without elevation (z = 0 everywhere) and the paper
    mode leave the column empty."""
    from dataclasses import replace

    from core.tracking.synthetic import circling_paths, room_dataset

    ds = room_dataset(*circling_paths(1, 60), seed=2)
    room = TrackerParams.default("cv", mode="room")
    raised = replace(ds, z_m=np.full_like(ds.z_m, 1.25))
    rows = _read(
        format_tracks_csv(track_rows(raised, track_dataset(raised, room, with_tracks=True)))
    )
    assert len(rows) > 0 and {r["z_m"] for r in rows} == {"1.2500"}
    flat = replace(ds, z_m=np.zeros_like(ds.z_m))
    rows = _read(format_tracks_csv(track_rows(flat, track_dataset(flat, room, with_tracks=True))))
    assert len(rows) > 0 and {r["z_m"] for r in rows} == {""}
    paper = track_dataset(raised, TrackerParams.default("cv"), with_tracks=True)
    rows = _read(format_tracks_csv(track_rows(raised, paper)))
    assert len(rows) > 0 and {r["z_m"] for r in rows} == {""}
