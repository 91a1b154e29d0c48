"""``radartune bench gui --soak SECONDS``: bad values are one line and exit 2 before anything
runs or is written; the soak's summary line carries its figures. (The soak itself starts the
window and streams for as long as asked: a benchmark, never run in the suite.)"""

from __future__ import annotations

from core.benchmarks import gui
from core.cli import main


def test_soak_refused_for_other_benchmarks_and_bad_seconds(tmp_path, capsys) -> None:
    out = tmp_path / "out"
    for argv in (
        ["bench", "track", "--soak", "5"],
        ["bench", "gui", "--soak", "0"],
        ["bench", "gui", "--soak", "-3"],
        ["bench", "gui", "--soak", "nan"],
        ["bench", "gui", "--soak", "inf"],
    ):
        assert main([*argv, "--out-dir", str(out)]) == 2, argv
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "--soak" in err[0], (argv, err)
    assert not out.exists()  # refused before the output folder is made


def test_soak_summary_names_its_figures() -> None:
    soak = {
        "seconds": 600.1, "frame_period_ms": 50.0, "frames_sent": 12003,
        "frames_received": 12002, "dropped": 0, "damaged": 0, "frames_drawn_tracked": 9000,
        "latency_ms": {"median": 28.7, "p90": 70.7, "max": 179.9}, "max_gap_ms": 261.5,
        "rss_start_mb": 421.8, "rss_end_mb": 450.0, "rss_growth_kb_per_frame": 2.41,
    }  # fmt: skip
    line = gui.summary({"soak": soak, "targets": {}})
    assert "20 frames/s" in line and "12002 of 12003 frames received, 0 dropped" in line
    assert "median 28.7 ms (p90 70.7, max 179.9" in line
    assert "RSS 421.8 → 450.0 MB (2.41 kB a frame received)" in line
