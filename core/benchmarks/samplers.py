"""Held-out loss against trials and run time, per sampler, with and without pruning.

``radartune bench samplers [--quick]`` writes ``bench/results/samplers.json`` and the plot
``docs/tuning/samplers.png`` with its table ``docs/tuning/samplers.md``; ``--render-only``
re-draws both from the JSON. Long (not in ``bench all``): 30 studies of 300 trials.

For every sampler (TPE, random, CMA-ES when the ``cmaes`` package is installed, GP when
``torch`` is), pruner (ASHA, none) and sampler seed 0–4, one CV study of ``n_trials`` trials on
the walking training set paper:0 (:func:`core.optimization.data.resolve_dataset`), run as
``radartune tune --trials N --sampler S --pruner P --seed s`` runs it, with one worker in this
process (:func:`core.optimization.study.run_worker`) and Optuna's in-memory storage, so that
the time axis holds the objective and the sampler, not a database (``radartune bench tune``
measures the storages). Timed per trial by the clock before each trial (wall and process CPU
seconds since the first trial started), and the objective alone (every call of
:func:`core.optimization.objective.evaluate` the worker makes) apart.

The *incumbent* after t trials is the COMPLETE trial with the lowest training loss among the
first t (pruned trials count as trials but never become incumbents). Every incumbent a study
ever had is tracked again, after the study and outside its clock, on the held-out sets — the
validation set paper:1000 and the test sets paper:2000–2003, walking, 35 trajectories each —
giving the held-out paper loss L_t (the mean of the sets' L_t, eq. 14: the L_t of the 175
trajectories) and the capped loss (:mod:`core.evaluation.robust`). The incumbent is a step
function of trials and of time, so checkpoints (after 10, 20, 50, 100, … trials; at 1, 2, 5,
10, … s) are read off it, and the plot shows the median and interquartile band over seeds.

``--quick``: TPE and random (and CMA-ES if installed), both pruners, seeds 0 and 1, 12 trials,
on five-trajectory walking sets at the measurement level (paper:0 to train, paper:1000 held
out); its plot goes to ``bench/results/samplers-quick/``.
"""

from __future__ import annotations

import importlib.metadata
import importlib.util
import itertools
import math
import os
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from core.files import save_figure, write_text_atomic

#: trials after which the incumbent is read off (those up to ``n_trials``) and shown in tables
TRIAL_CHECKPOINTS = (10, 20, 50, 100, 200, 300, 500, 1000)
#: seconds since the first trial at which the incumbent is read off
TIME_CHECKPOINTS_S = (0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1000.0)
#: the bench's samplers, in plotting order; those whose package is missing are left out
SAMPLERS = ("tpe", "random", "cmaes", "gp")
PRUNERS = ("asha", "none")


@dataclass(frozen=True, slots=True, kw_only=True)
class Settings:
    """One run of the benchmark."""

    models: tuple[str, ...] = ("cv", "ca")
    samplers: tuple[str, ...] = SAMPLERS
    pruners: tuple[str, ...] = PRUNERS
    seeds: tuple[int, ...] = tuple(range(5))
    n_trials: int = 400
    training_seed: int = 0
    heldout_seeds: tuple[int, ...] = (1000, 2000, 2001, 2002, 2003)
    n_trajectories: int = 35
    person_model: str = "walking"
    fidelity: str = "exact"
    #: studies run at once, each in its own process with one worker (1: in this process)
    processes: int = 2


QUICK = Settings(
    models=("cv",), samplers=("tpe", "random", "cmaes"), seeds=(0, 1), n_trials=12,
    heldout_seeds=(1000,), n_trajectories=5, fidelity="measurement", processes=1,
)  # fmt: skip


def available(samplers: tuple[str, ...]) -> tuple[tuple[str, ...], dict[str, str]]:
    """The samplers whose package is installed, and why each other one is left out."""
    from core.errors import InputError
    from core.optimization.study import check_sampler

    ok, skipped = [], {}
    for s in samplers:
        try:
            check_sampler(s)
        except InputError as exc:
            skipped[s] = str(exc)
        else:
            ok.append(s)
    return tuple(ok), skipped


def dataset_path(seed: int, s: Settings) -> str:
    """The cached walking paper data set of ``seed`` at the settings' size and level."""
    from core.pipeline import paper_dataset_file

    return str(
        paper_dataset_file(seed, s.n_trajectories, fidelity=s.fidelity, person_model=s.person_model)
    )


