"""Importance and one-at-a-time sweeps: known answers on objectives whose shape is known."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from core.errors import InputError
from core.optimization import StudySettings, prepare_study, run_worker, study_progress
from core.optimization.objective import QuadraticLosses, make_losses
from core.optimization.progress import TrialSummary
from core.optimization.sensitivity import oat_sweep, parameter_importance, sweep_values
from core.optimization.space import search_space
from core.tracking.space import tracker_params_dict
from core.tracking.synthetic import synthetic_dataset


def _random_trials(model: str, n: int, value, seed: int = 0) -> list[TrialSummary]:
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        p = {}
        for b in search_space(model):
            u = rng.uniform()
            p[b.name] = (math.exp(math.log(b.low) + u * math.log(b.high / b.low)) if b.log
                         else b.low + u * (b.high - b.low))  # fmt: skip
        out.append(TrialSummary(number=i, state="COMPLETE", value=value(p), params=p,
                                duration_s=1.0, datetime_start=None,
                                datetime_complete=None))  # fmt: skip
    return out


@pytest.mark.parametrize("name", ["r11", "p_d"])
def test_importance_ranks_the_only_parameter_that_matters_first(name: str) -> None:
    b = next(b for b in search_space("ca") if b.name == name)
    centre = math.sqrt(b.low * b.high) if b.log else 0.5 * (b.low + b.high)

    def value(p: dict[str, float]) -> float:
        x = math.log(p[name] / centre) if b.log else p[name] - centre
        return x * x  # depends on one parameter only

    imp = parameter_importance(_random_trials("ca", 120, value), "ca")
    assert imp.ranked()[0][0] == name
    assert list(imp.values) == [b.name for b in search_space("ca")]
    assert sum(imp.values.values()) == pytest.approx(1.0)
    assert imp.values[name] > 0.5


def test_importance_needs_enough_completed_trials() -> None:
    trials = _random_trials("cv", 9, lambda p: p["r11"])
    with pytest.raises(InputError, match="at least 10 completed"):
        parameter_importance(trials, "cv")


def test_sweep_values_span_the_bounds_in_the_sampling_scale() -> None:
    xs = sweep_values("q_coeff", 2.0, 15)  # log scale, 0.1 … 30
    assert xs[0] == 0.1 and xs[-1] == 30.0 and 2.0 in xs and len(xs) == 16
    grid = xs[xs != 2.0]
    assert np.allclose(np.diff(np.log(grid)), math.log(300.0) / 14)
    xs = sweep_values("p_d", 0.9, 5)  # linear, 0.8 … 0.99; 0.9 is not a grid point
    assert np.allclose(np.diff(xs[xs != 0.9]), 0.19 / 4) and 0.9 in xs


def test_quadratic_objective_sweeps_have_their_minimum_at_the_known_optimum() -> None:
    """QuadraticLosses has its minimum at the centre of the (log) cube: every sweep through the
    centre is lowest there and symmetric in the sampling scale."""
    model = "cv"
    centre = {b.name: (math.sqrt(b.low * b.high) if b.log else 0.5 * (b.low + b.high))
              for b in search_space(model)}  # fmt: skip
    params = tracker_params_dict(centre, model)
    out = oat_sweep({"q": QuadraticLosses(model=model)}, params, n_points=5)
    assert list(out["q"]) == [b.name for b in search_space(model)]
    for s in out["q"].values():
        loss = np.array(s.loss)
        assert s.optimum_index == 2 and len(loss) == 5  # the centre is a grid point
        assert loss.argmin() == 2 and loss[2] == pytest.approx(1e-4, rel=1e-12)
        assert loss[0] == pytest.approx(loss[4], rel=1e-9)


def test_oat_at_the_optimum_reproduces_the_optimum_loss_exactly(tmp_path: Path) -> None:
    train = synthetic_dataset(seed=1, n_per_class=1, n_frames=50)
    train.save(tmp_path / "train.npz")
    url = f"memory://{tmp_path}"
    s = StudySettings(model="ca", n_trials=4, storage=url, study_name="ca",
                      dataset=str(tmp_path / "train.npz"))  # fmt: skip
    prepare_study(s, dataset_path=s.dataset)
    run_worker(url, s.name, seed=0)
    _, best = study_progress(url, "ca")
    assert best is not None and best.value is not None
    params = best.tracker_params("ca")
    sources = {"training": make_losses("tracker", "ca", train, capped=True)}
    out = oat_sweep(sources, params, n_points=4)
    for name, sweep in out["training"].items():
        assert sweep.values[sweep.optimum_index] == best.params[name]
        assert sweep.loss[sweep.optimum_index] == best.value  # bit for bit
        assert all(math.isfinite(c) for c in sweep.capped)
