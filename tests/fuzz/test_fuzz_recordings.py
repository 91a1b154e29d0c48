"""Property-based fuzzing of the real-data readers: TI UART logs (every written point format,
mutated byte by byte and cut into random chunks) and Industrial Visualizer replays, through the
reader and through ``radartune import``. The reader may only yield frames or raise
:class:`InputError`; the CLI must give exit 0, or exit 2 with one line."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from core.config import PAPER_RADAR
from core.errors import InputError
from core.formats import ti_uart
from core.pointcloud import PointCloud
from tests.fuzz.conftest import FUZZ_SETTINGS
from tests.fuzz.harness import check, run_input
from tests.fuzz.test_fuzz_inputs import byte_mutations, tree_mutation

pytestmark = pytest.mark.fuzz


def _cloud(n: int, seed: int) -> PointCloud:
    rng = np.random.default_rng(seed)
    r, az = rng.uniform(0.5, 10, n), rng.uniform(-1, 1, n)
    x, y = r * np.sin(az), r * np.cos(az)
    z = np.zeros(n)
    return PointCloud(
        range_m=r,
        azimuth_rad=az,
        elevation_rad=z,
        radial_velocity_mps=rng.uniform(-2, 2, n),
        snr_db=rng.uniform(5, 30, n),
        x_m=x,
        y_m=y,
        z_m=z,
        source=np.zeros(n, dtype=np.int32),
    )


def valid_log(fmt: str) -> bytes:
    return b"".join(
        ti_uart.encode_frame(_cloud(n, k), 1 + k, fmt=fmt, radar=PAPER_RADAR)
        for k, n in enumerate((3, 0, 7, 2))
    )


LOGS = {fmt: valid_log(fmt) for fmt in ti_uart.WRITE_FORMATS}


@FUZZ_SETTINGS
@given(data=st.data(), fmt=st.sampled_from(sorted(LOGS)))
def test_mutated_uart_logs_reader(data, fmt: str) -> None:
    """Mutated logs fed in random chunk sizes: frames or one InputError, nothing else."""
    raw = data.draw(byte_mutations(LOGS[fmt]))
    size = data.draw(st.integers(1, 300))
    chunks = [raw[i : i + size] for i in range(0, len(raw), size)]
    report = ti_uart.UartReport()
    try:
        frames = list(ti_uart.iter_uart_frames(chunks, radar=PAPER_RADAR, report=report))
    except InputError as exc:
        assert "\n" not in str(exc)
        return
    assert report.n_frames == len(frames) >= 1
    for f in frames:
        assert len(f.points.x_m) == len(f.points.velocity_mps)


@FUZZ_SETTINGS
@given(data=st.data(), fmt=st.sampled_from(sorted(LOGS)), with_cfg=st.booleans())
def test_mutated_uart_logs_import(data, fmt: str, with_cfg: bool) -> None:
    raw = data.draw(byte_mutations(LOGS[fmt]))

    def write(folder: Path) -> list[str]:
        (folder / "log.dat").write_bytes(raw)
        argv = ["import", str(folder / "log.dat"), "--out", str(folder / "out" / "d.npz")]
        if with_cfg:
            from core.formats.ti_cfg import write_ti_cfg

            write_ti_cfg(PAPER_RADAR, folder / "r.cfg")
            argv += ["--cfg", str(folder / "r.cfg"), "--format", "uart"]
        return argv

    check(run_input(write, label="uart log"))


REPLAY = {
    "cfg": ["sensorStart"],
    "demo": "x",
    "device": "xWR6843",
    "data": [
        {
            "frameData": {
                "frameNum": k,
                "pointCloud": [[0.5, 2.0, 0.0, -0.3, 12.0, 1.0, 255]],
                "numDetectedPoints": 1,
            },
            "timestamp": 1.0 * k,
        }
        for k in range(1, 4)
    ],
}


@FUZZ_SETTINGS
@given(data=st.data(), bytes_level=st.booleans())
def test_mutated_replays_import(data, bytes_level: bool) -> None:
    if bytes_level:
        text = data.draw(byte_mutations(json.dumps(REPLAY).encode()))
    else:
        text = json.dumps(data.draw(tree_mutation(REPLAY))).encode()

    def write(folder: Path) -> list[str]:
        (folder / "replay_1.json").write_bytes(text)
        return [
            "import",
            str(folder / "replay_1.json"),
            "--format",
            "replay",
            "--out",
            str(folder / "out" / "d.npz"),
        ]

    check(run_input(write, label="replay"))


OOB_CSV = (
    b"Frame #,# Obj,X,Y,Z,Doppler,,y,m,d,h,m,s\n"
    b"5,2,1.0,2.0,0.5,-0.25,100,2019,7,13,11,18,0.000\n"
    b"5,2,1.5,2.0,0.5,-0.25,163,2019,7,13,11,18,0.000\n"
    b"6,1,0,0,0,0,163,2019,7,13,11,18,0.100\n"
    b"8,1,0.2,3.0,0.1,0.5,200,2019,7,13,11,18,0.300\n"
    b"1,1,0.2,3.1,0.1,0.5,210,2019,7,13,11,18,9.000\n"
)
PEOPLE_CSV = (
    "time,fN,type,posX,posY,posZ,velX,velY,velZ,accX,accY,accZ,"
    + ",".join(f"ec{i}" for i in range(16))
    + ",g,confi,tid\n"
    "2023-06-21 12:27:01.100000,10,v6,0.1,-0.5,2.0,0.3,-991.32,-0.95,1.73,0.2\n"
    "2023-06-21 12:27:01.100000,10,v7,1,2,0.1,0.1,-0.2,0,0,0,0,"
    + ",".join(["0"] * 16)
    + ",2,0.9,4\n"
    "2023-06-21 12:27:01.200000,11,v6,0.0,0.0,1.0,-0.4,10.0,0.0,1.0,0.0\n"
    '2023-06-21 12:27:01.200000,11,v8,"[4]"\n'
).encode()
TRUTH_CSV = b"time_s,person,x_m,y_m\n0,0,1,2\n0.1,0,1,2.1\n0.2,1,-1,3\n"
COUNT_CSV = b"t_start_s,t_end_s,people\n0,0.15,1\n0.2,10,0\n"


@FUZZ_SETTINGS
@given(data=st.data(), which=st.sampled_from(["oob", "people", "mapped"]))
def test_mutated_point_cloud_csvs_import(data, which: str) -> None:
    """The CSV readers on mutated files (detected, or forced by --format / --columns): exit 0,
    or exit 2 with one line."""
    raw = data.draw(byte_mutations(PEOPLE_CSV if which == "people" else OOB_CSV))

    def write(folder: Path) -> list[str]:
        (folder / "pc.csv").write_bytes(raw)
        argv = ["import", str(folder / "pc.csv"), "--out", str(folder / "out" / "d.npz")]
        if which == "mapped":
            argv += ["--columns", "frame=Frame #,x=X,y=Y,doppler=Doppler,time=s"]
        elif data.draw(st.booleans()):
            argv += ["--format", "people-csv" if which == "people" else "oob-csv"]
        return argv

    check(run_input(write, label=f"{which} csv"))


@FUZZ_SETTINGS
@given(data=st.data(), which=st.sampled_from(["truth", "count"]))
def test_mutated_truth_and_count_csvs_import(data, which: str) -> None:
    raw = data.draw(byte_mutations(TRUTH_CSV if which == "truth" else COUNT_CSV))

    def write(folder: Path) -> list[str]:
        (folder / "pc.csv").write_bytes(OOB_CSV)
        (folder / "t.csv").write_bytes(raw)
        flag = "--truth" if which == "truth" else "--people-csv"
        return ["import", str(folder / "pc.csv"), flag, str(folder / "t.csv"),
                "--out", str(folder / "out" / "d.npz")]  # fmt: skip

    check(run_input(write, label=f"{which} csv"))
