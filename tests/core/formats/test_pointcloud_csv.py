"""Point-cloud CSVs: the people-counting vendor CSV, the out-of-box CSV and a mapped CSV, read
from small files written here (values derived by hand) and from the shared real recordings
(skipped when ``../shared/real`` is absent)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from core.benchmarks.clouds import real_data_dir
from core.cli import main
from core.errors import InputError
from core.formats import pointcloud_csv as pc
from core.recordings import detect_format, read_recording

REAL = real_data_dir()
OOB_HEAD = "Frame #,# Obj,X,Y,Z,Doppler,,y,m,d,h,m,s\n"


def _oob_row(fn: int, nobj: int, x: float, y: float, inten: float, t: float) -> str:
    return f"{fn},{nobj},{x},{y},0.5,-0.25,{inten},2019,7,13,11,18,{t:.3f}\n"


def test_oob_csv_placeholders_gaps_restart_and_period(tmp_path: Path) -> None:
    """Frames 5,6 (two points), 7 a placeholder, 9 (8 lost: filled), then a restart at 1: a
    second run; the period is the longest run's time span over its frame span (0.1 s)."""
    rows = [
        _oob_row(5, 2, 1.0, 2.0, 100.0, 0.0),
        _oob_row(5, 2, 1.5, 2.0, 1000.0, 0.0),
        _oob_row(6, 1, 0.0, 3.0, 10.0, 0.1),
        "7,1,0,0,0,0,163,2019,7,13,11,18,0.200\n",
        _oob_row(9, 1, 0.0, 4.0, 10.0, 0.4),
        _oob_row(1, 1, 0.0, 1.0, 10.0, 5.0),
        _oob_row(2, 1, 0.0, 1.0, 10.0, 5.1),
    ]
    f = tmp_path / "walk.csv"
    f.write_text(OOB_HEAD + "".join(rows))
    assert detect_format(f).name == pc.OOB_CSV
    rec = read_recording(f, fmt=None, cfg=None)
    assert rec.counts.tolist() == [2, 1, 0, 0, 1, 1, 1]  # 5, 6, 7 (empty), 8 (filled), 9, 1, 2
    assert rec.trajectory.tolist() == [0, 0, 0, 0, 0, 1, 1]
    assert rec.radar.frame_period_s == pytest.approx(0.1)
    # host times; the filled frame 8 halfway between 7 and 9
    np.testing.assert_allclose(rec.t_s, [0.0, 0.1, 0.2, 0.3, 0.4, 5.0, 5.1], atol=1e-9)
    np.testing.assert_allclose(rec.cloud.snr_db[:3], [40.0, 60.0, 20.0])  # 20·log10(I)
    assert rec.cloud.range_m[0] == pytest.approx(math.sqrt(1 + 4 + 0.25))
    np.testing.assert_allclose(rec.cloud.radial_velocity_mps, -0.25)


def _v6(order_range_first: bool, el: float, az: float, r: float, v: float, snr: float) -> str:
    x = r * math.cos(el) * math.sin(az)
    y = r * math.cos(el) * math.cos(az)
    z = r * math.sin(el)
    a, b = (r, v) if order_range_first else (v, r)
    return f"{el},{az},{a},{b},{snr},{x},{y},{z}"


V7_HEADER = (
    "time,fN,type,posX,posY,posZ,velX,velY,velZ,accX,accY,accZ,"
    + ",".join(f"ec{i}" for i in range(16))
    + ",g,confi,tid\n"
)


def _v7(x: float, y: float, vx: float, vy: float, tid: int) -> str:
    return ",".join(map(str, [x, y, 0.1, vx, vy, 0, 0, 0, 0, *([0.0] * 16), 2.0, 0.9, tid]))


