"""``radartune radar [--cfg FILE] [--json]``: print a radar configuration and its derived values."""

from __future__ import annotations

import argparse
import json
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from core.config import RadarConfig


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "radar", help="show a radar configuration (the paper's or a TI .cfg) and derived values"
    )
    p.add_argument("--cfg", metavar="FILE", help="TI mmWave SDK .cfg file (default: the paper's)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=run)


def describe(radar: RadarConfig) -> dict[str, Any]:
    """Fields and derived values of ``radar`` as one flat JSON-ready dict."""
    return {"name": radar.name, **radar.to_dict(), **radar.derived()}


def run(args: argparse.Namespace) -> int:
    from core.config import PAPER_RADAR
    from core.formats.ti_cfg import read_ti_cfg

    radar = read_ti_cfg(args.cfg) if args.cfg else PAPER_RADAR
    info = describe(radar)
    if args.json:
        print(json.dumps(info, indent=2))
        return 0
    d = radar.derived()
    print(f"radar configuration: {radar.name}" + (f" ({args.cfg})" if args.cfg else ""))
    rows = [
        ("carrier frequency", f"{radar.start_frequency_hz / 1e9:.3f} GHz"),
        ("wavelength", f"{d['wavelength_m'] * 1e3:.4f} mm"),
        ("ramp / idle time", f"{radar.ramp_time_s * 1e6:.2f} / {radar.idle_time_s * 1e6:.2f} us"),
        (
            "bandwidth, slope",
            f"{radar.bandwidth_hz / 1e9:.4f} GHz, {d['slope_hz_per_s'] / 1e12:.4f} MHz/us",
        ),
        ("TX x RX (TX order)", f"{radar.n_tx} x {radar.n_rx} {radar.tx_order}"),
        (
            "loops x samples",
            f"{radar.n_loops} x {radar.n_samples} at {radar.sample_rate_hz / 1e6:.3f} Msps",
        ),
        ("frame period", f"{radar.frame_period_s * 1e3:.1f} ms"),
        ("range bin", f"{d['range_resolution_m'] * 100:.3f} cm"),
        ("max range", f"{d['max_range_m']:.2f} m"),
        ("max velocity", f"+-{d['max_velocity_mps']:.3f} m/s"),
        ("velocity bin", f"{d['velocity_resolution_mps']:.4f} m/s"),
        ("Pt, Gmax", f"{radar.tx_power_dbm:.1f} dBm, {radar.antenna_gain_db:.1f} dB"),
        (
            "Ge, F, Be",
            f"{radar.receiver_gain_db:.1f} dB, {radar.noise_figure_db:.1f} dB, "
            f"{radar.receiver_bandwidth_hz / 1e6:.3f} MHz",
        ),
        ("elevation", "yes" if radar.has_elevation else "no"),
    ]
    for key, value in rows:
        print(f"  {key:20s} {value}")
    return 0
