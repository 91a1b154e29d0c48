"""DCA1000 captures through the exact chain: simulated round trips and the real OpenRadar frames."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from core.benchmarks.clouds import real_data_dir
from core.config import SPEED_OF_LIGHT_MPS
from core.dataset import Dataset
from core.errors import InputError
from core.formats.dca1000 import CaptureLayout, open_capture, write_capture_frames
from core.formats.ti_cfg import AdcFormat, read_ti_capture_cfg
from core.pipeline import iter_frames, processing_settings
from core.pipeline.capture import (
    ADC_NOISE_RMS_COUNTS,
    adc_count_v,
    dataset_from_capture,
    iter_adc_frames,
    quantise,
    write_capture,
)
from core.pointcloud import POINT_FIELDS
from core.scene import Scene
from core.simulation.frame import process_cube
from tests.scenes import small_scene

#: the real DCA1000 frames beside the checkout (../shared/real; $RADARTUNE_REAL_DATA overrides)
REAL = real_data_dir() / "openradar_adc"


@pytest.fixture(scope="module")
def scene() -> Scene:
    return Scene.from_dict(small_scene(velocity_mps=(0.4, -1.0), frames=4))


def test_written_capture_reads_back_bit_exact_with_same_points(
    scene: Scene, tmp_path: Path
) -> None:
    """simulate -> write -> read: the same int16 samples, and through the processing chain the
    same points as processing the quantised cube directly."""
    bin_path, cfg_path = write_capture(scene, tmp_path / "scene.bin")
    radar, adc = read_ti_capture_cfg(cfg_path)
    assert radar == scene.radar  # the .cfg describes the scene's radar
    layout = CaptureLayout.from_radar(radar, adc)
    capture = open_capture(bin_path, layout)
    assert capture.n_frames == scene.n_frames and capture.trailing_bytes == 0
    settings = processing_settings(scene)
    ds = dataset_from_capture(bin_path, cfg_path, settings=settings, elevation=False)
    from core.formats.dca1000 import iter_capture_frames

    direct = []
    for (i, q, n_clipped), cube in zip(
        iter_adc_frames(scene), iter_capture_frames(capture), strict=True
    ):
        assert n_clipped == 0
        assert np.array_equal(cube.real, i) and np.array_equal(cube.imag, q)
        quantised = i.astype(np.complex64) + 1j * q.astype(np.complex64)
        direct.append(process_cube(quantised, radar, settings=settings).point_cloud)
    for f, cloud in enumerate(direct):
        got = ds.point_cloud(f)
        assert len(got) == len(cloud) >= 1
        for name in POINT_FIELDS:
            assert np.array_equal(getattr(got, name), getattr(cloud, name)), name


def test_written_samples_are_the_exact_chains(scene: Scene) -> None:
    """The quantised samples are the exact chain's received cube (its signal plus its receiver
    noise) to half a count, the noise ADC_NOISE_RMS_COUNTS counts; processed they give the exact
    chain's points."""
    from core.pipeline.frames import frame_inputs
    from core.pipeline.plan import plan
    from core.simulation.baseband import synthesize_signal
    from core.simulation.gaussian import complex_noise
    from core.simulation.link import noise_power_v2

    radar = scene.radar
    lsb = adc_count_v(radar)
    fi = next(frame_inputs(scene, plan(scene, fidelity="exact"), scene.seed))
    signal = synthesize_signal(radar, fi.scatterers, fi.antenna)
    noise = complex_noise(signal.shape, noise_power_v2(radar), fi.rng)
    i, q, n_clipped = next(iter_adc_frames(scene))
    assert n_clipped == 0
    received = (signal + noise) / lsb
    assert np.abs(i - received.real).max() <= 0.5 + 1e-3
    assert np.abs(q - received.imag).max() <= 0.5 + 1e-3
    assert np.std(noise.real / lsb) == pytest.approx(ADC_NOISE_RMS_COUNTS, rel=0.02)
    settings = processing_settings(scene)
    cube = (i.astype(np.complex64) + 1j * q.astype(np.complex64)) * np.float32(lsb)
    ours = process_cube(cube, radar, settings=settings).point_cloud
    exact = next(iter_frames(scene, fidelity="exact")).point_cloud
    assert len(ours) == len(exact) == 1
    # quantisation adds 1/12 count^2 to 64: the point moves by far less than a range bin
    assert abs(ours.range_m[0] - exact.range_m[0]) < 0.02 * radar.range_resolution_m
    assert abs(ours.snr_db[0] - exact.snr_db[0]) < 0.1


