"""``radartune tune`` with held-out validation, repeats and robust objectives, through the CLI."""

from __future__ import annotations

import dataclasses
import json
import subprocess
import sys
from pathlib import Path

import pytest

from core.dataset import Dataset
from core.optimization.validation import validate_study
from core.tracking.synthetic import synthetic_dataset

ROOT = Path(__file__).resolve().parents[2]


def cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "core.cli", *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
    )


@pytest.fixture(scope="module")
def sets(tmp_path_factory) -> dict[str, str]:
    d = tmp_path_factory.mktemp("tune")
    out = {}
    for name, seed in (("train", 3), ("val", 4)):
        out[name] = str(d / f"{name}.npz")
        synthetic_dataset(seed=seed, n_per_class=1, n_frames=50).save(out[name])
    ds = Dataset.load(out["val"])
    radar = json.loads(ds.radar_json) if ds.radar_json else {}
    radar["frame_period_s"] = 0.05
    out["other"] = str(d / "other.npz")
    dataclasses.replace(ds, radar_json=json.dumps(radar)).save(out["other"])
    return out


def test_repeats_choose_by_validation(sets, tmp_path: Path) -> None:
    db = f"sqlite:///{tmp_path}/s.db"
    r = cli(
        *("tune", "--model", "cv", "--trials", "4", "--pruner", "none", "--no-progress"),
        *("--dataset", sets["train"], "--validation", sets["val"], "--repeats", "2"),
        *("--top-k", "3", "--loss", "capped", "--storage", db, "--study", "v"),
    )
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    studies = out["studies"]
    assert [s["study"] for s in studies] == ["v-r0", "v-r1"]
    # the choice is the study whose chosen trial has the lowest validation objective
    best = min(studies, key=lambda s: s["validation_value"])
    assert out["chosen_study"] == best["study"]
    assert out["validation_value"] == best["validation_value"]
    assert out["params"] == best["params"] and out["loss"] == "capped"
    # each study's record is what validate_study gives for it
    for s in studies:
        top = validate_study(db, s["study"], sets["val"], top_k=3)[0]
        assert top.validation_value == s["validation_value"] and top.number == s["trial"]


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (("--repeats", "0"), "--repeats must be >= 1, got 0"),
        (("--loss", "rmse"), "loss must be one of paper, capped, median, trimmed"),
        (("--top-k", "0"), "--top-k must be >= 1"),
        (("--validation", "OTHER"), "another radar configuration"),
    ],
)
def test_bad_input_is_one_line_and_touches_no_study(sets, tmp_path: Path, extra, message) -> None:
    extra = tuple(sets["other"] if a == "OTHER" else a for a in extra)
    db = tmp_path / "s.db"
    r = cli(
        *("tune", "--model", "cv", "--trials", "2", "--no-progress", "--dataset", sets["train"]),
        *("--storage", f"sqlite:///{db}", *extra),
    )
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], r.stderr
    assert not db.exists()  # no study was created


def test_default_objective_is_trimmed_and_a_resumed_study_keeps_its_own(sets, tmp_path) -> None:
    """Without --loss a new study minimises the trimmed mean (docs/decisions/tuning-08); a
    study made with --loss paper resumes with it, not refused for the new default."""
    from core.optimization.storage import load_existing_study, open_storage

    db = f"sqlite:///{tmp_path}/s.db"
    base = ("tune", "--model", "cv", "--pruner", "none", "--no-progress", "--storage", db)
    data = ("--dataset", sets["train"], "--validation", sets["val"], "--top-k", "1")
    r = cli(*base, *data, "--trials", "2", "--study", "new")
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["loss"] == "trimmed"
    r = cli(*base, *data, "--trials", "2", "--study", "old", "--loss", "paper")
    assert r.returncode == 0, r.stderr
    r = cli(*base, *data, "--trials", "3", "--study", "old")
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["loss"] == "paper"
    store = open_storage(db, create=False)
    assert load_existing_study(store, "new").user_attrs["loss"] == "trimmed"
    assert len(load_existing_study(store, "old").trials) == 3
