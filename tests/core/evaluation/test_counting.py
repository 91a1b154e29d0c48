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


def _with_reference(ds, xy_offset: float):
    """The truth as the data set's reference layer, shifted by ``xy_offset`` m along x."""
    f = np.flatnonzero(np.isfinite(ds.truth_xy_m[:, 0, 0]))
    xy = ds.truth_xy_m[f, 0]
    v = ds.truth_v_mps[f, 0]
    return dataclasses.replace(
        _without_truth(ds),
        ref_frame=f.astype(np.int64), ref_track_id=np.zeros(len(f), np.int64),
        ref_x_m=xy[:, 0] + xy_offset, ref_y_m=xy[:, 1], ref_z_m=np.zeros(len(f)),
        ref_vx_mps=v[:, 0], ref_vy_mps=v[:, 1],
    )  # fmt: skip


def test_reference_agreement_sees_a_shift_of_the_reference() -> None:
    from core.evaluation.counting import reference_agreement, trajectory_terms

    base = synthetic_dataset(4, 1, classes="abc", n_frames=120)
    est = track_dataset(base, TrackerParams.default("cv"), with_tracks=True)
    near = reference_agreement(_with_reference(base, 0.0), est)
    far = reference_agreement(_with_reference(base, 0.6), est)
    assert len(near.gospa_m) == len(est.frame_index)
    # a one-person frame where both have one track: GOSPA = the distance (below c = 1 m)
    both = (near.n_estimated == 1) & (near.n_reference == 1)
    assert both.mean() > 0.8
    assert np.median(near.gospa_m[both]) < 0.3
    np.testing.assert_allclose(np.median(far.gospa_m[both]), 0.6, atol=0.15)
    # the reference objective is the frame-weighted mean of the same GOSPA
    terms = trajectory_terms("reference", est, None, _with_reference(base, 0.6))
    v, w = np.array(terms).T
    assert np.sum(v * w) / np.sum(w) == pytest.approx(far.mean_gospa_m, rel=1e-12)
    scores = recording_scores(_with_reference(base, 0.6), est, 0.08)
    assert scores.to_dict()["reference"]["frames"] == len(est.frame_index)


def test_the_data_sets_own_head_count_and_unknown_frames() -> None:
    from core.evaluation.counting import trajectory_terms

    ds = _without_truth(synthetic_dataset(0, 1, classes="ab", n_frames=100))
    est = track_dataset(ds, TrackerParams.default("cv"), with_tracks=True)
    own = np.ones(ds.n_frames, np.int64)
    own[:20] = -1  # unknown at the start
    counted = dataclasses.replace(ds, people_count=own)
    np.testing.assert_array_equal(head_counts(counted), own)
    s = recording_scores(counted, est, 0.08)
    assert s.people == "people_count" and s.count.n_frames == ds.n_frames - 20
    right = np.mean(est.n_confirmed[20:] == 1)
    assert s.count.right == pytest.approx(right)
    (v0, w0), _ = trajectory_terms("count", est, own[est.frame_index])
    assert w0 == ds.trajectory_offsets[1] - 20
    # --people overrides the data set's count
    assert recording_scores(counted, est, 0.08, people=2).people == "--people 2"
