"""``python -m core.benchmarks.import_adc``: its figures are consistent with their definitions
(no timed assertion: the figures themselves are the benchmark's)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from core.benchmarks import import_adc


def test_quick_run_writes_consistent_figures(tmp_path: Path) -> None:
    assert import_adc.main(["--quick", "--out-dir", str(tmp_path)]) == 0
    r = json.loads((tmp_path / "import_adc.json").read_text())
    assert r["frames"] == 40
    # paper radar: 3 TX x 4 RX x 32 loops x 256 complex samples x 2 bytes x 2 (I and Q)
    assert r["frame_bytes"] == 3 * 4 * 32 * 256 * 4
    assert r["capture_over_exact"] == pytest.approx(r["capture_fps"] / r["exact_fps"])
    assert r["capture_mb_per_s"] == pytest.approx(r["capture_fps"] * r["frame_bytes"] / 1e6)
    # the same frames, the same chain: the clouds differ only by the 16-bit quantisation
    pts = r["points_per_frame"]
    assert pts["exact"] > 0 and abs(pts["capture"] - pts["exact"]) <= 0.25 * pts["exact"]
