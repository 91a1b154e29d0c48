"""Search space: exactly the paper's eq. (15) bounds; samples always inside them."""

from __future__ import annotations

import json
import math
from pathlib import Path

import optuna
import pytest

from core.errors import InputError
from core.optimization.space import SEARCH_SPACE, search_space, suggest_params
from core.optimization.study import make_sampler
from core.tracking.space import flat_params, tracker_params_dict

# eq. (15) of the paper, transcribed independently of the implementation
PAPER = {
    "q_coeff": (0.1, 30),
    "r11": (0.01, 0.5),
    "r22": (0.01, 0.2),
    "r33": (0.1, 3),
    "p0_00": (0.1, 10),
    "p0_11": (0.1, 10),
    "p0_22": (0.01, 10),
    "p0_33": (0.01, 10),
    "p0_44": (0.001, 10),
    "p0_55": (0.001, 10),
    "p_d": (0.8, 0.99),
    "p_te": (0.2, 1),
    "p11": (0.7, 1),
    "p21": (0, 0.4),
}


def test_bounds_are_the_papers() -> None:
    assert {b.name: (b.low, b.high) for b in SEARCH_SPACE if "paper" in b.modes} == PAPER


def test_cv_never_has_acceleration_entries_and_ca_has_all() -> None:
    cv = {b.name for b in search_space("cv")}
    ca = {b.name for b in search_space("ca")}
    assert ca - cv == {"p0_44", "p0_55"}
    assert len(cv) == 12 and len(ca) == 14


def test_log_scale_exactly_where_the_range_spans_a_decade() -> None:
    for b in SEARCH_SPACE:
        spans_decade = b.low > 0 and b.high / b.low >= 10
        assert b.log == spans_decade, b.name


@pytest.mark.parametrize("model", ["cv", "ca"])
@pytest.mark.parametrize("sampler", ["tpe", "random"])
def test_sampled_values_lie_inside_the_bounds(model: str, sampler: str) -> None:
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    study = optuna.create_study(sampler=make_sampler(sampler, 3))
    names = {b.name for b in search_space(model)}

    def objective(trial: optuna.Trial) -> float:
        p = suggest_params(trial, model)
        # far from the centre: pushes TPE toward the corners of the box
        return -sum(abs(math.log(v + 1e-9)) for v in p.values())

    study.optimize(objective, n_trials=40)
    for t in study.trials:
        assert set(t.params) == names
        for b in search_space(model):
            assert b.low <= t.params[b.name] <= b.high, (b.name, t.params[b.name])


def test_tracker_params_json_round_trip() -> None:
    flat = {b.name: b.low for b in search_space("ca")}
    tp = tracker_params_dict(flat, "ca")
    assert tp["model"] == "ca" and tp["p0"] == [0.1, 0.1, 0.01, 0.01, 0.001, 0.001]
    assert "p0_00" not in tp
    assert flat_params(tp) == flat
    cv = tracker_params_dict({b.name: b.high for b in search_space("cv")}, "cv")
    assert len(cv["p0"]) == 4


def test_out_of_bounds_and_wrong_model_are_clear_errors() -> None:
    tp = tracker_params_dict({b.name: b.low for b in search_space("cv")}, "cv")
    with pytest.raises(InputError, match=r"p_d must be in \[0.8, 0.99\], got 0.5"):
        flat_params({**tp, "p_d": 0.5})
    with pytest.raises(InputError, match="model must be one of cv, ca, got 'ct'"):
        search_space("ct")
    with pytest.raises(InputError, match="p0 must have 6 entries"):
        flat_params({**tp, "model": "ca"})


SEEDED = Path(__file__).parent / "data" / "seeded_suggestions.json"


@pytest.mark.parametrize("model", ["cv", "ca"])
@pytest.mark.parametrize("sampler", ["tpe", "random"])
def test_seeded_studies_suggest_what_they_always_did(model: str, sampler: str) -> None:
    # Recorded before the search space became one table: same seed → the same parameter sets,
    # bit for bit and in the same suggest order (10 random start-up trials, then 4 TPE ones).
    record = json.loads(SEEDED.read_text())
    if optuna.__version__ != record["optuna"]:
        pytest.skip(f"suggestions recorded with optuna {record['optuna']}")
    expected = record["suggestions"][f"{sampler}-{model}"]
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    study = optuna.create_study(sampler=make_sampler(sampler, record["seed"]))
    got: list[dict[str, float]] = []

    def objective(trial: optuna.Trial) -> float:
        p = suggest_params(trial, model)
        got.append(p)
        return sum((math.log(v + 1.0) - 0.5) ** 2 for v in p.values())

    study.optimize(objective, n_trials=len(expected))
    assert [list(p.items()) for p in got] == [list(p.items()) for p in expected]
