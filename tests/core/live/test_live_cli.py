"""``radartune live`` against the sensor emulator: status lines, the record, the tracks CSV,
one line and exit 2 for each fault, sensorStop on --frames and on Ctrl-C."""

from __future__ import annotations

import csv
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from core.cli import main
from core.live.emulator import Faults, SensorEmulator

FAST = 0.004
HEADER = "frame,time_s,track_id,status,x_m,y_m,z_m,vx_mps,vy_mps,existence,n_points"


def live_args(em, cfg, *extra):
    return ["live", "--cli-port", em.cli_port, "--data-port", em.data_port, "--cfg", str(cfg)] + [
        str(x) for x in extra
    ]


def test_frames_n_tracks_records_and_stops(capture, tmp_path, capsys) -> None:
    data, cfg = capture
    rec, tracks = tmp_path / "rec.dat", tmp_path / "tracks.csv"
    with SensorEmulator(data, faults=Faults(frame_period_s=FAST)) as em:
        code = main(live_args(em, cfg, "--record", rec, "--tracks", tracks, "--frames", 40))
        assert em.commands[-1] == "sensorStop" and em.stopped.is_set()
        sent = bytes(em.sent)
    out = capsys.readouterr().out.splitlines()
    assert code == 0
    status = [ln for ln in out if ln.startswith("frame ")]
    assert len(status) == 40
    assert status[0].startswith("frame 0 (no. 1) t=0.00 s: 3 points")
    assert "1 confirmed: #" in status[-1]
    assert out[-1] == (
        "40 frames tracked, 0 dropped (frame-number gaps), 0 damaged packets skipped, 0 bytes "
        f"outside packets; recorded {rec.stat().st_size} bytes to {rec}; tracks written to {tracks}"
    )
    # what arrived is recorded: the first 40 packets at least, all a prefix of what was sent
    assert (
        rec.read_bytes() == sent[: rec.stat().st_size]
        and rec.stat().st_size >= 40 * len(data) // 60
    )
    rows = list(csv.DictReader(tracks.open()))
    assert tracks.read_text().splitlines()[0] == HEADER
    assert {int(r["frame"]) for r in rows} <= set(range(40))
    assert max(int(r["frame"]) for r in rows) == 39
    last = [r for r in rows if r["frame"] == "39" and r["status"] == "confirmed"]
    assert last and float(last[0]["time_s"]) == pytest.approx(39 * 0.05)


@pytest.mark.parametrize(
    ("faults", "expected"),
    [
        (Faults(error_on="chirpCfg"), "the sensor rejected 'chirpCfg 0 0 0 0 0 0 0 1': Error -1"),
        (Faults(frame_period_s=FAST, vanish_after=12), "the data port vanished after"),
    ],
    ids=["error-answer", "port-closed"],
)
def test_faults_are_one_line_and_exit_2(capture, tmp_path, capsys, faults, expected) -> None:
    data, cfg = capture
    rec, tracks = tmp_path / "rec.dat", tmp_path / "tracks.csv"
    with SensorEmulator(data, faults=faults) as em:
        code = main(live_args(em, cfg, "--record", rec, "--tracks", tracks, "--quiet"))
        sent = bytes(em.sent)
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len([ln for ln in err if ln.startswith("radartune live: error:")]) == 1
    line = next(ln for ln in err if ln.startswith("radartune live: error:"))
    assert expected in line
    if faults.vanish_after:
        assert "12 frames" in line and f"{rec} keeps the {len(sent)} bytes" in line
        assert rec.read_bytes() == sent
        assert line.endswith(f"; {tracks} holds the tracks of the 12 frames")
        frames = {int(r["frame"]) for r in csv.DictReader(tracks.open())}
        assert max(frames) == 11
    else:
        assert not rec.exists() and not tracks.exists()


def test_bad_cfg_is_one_line_before_any_port(tmp_path, capsys) -> None:
    cfg = tmp_path / "bad.cfg"
    cfg.write_text("sensorStop\nframeCfg 0 2 32 0 abc 1 0\n")
    code = main(["live", "--cli-port", "/dev/null", "--data-port", "/dev/zero", "--cfg", str(cfg)])
    assert code == 2
    assert "bad.cfg" in capsys.readouterr().err


def test_a_missing_port_is_one_line(capture, capsys) -> None:
    _, cfg = capture
    code = main(
        ["live", "--cli-port", "/dev/nonexistent-tty", "--data-port", "/dev/x", "--cfg", str(cfg)]
    )
    err = capsys.readouterr().err.strip()
    assert code == 2 and "\n" not in err
    assert err.startswith("radartune live: error: /dev/nonexistent-tty: cannot open the CLI port")


def test_ctrl_c_sends_sensor_stop_and_keeps_the_record(capture, tmp_path) -> None:
    data, cfg = capture
    rec = tmp_path / "rec.dat"
    with SensorEmulator(data, faults=Faults(frame_period_s=0.02), loop=True) as em:
        proc = subprocess.Popen(
            [sys.executable, "-m", "core.cli", *live_args(em, cfg, "--record", rec)],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            cwd=Path(__file__).parents[3],
            env={**os.environ, "PYTHONUNBUFFERED": "1"},
        )
        n = 0
        deadline = time.monotonic() + 60
        while n < 5 and time.monotonic() < deadline:
            if proc.stdout.readline().startswith("frame "):
                n += 1
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=30)
        assert proc.returncode == 130
        assert err.strip().splitlines()[-1] == "radartune live: interrupted"
        assert em.commands[-1] == "sensorStop" and em.stopped.is_set()
        sent = bytes(em.sent)
    got = rec.read_bytes()
    assert len(got) >= 5 * len(data) // 60 and sent.startswith(got)
