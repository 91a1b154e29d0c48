"""The objective: track the cached data set with a trial's parameters and return L_t (eq. 14).

A trial never simulates: it tracks the cached point clouds of a :class:`core.dataset.Dataset`.
Trajectories are evaluated one at a time in round-robin class order (a, b, c, d, e, a, …) and
after each one the trial reports to the pruner:

- successive halving (ASHA, the default): the running mean loss after ``i`` trajectories,
  ``L̄_i = (1/i) Σ_{j≤i} L(k_j)`` at step ``i`` — an unbiased estimate of L_t at every rung
  because every prefix of a round-robin order covers the classes evenly;
- Wilcoxon: the loss of the trajectory itself, ``L(k_i)`` at step ``k_i``, because the Wilcoxon
  signed-rank test pairs the per-instance values of a trial with those of the best trial.

Two loss sources share one interface (:class:`TrajectoryLosses`): :class:`TrackerLosses` (the real
IPDA tracker on a data set) and :class:`QuadraticLosses` (a cheap deterministic function with a
known minimum and the same shape, used to test and benchmark the study machinery — storage,
resume, kill, reproducibility — without depending on the tracker's speed).
"""

from __future__ import annotations

import math
import time
from collections.abc import Collection, Sequence
from dataclasses import dataclass, field
from typing import Any, NamedTuple, Protocol

import numpy as np

from core.errors import InputError
from core.evaluation.loss import NO_CONFIRMATION_LOSS
from core.evaluation.robust import OBJECTIVES, aggregate, check_objective
from core.optimization.space import GTRACK, P0_NAMES, check_tuned, search_space
from core.tracking.space import tracker_params_dict


class TrajectoryScore(NamedTuple):
    """One trajectory's scores: the paper's ``L(k)`` (m², eq. 13; NaN on a data set without
    truth), ``MSE(k)`` (m², NaN when ``N_c = 0``), ``N_c(k)``, the capped loss ``C(k)`` (m²,
    :mod:`core.evaluation.robust`) and, for an objective without positions
    (:func:`core.evaluation.counting.trajectory_terms`), its ``value`` and ``weight``."""

    loss: float
    mse: float
    n_c: int
    capped: float
    value: float = math.nan
    weight: float = 1.0


class TrajectoryLosses(Protocol):
    """Per-trajectory paper loss for a parameter set."""

    @property
    def trajectory_classes(self) -> tuple[str, ...]:
        """Class label of each trajectory, length K."""
        ...

    def losses(self, params: dict[str, Any], ks: Sequence[int]) -> list[TrajectoryScore]:
        """``(L(k), MSE(k), N_c(k))`` of each trajectory ``k`` in ``ks`` for TrackerParams JSON."""
        ...


def round_robin_order(classes: Sequence[str]) -> list[int]:
    """Trajectory indices ordered round-robin over the classes.

    Classes are visited in sorted order, each class's trajectories in their data-set order:
    ``classes = [a, a, b, b, c]`` → ``[0, 2, 4, 1, 3]``.
    """
    by_class: dict[str, list[int]] = {}
    for k, c in enumerate(classes):
        by_class.setdefault(str(c), []).append(k)
    queues = [by_class[c] for c in sorted(by_class)]
    order: list[int] = []
    for i in range(max((len(q) for q in queues), default=0)):
        order.extend(q[i] for q in queues if i < len(q))
    return order


@dataclass(frozen=True, slots=True, kw_only=True)
class QuadraticLosses:
    """Deterministic test objective with the shape of the tracker loss and a known minimum.

    In the unit cube of the search space (log-scaled where the space is), with ``u`` the trial's
    point and ``c`` the optimum: ``L(k) = L_min·(1 + w_k·Σ_i (u_i − c_i)²)``, ``w_k = 1 + k/K``.
    The optimum ``c`` is the centre of the cube. ``delay_s`` sleeps per trajectory to make trials
    last long enough to be killed mid-trial in tests.
    """

    model: str
    n_trajectories: int = 10
    loss_min: float = 1e-4
    delay_s: float = 0.0
    classes: tuple[str, ...] = field(default=())

    @property
    def trajectory_classes(self) -> tuple[str, ...]:
        if self.classes:
            return self.classes
        return tuple("abcde"[k % 5] for k in range(self.n_trajectories))

    def losses(self, params: dict[str, Any], ks: Sequence[int]) -> list[TrajectoryScore]:
        return [self._loss(params, k) for k in ks]

    def _loss(self, params: dict[str, Any], k: int) -> TrajectoryScore:
        if self.delay_s:
            time.sleep(self.delay_s)
        p = dict(params)
        p.update(zip(P0_NAMES, p.get("p0", [])))
        d2 = 0.0
        for b in search_space(self.model):
            v = float(p[b.name])
            if b.log:
                u = (math.log(v) - math.log(b.low)) / (math.log(b.high) - math.log(b.low))
            else:
                u = (v - b.low) / (b.high - b.low)
            d2 += (u - 0.5) ** 2
        w = 1.0 + k / max(self.n_trajectories, 1)
        # L(k) = L_min (1 + w_k |u - c|^2)
        value = self.loss_min * (1.0 + w * d2)
        n_c = 100
        return TrajectoryScore(value, value * n_c, n_c, value)