@pytest.mark.parametrize("range_first", [True, False])
def test_people_csv_orders_snr_tracks_and_indices(tmp_path: Path, range_first: bool) -> None:
    """Either column order is decided from the values (range matches |xyz|); a negative SNR is
    an unsigned count read as signed: -991.32 + 65536·0.04 = 1630.12; v7 rows become the
    reference tracks; the v8 row of frame f labels frame f-1's points."""
    t0 = "2023-06-21 12:27:01.000000"
    t1 = "2023-06-21 12:27:01.100000"
    t2 = "2023-06-21 12:27:01.200000"
    lines = [
        f"{t0},10,v6,{_v6(range_first, 0.1, -0.5, 2.0, 0.3, 5.52)}",
        f"{t0},10,v6,{_v6(range_first, 0.0, 0.2, 3.0, 0.0, -991.32)}",
        f"{t0},10,v7,{_v7(1.0, 2.0, 0.1, -0.2, 4)}",
        f"{t1},11,v6,{_v6(range_first, 0.0, 0.0, 1.0, -0.4, 10.0)}",
        f"{t1},11,v7,{_v7(1.1, 2.1, 0.1, -0.2, 4)}",
        f"{t1},11,v7,{_v7(-1.0, 3.0, 0.0, 0.0, 7)}",
        f'{t1},11,v8,"[4, 255]"',
        f'{t2},12,v8,"[7]"',
    ]
    f = tmp_path / "pc3.csv"
    f.write_text(V7_HEADER + "\n".join(lines) + "\n")
    assert detect_format(f).name == pc.PEOPLE_CSV
    rec = read_recording(f, fmt=None, cfg=None)
    assert rec.counts.tolist() == [2, 1, 0]
    np.testing.assert_allclose(rec.cloud.range_m, [2.0, 3.0, 1.0])
    np.testing.assert_allclose(rec.cloud.radial_velocity_mps, [0.3, 0.0, -0.4])
    np.testing.assert_allclose(
        rec.cloud.snr_db, 10 * np.log10([5.52, -991.32 + 65536 * 0.04, 10.0]), rtol=1e-9
    )
    assert rec.radar.frame_period_s == pytest.approx(0.1)
    ref = rec.ref_tracks
    assert ref is not None
    assert ref["frame"].tolist() == [0, 1, 1]
    assert ref["track_id"].tolist() == [4, 4, 7]
    np.testing.assert_allclose(ref["x_m"], [1.0, 1.1, -1.0])
    np.testing.assert_allclose(ref["vy_mps"], [-0.2, -0.2, 0.0])
    assert rec.ref_point_track is not None
    assert rec.ref_point_track.tolist() == [4, -1, 7]


