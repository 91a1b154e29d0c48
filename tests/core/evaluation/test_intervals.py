"""Statistics of tracking losses (core.evaluation.intervals): paired bootstrap ratio and its
verdict, rates and rate ratios, the bulk and the tail events."""

from __future__ import annotations

import numpy as np
import pytest

from core.evaluation.intervals import loss_ratio_interval, verdict


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


def test_regular_loss_leaves_out_runs_without_a_confirmed_track() -> None:
    from core.evaluation.intervals import rate_interval, regular_loss

    loss = np.array([[1.0, 2.0, 1000.0], [3.0, 1000.0, 1000.0]])
    seen = np.array([[True, True, False], [True, False, False]])
    reg = regular_loss(loss, seen)
    np.testing.assert_allclose(reg[:2], [2.0, 2.0])
    assert np.isnan(reg[2])
    q, lo, hi = rate_interval(2, 840)
    assert q == pytest.approx(2 / 840) and lo < q < hi
    # Clopper-Pearson: zero events in n runs -> upper bound 1 - 0.025^(1/n) ~ 3.69 / n
    assert rate_interval(0, 1000)[2] == pytest.approx(1 - 0.025 ** (1 / 1000), rel=1e-9)


def test_split_tail_separates_rare_large_runs_by_the_exact_median() -> None:
    from core.evaluation.intervals import exact_median_loss, split_tail

    # 3 seeds x 3 trajectories; trajectory 2 never confirmed in seed 0
    ex = np.array([[1.0, 2.0, 9.0], [2.0, 4.0, 5.0], [3.0, 6.0, 7.0]])
    ex_seen = np.array([[True, True, False], [True, True, True], [True, True, True]])
    med = exact_median_loss(ex, ex_seen)
    np.testing.assert_allclose(med, [2.0, 4.0, 6.0])  # the unconfirmed 9.0 is left out
    level = np.array([[2.0, 41.0, 6.0], [20.0, 3.0, 61.0], [20.1, 5.0, 7.0]])
    seen = np.ones((3, 3), dtype=bool)
    bulk, tail = split_tail(level, seen, med, factor=10.0)
    # tail: strictly above 10x the median (41 > 40, 61 > 60, 20.1 > 20; 20.0 is not)
    assert tail.tolist() == [[False, True, False], [False, False, True], [True, False, False]]
    np.testing.assert_allclose(bulk, [11.0, 4.0, 6.5])
    # a trajectory whose every run is a tail event has no bulk
    bulk, tail = split_tail(np.full((2, 1), 100.0), np.ones((2, 1), bool), np.array([1.0]))
    assert np.isnan(bulk[0]) and tail.all()
    # no exact run with a track: no median, nothing is a tail event, the bulk is the mean
    med = exact_median_loss(np.ones((2, 1)), np.zeros((2, 1), bool))
    assert np.isnan(med[0])
    bulk, tail = split_tail(np.array([[1.0], [3.0]]), np.ones((2, 1), bool), med)
    assert not tail.any() and bulk[0] == pytest.approx(2.0)


def test_rate_ratio_interval_is_exact_and_covers_equal_rates() -> None:
    from core.evaluation.intervals import rate_ratio_interval

    ratio, lo, hi = rate_ratio_interval(20, 1000, 10, 1000)
    assert ratio == pytest.approx(2.0) and lo < 2.0 < hi
    # conditional binomial: 20 of 30 events, pi's Clopper-Pearson interval mapped to the ratio
    from scipy.stats import beta

    pi_lo, pi_hi = beta.ppf(0.025, 20, 11), beta.ppf(0.975, 21, 10)
    assert lo == pytest.approx(pi_lo / (1 - pi_lo)) and hi == pytest.approx(pi_hi / (1 - pi_hi))
    # unequal run counts scale the ratio: same rate 1 % on 840 and 1680 runs
    ratio, lo, hi = rate_ratio_interval(17, 1680, 8, 840)
    assert ratio == pytest.approx((17 / 1680) / (8 / 840)) and lo < 1.0 < hi
    assert rate_ratio_interval(0, 10, 0, 10)[1:] == (0.0, float("inf"))
    # coverage: two samples of one Poisson rate, the interval holds 1 in most repetitions
    rng = np.random.default_rng(5)
    hits = sum(
        lo <= 1.0 <= hi
        for lo, hi in (
            rate_ratio_interval(int(rng.poisson(15)), 1680, int(rng.poisson(7.5)), 840)[1:]
            for _ in range(200)
        )
    )
    assert hits >= 185


def _median_ratio(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    return np.median(x, axis=(-2, -1)) / np.median(y, axis=(-2, -1))


def test_two_level_bootstrap_covers_a_known_ratio_of_medians() -> None:
    """Cells ln x = μ + a_s + b_t + e (study, test set and cell effects, all symmetric), the
    test-set effect shared by both models: the median of the population of cells is e^μ, so
    the true CV/CA ratio of medians is e^(μ_cv − μ_ca) = 0.8. Over 100 independent experiments
    of 8 studies × 20 sets the 95 % interval must hold it in most (≥ 88 %), and a one-level
    interval that ignores the study effect must hold it less often."""
    from core.evaluation.intervals import bootstrap_interval, two_level_bootstrap

    rng = np.random.default_rng(7)
    truth = 0.8
    covered = covered_one = 0
    for _ in range(100):
        b = rng.normal(0, 0.5, (1, 20))  # test-set effect, paired
        cv = np.exp(np.log(truth) + rng.normal(0, 0.4, (8, 1)) + b + rng.normal(0, 0.3, (8, 20)))
        ca = np.exp(rng.normal(0, 0.4, (8, 1)) + b + rng.normal(0, 0.3, (8, 20)))
        _, lo, hi = two_level_bootstrap(_median_ratio, cv, ca, n_boot=1000)
        covered += lo <= truth <= hi
        # one level: the sets resampled, the eight studies treated as fixed
        s = np.median(cv, axis=0), np.median(ca, axis=0)
        _, lo1, hi1 = bootstrap_interval(
            lambda x, y: np.median(x, axis=-1) / np.median(y, axis=-1), *s, n_boot=1000
        )
        covered_one += lo1 <= truth <= hi1
    assert covered >= 88  # measured: 95
    assert covered_one <= 80  # measured: 68


def test_two_level_bootstrap_with_one_study_is_the_one_level_bootstrap() -> None:
    from core.evaluation.intervals import bootstrap_interval, two_level_bootstrap

    rng = np.random.default_rng(3)
    cv, ca = rng.lognormal(0, 1, (1, 20)), rng.lognormal(0.1, 1, (1, 20))
    two = two_level_bootstrap(_median_ratio, cv, ca, n_boot=2000, seed=5)
    one = bootstrap_interval(
        lambda x, y: np.median(x, axis=-1) / np.median(y, axis=-1),
        cv[0],
        ca[0],
        n_boot=2000,
        seed=5,
    )
    assert two == pytest.approx(one, rel=0, abs=0)
    assert two[1] < two[0] < two[2]  # a real interval, not a degenerate one


def test_two_level_bootstrap_identical_cells_and_bad_shapes() -> None:
    from core.evaluation.intervals import two_level_bootstrap

    x = np.full((8, 20), 2.0)
    assert two_level_bootstrap(_median_ratio, 1.5 * x, x, n_boot=200) == (1.5, 1.5, 1.5)
    with pytest.raises(ValueError, match="one shape"):
        two_level_bootstrap(_median_ratio, x, x[:, :10])
    with pytest.raises(ValueError, match="matrices"):
        two_level_bootstrap(_median_ratio, x[0], x[0])
