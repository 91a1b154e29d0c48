"""Studies: create or resume, run workers, cap the total, survive crashes.

Reading them (trials, progress, model, names): :mod:`core.optimization.progress`.

One study per motion model. The study's settings live in its user attributes (``model``,
``objective``, ``dataset``, ``n_trials``, ``sampler``, ``pruner``, ``seed``), so that a worker
joining from another machine needs only the storage URL and the study name, and a study of the
other model under the same name is refused.

Total cap ("exactly the asked total"): the total counts trials that finished COMPLETE or PRUNED.
A worker asks for a trial, then counts the trials numbered below it that are COMPLETE, PRUNED,
RUNNING or WAITING; if that count already reaches ``n_trials`` the new trial is surplus and is
closed as FAIL with the user attribute ``surplus=True`` (Optuna cannot delete trials). Trial
numbers are assigned atomically by every storage, so two workers can never both take the last
slot. A trial that fails (tracker error) frees its slot, so the total is still reached.

Seeds: trial n samples with a sampler seeded by :func:`trial_seed` (base seed, n). Trial numbers
are unique in a study, so no two trials — of one worker, of several workers, of two ``tune`` runs
on the study at once, of a resume or of a ``worker`` that joins — ever sample with the same seed,
and one worker with the same base seed reproduces the same trials.

Crashes: every trial records its worker ``host:pid:start-ticks``. On resume, a RUNNING trial whose
worker is on this host and no longer alive is marked FAIL at once; one from another host is
marked FAIL when it has run longer than ``stale_after_s`` (trials take seconds).
"""

from __future__ import annotations

import datetime as dt
import math
import os
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from core.errors import InputError
from core.evaluation.robust import DEFAULT_OBJECTIVE, check_objective
from core.optimization.objective import evaluate, make_losses, uses_capped, without_positions
from core.optimization.space import check_tuned, suggest_params
from core.optimization.storage import (
    DEFAULT_STORAGE,
    absolute_url,
    load_existing_study,
    normalize_url,
    open_storage,
    redact,
)
from core.tracking.space import GTRACK, check_mode, tracker_params_dict

SAMPLERS = ("tpe", "random", "cmaes", "gp")
#: samplers that need a package Optuna does not install itself: sampler -> module
SAMPLER_PACKAGES = {"cmaes": "cmaes", "gp": "torch"}
PRUNERS = ("asha", "wilcoxon", "none")
OBJECTIVES = ("tracker", "quadratic")
#: states that occupy a slot of the total
_OCCUPYING = ("COMPLETE", "PRUNED", "RUNNING", "WAITING")
#: consecutive failed trials after which a worker gives up (a broken objective)
MAX_CONSECUTIVE_FAILURES = 5
STALE_AFTER_S = 600.0
ROOT = Path(__file__).resolve().parents[2]