def test_written_capture_is_i_first_as_ti_documents(scene: Scene, tmp_path: Path) -> None:
    """The first chirp's first words are I(0) I(1) Q(0) Q(1) of virtual channel 0, and the .cfg
    says so (sampleSwap 0)."""
    bin_path, cfg_path = write_capture(scene, tmp_path / "s.bin")
    assert read_ti_capture_cfg(cfg_path)[1] == AdcFormat(iq_swap=False)
    i, q, _ = next(iter_adc_frames(scene))
    words = np.fromfile(bin_path, dtype="<i2", count=4)
    assert words.tolist() == [i[0, 0, 0], i[0, 0, 1], q[0, 0, 0], q[0, 0, 1]]


def test_quantise_rounds_and_saturates() -> None:
    cube = np.array([0.4 + 1.6j, -2.5 - 1e9j, 1e9 + 0j])
    i, q, n = quantise(cube, 1.0)
    assert i.tolist() == [0, -2, 32767] and q.tolist() == [2, -32768, 0] and n == 2


def test_truth_csv_interpolated_to_frames(scene: Scene, tmp_path: Path) -> None:
    bin_path, cfg_path = write_capture(scene, tmp_path / "s.bin")
    t = scene.radar.frame_period_s
    csv = tmp_path / "truth.csv"
    # person 1 walks x = 1 + 2 t from t = 0 to 2 frames; person 0 stands from frame 1 on
    csv.write_text(
        f"time_s,person,x_m,y_m\n0,1,1,5\n{2 * t},1,{1 + 4 * t},5\n{t},0,-1,2\n{9 * t},0,-1,2\n"
    )
    ds = dataset_from_capture(bin_path, cfg_path, truth=csv)
    assert ds.truth_xy_m.shape == (4, 2, 2)
    assert np.isnan(ds.truth_xy_m[0, 0]).all() and ds.truth_xy_m[1, 0].tolist() == [-1, 2]
    assert ds.truth_xy_m[1, 1, 0] == pytest.approx(1 + 2 * t)
    assert ds.truth_v_mps[1, 1].tolist() == pytest.approx([2.0, 0.0])
    assert np.isnan(ds.truth_xy_m[3, 1]).all()  # after person 1's last row
    assert ds.fidelity == "real" and ds.trajectory_class.tolist() == ["real"]
    assert ds.scene()["imported"]["format"] == "dca1000"


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("time_s,person,x_m\n0,0,1\n", ":1: the first line must name the columns"),
        ("time_s,person,x_m,y_m\n0,0,1,nan\n1,0,1,1\n", ":2: y_m must be finite"),
        ("time_s,person,x_m,y_m\n0,-1,1,1\n", ":2: person must be an integer"),
        ("time_s,person,x_m,y_m\n-1,0,1,1\n", ":2: time_s must be >= 0"),
        ("", "no header line time_s,person,x_m,y_m"),
    ],
)
def test_bad_truth_csv_is_one_line(scene: Scene, tmp_path: Path, text: str, expected: str) -> None:
    bin_path, cfg_path = write_capture(scene, tmp_path / "s.bin")
    csv = tmp_path / "truth.csv"
    csv.write_text(text)
    with pytest.raises(InputError, match=expected) as err:
        dataset_from_capture(bin_path, cfg_path, truth=csv)
    assert "\n" not in str(err.value) and "truth.csv" in str(err.value)


