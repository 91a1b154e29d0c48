"""Property-based fuzzing of every file the CLI reads: scene JSON (``simulate``), TI ``.cfg``
(``radar``), tracker parameter JSON and data-set ``.npz`` (``track``) — generated from the
formats' structure and made by byte-level and tree-level mutations of valid files (the shipped
resources and a small simulated data set). Each input must give exit 0, or exit 2 with one line;
see :func:`tests.fuzz.harness.run_input`."""

from __future__ import annotations

import io
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tests.fuzz.conftest import FUZZ_SETTINGS
from tests.fuzz.harness import check, run_input

pytestmark = pytest.mark.fuzz

ROOT = Path(__file__).resolve().parents[2]
SCENES = sorted((ROOT / "resources" / "scenes").glob("*.json"))
CFGS = sorted((ROOT / "resources" / "radar").glob("*.cfg"))

# ---- building blocks -----------------------------------------------------------------------------

#: Numbers at and past the edges: zero, signs, huge, tiny, integers as floats, limits' neighbours.
EDGE_NUMBERS = [
    0,
    -1,
    1,
    2,
    8,
    9,
    200,
    201,
    10_000,
    100_000,
    10**9,
    10**12,
    2**63,
    -(2**63),
    0.0,
    -0.0,
    0.5,
    1e-300,
    1e-12,
    1e12,
    3e298,
    1e308,
    -1e308,
    0.08,
    60e9,
    math.pi,
]
numbers = st.one_of(
    st.sampled_from(EDGE_NUMBERS),
    st.integers(-(10**6), 10**6),
    st.floats(allow_nan=False, allow_infinity=False),
    st.floats(-50, 50),
)
#: Strings with the characters that broke readers: NUL, lone surrogates, paths, controls.
EDGE_STRINGS = [
    "",
    "\x00",
    "\ud800",
    "a\udfffb",
    "paper",
    "cv",
    "ca",
    "nonparametric",
    "../../etc/passwd",
    "x" * 5000,
    "\n",
    "résumé",
    "paper.cfg",
    "../radar/paper.cfg",
    "drawn",
    "a",
    "extended",
]
strings = st.one_of(st.sampled_from(EDGE_STRINGS), st.text(max_size=20))
scalars = st.one_of(numbers, strings, st.booleans(), st.none())
json_values = st.recursive(
    scalars,
    lambda inner: st.one_of(
        st.lists(inner, max_size=4), st.dictionaries(strings, inner, max_size=4)
    ),
    max_leaves=12,
)
#: Special texts inserted by byte mutations.
TOKENS = [
    b"NaN",
    b"Infinity",
    b"-1",
    b"1e308",
    b"3e298",
    b"1e9",
    b"100000",
    b"[" * 200,
    b"{" * 200,
    b'"\\u0000"',
    b'"\\ud800"',
    b"\x00",
    b"\xff\xfe",
    b"\xe9",
    b"null",
    b"true",
    b'""',
    b",",
    b"}",
]


@st.composite
def byte_mutations(draw, data: bytes) -> bytes:
    """``data`` with 1-8 random edits: flip, set, insert, delete, truncate, splice a token."""
    out = bytearray(data)
    for _ in range(draw(st.integers(1, 8))):
        op = draw(st.sampled_from(["flip", "set", "insert", "delete", "truncate", "token", "dup"]))
        at = draw(st.integers(0, max(0, len(out) - 1)))
        if op == "flip" and out:
            out[at] ^= 1 << draw(st.integers(0, 7))
        elif op == "set" and out:
            out[at] = draw(st.integers(0, 255))
        elif op == "insert":
            out[at:at] = bytes([draw(st.integers(0, 255))])
        elif op == "delete":
            del out[at : at + draw(st.integers(1, 16))]
        elif op == "truncate":
            del out[at:]
        elif op == "token":
            n = draw(st.integers(0, 8))
            out[at : at + n] = draw(st.sampled_from(TOKENS))
        elif op == "dup":
            n = draw(st.integers(1, 64))
            out[at:at] = out[at : at + n]
    return bytes(out)