@dataclass(frozen=True, slots=True, kw_only=True)
class StudySettings:
    """Everything needed to start (or resume) a study; Qt- and Optuna-free.

    Parameters
    ----------
    model
        Motion model, ``"cv"`` or ``"ca"``, or ``"gtrack"`` (TI's tracker, its own table).
    n_trials
        Total number of counted (COMPLETE + PRUNED) trials over all workers and runs.
    n_jobs
        Worker processes started on this machine.
    storage
        Storage URL (``sqlite:///…``, ``journal:///…``, ``postgresql://…``).
    study_name
        None: ``radartune-<model>``.
    seed
        Base seed: trial n samples with :func:`trial_seed` (seed, n).
    sampler
        ``"tpe"``, ``"random"`` (baseline), ``"cmaes"`` or ``"gp"`` (:func:`make_sampler`).
    pruner
        ``"asha"`` (successive halving), ``"wilcoxon"`` or ``"none"``.
    dataset
        Path of a data set ``.npz``; None: the paper's data set (seed 0, 35 trajectories, cached).
    objective
        ``"tracker"`` (the IPDA tracker on the data set) or ``"quadratic"`` (test objective).
    loss
        What a trial minimises (:data:`core.evaluation.robust.OBJECTIVES`): ``"trimmed"`` (the
        default, :data:`core.evaluation.robust.DEFAULT_OBJECTIVE`), ``"paper"`` (the paper's
        L_t, eq. 14), ``"capped"`` or ``"median"``. The paper's L_t is
        recorded beside it on every trial (user attribute ``paper_loss``).
    objective_options
        Options of the quadratic objective (``n_trajectories``, ``delay_s``).
    people
        Head count in every frame of the data set (``--people N``) for the objectives without
        positions (``count``, ``fragmentation``); None: the truth's.
    mix
        Further training data sets, ``(path, weight)`` each (:mod:`core.optimization.mix`); the
        study's own data set weighs 1.
    recording_loss
        The objective of a data set without what ``loss`` needs (a recording without truth, in
        a mixed study or at validation); ``""``: fragmentation with ``people``, else nis.
    """

    model: str = "cv"
    n_trials: int = 300
    n_jobs: int = 1
    storage: str = DEFAULT_STORAGE
    study_name: str | None = None
    seed: int = 0
    sampler: str = "tpe"
    pruner: str = "asha"
    dataset: str | None = None
    objective: str = "tracker"
    objective_options: dict[str, float] = field(default_factory=dict)
    loss: str = DEFAULT_OBJECTIVE
    people: int | None = None
    mix: tuple[tuple[str, float], ...] = ()
    recording_loss: str = ""
    mode: str = "paper"

    def __post_init__(self) -> None:
        check_tuned(self.model)
        check_mode(self.mode)
        if self.model == GTRACK and self.mode != "paper":
            raise InputError(f"mode {self.mode!r} is the IPDA tracker's: not with model gtrack")
        if self.recording_loss:
            check_objective(self.recording_loss)
        for path, weight in self.mix:
            if not (math.isfinite(weight) and weight > 0):
                raise InputError(f"mix {path}: weight must be > 0, got {weight}")
        if self.people is not None and (isinstance(self.people, bool) or int(self.people) < 0):
            raise InputError(f"people must be a whole number >= 0, got {self.people!r}")
        if int(self.n_trials) < 1:
            raise InputError(f"n_trials must be >= 1, got {self.n_trials}")
        if int(self.n_jobs) < 1:
            raise InputError(f"n_jobs must be >= 1, got {self.n_jobs}")
        check_sampler(self.sampler)
        if self.pruner not in PRUNERS:
            raise InputError(f"pruner must be one of {', '.join(PRUNERS)}, got {self.pruner!r}")
        if self.objective not in OBJECTIVES:
            raise InputError(
                f"objective must be one of {', '.join(OBJECTIVES)}, got {self.objective!r}"
            )
        check_objective(self.loss)
        normalize_url(self.storage)

    @property
    def name(self) -> str:
        """The study name (default ``radartune-<model>``)."""
        return self.study_name or f"radartune-{self.model}"


# ---- samplers and pruners ---------------------------------------------------------------------
def check_sampler(kind: str) -> str:
    """``kind`` if it names a sampler whose package is installed; else one :class:`InputError`."""
    import importlib.util

    if kind not in SAMPLERS:
        raise InputError(f"sampler must be one of {', '.join(SAMPLERS)}, got {kind!r}")
    package = SAMPLER_PACKAGES.get(kind)
    if package is not None and importlib.util.find_spec(package) is None:
        raise InputError(f"sampler {kind!r} needs the Python package {package!r} (not installed)")
    return kind


def make_sampler(kind: str, seed: int | None) -> Any:
    """Optuna sampler with every argument set explicitly (Optuna 5 changed the defaults).

    TPE: multivariate (one joint Parzen estimator over all parameters, ``multivariate=True``),
    which reads the trial history once per trial instead of once per parameter (decision
    tuning-02; the paper's Optuna 3 default was independent per-parameter estimators), 10 random
    start-up trials, 24 EI candidates, and the constant liar so that parallel workers do not
    sample the same point while trials run. (Prior, magic clip and endpoints keep their
    defaults: their arguments are deprecated in Optuna 5.)

    CMA-ES (``cmaes``, needs the ``cmaes`` package): every parameter scaled to [0, 1] (log ones
    in log space), starting at the centre with σ₀ = 1/6, after one random start-up trial, with
    the default population 4 + ⌊3 ln d⌋; pruned trials are not told to it. Its state
    lives in the study's trials, so the fresh sampler a worker makes per trial resumes it.
    GP (``gp``, needs ``torch``): Optuna's Gaussian-process sampler, 10 random start-up trials.
    A trial without a relative sample (the start-up) is drawn by a random sampler of the seed.
    """
    import optuna

    check_sampler(kind)
    if kind == "random":
        return optuna.samplers.RandomSampler(seed=seed)
    if kind == "cmaes":
        return optuna.samplers.CmaEsSampler(
            n_startup_trials=1,
            independent_sampler=optuna.samplers.RandomSampler(seed=seed),
            warn_independent_sampling=False,
            seed=seed,
            consider_pruned_trials=False,
            use_separable_cma=False,
            with_margin=False,
            lr_adapt=False,
        )
    if kind == "gp":
        return optuna.samplers.GPSampler(
            seed=seed,
            independent_sampler=optuna.samplers.RandomSampler(seed=seed),
            n_startup_trials=10,
            deterministic_objective=False,
            warn_independent_sampling=False,
        )
    return optuna.samplers.TPESampler(
        n_startup_trials=10,
        n_ei_candidates=24,
        seed=seed,
        multivariate=True,
        group=False,
        constant_liar=True,
    )


