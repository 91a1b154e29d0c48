"""Every bad input the CLI reads gets one line on stderr, exit code 2, and nothing written.

One test per kind of input that ended in a traceback, a huge allocation, a run of minutes or a
``nan`` before. The CLI runs in-process (``core.cli.main``)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from core.cli import main
from core.limits import (
    MAX_PERSON_FRAMES,
    MAX_PERSONS,
    MAX_STATIC_REFLECTORS,
    MAX_TRACKS,
    VARIANCE_RANGE,
)
from tests.scenes import small_scene

SCENE = small_scene()


def run_cli(capsys, *argv: str) -> tuple[int, str, str]:
    capsys.readouterr()
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def assert_one_line(code: int, err: str, *needles: str) -> None:
    assert code == 2, err
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert "Traceback" not in err
    for needle in needles:
        assert needle in lines[0], lines[0]


@pytest.fixture(scope="module")
def dataset(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("edges")
    scene = folder / "scene.json"
    scene.write_text(json.dumps(SCENE))
    out = folder / "ok.npz"
    assert main(["simulate", "--scene", str(scene), "--out", str(out), "--fidelity", "fast"]) == 0
    return out


def rewrite(src: Path, dst: Path, **changes) -> Path:
    with np.load(src) as z:
        arrays = {k: z[k] for k in z.files}
    arrays.update(changes)
    np.savez(dst, **arrays)
    return dst


# ---- data-set .npz -----------------------------------------------------------------------------


def test_track_valid_dataset(capsys, dataset: Path) -> None:
    code, out, err = run_cli(capsys, "track", "--data", str(dataset))
    assert code == 0, err
    assert "nan" not in out.lower()


def test_zero_byte_dataset(capsys, tmp_path: Path) -> None:
    (tmp_path / "empty.npz").write_bytes(b"")
    code, _, err = run_cli(capsys, "track", "--data", str(tmp_path / "empty.npz"))
    assert_one_line(code, err, "empty.npz", "0 bytes")


def test_dataset_header_claiming_1e12_elements(capsys, dataset: Path, tmp_path: Path) -> None:
    import io
    import zipfile

    bad = tmp_path / "huge.npz"
    with zipfile.ZipFile(dataset) as src, zipfile.ZipFile(bad, "w") as dst:
        for info in src.infolist():
            data = src.read(info)
            if info.filename == "range_m.npy":
                buf = io.BytesIO()
                header = {"descr": "<f8", "fortran_order": False, "shape": (10**12,)}
                np.lib.format.write_array_header_1_0(buf, header)
                data = buf.getvalue()
            dst.writestr(info.filename, data)
    code, _, err = run_cli(capsys, "track", "--data", str(bad))
    assert_one_line(code, err, "huge.npz", "range_m")


def test_dataset_flipped_bytes(capsys, dataset: Path, tmp_path: Path) -> None:
    data = bytearray(dataset.read_bytes())
    bad = tmp_path / "flipped.npz"
    refused = 0
    for at in range(100, len(data) - 100, max(1, len(data) // 60)):
        mutated = bytearray(data)
        mutated[at] ^= 0x5A
        bad.write_bytes(bytes(mutated))
        code, _, err = run_cli(capsys, "track", "--data", str(bad))
        if code != 0:
            assert_one_line(code, err, "flipped.npz")
            refused += 1
    assert refused > 10


@pytest.mark.parametrize(
    ("change", "needle"),
    [
        ({"truth_xy_m": np.zeros((3, 1, 2))}, "truth_xy_m"),
        ({"truth_xy_m": np.zeros((6, 2))}, "truth_xy_m"),
        ({"truth_v_mps": np.zeros((6, 2, 2))}, "truth_v_mps"),
        ({"truth_t_s": np.zeros(2)}, "truth_t_s"),
        ({"trajectory": np.zeros(4, dtype=np.int32)}, "shape"),
        ({"trajectory": np.array([0, 0, 0, 2, 2, 2], dtype=np.int32)}, "trajectory"),
        ({"trajectory_class": np.array(["c", "c", "c"])}, "trajectory_class"),
        ({"trajectory_class": np.array([1, 2])}, "trajectory_class"),
        ({"frame": np.array(["x"])}, "frame"),
        ({"truth_t_s": np.full(6, np.inf)}, "truth_t_s"),
        ({"truth_xy_m": np.array([[[1.0, np.nan]]] * 6)}, "NaN together"),
        ({"scene_json": np.array("[" * 5000)}, "nested deeper"),
        ({"radar_json": np.array('{"frame_period_s": 1e300}')}, "frame_period_s"),
        ({"seed": np.array([1, 2])}, "seed"),
    ],
)
def test_inconsistent_dataset_arrays(capsys, dataset, tmp_path, change, needle) -> None:
    """Before the fix: IndexError/ValueError/TypeError tracebacks or a `nan` in the table."""
    bad = rewrite(dataset, tmp_path / "bad.npz", **change)
    code, out, err = run_cli(capsys, "track", "--data", str(bad), "--out", str(tmp_path / "o.json"))
    assert_one_line(code, err, "bad.npz", needle)
    assert not (tmp_path / "o.json").exists()


# ---- JSON files --------------------------------------------------------------------------------


def test_scene_nested_1000_deep(capsys, tmp_path: Path) -> None:
    path = tmp_path / "deep.json"
    path.write_text('{"schema_version": 1, "persons": ' + "[" * 1000 + "]" * 1000 + "}")
    code, _, err = run_cli(
        capsys, "simulate", "--scene", str(path), "--out", str(tmp_path / "o.npz")
    )
    assert_one_line(code, err, "deep.json:1", "nested deeper")
    assert not (tmp_path / "o.npz").exists()


def test_params_nested_1000_deep(capsys, dataset, tmp_path: Path) -> None:
    path = tmp_path / "deep.json"
    path.write_text('{"p0": ' + "[" * 1000 + "]" * 1000 + "}")
    code, _, err = run_cli(capsys, "track", "--data", str(dataset), "--params", str(path))
    assert_one_line(code, err, "deep.json:1", "nested deeper")


def test_params_latin1_byte(capsys, dataset, tmp_path: Path) -> None:
    path = tmp_path / "latin.json"
    path.write_bytes(b'{"model": "cv", "r11": 0.05, "note\xe9": 1}')
    code, _, err = run_cli(capsys, "track", "--data", str(dataset), "--params", str(path))
    assert_one_line(code, err, "latin.json:1", "not UTF-8")


@pytest.mark.parametrize(
    ("radar", "needle"),
    [("\u0000", "NUL"), ("\ud800", "surrogate"), ("x" * 5000 + ".cfg", "radar")],
)
def test_scene_radar_string_nul_surrogate_long(capsys, tmp_path, radar, needle) -> None:
    path = tmp_path / "s.json"
    path.write_text(json.dumps({**SCENE, "radar": radar}))  # json.dumps escapes to \\u0000
    code, _, err = run_cli(
        capsys, "simulate", "--scene", str(path), "--out", str(tmp_path / "o.npz")
    )
    assert_one_line(code, err, "s.json", needle)


def test_scene_binary_bytes(capsys, tmp_path: Path) -> None:
    path = tmp_path / "bin.json"
    path.write_bytes(bytes(range(256)))
    code, _, err = run_cli(capsys, "simulate", "--scene", str(path), "--explain")
    assert_one_line(code, err, "bin.json")


# ---- values that validate but cannot run -------------------------------------------------------


@pytest.mark.parametrize(
    ("params", "needle"),
    [
        ({"max_tracks": 1e9}, f"max_tracks must be in [1, {MAX_TRACKS}]"),
        ({"max_tracks": MAX_TRACKS + 1}, "max_tracks"),
        ({"r22": 3e298}, f"r22 must be in [{VARIANCE_RANGE[0]:g}, {VARIANCE_RANGE[1]:g}]"),
        ({"r11": 1e-300}, "r11 must be in"),
        ({"q_coeff": 1e200}, "q_coeff must be in"),
        ({"p0": [1e300, 1, 1, 1]}, "p0[0] must be in"),
        ({"clutter_density": 1e300}, "clutter_density must be in"),
    ],
)
def test_params_past_what_the_kernel_runs(capsys, dataset, tmp_path, params, needle) -> None:
    """Before the fix: 1.2 TiB allocation, OverflowError in the kernel, or accepted."""
    path = tmp_path / "p.json"
    path.write_text(json.dumps(params))
    code, _, err = run_cli(capsys, "track", "--data", str(dataset), "--params", str(path))
    assert_one_line(code, err, "p.json", needle)


def test_max_tracks_limit_itself_runs(capsys, dataset, tmp_path) -> None:
    path = tmp_path / "p.json"
    path.write_text(json.dumps({"max_tracks": MAX_TRACKS, "r22": VARIANCE_RANGE[1]}))
    code, out, err = run_cli(capsys, "track", "--data", str(dataset), "--params", str(path))
    assert code == 0, err


def person(frames: int) -> dict:
    return {
        "trajectory": {
            "initial_position_m": [1.0, 5.0],
            "initial_velocity_mps": [0.0, 0.0],
            "acceleration_mps2": [0.0, 0.0],
            "frames": frames,
        }
    }


@pytest.mark.parametrize(
    ("change", "needle"),
    [
        ({"persons": [person(5)] * 10_000}, f"more than the limit {MAX_PERSONS}"),
        (
            {"static_reflectors": [{"x_m": 1.0, "y_m": 2.0}] * (MAX_STATIC_REFLECTORS + 1)},
            f"more than the limit {MAX_STATIC_REFLECTORS}",
        ),
        ({"persons": [person(100_000)]}, "frames"),
        ({"persons": [person(MAX_PERSON_FRAMES // 4)] * 5}, "persons x frames"),
        (
            {
                "persons": [{"trajectory": {"class": "c", "duration_s": 600.0}}],
                "radar": {"n_loops": 1, "frame_period_s": 0.001},
            },
            "frames",
        ),
        ({"radar": {"n_samples": 65536, "n_loops": 128, "frame_period_s": 10.0}}, "limit"),
    ],
)
def test_scene_work_bounded(capsys, tmp_path, change, needle) -> None:
    """Before the fix: MemoryError (10^4 persons, 10^6 reflectors) or minutes of simulation."""
    path = tmp_path / "s.json"
    path.write_text(json.dumps({**SCENE, **change}))
    code, _, err = run_cli(
        capsys, "simulate", "--scene", str(path), "--out", str(tmp_path / "o.npz")
    )
    assert_one_line(code, err, "s.json", needle)
    assert not (tmp_path / "o.npz").exists()


def test_scene_with_a_person_1e300_m_away(capsys, tmp_path) -> None:
    """Before the fix: accepted and simulated with an overflow warning."""
    far = {"trajectory": {"initial_position_m": [1e300, 5.0], "initial_velocity_mps": [0.0, 0.0],
                          "acceleration_mps2": [0.0, 0.0], "frames": 5}}  # fmt: skip
    path = tmp_path / "s.json"
    path.write_text(json.dumps({**SCENE, "persons": [far]}))
    code, _, err = run_cli(
        capsys, "simulate", "--scene", str(path), "--out", str(tmp_path / "o.npz")
    )
    assert_one_line(code, err, "s.json", "persons[0].trajectory.initial_position_m[0]", "1e+300")
    assert not (tmp_path / "o.npz").exists()


# ---- command line ------------------------------------------------------------------------------


@pytest.mark.parametrize("port", ["70000", "-1"])
def test_dashboard_port_out_of_range(capsys, port: str) -> None:
    """Before the fix: OverflowError traceback."""
    code, _, err = run_cli(capsys, "dashboard", "--port", port, "--no-browser")
    assert_one_line(code, err, "--port must be in [0, 65535]")


def test_unexpected_error_is_one_line_and_debug_shows_traceback(capsys, monkeypatch, tmp_path):
    import core.cli.radar as radar

    def boom(args):
        raise ZeroDivisionError("division by zero\nsecond line")

    monkeypatch.setattr(radar, "run", boom)
    cfg = tmp_path / "x.cfg"
    code, _, err = run_cli(capsys, "radar", "--cfg", str(cfg))
    assert_one_line(
        code, err, "unexpected ZeroDivisionError", "x.cfg", "division by zero", "--debug"
    )
    code, _, err = run_cli(capsys, "--debug", "radar", "--cfg", str(cfg))
    assert code == 2 and "Traceback" in err and "ZeroDivisionError" in err


def test_keyboard_interrupt_and_broken_pipe_kept(capsys, monkeypatch) -> None:
    import core.cli.radar as radar

    def interrupt(args):
        raise KeyboardInterrupt

    monkeypatch.setattr(radar, "run", interrupt)
    code, _, err = run_cli(capsys, "radar")
    assert code == 130 and err.strip() == "radartune radar: interrupted"


# ---- arguments and outputs ---------------------------------------------------------------------


def test_unwritable_output_refused_before_the_work(capsys, dataset, tmp_path) -> None:
    """Before the fix: a FileNotFoundError/IsADirectoryError traceback after simulating."""
    scene = tmp_path / "s.json"
    scene.write_text(json.dumps(SCENE))
    code, _, err = run_cli(capsys, "simulate", "--scene", str(scene), "--out", str(tmp_path))
    assert_one_line(code, err, "is a folder")
    (tmp_path / "file").write_text("x")
    out = str(tmp_path / "file" / "o.json")
    code, _, err = run_cli(capsys, "track", "--data", str(dataset), "--out", out)
    assert_one_line(code, err, "is not a folder")


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["dataset", "--out", "x.npz", "--trajectories", "100000000"], "--trajectories must be in"),
        (["dataset", "--out", "x.npz", "--jobs", "100000"], "--jobs must be in"),
        (["stability", "--frames", "1000000000"], "--frames must be in"),
    ],
)
def test_argument_limits(capsys, tmp_path, monkeypatch, argv, needle) -> None:
    monkeypatch.chdir(tmp_path)
    code, _, err = run_cli(capsys, *argv)
    assert_one_line(code, err, needle)
    assert list(tmp_path.iterdir()) == []


def test_track_trajectory_index_overflow(capsys, dataset) -> None:
    """Before the fix: OverflowError converting the index to int64."""
    code, _, err = run_cli(capsys, "track", "--data", str(dataset), "--trajectories", "9" * 25)
    assert_one_line(code, err, "--trajectories must be indices in [0, 1)")


@pytest.mark.parametrize(
    "argv", [["dashboard", "--port", "abc"], ["track"], ["bogus"], ["simulate", "--scene"]]
)
def test_usage_errors_are_one_line(capsys, argv) -> None:
    """argparse printed the usage and then the error: two lines or more before the fix."""
    with pytest.raises(SystemExit) as exc:
        main(argv)
    err = capsys.readouterr().err
    assert exc.value.code == 2 and len(err.splitlines()) == 1 and "--help" in err, err


def test_person_model_bad_input_is_one_line(tmp_path, capsys) -> None:
    code, _, err = run_cli(
        capsys, "dataset", "--out", str(tmp_path / "d.npz"), "--person-model", "stick-figure"
    )
    assert_one_line(code, err, "--person-model must be one of", "walking")
    walking = json.loads(json.dumps(SCENE))
    walking["persons"][0]["model"] = "walking"
    walking["persons"][0]["height_m"] = 0.0
    scene = tmp_path / "walking.json"
    scene.write_text(json.dumps(walking))
    out = tmp_path / "w.npz"
    code, _, err = run_cli(capsys, "simulate", "--scene", str(scene), "--out", str(out))
    assert_one_line(code, err, "persons[0].height_m must be in [1.0, 2.2]")
    walking["persons"][0]["height_m"] = 1.7
    scene.write_text(json.dumps(walking))
    code, _, err = run_cli(
        capsys, "simulate", "--scene", str(scene), "--out", str(out), "--fidelity", "measurement"
    )
    # the measurement level simulates the walking body (core.simulation.body_cells)
    assert code == 0 and out.exists(), err
