"""The import benchmark's synthetic log is a valid SDK 3.x log that the importer and the plain
reference read to the same points (its figures are only meaningful if both do the same work)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from core.benchmarks.import_ import POINTS_PER_PACKET, plain_read, synthetic_packet
from core.formats.ti_uart_import import read


def test_synthetic_log_reads_the_same_in_both_readers() -> None:
    rng = np.random.default_rng(3)
    data = b"".join(synthetic_packet(k, rng) for k in range(20))
    rec = read(
        Path("bench.dat"), None, chunks=[data[i : i + 1000] for i in range(0, len(data), 1000)]
    )
    assert len(rec.cloud) == plain_read(data) == 20 * POINTS_PER_PACKET
    assert rec.counts.tolist() == [POINTS_PER_PACKET] * 20
    assert "0 dropped" in rec.notes[0] and "range_profile" in rec.notes[-1]
    assert np.all(rec.cloud.snr_db >= 5.0)  # side info (50..300 x 0.1 dB) attached to points


def test_synthetic_csvs_read_to_their_points(tmp_path: Path) -> None:
    """The CSV benchmark's files are valid: every frame, every point, a 0.1 s period."""
    from core.benchmarks.import_ import synthetic_oob_csv, synthetic_people_csv
    from core.formats.pointcloud_csv import read_oob, read_people

    rng = np.random.default_rng(5)
    synthetic_oob_csv(tmp_path / "o.csv", 30, rng)
    synthetic_people_csv(tmp_path / "p.csv", 30, rng)
    for rec in (read_oob(tmp_path / "o.csv", None), read_people(tmp_path / "p.csv", None)):
        assert rec.counts.tolist() == [POINTS_PER_PACKET] * 30
        assert abs(rec.radar.frame_period_s - 0.1) < 1e-6
    assert read_people(tmp_path / "p.csv", None).ref_tracks is not None