@contextmanager
def timed_objective(log: list[tuple[float, float]]) -> Iterator[None]:
    """Append (wall s, CPU s) of every objective evaluation a worker makes in this process.

    :func:`core.optimization.study.run_worker` calls :func:`core.optimization.objective.evaluate`
    by its name in the study module; it is wrapped there for the duration only.
    """
    import core.optimization.study as study_module

    inner = study_module.evaluate

    def evaluate(*args: Any, **kwargs: Any) -> Any:
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            return inner(*args, **kwargs)
        finally:
            log.append((time.perf_counter() - t0, time.process_time() - c0))

    study_module.evaluate = evaluate
    try:
        yield
    finally:
        study_module.evaluate = inner


class HeldOut:
    """The held-out sets; L_t and capped loss of TrackerParams JSON, remembered per trial."""

    def __init__(self, paths: list[str]) -> None:
        from core.dataset import Dataset
        from core.optimization.objective import TrackerLosses

        self.losses = [TrackerLosses(Dataset.load(p), capped=True) for p in paths]

    def score(self, params: dict[str, Any]) -> dict[str, list[float]]:
        """Per held-out set: the paper's L_t (m², eq. 14) and the mean capped loss (m²)."""
        from core.optimization.objective import evaluate

        out: dict[str, list[float]] = {"paper": [], "capped": []}
        for losses in self.losses:
            r = evaluate(losses, params)
            out["paper"].append(float(r.paper_value))
            out["capped"].append(float(np.mean(r.capped)))
        return out


def run_study(
    model: str, sampler: str, pruner: str, seed: int, s: Settings, train: str, heldout: HeldOut
) -> dict[str, Any]:
    """One study, timed per trial; its incumbents with their held-out losses."""
    from core.optimization.progress import study_progress
    from core.optimization.study import StudySettings, prepare_study, run_worker

    name = f"{model}-{sampler}-{pruner}-s{seed}"
    settings = StudySettings(
        model=model,
        n_trials=s.n_trials,
        storage=f"memory://bench-samplers-{os.getpid()}-{time.monotonic_ns()}-{name}",
        study_name=name,
        seed=seed,
        sampler=sampler,
        pruner=pruner,
        dataset=train,
    )
    marks: list[tuple[float, float]] = []  # (wall, CPU) before each trial and at the end

    def stop() -> bool:
        marks.append((time.perf_counter(), time.process_time()))
        return False

    objective: list[tuple[float, float]] = []
    t0, c0 = time.perf_counter(), time.process_time()
    prepare_study(settings, dataset_path=train)
    with timed_objective(objective):
        run_worker(settings.storage, name, seed=seed, dataset_path=train, stop=stop)
    trials = sorted(study_progress(settings.storage, name)[0], key=lambda t: t.number)
    # one worker: trial i runs between the (i+1)-th and (i+2)-th call of stop()
    if len(marks) != len(trials) + 1:
        raise RuntimeError(f"{name}: {len(marks)} clock marks for {len(trials)} trials")
    w0, cpu0 = marks[0]
    wall = [m[0] - w0 for m in marks[1:]]
    cpu = [m[1] - cpu0 for m in marks[1:]]
    incumbents: list[dict[str, Any]] = []
    best = math.inf
    for i, t in enumerate(trials):
        if t.state != "COMPLETE" or t.value is None or not t.value < best:
            continue
        best = float(t.value)
        params = t.tracker_params(model)
        held = heldout.score(params)
        incumbents.append(
            {
                "trials": i + 1,
                "number": t.number,
                "wall_s": wall[i],
                "cpu_s": cpu[i],
                "train_loss": best,
                "heldout_paper": float(np.mean(held["paper"])),
                "heldout_capped": float(np.mean(held["capped"])),
                "heldout_paper_per_set": held["paper"],
                "params": params,
            }
        )
    states = [t.state for t in trials]
    return {
        "model": model,
        "sampler": sampler,
        "pruner": pruner,
        "seed": seed,
        "trials": len(trials),
        "complete": states.count("COMPLETE"),
        "pruned": states.count("PRUNED"),
        "failed": states.count("FAIL"),
        "setup_wall_s": w0 - t0,
        "setup_cpu_s": cpu0 - c0,
        "wall_s": wall[-1],
        "cpu_s": cpu[-1],
        "objective_wall_s": float(sum(o[0] for o in objective)),
        "objective_cpu_s": float(sum(o[1] for o in objective)),
        "incumbents": incumbents,
    }