#: successive halving: first rung after one round over the five classes, reduction factor η
ASHA_MIN_RESOURCE = 5
ASHA_REDUCTION_FACTOR = 3


def asha_rungs(n_steps: int) -> list[int]:
    """Steps at which successive halving decides: r·η^k ≤ n_steps (5, 15, 45, …)."""
    rungs, step = [], ASHA_MIN_RESOURCE
    while step <= n_steps:
        rungs.append(step)
        step *= ASHA_REDUCTION_FACTOR
    return rungs


def make_pruner(kind: str) -> Any:
    """ASHA: rungs at 5, 15 trajectories (one and three rounds over the five classes), η = 3."""
    import optuna

    if kind == "asha":
        return optuna.pruners.SuccessiveHalvingPruner(
            min_resource=ASHA_MIN_RESOURCE,
            reduction_factor=ASHA_REDUCTION_FACTOR,
            min_early_stopping_rate=0,
            bootstrap_count=0,
        )
    if kind == "wilcoxon":
        import warnings

        with warnings.catch_warnings():  # "experimental" since Optuna 3.6; chosen knowingly
            warnings.simplefilter("ignore", optuna.exceptions.ExperimentalWarning)
            return optuna.pruners.WilcoxonPruner(p_threshold=0.1, n_startup_steps=5)
    if kind == "none":
        return optuna.pruners.NopPruner()
    raise InputError(f"pruner must be one of {', '.join(PRUNERS)}, got {kind!r}")


# ---- worker identity and crash recovery -------------------------------------------------------
def _start_ticks(pid: int) -> str | None:
    """Start time of a running process in clock ticks (Linux ``/proc``), to tell a reused pid
    apart; None when no such process runs.

    A zombie (state ``Z``, or ``X`` while it is removed) has ended: it keeps its ``/proc``
    entry only until its parent reaps it (``tune`` polls its workers every 0.5 s), and another
    worker finishing the study in that window must see it dead to free its trial's slot.
    """
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    fields = stat.rsplit(")", 1)[1].split()  # state, ppid, ... (after the command name)
    if fields[0] in ("Z", "X"):
        return None
    return fields[19]


def worker_id() -> str:
    """``host:pid:start-ticks`` of this process."""
    pid = os.getpid()
    return f"{socket.gethostname()}:{pid}:{_start_ticks(pid) or 0}"


def worker_alive(wid: str) -> bool | None:
    """True/False for a worker on this host, None if it runs on another host."""
    try:
        host, pid, ticks = wid.rsplit(":", 2)
    except ValueError:
        return None
    if host != socket.gethostname():
        return None
    now = _start_ticks(int(pid))
    return now is not None and now == ticks


def trial_seed(seed: int, number: int) -> int:
    """The sampler seed of trial ``number`` in a study with base seed ``seed``.

    ``(h(seed) + number) mod 2**32`` with ``h`` a SeedSequence hash: distinct for every trial
    number (below 2**32) of a base seed, so the trials of a study never share a seed whichever
    worker or run asks for them; other base seeds give unrelated sequences.
    """
    base = int(np.random.SeedSequence(int(seed) % 2**64).generate_state(1)[0])
    return (base + int(number)) % 2**32


