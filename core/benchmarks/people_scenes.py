"""The shipped multi-person scenes simulated and tracked: the table in ``docs/people.md``.

``python -m core.benchmarks.people_scenes [--fidelity exact] [--model cv]`` simulates every scene
of ``resources/scenes/`` with more than one person (as ``radartune simulate`` does, the scene's
own seed), tracks it with the model's default parameters (as ``radartune track`` does) and prints
one Markdown row per scene: the several-person loss, GOSPA and its decomposition, the mean
people-count error, identity switches and, per person, L ×10⁻³ and the frames missed.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from core.evaluation import evaluate
from core.pipeline import plan, simulate_scene
from core.scene import Scene
from core.tracking import TrackerParams, track_dataset

SCENES_DIR = Path(__file__).resolve().parents[2] / "resources" / "scenes"


def table(fidelity: str = "exact", model: str = "cv") -> str:
    """The Markdown table (header and one row per multi-person scene)."""
    lines = [
        "| scene | persons | frames | L_t ×10⁻³ | GOSPA (m) | localisation / missed / false "
        "(m² a frame) | mean count error | identity switches | per person: L ×10⁻³ "
        "(frames missed of present) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    params = TrackerParams.default(model)
    for path in sorted(SCENES_DIR.glob("*.json")):
        scene = Scene.from_json(path)
        if scene.n_persons < 2:
            continue
        ds = simulate_scene(scene, the_plan=plan(scene, fidelity=fidelity)).to_dataset()
        ev = evaluate(ds, track_dataset(ds, params, with_tracks=True))
        g = ev.gospa
        persons = "; ".join(
            f"{m.person}: {m.loss * 1e3:.3g} ({m.frames_missed}/{m.frames_present})"
            for m in ev.persons
        )
        lines.append(
            f"| {path.stem} | {ds.n_persons} | {ds.n_frames} | {ev.loss_total * 1e3:.4g} | "
            f"{g['gospa_m']:.3f} | {g['localisation']:.4f} / {g['missed']:.3f} / "
            f"{g['false']:.3f} | {g['count_error']:+.2f} | {ev.identity_switches_total} | "
            f"{persons} |"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m core.benchmarks.people_scenes")
    p.add_argument("--fidelity", default="exact", help="simulator level (default: exact)")
    p.add_argument("--model", choices=("cv", "ca"), default="cv", help="default: cv")
    args = p.parse_args(argv)
    print(table(args.fidelity, args.model))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