def at(incumbents: list[dict[str, Any]], key: str, x: float, value: str = "heldout_paper") -> float:
    """The incumbent's ``value`` once ``key`` (``trials``, ``wall_s``, ``cpu_s``) reached ``x``;
    NaN before the first COMPLETE trial."""
    out = math.nan
    for inc in incumbents:
        if inc[key] <= x:
            out = inc[value]
        else:
            break
    return out


def checkpoints(study: dict[str, Any], n_trials: int) -> dict[str, Any]:
    """Held-out L_t and capped loss at the trial and wall-clock checkpoints."""
    inc = study["incumbents"]
    ks = [k for k in TRIAL_CHECKPOINTS if k < n_trials] + [n_trials]
    ts = [t for t in TIME_CHECKPOINTS_S if t < study["wall_s"]] + [study["wall_s"]]
    return {
        "by_trials": [
            {
                "trials": k,
                "heldout_paper": at(inc, "trials", k),
                "heldout_capped": at(inc, "trials", k, "heldout_capped"),
                "train_loss": at(inc, "trials", k, "train_loss"),
            }
            for k in ks
        ],
        "by_wall_s": [
            {
                "wall_s": t,
                "heldout_paper": at(inc, "wall_s", t),
                "heldout_capped": at(inc, "wall_s", t, "heldout_capped"),
            }
            for t in ts
        ],
    }


#: the held-out sets of a pool process (loaded once by :func:`_pool_init`)
_POOL: dict[str, Any] = {}


def _pool_init(s: Settings, train: str, held_paths: list[str]) -> None:
    _POOL.update(settings=s, train=train, heldout=HeldOut(held_paths))


def _pool_study(task: tuple[str, str, str, int]) -> dict[str, Any]:
    model, sampler, pruner, seed = task
    s = _POOL["settings"]
    r = run_study(model, sampler, pruner, seed, s, _POOL["train"], _POOL["heldout"])
    r["checkpoints"] = checkpoints(r, s.n_trials)
    return r


def run(quick: bool = False, settings: Settings | None = None) -> dict:
    """Every study of the settings, ``processes`` at a time (seed by seed, so that the partial
    file ``bench/results/samplers[-quick]-partial.json``, written after each, holds whole
    seeds first); the plot and table."""
    import multiprocessing

    from core.files import write_json_atomic

    s = settings or (QUICK if quick else Settings())
    samplers, skipped = available(s.samplers)
    train = dataset_path(s.training_seed, s)
    held_paths = [dataset_path(seed, s) for seed in s.heldout_seeds]
    load = os.getloadavg()
    studies: dict[str, Any] = {}
    partial = Path("bench/results") / f"samplers{'-quick' if quick else ''}-partial.json"
    partial.parent.mkdir(parents=True, exist_ok=True)
    tasks = [
        (model, sampler, pruner, seed)
        for seed, model, sampler, pruner in itertools.product(
            s.seeds, s.models, samplers, s.pruners
        )
    ]
    if s.processes > 1:
        pool = multiprocessing.get_context("spawn").Pool(
            s.processes, initializer=_pool_init, initargs=(s, train, held_paths)
        )
        results: Iterator[dict[str, Any]] = pool.imap(_pool_study, tasks)
    else:
        pool = None
        _pool_init(s, train, held_paths)
        results = map(_pool_study, tasks)
    try:
        for r in results:
            key = f"{r['model']}-{r['sampler']}-{r['pruner']}-s{r['seed']}"
            studies[key] = r
            write_json_atomic(partial, {"settings": asdict(s), "studies": studies})
            last = r["incumbents"][-1]["heldout_paper"] * 1e3 if r["incumbents"] else math.nan
            print(
                f"{key}: {r['trials']} trials, {r['cpu_s']:.1f} s CPU, {r['wall_s']:.1f} s, "
                f"held-out L_t {last:.4f}e-3",
                flush=True,
            )
    finally:
        if pool is not None:
            pool.close()
            pool.join()
    versions = {}
    for package in ("optuna", "cmaes", "torch"):
        if importlib.util.find_spec(package) is not None:
            versions[package] = importlib.metadata.version(package)
    result = {
        "settings": {k: list(v) if isinstance(v, tuple) else v for k, v in asdict(s).items()},
        "samplers": list(samplers),
        "skipped_samplers": skipped,
        "training_set": f"paper:{s.training_seed}:{s.person_model} ({Path(train).name})",
        "heldout_sets": [f"paper:{seed}:{s.person_model}" for seed in s.heldout_seeds],
        "storage": "memory (Optuna InMemoryStorage), one worker in the study's process"
        + (f", {s.processes} studies at a time" if s.processes > 1 else ""),
        "versions": versions,
        "load_average_start": list(load),
        "load_average_end": list(os.getloadavg()),
        "studies": studies,
    }
    render(result, quick=quick)
    return result


