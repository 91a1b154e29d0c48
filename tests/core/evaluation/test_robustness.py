"""Clutter robustness: ρ ×1 is the plain evaluation bit for bit; every row is what it says."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from core.errors import InputError
from core.evaluation import evaluate
from core.evaluation.robust import trajectory_capped_losses
from core.evaluation.robustness import RHO_FACTORS, clutter_robustness, scene_clutter_rate
from core.tracking import TrackerParams, track_dataset
from core.tracking.synthetic import synthetic_dataset


@pytest.fixture(scope="module")
def data():
    return {
        "a": synthetic_dataset(seed=4, n_per_class=1, n_frames=60),
        "b": synthetic_dataset(seed=5, n_per_class=1, classes="cd", n_frames=60),
    }


def test_rho_times_one_is_the_plain_evaluation_bit_for_bit(data) -> None:
    params = TrackerParams.default("ca")
    r = clutter_robustness(params, data, RHO_FACTORS)
    assert len(r.rows) == 2 * len(RHO_FACTORS)
    for label, ds in data.items():
        est = track_dataset(ds, params)
        ev = evaluate(ds, est)
        row = r.row(label, 1.0)
        assert row.clutter_density == params.clutter_density
        assert row.loss_total == ev.loss_total
        assert row.median_loss == float(np.median(ev.loss))
        assert row.confirmed_fraction == ev.confirmed_fraction
        assert row.n_never_confirmed == int(np.sum(ev.n_c == 0))
        assert row.n_trajectories == ds.n_trajectories
        capped = trajectory_capped_losses(ds, est)
        assert row.capped_total == float(np.mean(capped))
        assert row.losses == tuple(ev.loss) and row.capped == tuple(capped)


def test_each_factor_tracks_with_its_scaled_density(data) -> None:
    params = TrackerParams.default("cv")
    r = clutter_robustness(params, {"a": data["a"]}, (0.2, 5.0))
    for f in (0.2, 5.0):
        row = r.row("a", f)
        # ρ' = f · ρ: the row is the plain evaluation of the parameters with that ρ
        p = dataclasses.replace(params, clutter_density=0.0073 * f)
        ev = evaluate(data["a"], track_dataset(data["a"], p))
        assert row.clutter_density == pytest.approx(0.0073 * f, rel=1e-15)
        assert row.loss_total == ev.loss_total
        assert row.confirmed_fraction == ev.confirmed_fraction
    d = r.to_dict()
    assert d["rho_factors"] == [0.2, 5.0] and len(d["rows"]) == 2
    # a synthetic set records no scene clutter rate: NaN here, None in JSON
    assert np.isnan(scene_clutter_rate(data["a"])) and d["rows"][0]["clutter_per_m2"] is None


def test_bad_inputs_are_one_line(data) -> None:
    with pytest.raises(InputError, match="numeric clutter_density"):
        clutter_robustness(TrackerParams(clutter_density="nonparametric"), data)
    with pytest.raises(InputError, match="rho_factors"):
        clutter_robustness(TrackerParams(), data, (1.0, 0.0))
    with pytest.raises(InputError, match="at least one data set"):
        clutter_robustness(TrackerParams(), {})
