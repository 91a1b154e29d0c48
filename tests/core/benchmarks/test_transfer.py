"""bench transfer: its held-out figures and its refusal without the public recordings."""

import dataclasses

import numpy as np
import pytest

from core.benchmarks import transfer
from core.errors import InputError
from core.tracking import TrackerParams
from core.tracking.synthetic import synthetic_dataset


def test_without_the_recordings_one_line(tmp_path, monkeypatch) -> None:
    monkeypatch.setenv("RADARTUNE_REAL", str(tmp_path))
    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError, match="RADARTUNE_REAL"):
        transfer.real_folder()


def test_scores_of_a_walker_and_a_reference() -> None:
    base = synthetic_dataset(12, 1, classes="ab", n_frames=100)
    empty = np.zeros((base.n_frames, 0, 2))
    walker = dataclasses.replace(base, truth_xy_m=empty, truth_v_mps=empty)
    f = np.flatnonzero(np.isfinite(base.truth_xy_m[:, 0, 0]))
    xy = base.truth_xy_m[f, 0]
    reference = dataclasses.replace(
        walker, ref_frame=f, ref_track_id=np.zeros(len(f), np.int64), ref_x_m=xy[:, 0],
        ref_y_m=xy[:, 1], ref_z_m=np.zeros(len(f)), ref_vx_mps=np.zeros(len(f)),
        ref_vy_mps=np.zeros(len(f)),
    )  # fmt: skip
    s = transfer._scores(TrackerParams.default("cv").to_dict(), walker, reference)
    assert set(transfer.FIGURES) <= set(s)
    assert 0.8 < s["walker_right_count"] <= 1.0  # one synthetic walker, mostly one track
    assert s["reference_mean_gospa_m"] < 0.6  # the reference is the walker's own path