class TrackerLosses:
    """The paper's loss of the real IPDA tracker on a cached data set (with several persons, its
    multi-person form: :mod:`core.evaluation.loss`).

    Parameters
    ----------
    dataset
        The cached point clouds and truth (:class:`core.dataset.Dataset`).
    base_params
        TrackerParams JSON keys that are not optimised (``p_g``, thresholds, ``clutter_density``);
        the trial's parameters override them.
    capped
        Also score the capped loss ``C(k)`` (:mod:`core.evaluation.robust`); without it the
        scores' ``capped`` is NaN. It costs about a tenth of a trial, so a study computes it
        only when its objective uses it (:func:`uses_capped`).
    without_positions
        ``"count"``, ``"fragmentation"``, ``"nis"`` or ``"reference"``: also score that
        objective per trajectory (the scores' ``value`` and ``weight``); ``""``: none.
    people
        Head count in every frame (``--people N``); None: the truth's, if any.
    """

    def __init__(
        self,
        dataset: Any,
        base_params: dict[str, Any] | None = None,
        *,
        capped: bool = True,
        without_positions: str = "",
        people: int | None = None,
    ) -> None:
        from core.evaluation.counting import head_counts
        from core.formats.recording import has_truth

        self.dataset = dataset
        self.base_params = dict(base_params or {})
        self.capped = capped
        self.without_positions = without_positions
        self.truth = has_truth(dataset)
        self.counts = head_counts(dataset, people)
        if without_positions in ("count", "fragmentation") and self.counts is None:
            raise InputError(
                f"the {without_positions} objective needs a head count: give --people N (the "
                "data set has no truth)"
            )
        if without_positions == "reference" and not dataset.has_reference:
            raise InputError(
                "the reference objective needs a recording with its own tracks (a reference "
                "layer: TI's tracks of a people-counting recording)"
            )

    @property
    def trajectory_classes(self) -> tuple[str, ...]:
        return tuple(str(c) for c in self.dataset.trajectory_class)

    def warm_up(self, model: str) -> None:
        """Load the compiled tracker (numba) before the first trial, so trial times are honest."""
        from core.tracking import TrackerParams
        from core.tracking.warm import load_compiled

        flat = {b.name: b.high for b in search_space(model)}
        load_compiled(
            TrackerParams.from_dict({**self.base_params, **tracker_params_dict(flat, model)})
        )

    def losses(self, params: dict[str, Any], ks: Sequence[int]) -> list[TrajectoryScore]:
        from core.tracking import TrackerParams, track_dataset

        if not len(ks):
            return []
        tp = TrackerParams.from_dict({**self.base_params, **params})
        # several persons are scored from every confirmed track (the multi-person loss); one
        # person from the single-person estimate, as ever (the same numbers bit for bit); the
        # track ids and NIS of fragmentation and nis come from the kernel's record of every track
        several = self.dataset.n_persons > 1
        est = track_dataset(
            self.dataset, tp, trajectories=list(ks), with_tracks=several or self._record()
        )
        return self._scores(est)

    def _record(self) -> bool:
        """The objective needs every track of every frame (ids, NIS, the reference GOSPA)."""
        return self.without_positions in ("fragmentation", "nis", "reference")

    def _scores(self, est: Any, nis_dof: int | None = None) -> list[TrajectoryScore]:
        """The trajectories' scores of the estimates ``est`` (``nis_dof``: the measurement's
        dimension for the nis objective when not the paper tracker's 3)."""
        from core.evaluation import trajectory_loss_terms
        from core.evaluation.robust import trajectory_capped_losses

        n = len(est.trajectories)
        nan = [math.nan] * n
        terms = (
            trajectory_loss_terms(self.dataset, est)
            if self.truth
            else [(math.nan, math.nan, 0)] * n
        )
        capped = trajectory_capped_losses(self.dataset, est) if self.capped and self.truth else nan
        extra = [(math.nan, 1.0)] * n
        if self.without_positions:
            from core.evaluation.counting import trajectory_terms

            counts = None if self.counts is None else self.counts[est.frame_index]
            dof = {} if nis_dof is None else {"nis_dof": nis_dof}
            extra = trajectory_terms(self.without_positions, est, counts, self.dataset, **dof)
        return [
            TrajectoryScore(float(value), float(mse), int(n_c), c, v, w)
            for (value, mse, n_c), c, (v, w) in zip(terms, capped, extra, strict=True)
        ]