def _ask_as(
    study: Any,
    worker: str,
    sampler: Callable[[int], Any] | None = None,
    *,
    waiting: bool | None = None,
) -> Any:
    """``study.ask()`` with the worker recorded in the same storage write that creates the trial.

    ``sampler(number)``, if given, becomes ``study.sampler`` for the new trial once its number
    is known (the sampler is consulted first when the ``optuna.Trial`` is made; enqueued trials,
    whose parameters are fixed, keep the current sampler).

    Set afterwards (``trial.set_user_attr``), a SIGKILL between the two writes left a RUNNING
    trial without a worker, which resume could not tell from a live one on another host (seen
    in the SIGKILL test under load). ``create_new_trial`` with a template is the storage API that
    ``ask`` uses itself; ``optuna.Trial`` then runs the sampler's ``before_trial`` as ``ask`` does.

    ``waiting``: whether enqueued (WAITING) trials exist, if the caller read the study just
    before; None: read it here.
    """
    import optuna
    from optuna.trial import FrozenTrial, TrialState

    if waiting is None:
        waiting = bool(study.get_trials(deepcopy=False, states=(TrialState.WAITING,)))
    if waiting:
        # an enqueued trial runs first (ask pops it); only these keep the two writes
        trial = study.ask()
        trial.set_user_attr("worker", worker)
        return trial
    template = FrozenTrial(
        number=-1, state=TrialState.RUNNING, value=None, datetime_start=dt.datetime.now(),
        datetime_complete=None, params={}, distributions={}, user_attrs={"worker": worker},
        system_attrs={}, intermediate_values={}, trial_id=-1,
    )  # fmt: skip
    trial_id = study._storage.create_new_trial(study._study_id, template_trial=template)
    if sampler is not None:
        study.sampler = sampler(study._storage.get_trial_number_from_id(trial_id))
    return optuna.Trial(study, trial_id)


def fail_stale_trials(study: Any, *, stale_after_s: float = STALE_AFTER_S) -> list[int]:
    """Mark FAIL the RUNNING trials whose worker died; return their numbers.

    A RUNNING trial of a dead worker on this host fails at once; one without a worker record
    or from another host fails when it has run longer than ``stale_after_s``.
    """
    from optuna.trial import TrialState

    failed = []
    now = dt.datetime.now()
    for t in study.get_trials(deepcopy=False, states=(TrialState.RUNNING,)):
        alive = worker_alive(str(t.user_attrs.get("worker", "")))
        age = (now - t.datetime_start).total_seconds() if t.datetime_start else math.inf
        if alive is False or (alive is None and age > stale_after_s):
            try:
                study._storage.set_trial_user_attr(t._trial_id, "stale", True)
                study._storage.set_trial_state_values(t._trial_id, state=TrialState.FAIL)
            except RuntimeError:  # finished meanwhile
                continue
            failed.append(t.number)
    return failed


# ---- creating, loading ------------------------------------------------------------------------
def loss_of_study(storage: str, study_name: str) -> str:
    """The objective a study started now minimises when none is asked for: a study being resumed
    keeps its own (one made before robust objectives existed: the paper's); a new study gets
    :data:`core.evaluation.robust.DEFAULT_OBJECTIVE`."""
    from core.evaluation.robust import DEFAULT_OBJECTIVE

    try:
        store = open_storage(storage, create=False)
    except InputError:
        return DEFAULT_OBJECTIVE  # no storage yet: a new study
    study = load_existing_study(store, study_name)
    if study is None:
        return DEFAULT_OBJECTIVE
    return str(study.user_attrs.get("loss", "paper"))


