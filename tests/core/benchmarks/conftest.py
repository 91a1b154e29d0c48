"""Shared fixtures of the bench tests."""

import dataclasses
from collections.abc import Callable

import numpy as np
import pytest

from core.tracking.synthetic import synthetic_dataset


@pytest.fixture
def walker_and_reference() -> Callable:
    """``make(classes)``: a synthetic walker (seed 12, 100 frames) as a recording without truth,
    and the same recording with the walker's own path as its reference tracks (track 0, at rest,
    on the floor)."""

    def make(classes: str):
        base = synthetic_dataset(12, 1, classes=classes, n_frames=100)
        empty = np.zeros((base.n_frames, 0, 2))
        walker = dataclasses.replace(base, truth_xy_m=empty, truth_v_mps=empty)
        f = np.flatnonzero(np.isfinite(base.truth_xy_m[:, 0, 0]))
        xy = base.truth_xy_m[f, 0]
        reference = dataclasses.replace(
            walker, ref_frame=f, ref_track_id=np.zeros(len(f), np.int64), ref_x_m=xy[:, 0],
            ref_y_m=xy[:, 1], ref_z_m=np.zeros(len(f)), ref_vx_mps=np.zeros(len(f)),
            ref_vy_mps=np.zeros(len(f)),
        )  # fmt: skip
        return walker, reference

    return make