@st.composite
def tree_mutation(draw, doc: Any) -> Any:
    """``doc`` (parsed JSON) with one node replaced by a generated value, removed, or a list
    entry repeated many times."""
    doc = json.loads(json.dumps(doc))
    paths: list[tuple] = []

    def walk(node: Any, path: tuple) -> None:
        paths.append(path)
        if isinstance(node, dict):
            for k, v in node.items():
                walk(v, (*path, k))
        elif isinstance(node, list):
            for i, v in enumerate(node):
                walk(v, (*path, i))

    walk(doc, ())
    path = draw(st.sampled_from(paths))
    op = draw(st.sampled_from(["replace", "replace", "delete", "repeat", "add"]))
    value = draw(json_values)
    if not path:
        return value if op == "replace" else doc
    parent = doc
    for key in path[:-1]:
        parent = parent[key]
    key = path[-1]
    if op == "replace":
        parent[key] = value
    elif op == "delete":
        del parent[key]
    elif op == "repeat" and isinstance(parent, list):
        parent[key:key] = [parent[key]] * draw(st.sampled_from([1, 8, 9, 1001, 10_000]))
    elif op == "add" and isinstance(parent[key], dict):
        parent[key][draw(strings)] = value
    else:
        parent[key] = value
    return doc


def dumps(doc: Any) -> bytes:
    """JSON bytes as any tool might write them (NaN as the literal, non-ASCII as UTF-8, lone
    surrogates escaped)."""
    return json.dumps(doc, indent=1).encode("utf-8", "surrogatepass")


# ---- scene JSON: simulate ------------------------------------------------------------------------


def simulate(name: str, data: bytes, label: str, extra: dict[str, bytes] | None = None) -> None:
    def write(folder: Path) -> list[str]:
        (folder / name).write_bytes(data)
        for other, content in (extra or {}).items():
            (folder / other).write_bytes(content)
        out = folder / "out" / "run.npz"
        return ["simulate", "--scene", str(folder / name), "--out", str(out), "--fidelity", "fast"]

    problems = run_input(write, label=label)
    check(problems)


trajectories = st.one_of(
    st.fixed_dictionaries(
        {"class": st.sampled_from(list("abcde") + ["z"])},
        optional={"seed": numbers, "speed_mps": numbers, "duration_s": numbers},
    ),
    st.fixed_dictionaries(
        {"waypoints": st.lists(st.lists(numbers, min_size=3, max_size=3), min_size=0, max_size=6)}
    ),
    st.fixed_dictionaries(
        {
            "initial_position_m": st.lists(numbers, min_size=2, max_size=2),
            "initial_velocity_mps": st.lists(numbers, min_size=2, max_size=2),
            "acceleration_mps2": st.lists(numbers, min_size=2, max_size=2),
        },
        optional={"frames": numbers},
    ),
    json_values,
)
radars = st.one_of(
    st.sampled_from(["paper", "../radar/paper.cfg", "missing.cfg", "x.cfg"]),
    st.dictionaries(
        st.sampled_from(
            [
                "n_loops",
                "n_samples",
                "frame_period_s",
                "n_tx",
                "sample_rate_hz",
                "start_frequency_hz",
                "bandwidth_hz",
                "tx_order",
                "colour",
            ]
        ),
        json_values,
        max_size=3,
    ),
    json_values,
)
scenes = st.fixed_dictionaries(
    {"schema_version": st.sampled_from([1, 1, 1, 2, "1"])},
    optional={
        "radar": radars,
        "seed": numbers,
        "clutter_density_per_m2": numbers,
        "aoi": st.dictionaries(
            st.sampled_from(["min_range_m", "max_range_m", "max_azimuth_deg", "colour"]),
            numbers,
            max_size=3,
        ),
        "static_reflectors": st.lists(
            st.dictionaries(st.sampled_from(["x_m", "y_m", "z_m", "rcs_dbsm"]), numbers), max_size=4
        ),
        "persons": st.lists(
            st.fixed_dictionaries(
                {"trajectory": trajectories},
                optional={
                    "rcs_dbsm": numbers,
                    "model": st.sampled_from(["point", "extended", "x"]),
                },
            ),
            max_size=3,
        ),
    },
)


@FUZZ_SETTINGS
@given(doc=scenes, cfg=st.sampled_from(CFGS))
def test_generated_scenes(doc: dict, cfg: Path) -> None:
    if doc.get("radar") == "x.cfg":
        simulate("scene.json", dumps(doc), "scene generated", {"x.cfg": cfg.read_bytes()})
    else:
        simulate("scene.json", dumps(doc), "scene generated")


