"""TI mmWave SDK .cfg reader and writer, and ``radartune radar --cfg``."""

from __future__ import annotations

import dataclasses
import subprocess
import sys
from pathlib import Path

import pytest

from core.cli import main
from core.config import RadarConfig
from core.errors import InputError
from core.formats.ti_cfg import read_ti_cfg, ti_cfg_text, write_ti_cfg

ROOT = Path(__file__).resolve().parents[3]
CFG_DIR = ROOT / "resources" / "radar"


def test_paper_cfg_reads_back_to_default_config() -> None:
    r = read_ti_cfg(CFG_DIR / "paper.cfg")
    default = RadarConfig()
    for f in dataclasses.fields(RadarConfig):
        assert getattr(r, f.name) == getattr(default, f.name) or f.name == "name", f.name
    assert r == default


@pytest.mark.parametrize("name", ["long_range", "high_velocity"])
def test_variant_cfgs_round_trip(name: str, tmp_path: Path) -> None:
    r = read_ti_cfg(CFG_DIR / f"{name}.cfg")
    assert r.name == name
    out = tmp_path / "again.cfg"
    write_ti_cfg(r, out)
    assert read_ti_cfg(out) == r
    assert not list(tmp_path.glob("*.tmp"))


def test_variants_differ_as_described() -> None:
    lr = read_ti_cfg(CFG_DIR / "long_range.cfg")
    hv = read_ti_cfg(CFG_DIR / "high_velocity.cfg")
    assert lr.max_range_m > 2 * RadarConfig().max_range_m
    assert hv.max_velocity_mps > 2 * RadarConfig().max_velocity_mps
    assert hv.n_virtual == 8 and not hv.has_elevation
    assert hv.azimuth_positions == tuple(range(8))


def test_tx_order_permutes_virtual_positions(tmp_path: Path) -> None:
    text = ti_cfg_text(RadarConfig()).replace(
        "chirpCfg 1 1 0 0 0 0 0 2", "chirpCfg 1 1 0 0 0 0 0 X"
    )
    text = text.replace("chirpCfg 2 2 0 0 0 0 0 4", "chirpCfg 2 2 0 0 0 0 0 2")
    text = text.replace("chirpCfg 1 1 0 0 0 0 0 X", "chirpCfg 1 1 0 0 0 0 0 4")
    p = tmp_path / "order.cfg"
    p.write_text(text)
    r = read_ti_cfg(p)
    assert r.tx_order == (0, 2, 1)
    # slot 1 is now TX2 (azimuth 4..7), slot 2 the elevated TX1
    assert r.azimuth_positions == (0, 1, 2, 3, 4, 5, 6, 7, 2, 3, 4, 5)
    assert r.elevation_positions == (0,) * 8 + (1,) * 4


def _broken(tmp_path: Path, old: str, new: str) -> Path:
    text = (CFG_DIR / "paper.cfg").read_text()
    assert old in text
    p = tmp_path / "bad.cfg"
    p.write_text(text.replace(old, new))
    return p


def _line_of(path: Path, prefix: str) -> int:
    for i, line in enumerate(path.read_text().splitlines(), start=1):
        if line.startswith(prefix):
            return i
    raise AssertionError(prefix)


def test_broken_profile_cfg_names_file_line_and_field(tmp_path: Path) -> None:
    p = _broken(tmp_path, " 61.3663366337 ", " 61.3x ")
    with pytest.raises(InputError) as err:
        read_ti_cfg(p)
    msg = str(err.value)
    assert str(p) in msg
    assert f":{_line_of(p, 'profileCfg')}:" in msg
    assert "freqSlopeConst" in msg and "61.3x" in msg
    assert "\n" not in msg


def test_short_profile_cfg_names_missing_field(tmp_path: Path) -> None:
    p = _broken(tmp_path, " 0 0 36\n", "\n")
    with pytest.raises(InputError, match=r"profileCfg needs 14 fields.*hpfCornerFreq1"):
        read_ti_cfg(p)


def test_two_tx_in_one_chirp_is_rejected(tmp_path: Path) -> None:
    p = _broken(tmp_path, "chirpCfg 1 1 0 0 0 0 0 2", "chirpCfg 1 1 0 0 0 0 0 3")
    with pytest.raises(InputError, match=r"bad.cfg:\d+: chirpCfg field 8 'txEnable'"):
        read_ti_cfg(p)


def test_missing_frame_cfg_is_named(tmp_path: Path) -> None:
    p = _broken(tmp_path, "frameCfg", "%frameCfg")
    with pytest.raises(InputError, match="frameCfg"):
        read_ti_cfg(p)


def test_cli_radar_text_reads_cfg(capsys) -> None:
    assert main(["radar", "--cfg", str(CFG_DIR / "long_range.cfg")]) == 0
    out = capsys.readouterr().out
    assert "long_range" in out and "29.48 m" in out


def test_cli_radar_bad_cfg_exits_2(tmp_path: Path) -> None:
    p = _broken(tmp_path, " 61.3663366337 ", " 61.3x ")
    res = subprocess.run(
        [sys.executable, "-m", "core.cli", "radar", "--cfg", str(p)],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert res.returncode == 2
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and "freqSlopeConst" in lines[0] and "bad.cfg" in lines[0]