# ---- report -----------------------------------------------------------------------------------
def report_dir(quick: bool = False) -> Path:
    return Path("bench/results/samplers-quick") if quick else Path("docs/tuning")


LABELS = {"tpe": "TPE", "random": "random", "cmaes": "CMA-ES", "gp": "GP"}


def groups(result: dict, model: str) -> dict[tuple[str, str], list[dict[str, Any]]]:
    """Studies of ``model`` by (sampler, pruner), seeds in order."""
    out: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for r in result["studies"].values():
        if r["model"] == model:
            out.setdefault((r["sampler"], r["pruner"]), []).append(r)
    for v in out.values():
        v.sort(key=lambda r: r["seed"])
    return out


def band(
    studies: list[dict[str, Any]], key: str, xs: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Median, lower and upper quartile over seeds of the held-out L_t at each x (NaN-aware:
    a seed without an incumbent yet is left out at that x)."""
    ys = np.array([[at(r["incumbents"], key, float(x)) for x in xs] for r in studies])
    ok = np.isfinite(ys).any(axis=0)
    q = np.full((3, len(xs)), np.nan)
    if ok.any():
        q[:, ok] = np.nanpercentile(ys[:, ok], [50, 25, 75], axis=0)
    return q[0], q[1], q[2]


def _fmt(v: float) -> str:
    return "–" if not math.isfinite(v) else f"{v * 1e3:.3f}"


def table(result: dict) -> str:
    """Markdown: held-out L_t (×10⁻³ m²) at 100, 300 and N trials, median [min, max] over seeds,
    with the study's seconds, the objective's share of its CPU time and the pruned share."""
    n = int(result["settings"]["n_trials"])
    ks = [k for k in (100, 300) if k < n] + [n]
    head = (
        "| model | sampler | pruner | "
        + " | ".join(f"L_t at {k} trials" for k in ks)
        + " | wall s (CPU s) per study | objective share of CPU | pruned |"
    )
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for model in result["settings"]["models"]:
        for (sampler, pruner), studies in groups(result, model).items():
            cells = []
            for k in ks:
                v = np.array([at(r["incumbents"], "trials", k) for r in studies])
                f = v[np.isfinite(v)]
                cells.append(
                    f"{_fmt(float(np.median(f)))} [{_fmt(float(f.min()))}, {_fmt(float(f.max()))}]"
                    if len(f)
                    else "–"
                )
            wall = float(np.median([r["wall_s"] for r in studies]))
            cpu = float(np.median([r["cpu_s"] for r in studies]))
            share = float(
                np.median([r["objective_cpu_s"] / max(r["cpu_s"], 1e-12) for r in studies])
            )
            pruned = float(np.median([r["pruned"] / max(r["trials"], 1) for r in studies]))
            lines.append(
                f"| {model.upper()} | {LABELS.get(sampler, sampler)} | {pruner} | "
                + " | ".join(cells)
                + f" | {wall:.1f} ({cpu:.1f}) | {share:.0%} | {pruned:.0%} |"
            )
    return "\n".join(lines)


def render(result: dict, quick: bool = False) -> list[Path]:
    """Write ``samplers.md`` (the table) and ``samplers.png`` (the panels)."""
    out = report_dir(quick)
    out.mkdir(parents=True, exist_ok=True)
    s = result["settings"]
    md = out / "samplers.md"
    skipped = result.get("skipped_samplers") or {}
    note = "".join(f"\n\nLeft out: {k}: {v}." for k, v in skipped.items())
    text = (
        "<!-- written by `radartune bench samplers` (core/benchmarks/samplers.py); "
        "do not edit -->\n"
        f"Held-out L_t (×10⁻³ m²) of the incumbent (the best trial by training loss so far), "
        f"studies of {s['n_trials']} trials on {result['training_set']}, held out: "
        f"{', '.join(result['heldout_sets'])} (the L_t of their trajectories together); "
        f"median [min, max] over sampler seeds {', '.join(map(str, s['seeds']))}. "
        f"Storage: {result['storage']}. Load average during the run: "
        f"{result['load_average_start'][1]:.1f} → {result['load_average_end'][1]:.1f} "
        "(5 min; the machine has 2 cores).\n\n" + table(result) + note + "\n"
    )
    write_text_atomic(md, text)
    return [md, _plot(result, out / "samplers.png")]


def _plot(result: dict, path: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    s = result["settings"]
    n = int(s["n_trials"])
    models = list(s["models"])
    fig, axes = plt.subplots(
        len(models), 2, figsize=(12, 4.4 * len(models)), sharey="row", squeeze=False
    )
    colors = {"tpe": "C0", "random": "C1", "cmaes": "C2", "gp": "C3"}
    styles = {"asha": "-", "none": "--", "wilcoxon": ":"}
    studies_all = list(result["studies"].values())
    firsts = [r["incumbents"][0]["wall_s"] for r in studies_all if r["incumbents"]]
    grids: dict[str, np.ndarray] = {
        "trials": np.unique(np.geomspace(1, n, 200).round()),
        "wall_s": np.geomspace(
            max(min(firsts, default=1e-3), 1e-3), max(r["wall_s"] for r in studies_all), 200
        ),
    }
    for row, model in zip(axes, models, strict=True):
        for ax, key in zip(row, ("trials", "wall_s"), strict=True):
            xs = grids[key]
            for (sampler, pruner), studies in groups(result, model).items():
                med, lo, hi = band(studies, key, xs)
                if key == "wall_s":  # drawn while every seed's study still runs
                    gone = xs > min(r["wall_s"] for r in studies)
                    med[gone], lo[gone], hi[gone] = np.nan, np.nan, np.nan
                c = colors.get(sampler, "k")
                ax.plot(
                    xs,
                    med,
                    color=c,
                    ls=styles.get(pruner, "-."),
                    lw=1.8,
                    drawstyle="steps-post",
                    label=f"{LABELS.get(sampler, sampler)}, "
                    + ("ASHA" if pruner == "asha" else "no pruning"),
                )
                ax.fill_between(xs, lo, hi, color=c, alpha=0.12, step="post", lw=0)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.grid(True, which="both", alpha=0.3)
            ax.set_title(
                f"{model.upper()}: against " + ("trials" if key == "trials" else "wall-clock time"),
                fontsize=10,
            )
        row[0].set_ylabel(f"{model.upper()}: held-out L_t of the incumbent (m²)")
        row[0].legend(fontsize=8, loc="upper right")
    axes[-1][0].set_xlabel("trials (pruned ones included)")
    load = float(np.mean([result["load_average_start"][1], result["load_average_end"][1]]))
    wall_per_cpu = float(np.median([r["wall_s"] / max(r["cpu_s"], 1e-9) for r in studies_all]))
    axes[-1][1].set_xlabel(
        "wall-clock seconds since the first trial (one worker, in memory)\n"
        f"load {load:.0f} on 2 cores: wall clock {wall_per_cpu:.1f}× the study's CPU time"
    )
    for row in axes:
        row[1].set_xlim(left=0.1)
    fig.suptitle(
        f"Studies on {result['training_set'].split(' ')[0]}, incumbent re-tracked on "
        f"{len(result['heldout_sets'])} held-out sets: median and interquartile band over "
        f"{len(s['seeds'])} sampler seeds",
        fontsize=10,
    )
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)
    return path


def summary(result: dict) -> str:
    s = result["settings"]
    lines = [
        f"bench samplers: {', '.join(m.upper() for m in s['models'])}, "
        f"{result['training_set']}, {s['n_trials']} trials, held out "
        f"{', '.join(result['heldout_sets'])}; {result['storage']}",
        "held-out L_t x1e-3 m2, median [min, max] over seeds:",
        table(result),
    ]
    for k, v in (result.get("skipped_samplers") or {}).items():
        lines.append(f"left out {k}: {v}")
    return "\n".join(lines)


__all__: list[str] = ["QUICK", "Settings", "available", "render", "run", "summary"]
