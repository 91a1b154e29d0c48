"""The fidelity bench's loss comparison: paired bootstrap ratio and its verdict."""

from __future__ import annotations

import numpy as np
import pytest

from core.benchmarks.fidelity import loss_ratio_interval, verdict


def test_identical_losses_are_within() -> None:
    exact = np.random.default_rng(0).exponential(1.0, 35)
    ratio, lo, hi = loss_ratio_interval(exact, exact, n_boot=500)
    assert ratio == lo == hi == pytest.approx(1.0)
    assert verdict(lo, hi) == "within"


def test_doubled_losses_are_outside() -> None:
    exact = np.random.default_rng(1).exponential(1.0, 35) + 0.1
    ratio, lo, hi = loss_ratio_interval(2 * exact, exact, n_boot=500)
    assert ratio == lo == hi == pytest.approx(2.0)
    assert verdict(lo, hi) == "outside"


def test_heavy_tailed_noise_is_undecided_and_interval_covers_truth() -> None:
    """Same law, independent heavy-tailed draws: the interval is wide and holds 1."""
    rng = np.random.default_rng(2)
    exact = rng.pareto(1.5, 35)
    level = rng.pareto(1.5, 35)
    ratio, lo, hi = loss_ratio_interval(level, exact, n_boot=2000)
    assert lo < ratio < hi
    assert hi - lo > 0.2
    assert verdict(lo, hi) == "undecided"
    # coverage over repetitions: the 95 % interval of two samples of one law holds 1 mostly
    hits = 0
    for k in range(60):
        r = np.random.default_rng(100 + k)
        a, b = r.gamma(2.0, 1.0, 35), r.gamma(2.0, 1.0, 35)
        _, lo, hi = loss_ratio_interval(a, b, n_boot=400, seed=k)
        hits += lo <= 1.0 <= hi
    assert hits >= 50


def test_verdict_bands() -> None:
    assert verdict(0.95, 1.05) == "within"
    assert verdict(0.85, 1.05) == "undecided"
    assert verdict(1.12, 1.5) == "outside"
    assert verdict(0.5, 0.89) == "outside"


def test_bench_tracks_with_the_tuned_parameters_unless_told(tmp_path) -> None:
    from core.benchmarks.fidelity import TUNED_PARAMS, tracker_parameters
    from core.errors import InputError
    from core.tracking import TrackerParams

    params, said = tracker_parameters()
    for model in ("cv", "ca"):
        assert TUNED_PARAMS[model].exists()
        assert params[model] == TrackerParams.load(TUNED_PARAMS[model])
        assert params[model] != TrackerParams.default(model)
    assert "docs/report/best_cv.json" in said and "docs/report/best_ca.json" in said
    own = TrackerParams.default("cv")
    path = own.save(tmp_path / "cv.json")
    params, said = tracker_parameters(params_cv=path)
    assert params["cv"] == own and str(path) in said
    with pytest.raises(InputError, match="model must be 'ca'"):
        tracker_parameters(params_ca=path)


def test_regular_loss_leaves_out_runs_without_a_confirmed_track() -> None:
    from core.benchmarks.fidelity import rate_interval, regular_loss

    loss = np.array([[1.0, 2.0, 1000.0], [3.0, 1000.0, 1000.0]])
    seen = np.array([[True, True, False], [True, False, False]])
    reg = regular_loss(loss, seen)
    np.testing.assert_allclose(reg[:2], [2.0, 2.0])
    assert np.isnan(reg[2])
    q, lo, hi = rate_interval(2, 840)
    assert q == pytest.approx(2 / 840) and lo < q < hi
    # Clopper-Pearson: zero events in n runs -> upper bound 1 - 0.025^(1/n) ~ 3.69 / n
    assert rate_interval(0, 1000)[2] == pytest.approx(1 - 0.025 ** (1 / 1000), rel=1e-9)