class GtrackLosses(TrackerLosses):
    """The paper's loss (and its multi-person form) of gtrack (:mod:`core.tracking.gtrack`,
    compiled) on a cached data set; ``base_params`` are GtrackParams JSON keys not tuned (the
    pose, the boxes, the frame period), the trial's parameters override them."""

    def warm_up(self, model: str) -> None:
        """Load the compiled gtrack before the first trial."""
        import numpy as np

        from core.tracking.gtrack import GtrackParams
        from core.tracking.gtrack.compiled import run_gtrack_compiled

        params = GtrackParams.from_dict(self.base_params)
        run_gtrack_compiled(np.zeros((0, 5)), np.zeros(2, dtype=np.int64), params)

    def losses(self, params: dict[str, Any], ks: Sequence[int]) -> list[TrajectoryScore]:
        from core.tracking.gtrack import GtrackParams
        from core.tracking.gtrack.batch import gtrack_dataset

        if not len(ks):
            return []
        gp = GtrackParams.from_dict({**self.base_params, **params})
        est, _ = gtrack_dataset(self.dataset, gp, trajectories=list(ks), with_tracks=self._record())
        return self._scores(est, nis_dof=gp.dims + 1)


@dataclass(frozen=True, slots=True, kw_only=True)
class TrialResult:
    """Outcome of evaluating one parameter set on all (or a pruned prefix of) trajectories.

    ``value`` is the study's objective (:data:`core.evaluation.robust.OBJECTIVES`);
    ``paper_value`` the paper's ``L_t`` (eq. 14) of the same trajectories, always computed;
    ``losses`` the paper's ``L(k)`` and ``capped`` the capped ``C(k)`` per trajectory.
    """

    value: float
    paper_value: float
    losses: tuple[float, ...]
    capped: tuple[float, ...]
    mse: tuple[float, ...]
    n_c: tuple[int, ...]
    order: tuple[int, ...]
    pruned: bool


class Reports(Protocol):
    def report(self, value: float, step: int) -> None: ...
    def should_prune(self) -> bool: ...