def prepare_study(settings: StudySettings, *, dataset_path: str | None = None) -> Any:
    """Create the study (once, before any worker starts) or resume it; return the Optuna study.

    Refuses — with one :class:`InputError` line and without touching the study — a study of the
    other model, objective or data set under the same name. On resume the total ``n_trials`` is
    updated and trials left RUNNING by a crash are marked FAIL.
    """
    import optuna

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    storage = open_storage(settings.storage)
    attrs = {
        "model": settings.model,
        "objective": settings.objective,
        "dataset": dataset_path or settings.dataset or "",
        "sampler": settings.sampler,
        "pruner": settings.pruner,
        "seed": int(settings.seed),
        "objective_options": dict(settings.objective_options),
        "loss": settings.loss,
        "mode": settings.mode,
        "space": "paper-eq15",
    }
    if settings.people is not None:
        attrs["people"] = int(settings.people)
    if settings.mix:
        attrs["mix"] = [[str(p), float(w)] for p, w in settings.mix]
    if settings.recording_loss:
        attrs["recording_loss"] = settings.recording_loss
    study = load_existing_study(storage, settings.name)
    if study is not None:
        old = study.user_attrs
        for key in ("mix", "recording_loss"):
            if old.get(key) != attrs.get(key):
                raise InputError(
                    f"study {settings.name!r} in {redact(settings.storage)} has {key}="
                    f"{old.get(key)!r}, asked {attrs.get(key)!r}; use another --study name"
                )
        if old.get("people") != attrs.get("people"):
            raise InputError(
                f"study {settings.name!r} in {redact(settings.storage)} has people="
                f"{old.get('people')!r}, asked {attrs.get('people')!r}; use another --study name"
            )
        for key in ("model", "objective", "sampler", "pruner", "loss", "mode"):
            # a study made before robust objectives (room mode) minimised the paper's loss (paper)
            if old.get(key, "paper" if key in ("loss", "mode") else None) != attrs[key]:
                raise InputError(
                    f"study {settings.name!r} in {redact(settings.storage)} has {key}="
                    f"{old.get(key)!r}, asked {attrs[key]!r}; use another --study name"
                )
        if old.get("dataset") and attrs["dataset"] and old["dataset"] != attrs["dataset"]:
            raise InputError(
                f"study {settings.name!r} was run on data set {old['dataset']!r}, asked "
                f"{attrs['dataset']!r}; use another --study name"
            )
        fail_stale_trials(study)
    else:
        study = optuna.create_study(
            storage=storage, study_name=settings.name, direction="minimize", load_if_exists=True
        )
        for key, value in attrs.items():
            study.set_user_attr(key, value)
    study.set_user_attr("n_trials", int(settings.n_trials))
    return study


def count_trials(study: Any, *, below: int | None = None) -> int:
    """Trials occupying a slot of the total (COMPLETE, PRUNED, RUNNING, WAITING)."""
    from optuna.trial import TrialState

    states = tuple(TrialState[s] for s in _OCCUPYING)
    trials = study.get_trials(deepcopy=False, states=states)
    if below is None:
        return len(trials)
    return sum(1 for t in trials if t.number < below)


class _RungReports:
    """A trial's reports to the pruner, sent to the storage with the pruner's question.

    ``evaluate`` reports a value and then, at a pruning point, asks ``should_prune``: the
    report and the pruner's own record (ASHA's rung value) are then written in one phase
    (:func:`core.optimization.batching.batched`). The pruner judges against the study as read
    when the trial started (no read per rung): with one worker nothing else changes it in
    between, so the decisions are the same; with several, other workers' rung values of the
    last trial's duration (tens of milliseconds) are seen at the next trial.
    """

    def __init__(self, trial: Any, store: Any) -> None:
        self.trial = trial
        self.store = store
        self.pending: list[tuple[float, int]] = []

    def report(self, value: float, step: int) -> None:
        self.pending.append((value, step))

    def flush(self) -> None:
        """Send the pending reports (inside the caller's phase, if any)."""
        for value, step in self.pending:
            self.trial.report(value, step)
        self.pending.clear()

    def should_prune(self) -> bool:
        from core.optimization.batching import batched

        with batched(self.store, read=False):
            self.flush()
            return bool(self.trial.should_prune())


def load_dataset_for(attrs: dict[str, Any], dataset_path: str | None) -> Any:
    """The data set a worker tracks: ``dataset_path`` or the study's recorded path."""
    if attrs.get("objective") != "tracker":
        return None
    from core.dataset import Dataset

    path = dataset_path or attrs.get("dataset")
    if not path:
        raise InputError("the study records no data set; pass --dataset PATH")
    if not Path(path).is_file():
        raise InputError(
            f"data set {path!r} (recorded in the study) does not exist here; "
            "pass --dataset PATH to this machine's copy"
        )
    return Dataset.load(path)


