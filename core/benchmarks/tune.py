"""``radartune bench tune``: completed trials per second of a CV study on every storage.

A CV study (TPE + ASHA, as ``radartune tune`` runs it) on the walking-body paper data set, with
1 and 2 worker processes on the SQLite file (the default storage), the journal file and
PostgreSQL (``$RADARTUNE_BENCH_POSTGRES`` or a throwaway server where the server binaries are
installed; left out otherwise). References measured in the same run, in this process:

- the bare objective: the IPDA tracker on the 35 trajectories with random parameters, no
  Optuna, no storage (the work of a trial that is not pruned);
- the same study in Optuna's in-memory storage (``run_worker`` on ``memory://``): Optuna's
  sampler and pruner without any storage round trip;
- the study with one worker in this process on each storage: CPU a trial of the storage's
  round trips without process start-up.

Per study: the steady rate (trials finished between the first trial's start and the last
trial's end), the end-to-end rate (from the ``tune`` call to the last worker's exit, process
start-up included), the workers' CPU seconds per trial, and the ratios to both references. The
machine is shared: the load average before and after each study and the share of a core a busy
loop got just before it (``cpu_share``; with the kernel's per-session scheduling, two workers of
one command share one session's slice) are recorded beside it, and CPU time per trial is the
figure that load disturbs least. The point-person data set's SQLite
2-job study and references are measured too, for comparison with earlier figures.
Goal: at least 20 trials/s with 2 jobs on SQLite.

``radartune bench tune --recording REC.npz [--people N]`` measures instead a study on a
recording (an imported data set without truth), cut to its first :data:`RECORDING_FRAMES`
frames, minimising the objective without positions a recording study minimises (fragmentation
with a head count, else nis): the same references (bare objective, in-memory study, one worker
in process) and the SQLite studies with 1 and 2 jobs; same goal.
"""

from __future__ import annotations

import os
import resource
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

GOAL_TRIALS_PER_S_2_JOBS = 20.0
#: Frames of the recording a recording study is measured on.
RECORDING_FRAMES = 2000


def _reference(
    dataset_path: str, n: int, *, loss: str = "paper", people: int | None = None
) -> dict[str, float]:
    """The bare objective in this process: a full (unpruned) trial's work, no Optuna."""
    from core.dataset import Dataset
    from core.optimization.objective import evaluate, tracker_losses
    from core.optimization.space import search_space
    from core.tracking.space import tracker_params_dict

    ds = Dataset.load(dataset_path)
    # the work of a default (paper-loss) trial, or of the recording study's objective
    losses = tracker_losses(ds, loss, people=people)
    rng = np.random.default_rng(0)

    def draw() -> dict[str, Any]:
        flat = {}
        for b in search_space("cv"):
            if b.log:
                flat[b.name] = float(np.exp(rng.uniform(np.log(b.low), np.log(b.high))))
            else:
                flat[b.name] = float(rng.uniform(b.low, b.high))
        return tracker_params_dict(flat, "cv")

    evaluate(losses, draw(), loss=loss)  # compile / warm caches
    t0, c0 = time.perf_counter(), time.process_time()
    for _ in range(n):
        evaluate(losses, draw(), loss=loss)
    dt, dc = time.perf_counter() - t0, time.process_time() - c0
    return {"trials": n, "seconds": dt, "trials_per_s": n / dt, "cpu_s_per_trial": dc / n}


def _settings(dataset_path: str, storage: str, n_jobs: int, n_trials: int, **study: Any) -> Any:
    """The bench study's settings; ``study``: ``loss`` and ``people`` of a recording study."""
    from core.optimization.study import StudySettings

    return StudySettings(
        model="cv",
        n_trials=n_trials,
        n_jobs=n_jobs,
        storage=storage,
        dataset=dataset_path,
        study_name=f"bench-cv-{n_jobs}-{time.time_ns()}",  # one storage may hold several
        **study,
    )


def _rates(storage: str, name: str) -> dict[str, Any]:
    from core.optimization.progress import counted, study_progress

    summaries, best = study_progress(storage, name)
    done = [t for t in summaries if t.state in ("COMPLETE", "PRUNED")]
    first = min(t.datetime_start for t in done)
    last = max(t.datetime_complete for t in done)
    steady = (last - first).total_seconds()
    return {
        "trials": counted(summaries),
        "pruned": sum(1 for t in done if t.state == "PRUNED"),
        "failed": sum(1 for t in summaries if t.state == "FAIL"),
        # opened by a worker after the total was reached, closed at once (not a failure)
        "surplus": sum(1 for t in summaries if t.state == "SURPLUS"),
        "steady_s": steady,
        "trials_per_s_steady": (len(done) - 1) / steady if steady > 0 else float("nan"),
        "best_loss": None if best is None else best.value,
    }