def test_mapped_csv_through_the_cli(tmp_path: Path, capsys) -> None:
    f = tmp_path / "pts.csv"
    f.write_text(
        "t,frame,px,py,v,s\n0.0,1,1.0,2.0,0.5,12\n0.05,2,1.0,2.1,0.5,13\n0.1,3,1,2.2,0.5,9\n"
    )
    out = tmp_path / "ds.npz"
    code = main(
        [
            "import",
            str(f),
            "--columns",
            "frame=frame,x=px,y=py,doppler=v,snr=s,time=t",
            "--out",
            str(out),
        ]
    )
    assert code == 0
    from core.dataset import Dataset

    ds = Dataset.load(out)
    assert ds.n_frames == 3 and len(ds.frame) == 3
    np.testing.assert_allclose(ds.snr_db, [12, 13, 9])
    assert "frame period 50.0 ms" in capsys.readouterr().out
    assert main(["import", str(f), "--format", "csv", "--out", str(out)]) == 2
    assert "needs a column map" in capsys.readouterr().err
    code = main(["import", str(f), "--columns", "frame=frame,x=nope,y=py", "--out", str(out)])
    assert code == 2
    assert "x=nope: no such column" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("body", "where", "message"),
    [
        ("5,1,0,x,0,0,1,2019,7,13,11,18,1.0\n", ":2", "Y must be a number, got 'x'"),
        ("5,1,0,0,0,0,1,2019,7,13,11,18\n", ":2", "expected 13 fields"),
        ("5,1,0,1_0,0,0,1,2019,7,13,11,18,1.0\n", ":2", "Y must be a number, got '1_0'"),
        ("5,1,0,\u0661,0,0,1,2019,7,13,11,18,1.0\n", ":2", "ASCII text only"),
        (
            "5,1,0,1,0,0,1,2019,7,13,11,18,2.0\n6,1,0,1,0,0,1,2019,7,13,11,18,1.0\n",
            ":3",
            "goes backwards",
        ),
        ("", ":1", "header line and no data rows"),
        (
            "5,1,0,1,0,0,1,2019,7,13,11,18,2.0\n\n6,1,0,1,0,0,1,2019,7,13,11,18,1.0\n",
            ":4",
            "goes backwards",
        ),
        (
            "5,1,0,1,0,0,1,2019,7,13,11,18,1.0\n6,1,0,1,0,0,1,2019,7,13,11,18,1.0\n",
            "",
            "frame period of 0 s",
        ),
        ("5,1,0,1e999,0,0,1,2019,7,13,11,18,1.0\n", ":2", "Y must be finite"),
    ],
)
def test_bad_oob_csv_is_one_line(
    tmp_path: Path, capsys, body: str, where: str, message: str
) -> None:
    f = tmp_path / "bad.csv"
    f.write_text(OOB_HEAD + body)
    out = tmp_path / "ds.npz"
    assert main(["import", str(f), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and message in err and f"bad.csv{where}" in err
    assert not out.exists()


def test_people_csv_bad_time_and_frame(tmp_path: Path) -> None:
    f = tmp_path / "pc3.csv"
    f.write_text(V7_HEADER + f"yesterday,10,v6,{_v6(True, 0, 0, 1, 0, 5)}\n")
    with pytest.raises(InputError, match=r"pc3.csv:2: time must be a date"):
        read_recording(f, fmt=None, cfg=None)
    f.write_text(V7_HEADER + f"2023-06-21 12:27:01,1_0,v6,{_v6(True, 0, 0, 1, 0, 5)}\n")
    with pytest.raises(InputError, match=r"pc3.csv:2: fN must be an integer"):
        read_recording(f, fmt=None, cfg=None)


# ---- the shared real recordings ---------------------------------------------------------------
PC3 = REAL / "pc3_iwr6843"
MMGAIT = REAL / "mmgait_walkers"


@pytest.mark.skipif(not PC3.is_dir(), reason="../shared/real/pc3_iwr6843 absent")
def test_real_people_csv_files() -> None:
    """Counts of PROVENANCE.txt: the 2023 file 122 frames, 16 774 points, 125 TI track rows;
    the 2021 files put Doppler before range (decided from the values: range = |xyz|)."""
    rec = read_recording(PC3 / "pc3_2023-06-21-12-27-01.csv", fmt=None, cfg=None)
    assert rec.n_frames == 122 and len(rec.cloud) == 16774
    assert rec.ref_tracks is not None and len(rec.ref_tracks["track_id"]) == 125
    assert rec.radar.frame_period_s == pytest.approx(0.1, rel=0.05)
    assert np.all(rec.cloud.snr_db > 0)  # linear SNR above 1 once unsigned
    assert np.mean(rec.cloud.radial_velocity_mps == 0) == pytest.approx(0.79, abs=0.01)
    assert np.all(rec.ref_point_track >= -1)
    for name in ("pc3_2021-12-19-21-25-28.csv", "pc3Aop2021-04-07-23-52-34.csv"):
        rec = read_recording(PC3 / name, fmt=None, cfg=None)
        assert "Doppler before range" in rec.notes[0]
        assert np.all(rec.cloud.range_m > 0.1)


@pytest.mark.skipif(not MMGAIT.is_dir(), reason="../shared/real/mmgait_walkers absent")
@pytest.mark.parametrize(
    ("name", "runs"),
    [
        ("room2_1p_fixed_60GHz_002.csv", 3),
        ("room2_1p_fixed_60GHz_022.csv", 3),
        ("room2_1p_fixed_60GHz_076.csv", 2),
    ],
)
def test_real_oob_csv_files(name: str, runs: int) -> None:
    """PROVENANCE.txt: a flushed earlier run, a restart at 1, a jump of 10-22 s; about 10
    frames/s; 20-25 points a frame on the person (the walk's median frame in this band)."""
    rec = read_recording(MMGAIT / name, fmt=None, cfg=None)
    assert int(rec.trajectory[-1]) + 1 == runs
    assert rec.radar.frame_period_s == pytest.approx(0.1, rel=0.02)
    assert np.all(np.diff(rec.t_s) >= 0)
    last = rec.trajectory == rec.trajectory[-1]
    assert 18 <= np.median(rec.counts[last]) <= 30