def _mixed_objective(attrs: dict[str, Any], main_set: Any, model: str) -> Any:
    """The study's :class:`~core.optimization.mix.MixedObjective`, or None for a study on one
    data set."""
    if not attrs.get("mix"):
        return None
    from core.dataset import Dataset
    from core.optimization.mix import MixedObjective, recording_objective

    people = attrs.get("people")
    parts = [(main_set, 1.0)]
    for path, weight in attrs["mix"]:
        if not Path(path).is_file():
            raise InputError(f"mixed data set {path!r} (recorded in the study) does not exist here")
        parts.append((Dataset.load(path), float(weight)))
    return MixedObjective(
        parts,
        model,
        loss=str(attrs.get("loss", "paper")),
        recording_loss=str(attrs.get("recording_loss") or recording_objective(people)),
        people=people,
    )


def run_worker(
    storage: str,
    study_name: str,
    *,
    seed: int | None,
    dataset_path: str | None = None,
    stop: Callable[[], bool] = lambda: False,
    log: Callable[[str], None] = lambda s: None,
) -> int:
    """Run trials of an existing study until the total is reached or ``stop()`` is true.

    Parameters
    ----------
    storage, study_name
        The study to join (created beforehand by :func:`prepare_study`).
    seed
        Base sampler seed (None: the study's ``seed``); trial n uses :func:`trial_seed` (seed, n).
    dataset_path
        Overrides the data-set path recorded in the study (another machine's file system).
    stop
        Checked before every trial; the running trial is always finished and told.

    Returns
    -------
    int
        Trials this worker finished (COMPLETE or PRUNED).
    """
    import optuna
    from optuna.trial import TrialState

    from core.optimization.batching import batched

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    store = open_storage(storage, create=False)
    probe = load_existing_study(store, study_name)
    if probe is None:
        raise InputError(f"no study {study_name!r} in {redact(storage)}")
    attrs = dict(probe.user_attrs)
    if "model" not in attrs:
        raise InputError(f"study {study_name!r} was not created by radartune (no model attribute)")
    model = attrs["model"]
    mode = str(attrs.get("mode", "paper"))
    n_total = int(attrs["n_trials"])
    base_seed = int(attrs.get("seed", 0)) if seed is None else int(seed)

    def sampler_for(number: int) -> Any:
        return make_sampler(attrs["sampler"], trial_seed(base_seed, number))

    study = optuna.load_study(
        study_name=study_name,
        storage=store,
        sampler=sampler_for(0),
        pruner=make_pruner(attrs["pruner"]),
    )
    loss = str(attrs.get("loss", "paper"))
    main_set = load_dataset_for(attrs, dataset_path)
    losses = make_losses(
        attrs["objective"],
        model,
        main_set,
        capped=uses_capped(loss),
        without_positions=without_positions(loss) if not attrs.get("mix") else "",
        people=attrs.get("people"),
        **dict(attrs.get("objective_options") or {}),
    )
    mixed = _mixed_objective(attrs, main_set, model)
    if hasattr(losses, "warm_up"):
        losses.warm_up(model)
    fail_stale_trials(study)
    n_steps = len(losses.trajectory_classes)
    prune_steps = set(asha_rungs(n_steps)) if attrs["pruner"] == "asha" else None
    me = worker_id()
    finished = 0
    failures = 0
    # what the last read of the study showed: occupied slots and enqueued trials
    occupied = count_trials(study)
    waiting = bool(study.get_trials(deepcopy=False, states=(TrialState.WAITING,)))
    while not stop():
        if occupied >= n_total:
            # near the end: count afresh; slots held by RUNNING trials of dead workers are
            # freed, then counted again
            if count_trials(study) >= n_total and (
                not fail_stale_trials(study) or count_trials(study) >= n_total
            ):
                break
        trial = _ask_as(study, me, sampler_for, waiting=waiting)
        try:
            # one read of the study (right after this trial got its number) serves the count
            # and the sampler; the parameters are written in one transaction
            with batched(store):
                trials = study.get_trials(deepcopy=False)
                occupied = sum(1 for t in trials if t.state.name in _OCCUPYING)
                waiting = any(t.state == TrialState.WAITING for t in trials)
                surplus = count_trials(study, below=trial.number) >= n_total
                if not surplus:
                    params = tracker_params_dict(suggest_params(trial, model, mode), model, mode)
            if surplus:
                trial.set_user_attr("surplus", True)
                study.tell(trial, state=TrialState.FAIL)
                break
            reports = _RungReports(trial, store)
            if mixed is not None:
                result = mixed.evaluate(params)  # scored whole: no pruning
            else:
                result = evaluate(
                    losses,
                    params,
                    trial=reports,
                    pruner=attrs["pruner"],
                    prune_steps=prune_steps,
                    loss=str(attrs.get("loss", "paper")),
                )
            with batched(store, read=False):
                reports.flush()
        except KeyboardInterrupt:
            study.tell(trial, state=TrialState.FAIL)
            raise
        except InputError as exc:
            trial.set_user_attr("error", f"{type(exc).__name__}: {exc}"[:500])
            study.tell(trial, state=TrialState.FAIL)
            raise
        except Exception as exc:  # a tracker error fails the trial, not the study
            trial.set_user_attr("error", f"{type(exc).__name__}: {exc}"[:500])
            study.tell(trial, state=TrialState.FAIL)
            log(f"trial {trial.number} failed: {type(exc).__name__}: {exc}")
            failures += 1
            if failures >= MAX_CONSECUTIVE_FAILURES:
                raise InputError(
                    f"{failures} trials in a row failed; last: {type(exc).__name__}: {exc}"
                ) from None
            continue
        failures = 0
        if attrs.get("loss", "paper") != "paper" and math.isfinite(result.paper_value):
            # else the trial's value is L_t itself, or the data set has no truth for it
            trial.set_user_attr("paper_loss", result.paper_value)
        if result.pruned:
            study.tell(trial, state=TrialState.PRUNED)
        else:
            study.tell(trial, result.value)
        finished += 1
    return finished


