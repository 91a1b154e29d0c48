"""RadarConfig derived values, processing settings and ``radartune radar --json``."""

from __future__ import annotations

import json

import pytest

from core.cli import main
from core.config import CfarSettings, ProcessingSettings, RadarConfig
from core.errors import InputError


def test_paper_derived_values() -> None:
    r = RadarConfig()
    assert r.wavelength_m == pytest.approx(4.9965e-3, abs=1e-7)
    assert r.range_resolution_m == pytest.approx(0.05630, abs=5e-6)
    assert r.max_range_m == pytest.approx(14.41, abs=5e-3)
    assert r.max_velocity_mps == pytest.approx(7.241, abs=5e-4)
    assert r.velocity_resolution_mps == pytest.approx(0.4526, abs=5e-5)
    assert r.chirp_period_s == pytest.approx(57.5e-6)
    assert r.slope_hz_per_s == pytest.approx(61.366e12, rel=1e-4)


def test_processing_defaults_follow_spec() -> None:
    s = ProcessingSettings()
    assert (s.range_window, s.doppler_window) == ("hann", "hann")
    rc, dc = s.range_cfar, s.doppler_cfar
    assert (rc.method, rc.n_train, rc.n_guard, rc.pfa, rc.cyclic) == ("caso", 8, 4, 1e-4, False)
    assert (dc.method, dc.n_train, dc.n_guard, dc.pfa, dc.cyclic) == ("ca", 4, 2, 1e-3, True)
    assert (s.min_range_m, s.max_range_m) == (0.3, 10.0)
    assert ProcessingSettings.from_dict(s.to_dict()) == s


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"range_window": "kaiser"}, "range_window"),
        ({"min_range_m": 5.0, "max_range_m": 4.0}, "max_range_m"),
        ({"angle_fft_size": 48}, "angle_fft_size"),
        ({"range_cfar": "caso"}, "range_cfar"),
    ],
)
def test_processing_settings_validation_names_field(kwargs, field) -> None:
    with pytest.raises(InputError, match=field):
        ProcessingSettings(**kwargs)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [({"method": "os"}, "method"), ({"pfa": 1.5}, "pfa"), ({"n_train": 0}, "n_train")],
)
def test_cfar_settings_validation_names_field(kwargs, field) -> None:
    with pytest.raises(InputError, match=field):
        CfarSettings(**kwargs)


def test_unknown_settings_key_is_named() -> None:
    with pytest.raises(InputError, match="windw"):
        ProcessingSettings.from_dict({"windw": "hann"})


def test_cli_radar_json_keys(capsys) -> None:
    assert main(["radar", "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    for key in (
        "range_resolution_m",
        "max_range_m",
        "max_velocity_mps",
        "velocity_resolution_mps",
        "wavelength_m",
        "n_tx",
        "n_rx",
        "n_loops",
        "n_samples",
        "frame_period_s",
    ):
        assert key in info
    assert info["range_resolution_m"] == pytest.approx(0.0563, abs=1e-4)