def cpu_share(seconds: float = 0.5) -> float:
    """Share of one core a busy loop in this process gets now (1.0 on an idle machine)."""
    t0, c0 = time.perf_counter(), time.process_time()
    x = 0
    while time.perf_counter() - t0 < seconds:
        x += 1
    return (time.process_time() - c0) / (time.perf_counter() - t0)


def _in_process(dataset_path: str, storage: str, n_trials: int, **study: Any) -> dict[str, Any]:
    """The study with one worker in this process (no process start-up): Optuna's in-memory
    storage (``memory://``) for the reference, or a file or server storage."""
    from core.optimization.study import prepare_study, run_worker

    s = _settings(dataset_path, storage, 1, n_trials, **study)
    prepare_study(s, dataset_path=dataset_path)
    share = cpu_share()
    t0, c0 = time.perf_counter(), time.process_time()
    run_worker(s.storage, s.name, seed=s.seed, dataset_path=dataset_path)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    r = _rates(s.storage, s.name)
    r.update(
        jobs=1,
        wall_s=wall,
        trials_per_s_end_to_end=r["trials"] / wall,
        cpu_s_per_trial=cpu / r["trials"],
        cpu_share=share,
    )
    return r


def _study(
    dataset_path: str, storage: str, n_jobs: int, n_trials: int, **study: Any
) -> dict[str, Any]:
    from core.optimization.study import start_study

    s = _settings(dataset_path, storage, n_jobs, n_trials, **study)
    share = cpu_share()
    load0 = os.getloadavg()[0]
    cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    handle = start_study(s, dataset_path=dataset_path)
    handle.wait()
    wall = time.perf_counter() - t0
    cpu1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = _rates(storage, s.name)
    cpu = (cpu1.ru_utime - cpu0.ru_utime) + (cpu1.ru_stime - cpu0.ru_stime)
    r.update(
        jobs=n_jobs,
        wall_s=wall,
        trials_per_s_end_to_end=r["trials"] / wall,
        # the workers' CPU, process start-up (imports, loading the compiled tracker) included
        cpu_s_per_trial=cpu / r["trials"],
        cpu_share=share,
        load_before=load0,
        load_after=os.getloadavg()[0],
        returncodes=handle.returncodes(),
    )
    return r


def _dataset_runs(
    dataset_path: str,
    n_trials: int,
    n_ref: int,
    storages: list[tuple[str, str]],
    jobs: tuple[int, ...],
    *,
    in_process: bool = True,
    **study: Any,
) -> dict[str, Any]:
    ref = _reference(dataset_path, n_ref, **study)
    memory = _in_process(dataset_path, f"memory://bench-{time.time_ns()}", n_trials, **study)
    memory["storage"] = "memory"
    one_process, runs = [], []
    for kind, url in storages:
        if in_process:
            r = _in_process(dataset_path, url.format(jobs="in-process"), n_trials, **study)
            r["storage"] = kind
            r["cpu_ratio_to_in_memory"] = r["cpu_s_per_trial"] / memory["cpu_s_per_trial"]
            one_process.append(r)
        for n_jobs in jobs:
            r = _study(dataset_path, url.format(jobs=n_jobs), n_jobs, n_trials, **study)
            r["storage"] = kind
            r["ratio_to_objective"] = r["trials_per_s_steady"] / ref["trials_per_s"]
            r["ratio_to_in_memory"] = r["trials_per_s_steady"] / memory["trials_per_s_steady"]
            runs.append(r)
    return {
        "dataset": Path(dataset_path).name,
        "objective_in_process": ref,
        "in_memory_study": memory,
        "in_process_studies": one_process,
        "studies": runs,
    }


def first_frames(dataset: Any, n: int) -> Any:
    """The data set cut to its first ``n`` frames (its points, truth and trajectories there)."""
    from dataclasses import replace

    n = min(int(n), dataset.n_frames)
    p = int(np.searchsorted(dataset.frame, n))
    per_point = ("frame", "range_m", "azimuth_rad", "elevation_rad", "radial_velocity_mps",
                 "snr_db", "x_m", "y_m", "z_m", "source")  # fmt: skip
    k = int(dataset.trajectory[n - 1]) + 1 if n else 0
    return replace(
        dataset,
        **{f: getattr(dataset, f)[:p] for f in per_point},
        trajectory=dataset.trajectory[:n],
        truth_t_s=dataset.truth_t_s[:n],
        truth_xy_m=dataset.truth_xy_m[:n],
        truth_v_mps=dataset.truth_v_mps[:n],
        trajectory_class=dataset.trajectory_class[:k],
    )