# ---- processes --------------------------------------------------------------------------------
class StudyHandle:
    """Worker processes of a running study (returned by :func:`start_study`)."""

    def __init__(self, settings: StudySettings, procs: list[subprocess.Popen]) -> None:
        self.settings = settings
        self.procs = procs

    def is_running(self) -> bool:
        """True while any worker process is alive."""
        return any(p.poll() is None for p in self.procs)

    def returncodes(self) -> list[int | None]:
        return [p.poll() for p in self.procs]

    def wait(self, timeout: float | None = None) -> bool:
        """Wait for the workers; True if all have exited."""
        end = None if timeout is None else time.monotonic() + timeout
        for p in self.procs:
            try:
                p.wait(None if end is None else max(0.0, end - time.monotonic()))
            except subprocess.TimeoutExpired:
                return False
        return True

    def stop(self, timeout: float = 30.0) -> None:
        """Ask every worker to stop after its current trial; kill those that do not in time.

        A killed worker's RUNNING trial is marked FAIL at once.
        """
        for p in self.procs:
            if p.poll() is None:
                p.send_signal(signal.SIGTERM)
        if not self.wait(timeout):
            for p in self.procs:
                if p.poll() is None:
                    p.kill()
            self.wait(10.0)
            import optuna

            study = optuna.load_study(
                study_name=self.settings.name, storage=open_storage(self.settings.storage)
            )
            fail_stale_trials(study)


def worker_command(
    storage: str, study_name: str, seed: int, dataset_path: str | None = None
) -> list[str]:
    """The ``radartune worker`` command line for one worker process."""
    cmd = [sys.executable, "-m", "core.cli", "worker", "--storage", storage, "--study", study_name]
    cmd += ["--seed", str(seed)]
    if dataset_path:
        cmd += ["--dataset", str(dataset_path)]
    return cmd


def start_study(
    settings: StudySettings,
    *,
    dataset_path: str | None = None,
    stdout: Any = None,
    stderr: Any = None,
) -> StudyHandle:
    """Create or resume the study, then start ``n_jobs`` worker processes; return their handle.

    The study is created here, once, before any worker starts. Every worker gets the base seed:
    the sampler seed of each trial is derived from it and the trial's number.
    ``dataset_path`` (default ``settings.dataset``) must be the cached ``.npz`` for the tracker
    objective (see :func:`core.optimization.data.resolve_dataset`).
    """
    path = dataset_path or settings.dataset
    if path:
        path = str(Path(path).resolve())
    settings = replace(settings, storage=absolute_url(settings.storage))
    prepare_study(settings, dataset_path=path)
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    procs = [
        subprocess.Popen(
            worker_command(settings.storage, settings.name, settings.seed, path),
            cwd=str(ROOT),
            env=env,
            stdout=stdout,
            stderr=stderr,
        )
        for _ in range(settings.n_jobs)
    ]
    return StudyHandle(settings, procs)
