"""The fidelity bench: its tracker parameters, and its report re-rendered from the stored JSON."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from core.benchmarks.fidelity_report import render, tables

STORED = Path(__file__).resolve().parents[3] / "bench" / "results" / "fidelity.json"


def test_bench_tracks_with_the_tuned_parameters_unless_told(tmp_path) -> None:
    from core.benchmarks.fidelity import TUNED_PARAMS, tracker_parameters
    from core.errors import InputError
    from core.tracking import TrackerParams

    params, said = tracker_parameters()
    for model in ("cv", "ca"):
        assert TUNED_PARAMS[model].exists()
        assert params[model] == TrackerParams.load(TUNED_PARAMS[model])
        assert params[model] != TrackerParams.default(model)
    assert "docs/report/best_cv.json" in said and "docs/report/best_ca.json" in said
    own = TrackerParams.default("cv")
    path = own.save(tmp_path / "cv.json")
    params, said = tracker_parameters(params_cv=path)
    assert params["cv"] == own and str(path) in said
    with pytest.raises(InputError, match="model must be 'ca'"):
        tracker_parameters(params_ca=path)


def _stored() -> dict:
    return json.loads(STORED.read_text())


def test_every_table_of_the_report_is_at_most_8_columns_wide() -> None:
    text = tables(_stored())
    rows = [line for line in text.splitlines() if line.startswith("|")]
    assert len(rows) > 10
    for row in rows:
        assert 3 <= row.count("|") - 1 <= 8, row


def test_main_table_carries_the_bulk_verdict_of_the_json() -> None:
    result = _stored()
    main = tables(result).split("\n\n## ")[0].splitlines()
    fast = next(r for r in main if r.startswith("| fast |"))
    cells = [c.strip() for c in fast.strip("|").split("|")]
    t = result["levels"]["fast"]
    assert cells[1].startswith(f"{t['fps']:.0f}")
    assert cells[2] == f"{t['speedup']:.1f}"
    for cell, model in zip(cells[3:5], ("cv", "ca")):
        ratio = t["tracking"][model]["bulk_loss_ratio_to_exact"]
        lo, hi = t["tracking"][model]["bulk_loss_ratio_ci95"]
        verdict = t["tracking"][model]["bulk_verdict_within_10pct"]
        assert cell == f"{ratio:.3f} ({lo:.3f}–{hi:.3f}) {verdict}"
    assert cells[6] == f"{t['false_points_per_frame']:.3f}"


def test_render_only_rewrites_table_and_plot_from_the_json(tmp_path, monkeypatch, capsys) -> None:
    from core.cli import main

    out = tmp_path / "results"
    out.mkdir()
    shutil.copy(STORED, out / "fidelity.json")
    monkeypatch.chdir(tmp_path)
    assert main(["bench", "fidelity", "--render-only", "--out-dir", str(out)]) == 0
    md = tmp_path / "docs" / "fidelity" / "results.md"
    png = tmp_path / "docs" / "fidelity" / "error_vs_runtime.png"
    assert md.read_text().count("\n## ") == 4
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "written:" in capsys.readouterr().out
    # the same figures through the function
    md2, _ = render(_stored(), quick=False)
    assert md2.resolve() == md.resolve()


def test_render_only_without_a_stored_result_is_one_line_and_exit_2(tmp_path, capsys) -> None:
    from core.cli import main

    code = main(["bench", "fidelity", "--render-only", "--out-dir", str(tmp_path)])
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "fidelity.json" in err[0]


def test_a_walking_body_result_renders_beside_the_point_persons(tmp_path, monkeypatch) -> None:
    """``--person-model walking`` reads ``fidelity-walking.json`` and writes
    ``results-walking.md`` and its plot, leaving the point person's report alone; its header
    names the command the result was made with and says how a body's point errors are taken."""
    import json

    from core.cli import main

    out = tmp_path / "results"
    out.mkdir()
    command = "radartune bench fidelity --person-model walking"
    result = {**_stored(), "person_model": "walking", "command": command}
    (out / "fidelity-walking.json").write_text(json.dumps(result))
    monkeypatch.chdir(tmp_path)
    argv = ["bench", "fidelity", "--render-only", "--person-model", "walking"]
    assert main([*argv, "--out-dir", str(out)]) == 0
    docs = tmp_path / "docs" / "fidelity"
    assert sorted(p.name for p in docs.iterdir()) == [
        "error_vs_runtime-walking.png",
        "results-walking.md",
    ]
    text = (docs / "results-walking.md").read_text()
    assert f"Command: `{command}`" in text
    assert f"`{command} --render-only`" in text
    assert "fidelity-walking.json" in text and "mean of its scatterers" in text
    # the point person's stored result says nothing of bodies
    assert "mean of its scatterers" not in render(_stored(), quick=False)[0].read_text()


def test_person_model_bad_or_misplaced_is_one_line_and_exit_2(tmp_path, capsys) -> None:
    from core.cli import main

    out = ["--out-dir", str(tmp_path)]
    for argv, said in (
        (["bench", "fidelity", "--render-only", "--person-model", "nobody"], "'nobody'"),
        (["bench", "sim", "--person-model", "walking"], "fidelity only"),
        (["bench", "clouds", "--render-only", "--person-model", "walking"], "fidelity only"),
    ):
        assert main([*argv, *out]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and said in err[0]
    assert list(tmp_path.iterdir()) == []
