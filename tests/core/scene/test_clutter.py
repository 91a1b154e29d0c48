"""Clutter draws (SPEC §2): Poisson count λ·area, uniform over the AOI, moving, CFAR-passing SNR."""

from __future__ import annotations

import numpy as np
import pytest

from core.config import PAPER_RADAR
from core.scene import AOI, draw_clutter, expected_clutter_count


def test_aoi_area_of_the_paper_scene() -> None:
    # A = (2π/3)/2 · (10² − 0.5²) = π/3 · 99.75 = 104.458 m²
    assert AOI().area_m2 == pytest.approx(np.pi / 3 * 99.75, rel=1e-12)
    assert expected_clutter_count(AOI(), 0.02) == pytest.approx(2.0892, abs=1e-4)


def test_clutter_count_is_poisson_with_mean_lambda_area() -> None:
    rng = np.random.default_rng(3)
    aoi = AOI()
    draws = [draw_clutter(aoi, 0.02, PAPER_RADAR, rng) for _ in range(4000)]
    n = np.array([len(d) for d in draws])
    mean = 0.02 * aoi.area_m2
    # standard error sqrt(2.09/4000) = 0.023: 5 sigma = 0.11
    assert abs(n.mean() - mean) < 0.12
    assert n.var() == pytest.approx(mean, rel=0.1)  # Poisson: variance = mean
    pos = np.concatenate([d.position_m for d in draws])
    assert aoi.contains(pos).all()
    # uniform over the area: P(r < 5 m) = (5² − 0.5²)/(10² − 0.5²) = 0.2481
    r = np.hypot(*pos.T)
    assert np.mean(r < 5.0) == pytest.approx(24.75 / 99.75, abs=0.02)
    az = np.arctan2(pos[:, 0], pos[:, 1])
    assert np.mean(az > 0) == pytest.approx(0.5, abs=0.02)


def test_clutter_velocity_and_snr() -> None:
    rng = np.random.default_rng(4)
    d = [draw_clutter(AOI(), 0.05, PAPER_RADAR, rng) for _ in range(500)]
    vr = np.concatenate([x.radial_velocity_mps for x in d])
    snr = np.concatenate([x.snr_db for x in d])
    dv, vmax = PAPER_RADAR.velocity_resolution_mps, PAPER_RADAR.max_velocity_mps
    assert np.abs(vr).min() >= 2 * dv  # survives static clutter removal
    assert np.abs(vr).max() <= vmax
    assert np.mean(vr > 0) == pytest.approx(0.5, abs=0.04)
    assert snr.min() >= 15.0 and snr.max() <= 30.0
    # the velocity vector is along the line of sight with the drawn radial component
    x = d[0] if len(d[0]) else d[1]
    p, v = x.position_m, x.velocity_mps
    np.testing.assert_allclose((p * v).sum(1) / np.hypot(*p.T), x.radial_velocity_mps)


def test_no_clutter_when_density_is_zero() -> None:
    rng = np.random.default_rng(0)
    assert all(len(draw_clutter(AOI(), 0.0, PAPER_RADAR, rng)) == 0 for _ in range(50))


@pytest.mark.parametrize("n_loops", [1, 2, 3, 4])
def test_too_few_loops_for_clutter_is_an_input_error_naming_n_loops(n_loops) -> None:
    # v_max = n_loops/2 velocity bins: |v| >= 2 bins inside ±v_max needs n_loops >= 5
    from dataclasses import replace

    from core.errors import InputError
    from core.scene import Scene

    radar = replace(PAPER_RADAR, n_loops=n_loops)
    assert radar.max_velocity_mps / radar.velocity_resolution_mps == pytest.approx(n_loops / 2)
    with pytest.raises(InputError, match=f"n_loops={n_loops} .*needs n_loops >= 5"):
        Scene(radar=radar, clutter_density_per_m2=0.02)
    with pytest.raises(InputError, match="n_loops"):
        draw_clutter(AOI(), 0.02, radar, np.random.default_rng(0))
    # without clutter the scene is valid and no clutter is drawn
    assert Scene(radar=radar, clutter_density_per_m2=0.0).radar.n_loops == n_loops
    assert len(draw_clutter(AOI(), 0.0, radar, np.random.default_rng(0))) == 0


def test_scene_file_with_too_few_loops_names_the_file_and_field(tmp_path) -> None:
    import json

    from core.errors import InputError
    from core.scene import Scene

    doc = {
        "schema_version": 1,
        "radar": {"n_loops": 2},
        "clutter_density_per_m2": 0.02,
        "persons": [{"trajectory": {"class": "a", "seed": 1}}],
    }
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(InputError, match="n_loops=2") as err:
        Scene.from_json(path)
    assert str(path) in str(err.value)


def test_five_loops_is_the_smallest_radar_that_draws_clutter() -> None:
    from dataclasses import replace

    radar = replace(PAPER_RADAR, n_loops=5)
    rng = np.random.default_rng(1)
    vr = np.concatenate(
        [draw_clutter(AOI(), 0.05, radar, rng).radial_velocity_mps for _ in range(200)]
    )
    dv = radar.velocity_resolution_mps
    assert vr.size > 500
    # 2 Δv <= |v| < v_max = 2.5 Δv
    assert np.all(np.abs(vr) >= 2 * dv) and np.all(np.abs(vr) < radar.max_velocity_mps)
