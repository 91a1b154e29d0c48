"""Studies of the room mode: the room tracker's rows join the suggestions; the paper mode's
suggestions are the paper's rows in the paper's order, as before."""

import json

import optuna
import pytest

from core.cli import main
from core.errors import InputError
from core.optimization.space import suggest_params
from core.optimization.study import StudySettings
from core.tracking.space import ROOM_NAMES, flat_params, parameter, tracker_params_dict

# eq. (15) of the paper, in its order (the CA model adds the two acceleration rows)
PAPER_CV = ("q_coeff", "r11", "r22", "r33", "p0_00", "p0_11", "p0_22", "p0_33",
            "p_d", "p_te", "p11", "p21")  # fmt: skip
PAPER_CA = (*PAPER_CV[:8], "p0_44", "p0_55", *PAPER_CV[8:])


def _names(model: str, mode: str | None) -> tuple[str, ...]:
    study = optuna.create_study(sampler=optuna.samplers.RandomSampler(seed=3))
    trial = study.ask()
    flat = suggest_params(trial, model) if mode is None else suggest_params(trial, model, mode)
    assert tuple(flat) == tuple(trial.params)  # suggested in this order
    return tuple(flat)


@pytest.mark.parametrize(("model", "paper"), [("cv", PAPER_CV), ("ca", PAPER_CA)])
def test_paper_mode_suggests_the_paper_rows_only_and_room_adds_the_eleven(model, paper):
    assert _names(model, None) == _names(model, "paper") == paper
    assert len(ROOM_NAMES) == 12
    assert _names(model, "room") == (*paper, *ROOM_NAMES)


def test_room_json_round_trips_and_paper_json_has_no_mode():
    flat = {n: parameter(n).high for n in (*PAPER_CV, *ROOM_NAMES)}
    room = tracker_params_dict(flat, "cv", "room")
    assert room["mode"] == "room" and room["alloc_points"] == 30.0
    assert flat_params(room) == flat
    paper = tracker_params_dict(flat, "cv")
    assert "mode" not in paper and not set(ROOM_NAMES) & set(paper)
    with pytest.raises(InputError, match="mode must be one of"):
        StudySettings(model="cv", mode="hall")
    with pytest.raises(InputError, match="not with model gtrack"):
        StudySettings(model="gtrack", mode="room")


def test_seeded_room_study_tunes_the_room_rows_and_its_params_track(tmp_path, capsys):
    from core.tracking.synthetic import circling_paths, room_dataset

    data = tmp_path / "room.npz"
    room_dataset(*circling_paths(1, 30), seed=2).save(data)
    db = tmp_path / "s.db"
    storage = f"sqlite:///{db}"
    code = main(["tune", "--model", "cv", "--mode", "room", "--dataset", str(data),
                 "--trials", "3", "--seed", "5", "--storage", storage, "--pruner", "none",
                 "--study", "room", "--no-progress"])  # fmt: skip
    assert code == 0
    out = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    study = optuna.load_study(study_name="room", storage=storage)
    assert study.user_attrs["mode"] == "room"
    trials = study.get_trials(deepcopy=False)
    assert len(trials) == 3
    for t in trials:
        assert tuple(t.params) == (*PAPER_CV, *ROOM_NAMES)
        for name, value in t.params.items():
            row = parameter(name)
            assert row.low <= value <= row.high, name
    assert out["params"]["mode"] == "room"
    assert out["params"] == tracker_params_dict(study.best_trial.params, "cv", "room")
    # the printed parameters load with `radartune track` and run the room tracker
    p = tmp_path / "P.json"
    p.write_text(json.dumps(out["params"]))
    tracks = tmp_path / "t.json"
    assert main(["track", "--data", str(data), "--params", str(p), "--out", str(tracks)]) == 0
    got = json.loads(tracks.read_text())["params"]
    assert got["mode"] == "room"
    assert {n: got[n] for n in ROOM_NAMES} == {n: out["params"][n] for n in ROOM_NAMES}
    capsys.readouterr()
    # the same study resumed in the paper mode is refused, one line, exit 2
    code = main(["tune", "--model", "cv", "--dataset", str(data), "--trials", "4",
                 "--pruner", "none", "--storage", storage, "--study", "room",
                 "--no-progress"])  # fmt: skip
    assert code == 2 and "mode='room'" in capsys.readouterr().err