def evaluate(
    losses: TrajectoryLosses,
    params: dict[str, Any],
    *,
    trial: Reports | None = None,
    pruner: str = "asha",
    prune_steps: Collection[int] | None = None,
    loss: str = "paper",
) -> TrialResult:
    """The objective ``loss`` of ``params`` (default L_t, eq. 14), reported after every
    trajectory.

    Parameters
    ----------
    losses
        Loss source.
    params
        TrackerParams JSON.
    trial
        Optuna trial (or anything with ``report``/``should_prune``); None: no reporting.
    pruner
        ``"asha"`` reports the running mean at step i (1-based count of trajectories done)
        after every trajectory, or only at ``prune_steps`` and the last step when given;
        ``"wilcoxon"`` reports L(k) at step k; ``"none"`` reports nothing.
    prune_steps
        Steps after which ``should_prune`` is asked (None: every step). Successive halving only
        acts at its rungs, so asking there alone gives the same decisions with fewer storage
        reads.
    loss
        The objective (:data:`core.evaluation.robust.OBJECTIVES`): ``"paper"`` (L_t),
        ``"capped"``, ``"median"`` or ``"trimmed"``. ASHA is told the objective of the
        trajectories done so far; Wilcoxon the per-trajectory loss the objective uses.

    Returns
    -------
    TrialResult
        ``value`` is the objective in m² (of the trajectories done at the pruning point if
        pruned). A NaN or infinite trajectory loss is an error (the tracker must never produce
        one).
    """
    per_trajectory, how = OBJECTIVES[check_objective(loss)]
    # the per-trajectory loss the objective uses: the paper's L(k), the capped C(k) or the
    # value of an objective without positions (weighted by what each trajectory scored)
    field = {"paper": "loss", "capped": "capped"}.get(per_trajectory, "value")
    order = round_robin_order(losses.trajectory_classes)
    if not order:
        raise InputError("the data set has no trajectories")
    n = len(order)
    # Trajectories are tracked in chunks that end where the pruner is asked (every step for
    # Wilcoxon, the rungs for ASHA, once without pruning): the values reported after each
    # trajectory are the same, with fewer calls into the tracker.
    if trial is None or pruner == "none":
        ends = [n]
    elif prune_steps is None:
        ends = list(range(1, n + 1))
    else:
        ends = sorted({i for i in prune_steps if 0 < i < n} | {n})
    ls: list[float] = []
    cs: list[float] = []
    ms: list[float] = []
    ns: list[int] = []
    used: list[float] = []
    ws: list[float] = []

    def result(pruned: bool) -> TrialResult:
        return TrialResult(
            value=aggregate(used, how, ws),
            paper_value=float(np.mean(ls)),
            losses=tuple(ls),
            capped=tuple(cs),
            mse=tuple(ms),
            n_c=tuple(ns),
            order=tuple(order[: len(ls)]),
            pruned=pruned,
        )

    start = 0
    for end in ends:
        for score in losses.losses(params, order[start:end]):
            k = order[len(ls)]
            value = float(getattr(score, field))
            if field != "value" and not math.isfinite(score.loss):
                raise FloatingPointError(f"trajectory {k}: loss is {score.loss}")
            if not math.isfinite(value):
                raise FloatingPointError(f"trajectory {k}: {loss} loss is {value}")
            ls.append(score.loss)
            cs.append(score.capped)
            used.append(value)
            ws.append(score.weight)
            ms.append(score.mse)
            ns.append(score.n_c)
            if trial is not None and pruner != "none":
                if pruner == "wilcoxon":
                    trial.report(used[-1], k)
                elif prune_steps is None or len(ls) == end:
                    # the objective of the first i trajectories (for L_t: L̄_i = (1/i) Σ_j L(k_j)),
                    # reported where the pruner decides (and at the end): every report is a
                    # storage write, and successive halving reads only the values at its rungs
                    trial.report(aggregate(used, how, ws), len(ls))
        start = end
        if trial is not None and pruner != "none" and end < n and trial.should_prune():
            return result(pruned=True)
    return result(pruned=False)


def uses_capped(loss: str) -> bool:
    """Whether the study objective ``loss`` needs the capped loss per trajectory."""
    return OBJECTIVES[check_objective(loss)][0] == "capped"


def without_positions(loss: str) -> str:
    """The objective's per-trajectory score when it needs no positions (``count``,
    ``fragmentation``, ``nis``, ``reference``), else ``""``."""
    kind = OBJECTIVES[check_objective(loss)][0]
    return "" if kind in ("paper", "capped") else kind


def tracker_losses(
    dataset: Any, loss: str, *, people: int | None = None, base_params: dict | None = None
) -> TrackerLosses:
    """The tracker's loss source for the study objective ``loss`` on ``dataset`` (the capped
    loss and the scores without positions computed only when ``loss`` uses them)."""
    return TrackerLosses(
        dataset,
        base_params,
        capped=uses_capped(loss),
        without_positions=without_positions(loss),
        people=people,
    )


def make_losses(objective: str, model: str, dataset: Any = None, **kwargs: Any) -> TrajectoryLosses:
    """Loss source by name: ``"tracker"`` (needs ``dataset``; ``capped=False`` skips the capped
    loss) or ``"quadratic"`` (tests)."""
    check_tuned(model)
    if objective == "tracker":
        if dataset is None:
            raise InputError("objective 'tracker' needs a data set")
        cls = GtrackLosses if model == GTRACK else TrackerLosses
        return cls(
            dataset,
            kwargs.get("base_params"),
            capped=bool(kwargs.get("capped", True)),
            without_positions=str(kwargs.get("without_positions", "")),
            people=kwargs.get("people"),
        )
    if objective == "quadratic":
        return QuadraticLosses(
            model=model,
            n_trajectories=int(kwargs.get("n_trajectories", 10)),
            delay_s=float(kwargs.get("delay_s", 0.0)),
        )
    raise InputError(f"objective must be 'tracker' or 'quadratic', got {objective!r}")


__all__ = [
    "NO_CONFIRMATION_LOSS",
    "GtrackLosses",
    "QuadraticLosses",
    "TrackerLosses",
    "TrajectoryLosses",
    "TrajectoryScore",
    "TrialResult",
    "evaluate",
    "make_losses",
    "round_robin_order",
    "uses_capped",
    "tracker_losses",
    "without_positions",
]
