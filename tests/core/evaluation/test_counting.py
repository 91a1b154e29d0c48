"""Scores without positions: head count, fragmentation and NIS of a tracker run."""

import dataclasses
import json

import numpy as np
import pytest

from core.cli import main
from core.errors import InputError
from core.evaluation.consistency import chi2_band
from core.evaluation.counting import count_scores, head_counts, nis_samples, recording_scores
from core.tracking import TrackerParams, track_dataset
from core.tracking.synthetic import synthetic_dataset


def _without_truth(ds):
    """The data set as an imported recording without truth has it (no persons)."""
    f = ds.n_frames
    empty = np.zeros((f, 0, 2))
    return dataclasses.replace(ds, truth_xy_m=empty, truth_v_mps=empty)


def test_count_scores_are_the_derived_numbers() -> None:
    f, period = 300, 0.1
    n_hat = np.ones(f, np.int64)
    n_hat[:30] = 0  # the person not yet confirmed
    n_hat[100:115] = 2  # a ghost for 1.5 s
    ids = np.full((f, 2), -1)
    ids[30:, 0] = 7
    ids[100:115, 1] = 9
    ids[200:, 0] = 12  # the person's track broken once
    s = count_scores(n_hat, np.ones(f, np.int64), ids, period)
    assert s.n_frames == f
    assert s.right == pytest.approx(255 / 300)
    assert s.error == pytest.approx(45 / 300)
    assert s.bias == pytest.approx((-30 + 15) / 300)
    assert s.n_ids == 3
    assert s.person_minutes == pytest.approx(300 * 0.1 / 60)
    assert s.fragmentation == pytest.approx(3 / 0.5)
    # blocks of 10 s = 100 frames: rights 0.70, 0.85, 1.00; their resampled means lie in there
    lo, hi = s.right_interval
    assert 0.70 <= lo < s.right < hi <= 1.0


def test_a_run_shorter_than_two_blocks_has_no_interval() -> None:
    s = count_scores(np.ones(150, np.int64), np.ones(150, np.int64), np.zeros((150, 1)), 0.1)
    assert s.right == 1.0 and s.error == 0.0
    assert np.isnan(s.right_interval).all()


def test_head_counts() -> None:
    ds = synthetic_dataset(0, 2, classes="a", n_frames=60)
    np.testing.assert_array_equal(head_counts(ds, 2), np.full(ds.n_frames, 2))
    present = np.isfinite(ds.truth_xy_m[..., 0]).sum(axis=1)
    np.testing.assert_array_equal(head_counts(ds), present)
    assert head_counts(_without_truth(ds)) is None
    for bad in (-1, 1.5, True):
        with pytest.raises(InputError, match="--people"):
            head_counts(ds, bad)


def test_scores_of_a_synthetic_walk() -> None:
    ds = synthetic_dataset(1, 1, n_frames=200)
    est = track_dataset(ds, TrackerParams.default("cv"), with_tracks=True)
    s = recording_scores(ds, est, 0.08, people=1)
    # one walker and the paper's clutter: the right count in most frames
    assert s.people == "--people 1" and s.count.right > 0.9
    assert s.count.n_ids >= ds.n_trajectories  # at least one track a walk
    # NIS: every confirmed update with a gated point; synthetic points follow the filter's own
    # R, so the PDA's NIS lies below χ²₃'s mean (3) and rarely above the band
    rec = est.record
    live = np.arange(rec.ids.shape[1])[None, :] < rec.n_tracks[:, None]
    v = rec.nis[live & rec.confirmed]
    assert s.nis.n == np.isfinite(v).sum() == len(nis_samples(est)) > 0
    assert s.nis.band == pytest.approx(chi2_band(3))
    assert 0.5 < s.nis.mean < 3.0 and s.nis.above < 0.05
    # the same run scored by its truth's head count: the same count (one person throughout)
    assert recording_scores(ds, est, 0.08).count.right == s.count.right


def test_cli_scores_a_recording_without_truth(tmp_path, capsys) -> None:
    ds = _without_truth(synthetic_dataset(0, 1, classes="ab", n_frames=100))
    data = ds.save(tmp_path / "rec.npz")
    out = tmp_path / "r.json"
    assert main(["track", "--data", str(data), "--people", "1", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "head count from --people 1" in text and "NIS (3 dof)" in text
    doc = json.loads(out.read_text())["without_positions"]
    assert doc["count"]["frames"] == ds.n_frames and doc["nis"]["n"] > 0
    assert main(["track", "--data", str(data)]) == 0
    assert "give --people N" in capsys.readouterr().out
