"""The one search-space table (core/tracking/space.py) and everything that derives from it.

The sliders' part is in tests/app/test_engine_geometry.py (app code); here: the table's rows,
the TrackerParams defaults, the JSON keys, the Optuna suggestions, the stability corners, and a
scan of core/ and app/ for any other place that restates parameter names with numbers.
"""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

from core.errors import InputError
from core.optimization.space import suggest_params
from core.tracking.models import process_noise
from core.tracking.params import DEFAULT_P0, STATE_DIM, TrackerParams
from core.tracking.space import (
    MODELS,
    P0_NAMES,
    SEARCH_SPACE,
    Parameter,
    defaults,
    flat_params,
    p0_names,
    parameter,
    search_space,
    tracker_params_dict,
)
from core.tracking.stability import corner_names, corner_params

ROOT = Path(__file__).resolve().parents[3]
TABLE = ROOT / "core" / "tracking" / "space.py"
NAMES = {p.name for p in SEARCH_SPACE}


def test_rows_are_unique_and_p0_follows_the_state() -> None:
    # the paper's 14 rows, then the room tracker's 12
    assert len(NAMES) == len(SEARCH_SPACE) == 26
    assert P0_NAMES == ("p0_00", "p0_11", "p0_22", "p0_33", "p0_44", "p0_55")
    for model in MODELS:
        assert len(p0_names(model)) == STATE_DIM[model]
        assert [p.name for p in search_space(model)] == [
            p.name for p in SEARCH_SPACE if model in p.models and "paper" in p.modes
        ]
    assert parameter("p0_44").models == parameter("p0_55").models == ("ca",)
    with pytest.raises(InputError, match="'p_g' is not an optimised tracker parameter"):
        parameter("p_g")


def test_units_and_labels() -> None:
    units = {p.name: p.unit for p in SEARCH_SPACE}
    assert units["q_coeff"] == "m²/s⁴"
    assert (units["r11"], units["r22"], units["r33"]) == ("m", "rad", "m/s")
    assert [units[n] for n in P0_NAMES] == ["m", "m", "m/s", "m/s", "m/s²", "m/s²"]
    assert all(units[n] == "" for n in ("p_d", "p_te", "p11", "p21"))
    assert parameter("r11").label == "r11 range σ [m]"
    assert parameter("p_d").label == "P_D detection probability"


@pytest.mark.parametrize("period_s", [0.05, 0.08])
def test_q_coeff_is_a_variance_in_m2_per_s4_for_both_models(period_s: float) -> None:
    q = 2.0
    # CV: velocity variance gained per frame = q·T² → q is an acceleration variance, (m/s²)²
    cv = process_noise("cv", period_s, q)
    assert cv[2, 2] == pytest.approx(q * period_s**2, rel=1e-12)
    # CA: acceleration variance gained per frame = q (no T) → q is the variance of the
    # per-frame acceleration increment, again (m/s²)², not a jerk variance (m²/s⁶)
    ca = process_noise("ca", period_s, q)
    assert ca[4, 4] == pytest.approx(q, rel=1e-12)


@pytest.mark.parametrize(
    ("change", "needle"),
    [
        ({"low": 1.0, "high": 1.0}, "r11: low must be < high"),
        ({"low": 0.0}, "r11: a log scale needs low > 0"),
        ({"default": 0.6}, r"r11: default must lie in \[0.01, 0.5\], got 0.6"),
        ({"models": ("ct",)}, "r11: models must be some of"),
    ],
)
def test_a_bad_row_is_an_error_naming_it(change: dict, needle: str) -> None:
    row = {
        "name": "r11",
        "symbol": "r11",
        "meaning": "range σ",
        "unit": "m",
        "low": 0.01,
        "high": 0.5,
        "log": True,
        "default": 0.05,
    }
    with pytest.raises(InputError, match=needle):
        Parameter(**{**row, **change})


@pytest.mark.parametrize("model", MODELS)
def test_trackerparams_defaults_are_the_tables(model: str) -> None:
    table = defaults(model)
    for params in (TrackerParams(model=model), TrackerParams.default(model)):
        d = params.to_dict()
        for name, value in table.items():
            got = d["p0"][P0_NAMES.index(name)] if name in P0_NAMES else d[name]
            assert got == value, name
    assert DEFAULT_P0[model] == tuple(table[n] for n in p0_names(model))


@pytest.mark.parametrize("model", MODELS)
def test_json_keys_derive_from_the_table(model: str) -> None:
    table = defaults(model)
    as_json = tracker_params_dict(table, model)
    assert set(as_json) == {"model", "p0"} | (set(table) - set(P0_NAMES))
    assert as_json["p0"] == [table[n] for n in p0_names(model)]
    assert TrackerParams.from_dict(as_json) == TrackerParams.default(model)
    assert set(as_json) <= set(TrackerParams.default(model).to_dict())
    assert flat_params(as_json) == table
    # a parameter file may spell p0 as the table's p0_ii keys, exactly those of its model
    flat_file = {"model": model, **{n: table[n] for n in p0_names(model)}}
    assert TrackerParams.from_dict(flat_file) == TrackerParams.default(model)
    with pytest.raises(InputError, match="unknown tracker parameter keys"):
        TrackerParams.from_dict({"model": model, "p0_66": 1.0})


class _RecordingTrial:
    def __init__(self) -> None:
        self.calls: list[tuple[str, float, float, bool]] = []

    def suggest_float(self, name: str, low: float, high: float, *, log: bool = False) -> float:
        self.calls.append((name, low, high, log))
        return low