def test_partial_frame_dropped_and_noted(scene: Scene, tmp_path: Path) -> None:
    bin_path, cfg_path = write_capture(scene, tmp_path / "s.bin")
    radar, adc = read_ti_capture_cfg(cfg_path)
    with bin_path.open("ab") as fh:
        fh.write(b"\0" * CaptureLayout.from_radar(radar, adc).chirp_bytes)
    notes: list[str] = []
    ds = dataset_from_capture(bin_path, cfg_path, note=notes.append)
    assert ds.n_frames == scene.n_frames
    assert len(notes) == 1 and "partial frame: dropped" in notes[0]


@pytest.mark.parametrize(
    ("drop", "expected"),
    [
        ("profileCfg", "missing command 'profileCfg'"),
        ("frameCfg", "missing command 'frameCfg'"),
        ("chirpCfg", "missing command 'chirpCfg'"),
    ],
)
def test_cfg_missing_fields_is_one_line(
    scene: Scene, tmp_path: Path, drop: str, expected: str
) -> None:
    bin_path, cfg_path = write_capture(scene, tmp_path / "s.bin")
    lines = cfg_path.read_text().splitlines()
    cfg_path.write_text("\n".join(li for li in lines if not li.startswith(drop)) + "\n")
    with pytest.raises(InputError, match=expected) as err:
        dataset_from_capture(bin_path, cfg_path)
    assert "s.cfg" in str(err.value)


def test_cfg_short_command_names_field(scene: Scene, tmp_path: Path) -> None:
    bin_path, cfg_path = write_capture(scene, tmp_path / "s.bin")
    text = cfg_path.read_text()
    line = next(li for li in text.splitlines() if li.startswith("profileCfg"))
    cfg_path.write_text(text.replace(line, " ".join(line.split()[:10])))
    with pytest.raises(InputError, match="numAdcSamples' missing"):
        dataset_from_capture(bin_path, cfg_path)


def test_cfg_of_another_radar_is_size_mismatch(scene: Scene, tmp_path: Path) -> None:
    bin_path, cfg_path = write_capture(scene, tmp_path / "s.bin")
    other = tmp_path / "other.cfg"
    other.write_text(cfg_path.read_text().replace(" 256 5900 ", " 250 5900 "))
    with pytest.raises(InputError, match="does not match") as err:
        dataset_from_capture(bin_path, other)
    assert "other.cfg" in str(err.value) and "s.bin" in str(err.value)


# ---- the real recordings (OpenRadar, TI 77 GHz, 2 TX x 4 RX TDM) ------------------------------

#: the chirp the recordings were made with (README / PROVENANCE of ../shared/real/openradar_adc)
F0_GHZ, IDLE_US, RAMP_US, SLOPE_MHZ_US, N_SAMPLES, FS_KSPS = 77.4201, 30.0, 62.0, 60.0, 128, 2500


def _real_cfg(path: Path, *, n_tx: int, n_rx: int, n_loops: int, idle_us: float) -> Path:
    chirps = ["chirpCfg 0 0 0 0 0 0 0 1", "chirpCfg 1 1 0 0 0 0 0 4"][:n_tx]
    path.write_text(
        "\n".join(
            [
                "% the OpenRadar recordings' chirp, written for the test",
                f"channelCfg {(1 << n_rx) - 1} {5 if n_tx == 2 else 1} 0",
                "adcCfg 2 1",
                "adcbufCfg -1 0 0 1 1",  # I before Q, as TI documents the DCA1000 layout
                f"profileCfg 0 {F0_GHZ} {idle_us} 6 {RAMP_US} 0 0 {SLOPE_MHZ_US} 1 {N_SAMPLES} "
                f"{FS_KSPS} 0 0 30",
                *chirps,
                f"frameCfg 0 {n_tx - 1} {n_loops} 1 100 1 0",
            ]
        )
        + "\n"
    )
    return path