@FUZZ_SETTINGS
@given(data=st.data(), path=st.sampled_from(SCENES), bytes_level=st.booleans())
def test_mutated_shipped_scenes(data, path: Path, bytes_level: bool) -> None:
    raw = path.read_bytes()
    if bytes_level:
        mutated = data.draw(byte_mutations(raw))
    else:
        mutated = dumps(data.draw(tree_mutation(json.loads(raw))))
    simulate("scene.json", mutated, "scene mutated")


# ---- TI .cfg: radar ------------------------------------------------------------------------


def radar(data: bytes, label: str) -> None:
    def write(folder: Path) -> list[str]:
        (folder / "radar.cfg").write_bytes(data)
        return ["radar", "--cfg", str(folder / "radar.cfg"), "--json"]

    problems = run_input(write, label=label)
    check(problems)


cfg_words = st.one_of(
    st.sampled_from(
        [
            "0",
            "1",
            "-1",
            "7",
            "15",
            "0x10",
            "1e308",
            "nan",
            "inf",
            "60",
            "256",
            "99999999999",
            "0.0",
            "-0",
            "abc",
            "\x00",
            "é",
        ]
    ),
    st.integers(-(10**9), 10**9).map(str),
    st.floats(allow_nan=False).map(repr),
)


@FUZZ_SETTINGS
@given(
    base=st.sampled_from(CFGS),
    edits=st.lists(
        st.tuples(
            st.sampled_from(["channelCfg", "adcCfg", "profileCfg", "chirpCfg", "frameCfg", "x"]),
            st.lists(cfg_words, max_size=16),
        ),
        min_size=1,
        max_size=4,
    ),
)
def test_generated_cfg_commands(base: Path, edits: list) -> None:
    """A shipped .cfg with commands replaced or added with generated fields."""
    lines = base.read_text().splitlines()
    for name, words in edits:
        line = " ".join([name, *words])
        hits = [i for i, ln in enumerate(lines) if ln.startswith(name + " ")]
        if hits:
            lines[hits[0]] = line
        else:
            lines.append(line)
    radar(("\n".join(lines) + "\n").encode("utf-8", "surrogatepass"), "cfg generated")


@FUZZ_SETTINGS
@given(data=st.data(), path=st.sampled_from(CFGS))
def test_mutated_shipped_cfgs(data, path: Path) -> None:
    radar(data.draw(byte_mutations(path.read_bytes())), "cfg mutated")


# ---- TI .cfg: gtrack's tracker lines (export-cfg) ------------------------------------------

GTRACK_CFG = ROOT / "resources" / "gtrack" / "ti_people_counting_isk.cfg"
TRACKER_LINES = [
    "trackingCfg", "sensorPosition", "boundaryBox", "staticBoundaryBox", "presenceBoundaryBox",
    "gatingParam", "stateParam", "allocationParam", "maxAcceleration",
]  # fmt: skip


def export_cfg(data: bytes, label: str) -> None:
    def write(folder: Path) -> list[str]:
        (folder / "base.cfg").write_bytes(data)
        return ["export-cfg", "--cfg", str(folder / "base.cfg"), "--out", str(folder / "o.cfg")]

    check(run_input(write, label=label))


@FUZZ_SETTINGS
@given(
    edits=st.lists(
        st.tuples(st.sampled_from(TRACKER_LINES), st.lists(cfg_words, max_size=9)),
        min_size=1,
        max_size=4,
    ),
)
def test_generated_tracker_lines(edits: list) -> None:
    """TI's default tracker lines with lines replaced by generated fields."""
    lines = GTRACK_CFG.read_text().splitlines()
    for name, words in edits:
        line = " ".join([name, *words])
        hits = [i for i, ln in enumerate(lines) if ln.split()[:1] == [name]]
        lines[hits[0]] = line
    export_cfg(("\n".join(lines) + "\n").encode("utf-8", "surrogatepass"), "tracker cfg generated")


@FUZZ_SETTINGS
@given(data=st.data())
def test_mutated_tracker_lines(data) -> None:
    export_cfg(data.draw(byte_mutations(GTRACK_CFG.read_bytes())), "tracker cfg mutated")


# ---- parameter JSON: track -----------------------------------------------------------------


def track(files: dict[str, Path], params: bytes | None, dataset: bytes | None, label: str) -> None:
    def write(folder: Path) -> list[str]:
        argv = ["track", "--out", str(folder / "out" / "track.json")]
        if params is not None:
            (folder / "params.json").write_bytes(params)
            argv += ["--params", str(folder / "params.json")]
        if dataset is not None:
            (folder / "data.npz").write_bytes(dataset)
            argv += ["--data", str(folder / "data.npz")]
        else:
            argv += ["--data", str(files["data"])]
        return argv

    problems = run_input(write, label=label)
    check(problems)