@pytest.mark.parametrize("model", MODELS)
def test_optuna_suggestions_are_the_table_in_table_order(model: str) -> None:
    trial = _RecordingTrial()
    suggest_params(trial, model)
    assert trial.calls == [(p.name, p.low, p.high, p.log) for p in search_space(model)]


@pytest.mark.parametrize("model", MODELS)
def test_stability_corners_are_the_tables_bounds(model: str) -> None:
    rows = search_space(model)
    assert corner_names(model) == [p.name for p in rows]
    for bit, side in ((0, "low"), (1, "high")):
        flat = flat_params(corner_params(model, (bit,) * len(rows)).to_dict())
        assert flat == {p.name: getattr(p, side) for p in rows}
    # one corner with mixed bits: each parameter at the bound its bit selects
    bits = tuple(int(b) for b in np.arange(len(rows)) % 2)
    flat = flat_params(corner_params(model, bits).to_dict())
    assert flat == {p.name: (p.low, p.high)[b] for p, b in zip(rows, bits)}


def restatements(source: str) -> list[str]:
    """Places in ``source`` that restate the table: a dict keyed by three or more parameter
    names, a list of five or more of them, a parameter name paired with a number in a dict or a
    call (``"r11": 0.05``, ``suggest_float("r11", 0.01, 0.5)``), a class giving three or more
    of them numeric defaults (``r11: float = 0.05``)."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ClassDef):
            named = [
                s.target.id
                for s in node.body
                if isinstance(s, ast.AnnAssign)
                and isinstance(s.target, ast.Name)
                and s.target.id in NAMES
                and s.value is not None
                and _numbers(s.value)
            ]
            if len(named) >= 3:
                found.append(f"line {node.lineno}: class {node.name} defaults {named}")
        elif isinstance(node, ast.Dict):
            keys = [k.value for k in node.keys if isinstance(k, ast.Constant)]
            named = [k for k in keys if k in NAMES]
            if len(named) >= 3:
                found.append(f"line {node.lineno}: dict keyed by {named}")
            for k, v in zip(node.keys, node.values):
                if isinstance(k, ast.Constant) and k.value in NAMES and _numbers(v):
                    found.append(f"line {node.lineno}: {k.value!r} with a number")
        elif isinstance(node, (ast.Tuple, ast.List, ast.Set)):
            named = [e.value for e in node.elts if isinstance(e, ast.Constant) and e.value in NAMES]
            if len(named) >= 5:
                found.append(f"line {node.lineno}: list of {named}")
        elif isinstance(node, ast.Call):
            args = [*node.args, *(k.value for k in node.keywords)]
            named = [a.value for a in args if isinstance(a, ast.Constant) and a.value in NAMES]
            if named and any(_numbers(a) for a in args):
                found.append(f"line {node.lineno}: call with {named} and a number")
    return found


def _numbers(node: ast.AST) -> bool:
    """A numeric literal, or a tuple/list of them."""
    if isinstance(node, ast.Constant):
        return isinstance(node.value, (int, float)) and not isinstance(node.value, bool)
    if isinstance(node, (ast.Tuple, ast.List)):
        return bool(node.elts) and all(_numbers(e) for e in node.elts)
    return False


def test_the_scan_finds_restatements() -> None:
    assert restatements('S = {"q_coeff": (0.1, 30.0)}')
    assert restatements('LABELS = {"r11": "a", "r22": "b", "r33": "c"}')
    assert restatements('names = ("p0_00", "p0_11", "p0_22", "p0_33", "p0_44")')
    assert restatements('trial.suggest_float("p_d", 0.8, 0.99)')
    assert restatements(
        "class P:\n    r11: float = 0.05\n    r22: float = 0.03\n    p_d = 1\n"
        "    p11: float = 0.98\n"
    )
    assert not restatements('d = {"p_d": scene.p_d, "seed": 0}')
    assert not restatements("class Scene:\n    p_d: float = 0.95\n")


def test_no_module_restates_the_table() -> None:
    problems = []
    for path in sorted([*(ROOT / "core").rglob("*.py"), *(ROOT / "app").rglob("*.py")]):
        if path == TABLE:
            continue
        for where in restatements(path.read_text()):
            problems.append(f"{path.relative_to(ROOT)} {where}")
    assert not problems, "derive these from core/tracking/space.py:\n" + "\n".join(problems)


def test_a_room_file_without_model_is_not_read_as_gtrack() -> None:
    # a room-mode parameter file without "model" is still the tracker's (CV by default), and
    # gtrack's is gtrack's; gtrack's allocation rows carry TI's names (snr_thre, points_thre...)
    # and a gtrack file with their earlier names (alloc_snr, alloc_points...) still reads
    from core.tracking.gtrack.params import GtrackParams
    from core.tracking.space import (
        GTRACK_LEGACY_NAMES,
        GTRACK_SPACE,
        defaults,
        flat_params,
        tracker_params_dict,
    )

    old_name = {v: k for k, v in GTRACK_LEGACY_NAMES.items()}

    room = tracker_params_dict(defaults("cv", "room"), "cv", "room")
    room.pop("model")
    assert set(flat_params(room)) == set(defaults("cv", "room"))
    assert set(flat_params(GtrackParams().to_dict())) == {b.name for b in GTRACK_SPACE}
    assert not {b.name for b in GTRACK_SPACE} & set(defaults("cv", "room"))
    legacy = {old_name.get(k, k): v for k, v in GtrackParams().to_dict().items()}
    assert "alloc_snr" in legacy and "snr_thre" not in legacy
    assert flat_params(legacy) == flat_params(GtrackParams().to_dict())
    assert GtrackParams.from_dict({"alloc_points": 7}).points_thre == 7