def _int16(a: np.ndarray) -> np.ndarray:
    """The stored parts (int16 read as uint16) back as int16."""
    return a.astype(np.uint16).view(np.int16)


def _plain_peak(x: np.ndarray) -> tuple[int, int]:
    """Range bin and Doppler bin (zero centred) of the strongest cell of a plain decode:
    ``x[loop, channel, sample]``, FFT over samples, mean over loops removed, FFT over loops."""
    rf = np.fft.fft(x, axis=-1)
    rf = rf - rf.mean(axis=0, keepdims=True)
    p = (np.abs(np.fft.fftshift(np.fft.fft(rf, axis=0), axes=0)) ** 2).sum(axis=1)
    j, k = np.unravel_index(np.argmax(p), p.shape)
    return int(k), int(j) - x.shape[0] // 2


@pytest.mark.skipif(not REAL.is_dir(), reason=f"real recordings not present: {REAL}")
@pytest.mark.parametrize(
    ("name", "range_m", "velocity_mps"),
    [("doppler_example_1", 2.9, 0.6), ("simple_frame_1", 2.0, -0.7)],
)
def test_real_openradar_frames_through_adc_path(
    tmp_path: Path, name: str, range_m: float, velocity_mps: float
) -> None:
    a = np.load(REAL / f"{name}.npy")
    if a.ndim == 2:
        # one virtual channel, its chirps every 2 x (idle + ramp): as one TX with the idle time
        # of the other TX's chirp added (the same loop period, hence the same Doppler axis)
        a = a[:, None, :]
        n_tx, n_rx, idle = 1, 1, IDLE_US + (IDLE_US + RAMP_US)
    else:
        n_tx, n_rx, idle = 2, 4, IDLE_US
    n_loops = a.shape[0]
    assert a.shape == (n_loops, n_tx * n_rx, N_SAMPLES)
    i, q = _int16(a.real), _int16(a.imag)
    cfg = _real_cfg(tmp_path / f"{name}.cfg", n_tx=n_tx, n_rx=n_rx, n_loops=n_loops, idle_us=idle)
    radar, adc = read_ti_capture_cfg(cfg)
    assert adc == AdcFormat()
    layout = CaptureLayout.from_radar(radar, adc)
    # [loop, channel, sample] -> the cube [channel, loop, sample]
    bin_path = write_capture_frames(
        tmp_path / f"{name}.bin",
        [(i.transpose(1, 0, 2).copy(), q.transpose(1, 0, 2).copy())],
        layout,
    )
    ds = dataset_from_capture(bin_path, cfg)
    assert ds.n_frames == 1 and len(ds.frame) >= 1
    strongest = int(np.argmax(ds.snr_db))
    r_got, v_got = ds.range_m[strongest], ds.radial_velocity_mps[strongest]

    # bins from the chirp: dR = c Fs / (2 S N), dv = lambda / (2 Ntx Nloops Tchirp)
    c = SPEED_OF_LIGHT_MPS
    d_r = c * FS_KSPS * 1e3 / (2 * SLOPE_MHZ_US * 1e12 * N_SAMPLES)
    lam = c / (F0_GHZ * 1e9)
    d_v = lam / (2 * 2 * n_loops * (IDLE_US + RAMP_US) * 1e-6)
    assert radar.range_resolution_m == pytest.approx(d_r, rel=1e-6)
    assert radar.velocity_resolution_mps == pytest.approx(d_v, rel=1e-6)
    # where the recordings' README puts the reflector, to one bin
    assert abs(r_got - range_m) <= d_r
    assert abs(v_got - velocity_mps) <= d_v + 0.05  # the README rounds to 0.1 m/s
    # where a plain decode of the stored array puts it, to one bin
    k, j = _plain_peak(i.astype(np.float64) + 1j * q.astype(np.float64))
    assert abs(r_got / d_r - k) <= 1 and abs(v_got / d_v - j) <= 1
    # ~50 dB above the noise: no weak detection was taken for the reflector
    assert ds.snr_db[strongest] > 30