PARAM_KEYS = [
    "model",
    "q_coeff",
    "r11",
    "r22",
    "r33",
    "p0",
    "p_d",
    "p_te",
    "p11",
    "p21",
    "p_g",
    "confirm_threshold",
    "delete_threshold",
    "clutter_density",
    "max_tracks",
    "association",
    "p0_00",
    "p0_11",
    "p0_22",
    "p0_33",
    "p0_44",
    "p0_55",
    "colour",
]


@FUZZ_SETTINGS
@given(
    doc=st.dictionaries(
        st.sampled_from(PARAM_KEYS),
        st.one_of(
            numbers, st.sampled_from(["cv", "ca", "nonparametric", "ipda", "jipda"]), json_values
        ),
        max_size=6,
    )
)
def test_generated_params(fuzz_files, doc: dict) -> None:
    track(fuzz_files, dumps(doc), None, "params generated")


@FUZZ_SETTINGS
@given(data=st.data(), bytes_level=st.booleans())
def test_mutated_params(fuzz_files, data, bytes_level: bool) -> None:
    raw = fuzz_files["params"].read_bytes()
    if bytes_level:
        mutated = data.draw(byte_mutations(raw))
    else:
        mutated = dumps(data.draw(tree_mutation(json.loads(raw))))
    track(fuzz_files, mutated, None, "params mutated")


# ---- data-set .npz: track ------------------------------------------------------------------------


DTYPES = ["<f8", "<f4", "<i4", "<i8", "|b1", "<U5", "<c16", "|V8", "O", "<M8[s]"]


@st.composite
def arrays(draw) -> np.ndarray:
    shape = tuple(draw(st.lists(st.sampled_from([0, 1, 2, 3, 6, 12, 13]), max_size=3)))
    dtype = draw(st.sampled_from(DTYPES))
    n = int(np.prod(shape))
    if dtype == "O":
        return np.array([{"x": 1}] * n, dtype=object).reshape(shape)
    if dtype.startswith("<U"):
        return np.array(draw(st.lists(strings, min_size=n, max_size=n)) or [], dtype="U5").reshape(
            shape
        )
    values = draw(
        st.lists(
            st.sampled_from([0.0, 1.0, -1.0, 5.0, 11.0, 12.0, 1e308, np.nan, np.inf, 1e-300]),
            min_size=n,
            max_size=n,
        )
    )
    with np.errstate(all="ignore"):
        try:
            return np.array(values, dtype=np.float64).astype(dtype).reshape(shape)
        except (TypeError, ValueError):
            return np.zeros(shape, dtype=dtype)


@FUZZ_SETTINGS
@given(data=st.data())
def test_mutated_dataset_arrays(fuzz_files, data) -> None:
    """The small data set with arrays replaced (shape, dtype, values), removed or added."""
    with np.load(fuzz_files["data"]) as z:
        content = {k: z[k] for k in z.files}
    for _ in range(data.draw(st.integers(1, 3))):
        key = data.draw(st.sampled_from([*sorted(content), "extra"]))
        op = data.draw(st.sampled_from(["replace", "replace", "delete", "perturb"]))
        if op == "delete":
            content.pop(key, None)
        elif op == "perturb" and key in content and content[key].dtype.kind in "iuf":
            a = content[key].copy()
            if a.size:
                value = data.draw(
                    st.sampled_from([-1, 0, 1, 10**6, 2**31 - 1])
                    if a.dtype.kind in "iu"
                    else st.sampled_from([np.nan, np.inf, -1.0, 1e308, 0.0])
                )
                with np.errstate(over="ignore", invalid="ignore"):  # 1e308 in float32: inf
                    a.flat[data.draw(st.integers(0, a.size - 1))] = value
            content[key] = a
        else:
            content[key] = data.draw(arrays())
    buf = io.BytesIO()
    if data.draw(st.booleans()):
        np.savez_compressed(buf, **content)
    else:
        np.savez(buf, **content)
    track(fuzz_files, None, buf.getvalue(), "dataset arrays")


@FUZZ_SETTINGS
@given(data=st.data())
def test_mutated_dataset_bytes(fuzz_files, data) -> None:
    raw = fuzz_files["data"].read_bytes()
    track(fuzz_files, None, data.draw(byte_mutations(raw)), "dataset bytes")
