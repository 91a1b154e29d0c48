"""Camera / motion-capture truth aligned in time and pose, head counts over intervals, and the
truth CSV's bad inputs (each one line naming file, line and field)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from core.cli import main
from core.dataset import Dataset
from core.errors import InputError
from core.formats.recording import (
    TruthAlignment,
    align_truth,
    count_on_frames,
    read_count_csv,
    read_truth_csv,
)

OOB_HEAD = "Frame #,# Obj,X,Y,Z,Doppler,,y,m,d,h,m,s\n"


def test_pose_maps_room_positions_into_the_radar_frame() -> None:
    """A radar at (2, 1) m, 2 m high, looking along the room's +x (yaw 90°), tilted down 30°:
    a person 3 m in front at floor + 2 m (level with it) is at y = 3 cos 30°, z = -3 sin 30°...
    checked with the rotation written out by hand."""
    a = TruthAlignment(sensor_x_m=2.0, sensor_y_m=1.0, sensor_height_m=2.0, yaw_deg=90.0,
                       tilt_deg=30.0)  # fmt: skip
    # person at room (5, 1, 2): straight ahead along the bearing, level with the radar
    xyz = a.positions(np.array([5.0]), np.array([1.0]), np.array([2.0]))[0]
    t = math.radians(30)
    np.testing.assert_allclose(xyz, [0.0, 3 * math.cos(t), 3 * math.sin(t)], atol=1e-12)
    # a person 1 m to the radar's right (room -y when looking along +x), on the floor
    xyz = a.positions(np.array([5.0]), np.array([0.0]), np.array([0.0]))[0]
    np.testing.assert_allclose(
        xyz, [1.0, 3 * math.cos(t) + 2 * math.sin(t), 3 * math.sin(t) - 2 * math.cos(t)],
        atol=1e-12,
    )  # fmt: skip
    # distances are kept by the rotation
    pts = np.random.default_rng(1).uniform(-5, 5, (20, 3))
    out = a.positions(pts[:, 0], pts[:, 1], pts[:, 2])
    d_room = np.linalg.norm(pts - [2.0, 1.0, 2.0], axis=1)
    np.testing.assert_allclose(np.linalg.norm(out, axis=1), d_room)


def test_time_offset_and_drift() -> None:
    a = TruthAlignment(offset_s=-100.0, drift_ppm=1000.0)
    np.testing.assert_allclose(a.times(np.array([100.0, 200.0])), [0.1, 100.2])
    truth = np.array(
        [(100.0, 0, 1.0, 2.0, np.nan)],
        dtype=[("time_s", "f8"), ("person", "i4"), ("x_m", "f8"), ("y_m", "f8"), ("z_m", "f8")],
    )
    out = align_truth(truth, a)
    assert out["time_s"][0] == pytest.approx(0.1) and out["x_m"][0] == 1.0
    # a truth array without z_m (built by hand) aligns too
    flat = np.array([(100.0, 0, 1.0, 2.0)], dtype=[("time_s", "f8"), ("person", "i4"),
                    ("x_m", "f8"), ("y_m", "f8")])  # fmt: skip
    moved = align_truth(flat, TruthAlignment(offset_s=-100.0, sensor_x_m=1.0))
    assert moved["x_m"][0] == 0.0 and moved["time_s"][0] == 0.0


def _walk(tmp_path: Path) -> Path:
    """20 frames at 0.1 s, one point each at (0, 2 + 0.05 k)."""
    rows = [f"{k + 1},1,0,{2 + 0.05 * k:.3f},1.0,0.5,100,2019,7,13,11,18,{k * 0.1:.3f}\n"
            for k in range(20)]  # fmt: skip
    f = tmp_path / "walk.csv"
    f.write_text(OOB_HEAD + "".join(rows))
    return f


def test_import_with_aligned_truth_and_head_count(tmp_path: Path) -> None:
    """Camera clock 1000 s ahead, radar at room (1, 0) facing +y: the truth lands on the points
    after --truth-offset -1000 and --sensor-pose 1,0,0,0,0; the head count fills people_count
    on the frames of its interval and -1 elsewhere."""
    rec = _walk(tmp_path)
    truth = tmp_path / "cam.csv"
    rows = [f"{1000 + k * 0.1:.3f},0,1.0,{2 + 0.05 * k:.3f}" for k in range(20)]
    truth.write_text("time_s,person,x_m,y_m\n" + "\n".join(rows) + "\n")
    counts = tmp_path / "count.csv"
    counts.write_text("t_start_s,t_end_s,people\n1000.5,1001.0,1\n")
    out = tmp_path / "ds.npz"
    args = ["import", str(rec), "--truth", str(truth), "--truth-offset", "-1000", "--sensor-pose",
            "1,0,0,0,0", "--people-csv", str(counts), "--out", str(out)]  # fmt: skip
    code = main(args)
    assert code == 0
    ds = Dataset.load(out)
    np.testing.assert_allclose(ds.truth_xy_m[:, 0, 0], 0.0, atol=1e-9)
    np.testing.assert_allclose(ds.truth_xy_m[:, 0, 1], ds.y_m, atol=1e-6)
    assert ds.people_count.tolist() == [-1] * 5 + [1] * 5 + [-1] * 10
    # the same truth without the offset overlaps no frame: one line, nothing written
    out2 = tmp_path / "ds2.npz"
    assert main(["import", str(rec), "--truth", str(truth), "--out", str(out2)]) == 2
    assert not out2.exists()


def test_truth_that_overlaps_no_frame_is_one_line(tmp_path: Path, capsys) -> None:
    rec = _walk(tmp_path)
    truth = tmp_path / "t.csv"
    truth.write_text("time_s,person,x_m,y_m\n1000000000,0,1,2\n1000000001,0,1,2\n")
    out = tmp_path / "ds.npz"
    assert main(["import", str(rec), "--truth", str(truth), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "overlap none of the frames" in err
    assert not out.exists()


@pytest.mark.parametrize(
    ("body", "message"),
    [
        ("", r"t.csv:1: the truth CSV has a header line and no samples"),
        ("1_0,0,1,2\n", r"t.csv:2: time_s must be a number, got '1_0'"),
        ("0,0,1_0,2\n", r"t.csv:2: x_m must be a number, got '1_0'"),
        ("0,\u0661,1,2\n", r"t.csv:2: person must be a number"),
        ("0,0,\u0663,2\n", r"t.csv:2: x_m must be a number"),
        ("0,0,1,2\n0,1,1,2\n0,0,2,2\n", r"t.csv:4: time_s of person 0 must increase"),
        ("1,0,1,2\n0.5,0,1,2\n", r"t.csv:3: time_s of person 0 must increase: 0.5 s after 1 s"),
        ("0,0,1,2\n0,1,1,2\n", r"t.csv: all 2 samples have the same time_s 0 s"),
        ("0,0,-1e308,2\n", r"t.csv:2: x_m must be within ±1000 m, got -1e\+308"),
        ("0,0,1e999,2\n", r"t.csv:2: x_m must be finite"),
        ("0,0,inf,2\n", r"t.csv:2: x_m must be finite"),
        ("0,0,1,2,3\n", r"t.csv:2: expected 4 fields"),
    ],
)
def test_bad_truth_csv(tmp_path: Path, body: str, message: str) -> None:
    p = tmp_path / "t.csv"
    p.write_text("time_s,person,x_m,y_m\n" + body)
    with pytest.raises(InputError, match=message):
        read_truth_csv(p)


def test_truth_with_heights_and_count_csv_errors(tmp_path: Path) -> None:
    p = tmp_path / "t.csv"
    p.write_text("time_s,person,x_m,y_m,z_m\n0,0,1,2,1.2\n0.1,0,1,2.1,1.2\n")
    a = read_truth_csv(p)
    np.testing.assert_allclose(a["z_m"], 1.2)
    c = tmp_path / "c.csv"
    for text, message in (
        ("t_start_s,t_end_s,people\n", "header line and no rows"),
        ("t_start_s,t_end_s,people\n1,1,2\n", "c.csv:2: t_end_s must be after t_start_s"),
        ("t_start_s,t_end_s,people\n0,1,1.5\n", "c.csv:2: people must be an integer"),
        ("t_start_s,t_end_s,people\n0,2,1\n1,3,2\n", "c.csv:3: the interval overlaps"),
        ("start,end,n\n0,1,1\n", "c.csv:1: the first line must name"),
    ):
        c.write_text(text)
        with pytest.raises(InputError, match=message):
            read_count_csv(c)
    counts = np.array([[0.0, 0.25, 2.0], [0.3, 1.0, 0.0]])
    assert count_on_frames(counts, np.arange(5) * 0.1).tolist() == [2, 2, 2, 0, 0]


@pytest.mark.parametrize(
    ("body", "message"),
    [
        ("", "t.csv:1: the truth CSV has a header line and no samples"),
        ("1_0,0,1,2\n", "t.csv:2: time_s must be a number, got '1_0'"),
        ("0,\u0661,1,2\n", "t.csv:2: person must be a number"),
        ("0,0,1,2\n0,1,1,2\n", "t.csv: all 2 samples have the same time_s 0 s"),
        ("1,0,1,2\n0.5,0,1,2\n", "t.csv:3: time_s of person 0 must increase"),
        ("1000000000,0,1,2\n1000000001,0,1,2\n", "overlap none of the frames"),
        ("0,0,-1e308,2\n", "t.csv:2: x_m must be within ±1000 m"),
    ],
)
def test_bad_truth_through_the_cli(tmp_path: Path, capsys, body: str, message: str) -> None:
    """Each bad truth file of the bad-input campaign, through ``radartune import``: exit 2, one
    line naming the file (and line and field where there is one), no data set written."""
    rec = _walk(tmp_path)
    truth = tmp_path / "t.csv"
    truth.write_text("time_s,person,x_m,y_m\n" + body)
    out = tmp_path / "ds.npz"
    assert main(["import", str(rec), "--truth", str(truth), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and message in err and "t.csv" in err
    assert not out.exists()