def test_real_sampled_capture_is_processed_up_to_half_the_range(tmp_path: Path) -> None:
    """Real samples (adcCfg format 0): one tone at bin k shows at k (and its mirror N-k, beyond
    the half of the bins that is kept)."""
    cfg = _real_cfg(tmp_path / "r.cfg", n_tx=1, n_rx=1, n_loops=32, idle_us=IDLE_US)
    cfg.write_text(
        cfg.read_text()
        .replace("adcCfg 2 1", "adcCfg 2 0")
        .replace("adcbufCfg -1 0 0 1 1", "adcbufCfg -1 1 0 1 1")
    )
    radar, adc = read_ti_capture_cfg(cfg)
    layout = CaptureLayout.from_radar(radar, adc)
    n, k, dj = N_SAMPLES, 40, 5
    m = np.arange(radar.n_loops)[:, None]
    # a real tone at range bin k moving by Doppler bin dj: cos(2 pi (k n / N + dj m / M))
    tone = 3000 * np.cos(2 * np.pi * (k * np.arange(n)[None, :] / n + dj * m / radar.n_loops))
    i = np.rint(tone + np.random.default_rng(0).normal(0, 8, tone.shape)).astype(np.int16)
    bin_path = write_capture_frames(tmp_path / "r.bin", [(i[None], None)], layout)
    ds = dataset_from_capture(bin_path, cfg)
    strongest = int(np.argmax(ds.snr_db))
    assert ds.range_m[strongest] / radar.range_resolution_m == pytest.approx(k, abs=0.5)
    assert ds.radial_velocity_mps[strongest] / radar.velocity_resolution_mps == pytest.approx(
        dj, abs=0.5
    )
    assert ds.range_m.max() <= radar.max_range_m / 2


def test_settings_are_taken(scene: Scene, tmp_path: Path) -> None:
    """A tighter range limit drops the person (at 5 m) from the cloud."""
    bin_path, cfg_path = write_capture(scene, tmp_path / "s.bin")
    near = dataclasses.replace(processing_settings(scene), max_range_m=3.0)
    assert len(dataset_from_capture(bin_path, cfg_path, settings=near).frame) == 0


def test_import_and_export_a_capture_through_the_cli(scene: Scene, tmp_path: Path, capsys) -> None:
    """`radartune export --format dca1000` then `radartune import --cfg`: the points of the
    capture processed directly."""
    from core.cli import main

    scene_file = tmp_path / "scene.json"
    scene.to_json(scene_file)
    out = tmp_path / "cap.bin"
    assert (
        main(["export", "--scene", str(scene_file), "--format", "dca1000", "--out", str(out)]) == 0
    )
    cfg = out.with_suffix(".cfg")
    assert cfg.is_file()
    ds_path = tmp_path / "cap.npz"
    assert main(["import", str(out), "--cfg", str(cfg), "--out", str(ds_path)]) == 0
    direct = dataset_from_capture(out, cfg)
    ds = Dataset.load(ds_path)
    assert ds.n_frames == scene.n_frames == direct.n_frames
    np.testing.assert_array_equal(ds.range_m, direct.range_m)
    np.testing.assert_array_equal(ds.radial_velocity_mps, direct.radial_velocity_mps)
    # the ADC samples are the exact chain's: another fidelity is refused with one line
    code = main(
        [
            "export",
            "--scene",
            str(scene_file),
            "--format",
            "dca1000",
            "--out",
            str(tmp_path / "b.bin"),
            "--fidelity",
            "fast",
        ]
    )
    err = capsys.readouterr().err
    assert code == 2 and "--fidelity must be exact for dca1000" in err
