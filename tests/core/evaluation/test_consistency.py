"""Filter consistency (core/evaluation/consistency.py): the χ² bands against scipy's quantiles, NEES
by hand, a linear-Gaussian Kalman filter that is exactly matched (NEES and NIS inside their bands)
and one whose R is 10× too small (NIS far above), and the tracker's samples on a data set
against an independent computation from the readable tracker."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import chi2

from core.evaluation.consistency import (
    average_band,
    chi2_band,
    consistency_report,
    consistency_samples,
    consistency_stat,
    dataset_consistency,
    measurement_spread,
    nees,
)
from core.tracking import TrackerParams, run_tracker
from core.tracking.ekf import joseph_update, predict
from core.tracking.models import process_noise, transition_matrix
from core.tracking.synthetic import SyntheticScene, synthetic_dataset


@pytest.mark.parametrize("dof", [1, 2, 3, 4])
def test_bands_are_the_chi2_quantiles(dof: int) -> None:
    lo, hi = chi2_band(dof)
    assert lo == pytest.approx(chi2.ppf(0.025, dof), rel=1e-12)
    assert hi == pytest.approx(chi2.ppf(0.975, dof), rel=1e-12)
    # one sample: the band of the mean is the per-sample band
    assert average_band(dof, 1) == pytest.approx((lo, hi), rel=1e-12)
    # N samples: N·ε̄ ~ χ²_{N n}
    m_lo, m_hi = average_band(dof, 100)
    assert m_lo == pytest.approx(chi2.ppf(0.025, 100 * dof) / 100, rel=1e-12)
    assert m_hi == pytest.approx(chi2.ppf(0.975, 100 * dof) / 100, rel=1e-12)
    # it narrows around n as N grows (the mean's standard deviation is √(2n/N))
    assert lo < m_lo < dof < m_hi < hi
    w = average_band(dof, 10_000)
    assert w[1] - w[0] == pytest.approx(2 * 1.96 * math.sqrt(2 * dof / 10_000), rel=0.01)
    assert math.isnan(average_band(dof, 0)[0])


def test_nees_by_hand() -> None:
    e = np.array([[1.0, 2.0], [3.0, 0.0]])
    P = np.array([np.diag([1.0, 4.0]), [[2.0, 1.0], [1.0, 2.0]]])
    # [1 2] diag(1, 1/4) [1 2]ᵀ = 1 + 1; [3 0] (1/3)[[2, −1], [−1, 2]] [3 0]ᵀ = 6
    np.testing.assert_allclose(nees(e, P), [2.0, 6.0], rtol=1e-12)
    assert nees(np.zeros((0, 2)), np.zeros((0, 2, 2))).shape == (0,)


def test_stat_fractions_and_verdict() -> None:
    lo, hi = chi2_band(3)
    s = consistency_stat(np.array([lo / 2, 3.0, 3.0, 2 * hi, np.nan]), 3)
    assert s.n == 4 and s.inside == 0.5 and s.below == 0.25 and s.above == 0.25
    assert s.mean == pytest.approx((lo / 2 + 6.0 + 2 * hi) / 4)
    empty = consistency_stat(np.array([np.nan]), 3)
    assert empty.n == 0 and math.isnan(empty.mean) and empty.verdict == "undefined"
    assert consistency_stat(np.full(50, 30.0), 3).verdict == "above"
    assert consistency_stat(np.full(50, 0.3), 3).verdict == "below"


def _linear_gaussian_runs(r_scale: float, n_runs: int = 400, n_steps: int = 30, seed: int = 2):
    """CV target with the model's own process noise, measured z = [x, y] + v, v ~ N(0, R);
    a Kalman filter with the true F, Q, P0 and R·r_scale. Returns NEES (4 dof) and NIS (2 dof)
    as (n_runs, n_steps) arrays."""
    rng = np.random.default_rng(seed)
    T, q = 0.08, 2.0
    F = transition_matrix("cv", T)
    Q = process_noise("cv", T, q)
    H = np.hstack((np.eye(2), np.zeros((2, 2))))
    R = np.diag([0.05**2, 0.08**2])
    R_f = R * r_scale
    P0 = np.diag([0.3, 0.3, 0.5, 0.5]) ** 2
    LQ = np.linalg.cholesky(Q + 1e-15 * np.eye(4))  # Q has rank 2 per axis pair: nudge for chol
    out_nees = np.empty((n_runs, n_steps))
    out_nis = np.empty((n_runs, n_steps))
    for k in range(n_runs):
        x_hat = np.array([0.0, 5.0, 1.0, 0.0])
        P = P0.copy()
        # x₀ ~ N(x̂₀, P₀): the filter's prior is exactly right
        x = x_hat + np.linalg.cholesky(P0) @ rng.standard_normal(4)
        for t in range(n_steps):
            x = F @ x + LQ @ rng.standard_normal(4)
            z = H @ x + np.sqrt(np.diag(R)) * rng.standard_normal(2)
            x_pred, P_pred = predict(x_hat, P, F, Q)
            # S = H P⁻ Hᵀ + R
            S = H @ P_pred @ H.T + R_f
            nu = z - H @ x_pred
            # K = P⁻ Hᵀ S⁻¹
            K = np.linalg.solve(S, H @ P_pred).T
            x_hat = x_pred + K @ nu
            P = joseph_update(P_pred, K, H, R_f)
            out_nis[k, t] = nu @ np.linalg.solve(S, nu)
            out_nees[k, t] = nees((x_hat - x)[None], P[None])[0]
    return out_nees, out_nis


def test_matched_linear_gaussian_filter_is_consistent() -> None:
    e_nees, e_nis = _linear_gaussian_runs(1.0)
    for values, dof in ((e_nees, 4), (e_nis, 2)):
        # ANEES/ANIS over the 400 independent runs at steps 10, 20, 30 against the band of
        # N·ε̄ ~ χ²_{N n} (each check of a consistent filter fails for 5 % of the seeds)
        for t in (9, 19, 29):
            assert consistency_stat(values[:, t], dof).verdict == "within", (dof, t)
        # all 12 000 samples: about 95 % inside the per-sample band (binomial sd 0.2 %, runs
        # independent, steps within a run correlated: allow ±1.5 %), mean about n
        s_all = consistency_stat(values, dof)
        assert abs(s_all.inside - 0.95) < 0.015
        assert abs(s_all.mean / dof - 1.0) < 0.05


def test_r_ten_times_too_small_makes_nis_far_above_its_band() -> None:
    _, e_nis = _linear_gaussian_runs(0.1, n_runs=100)
    s = consistency_stat(e_nis[:, -1], 2)
    _, m_hi = average_band(2, 100)
    assert s.verdict == "above" and s.mean > 3 * m_hi
    # far more than the 2.5 % of samples a consistent filter puts above χ²₂⁻¹(0.975)
    assert consistency_stat(e_nis, 2).above > 0.3
    assert consistency_stat(e_nis, 2).above > 10 * (1 - chi2.cdf(chi2.ppf(0.975, 2), 2))


SCENE = SyntheticScene(noise_std=(0.05, 0.02, 0.15), p_d=0.95, clutter_per_frame=0.5)


def _params(r_scale: float = 1.0) -> TrackerParams:
    r11, r22, r33 = (s * math.sqrt(r_scale) for s in SCENE.noise_std)
    return TrackerParams(
        model="cv", q_coeff=1.0, r11=r11, r22=r22, r33=r33, p_d=0.95,
        clutter_density=SCENE.clutter_density,
    )  # fmt: skip


def test_samples_equal_an_independent_computation_from_the_readable_tracker() -> None:
    ds = synthetic_dataset(3, n_per_class=1, scene=SCENE, n_frames=80)
    params = _params()
    samples = consistency_samples(ds, params)
    assert np.all(samples.paired <= samples.present)
    assert samples.paired.sum() > 0.8 * samples.present.sum()
    assert np.all(np.isnan(samples.nees_position[~samples.paired]))
    z, f_off, t_off = ds.measurements(), ds.frame_offsets, ds.trajectory_offsets
    from core.evaluation import assign_identities
    from core.tracking.batch import ConfirmedTracks

    checked = 0
    for k in range(ds.n_trajectories):
        a, b = t_off[k], t_off[k + 1]
        res = run_tracker((z[f_off[a] : f_off[b]], f_off[a : b + 1] - f_off[a]), params, 0.08)
        tracks = ConfirmedTracks.from_frames(res.frames)
        pair = assign_identities(tracks.ids, tracks.xy, ds.truth_xy_m[a:b])
        for f in range(b - a):
            tid = pair.track_id[f, 0]
            assert samples.paired[a + f, 0] == (tid >= 0)
            if tid < 0:
                continue
            ft = res.frames[f]
            i = int(np.flatnonzero(ft.ids == tid)[0])
            e = ft.state[i, :4] - np.r_[ds.truth_xy_m[a + f, 0], ds.truth_v_mps[a + f, 0]]
            P = ft.covariance[i]
            want_pos = e[:2] @ np.linalg.inv(P[:2, :2]) @ e[:2]
            want_state = e @ np.linalg.inv(P[:4, :4]) @ e
            assert samples.nees_position[a + f, 0] == pytest.approx(want_pos, rel=1e-8)
            assert samples.nees_state[a + f, 0] == pytest.approx(want_state, rel=1e-8)
            np.testing.assert_allclose(samples.nis[a + f, 0], ft.nis[i], rtol=1e-8)
            checked += 1
    assert checked > 200


def test_report_rows_and_smaller_r_raises_nees_and_nis() -> None:
    ds = synthetic_dataset(4, n_per_class=2, scene=SCENE, n_frames=100)
    matched = dataset_consistency(ds, _params(), label="matched")
    small = dataset_consistency(ds, _params(0.1), label="R x 0.1")
    assert list(matched.rows) == ["a", "b", "c", "d", "e", "total"]
    assert matched.frames_present["total"] == ds.n_frames
    assert sum(matched.frames_paired[c] for c in "abcde") == matched.frames_paired["total"]
    # matched R on synthetic measurements: the position NEES near n (here 2.34) ...
    assert 0.75 < matched.rows["total"]["nees_position"].mean_ratio < 1.5
    # ... R × 0.1: NEES an order of magnitude above its band
    for name in ("nees_position", "nees_state"):
        s_small = small.rows["total"][name]
        assert s_small.verdict == "above"
        assert s_small.mean > 5 * matched.rows["total"][name].mean
    # NIS rises above its band too, but cannot pass the gate: ν̃ = Σ βᵢ νᵢ (Σ βᵢ ≤ 1) is a convex
    # combination of gated innovations and 0, all inside the ellipsoid νᵀS⁻¹ν ≤ γ, so ε ≤ γ
    assert small.rows["total"]["nis"].verdict == "above"
    gamma = chi2.ppf(_params().p_g, 3)
    for r_scale in (1.0, 0.1):
        nis = consistency_samples(ds, _params(r_scale)).nis
        assert np.nanmax(nis) <= gamma * (1 + 1e-9)
    doc = matched.to_dict()
    assert doc["rows"]["total"]["nis"]["dof"] == 3
    assert doc["rows"]["total"]["nees_position"]["band"][1] == pytest.approx(chi2.ppf(0.975, 2))
    # per-class samples add up to the total
    s = consistency_samples(ds, _params())
    rep = consistency_report(s, ds.trajectory_class)
    assert sum(rep.rows[c]["nis"].n for c in "abcde") == rep.rows["total"]["nis"].n


def test_measurement_spread_is_the_synthetic_noise() -> None:
    """Synthetic person points are h(x_gt) + N(0, diag(σ²)): their RMS about h(x_gt) is σ
    within its sampling error (relative sd 1/√(2M) for M points)."""
    ds = synthetic_dataset(5, n_per_class=4, scene=SCENE, n_frames=150)
    m = int(np.sum(ds.source >= 0))
    assert m > 1500
    np.testing.assert_allclose(measurement_spread(ds), SCENE.noise_std, rtol=4 / math.sqrt(2 * m))