def run_recording(path: str, people: int | None, quick: bool = False) -> dict:
    """A study on a recording's first :data:`RECORDING_FRAMES` frames (see the module)."""
    from core.dataset import Dataset

    n_trials = 20 if quick else 200
    n_ref = 5 if quick else 30
    loss = "fragmentation" if people is not None else "nis"
    full = Dataset.load(path)
    ds = first_frames(full, RECORDING_FRAMES)
    with tempfile.TemporaryDirectory(prefix="radartune-bench-") as tmp:
        cut = str(ds.save(Path(tmp) / "recording.npz"))
        part = _dataset_runs(
            cut,
            n_trials,
            n_ref,
            [("sqlite", f"sqlite:///{tmp}/r{{jobs}}.db")],
            (1, 2),
            loss=loss,
            people=people,
        )
    part["dataset"] = Path(path).name
    return {
        "n_trials": n_trials,
        "goal_trials_per_s_2_jobs": GOAL_TRIALS_PER_S_2_JOBS,
        "recording": {
            **part,
            "frames": ds.n_frames,
            "points": int(len(ds.frame)),
            "runs": ds.n_trajectories,
            "loss": loss,
            "people": people,
        },
    }


def run(quick: bool = False, recording: str | None = None, people: int | None = None) -> dict:
    from core.benchmarks.postgres import postgres_server
    from core.optimization.data import resolve_dataset

    if recording:
        return run_recording(recording, people, quick)
    n_trials = 20 if quick else 200
    n_ref = 5 if quick else 30
    walking = resolve_dataset("paper:0:walking")
    point = resolve_dataset("paper:0")
    with tempfile.TemporaryDirectory(prefix="radartune-bench-") as tmp, postgres_server() as pg:
        storages = [
            ("sqlite", f"sqlite:///{tmp}/b{{jobs}}.db"),
            ("journal", f"journal:///{tmp}/b{{jobs}}.log"),
        ]
        if pg:
            storages.append(("postgresql", pg))
        result_walking = _dataset_runs(walking, n_trials, n_ref, storages, (1, 2))
        result_point = _dataset_runs(
            point,
            n_trials,
            n_ref,
            [("sqlite", f"sqlite:///{tmp}/p{{jobs}}.db")],
            (2,),
            in_process=False,
        )
    return {
        "n_trials": n_trials,
        "goal_trials_per_s_2_jobs": GOAL_TRIALS_PER_S_2_JOBS,
        "postgresql": bool(pg),
        "walking": result_walking,
        "point": result_point,
    }


def summary(result: dict) -> str:
    lines = [
        f"bench tune: CV study, TPE + ASHA, {result['n_trials']} trials; goal "
        f"{result['goal_trials_per_s_2_jobs']:.0f} trials/s with 2 jobs on SQLite",
    ]
    for person in ("walking", "point", "recording"):
        if person not in result:
            continue
        part = result[person]
        if person == "recording":
            lines.append(
                f"  recording {part['dataset']}: first {part['frames']} frames "
                f"({part['points']} points, {part['runs']} runs), --loss {part['loss']}"
                + (f", --people {part['people']}" if part["people"] is not None else "")
            )
        ref, mem = part["objective_in_process"], part["in_memory_study"]
        lines += [
            f"  {person} person ({part['dataset']}):",
            f"    objective in process (every trajectory, no Optuna): "
            f"{ref['trials_per_s']:.1f} trials/s, {1e3 * ref['cpu_s_per_trial']:.1f} ms CPU",
            f"    in process, 1 worker: memory {mem['trials_per_s_steady']:.1f} trials/s, "
            f"{1e3 * mem['cpu_s_per_trial']:.1f} ms CPU a trial ({mem['pruned']} pruned; "
            f"CPU share {mem['cpu_share']:.2f})",
        ]
        for r in part["in_process_studies"]:
            lines.append(
                f"    in process, 1 worker: {r['storage']} {r['trials_per_s_steady']:.1f} "
                f"trials/s, {1e3 * r['cpu_s_per_trial']:.1f} ms CPU a trial "
                f"(x{r['cpu_ratio_to_in_memory']:.2f} of memory's CPU; CPU share "
                f"{r['cpu_share']:.2f})"
            )
        for r in part["studies"]:
            lines.append(
                f"    {r['storage']:<10} jobs={r['jobs']}: {r['trials_per_s_steady']:5.1f} "
                f"trials/s steady, {r['trials_per_s_end_to_end']:5.1f} end to end, "
                f"{1e3 * r['cpu_s_per_trial']:.1f} ms CPU a trial with start-up; "
                f"x{r['ratio_to_objective']:.2f} of the objective, x{r['ratio_to_in_memory']:.2f}"
                f" of in-memory ({r['trials']} trials, {r['pruned']} pruned, CPU share "
                f"{r['cpu_share']:.2f}, load {r['load_before']:.1f}->{r['load_after']:.1f})"
            )
    return "\n".join(lines)
