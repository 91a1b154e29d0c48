"""Optuna storages that make fewer round trips for a worker: one read and one write per phase.

A trial of the paper data set tracks in about 10 ms; Optuna's SQL storage spent about 60 ms of
CPU a trial on ~117 SQL statements (decision tuning-07): twelve parameter writes of three
statements each, the study re-read for every sampler and pruner question, and every read of
the worker's own running trial (six statements each time). These subclasses keep Optuna's
storage format and the sampler's and pruner's logic as they are, and change only when the
statements are sent:

- **Own running trials.** A trial created by this process is written only by this process
  while it runs (other processes only read it, or mark it FAIL once its worker is dead), so
  ``get_trial`` of such a trial is answered from a copy kept up to date by this process's own
  writes. The copy is dropped when the trial finishes.
- **Phases** (:meth:`batched`). Inside a phase, the first read of the study's trials goes to the
  storage and later reads reuse it (the sampler asks several times while sampling one trial),
  and writes to this process's running trials are held and committed together when the phase
  ends: a trial's twelve parameters and the sampler's note for the constant liar become one
  transaction; a rung's intermediate value and the pruner's rung record another. If the phase
  raises, the held writes are dropped (the trial is then told FAIL).

A worker killed inside a phase leaves a RUNNING trial without the held writes, which the crash
recovery marks FAIL as before (:func:`core.optimization.study.fail_stale_trials`). Readers
(progress, dashboard) see a trial's parameters a few milliseconds later than before, all at once.

Optuna's internals used here (RDBStorage's session helper and ORM models, JournalStorage's log
writer) are those of Optuna 4.x–5.x; :func:`batching_available` says whether they are present,
and :func:`core.optimization.storage.open_storage` falls back to Optuna's own classes if not.
"""

from __future__ import annotations

import copy
import datetime as dt
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import optuna
from optuna.storages import JournalStorage, RDBStorage
from optuna.trial import FrozenTrial, TrialState

try:  # Optuna's RDB internals (4.x, 5.x); without them the plain storages are used
    from optuna import distributions as _dists
    from optuna.storages._rdb import models as _models
    from optuna.storages._rdb.storage import _create_scoped_session

    _HAVE_RDB_INTERNALS = all(
        hasattr(RDBStorage, name)
        for name in (
            "_create_new_trial",
            "_set_trial_param",
            "_set_trial_param_without_commit",
            "_set_trial_attr_without_commit",
            "_set_trial_intermediate_value_without_commit",
            "_get_trials",
        )
    )
except ImportError:  # pragma: no cover - another Optuna
    _HAVE_RDB_INTERNALS = False


def batching_available(kind: str) -> bool:
    """Whether the batching storage of ``kind`` (``"rdb"`` or ``"journal"``) can be used."""
    if kind == "rdb":
        return _HAVE_RDB_INTERNALS
    return hasattr(JournalStorage, "_write_log") and hasattr(JournalStorage, "_sync_with_backend")


class _Phase:
    """State of one :meth:`BatchingRDBStorage.batched` phase: held writes, whether read."""

    __slots__ = ("read", "writes")

    def __init__(self) -> None:
        self.read = False
        # (kind, trial_id, name) -> (value, extra): the last write of each field wins
        self.writes: dict[tuple[str, int, Any], tuple[Any, Any]] = {}


class BatchingRDBStorage(RDBStorage):
    """:class:`optuna.storages.RDBStorage` (SQLite, PostgreSQL) with fewer round trips.

    Same constructor and database as ``RDBStorage``; see the module docstring. A phase belongs
    to the thread that opened it; other threads' reads and writes go to the database as usual.
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._own: dict[int, FrozenTrial] = {}  # trials this process created, while they run
        self._finished: set[int] = set()  # own trials finished since the last read
        self._local = threading.local()  # the phase belongs to the thread that opened it

    def __getstate__(self) -> dict[str, Any]:
        state = dict(super().__getstate__())
        state.pop("_local", None)  # a copy in another process starts with no phase
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        super().__setstate__(state)
        self._local = threading.local()

    @property
    def _phase(self) -> _Phase | None:
        return getattr(self._local, "phase", None)

    @_phase.setter
    def _phase(self, phase: _Phase | None) -> None:
        self._local.phase = phase

    # -- phases --------------------------------------------------------------------------------
    @contextmanager
    def batched(self, *, read: bool = True) -> Iterator[None]:
        """One phase: own writes commit together at its end; the first read of the study is
        reused by later reads, or, with ``read=False``, the study is not read again at all
        (reads answer what this process read last)."""
        if self._phase is not None:  # nested: part of the outer phase
            yield
            return
        self._phase = phase = _Phase()
        phase.read = not read
        try:
            yield
        except BaseException:
            self._phase = None
            raise
        self._phase = None
        if phase.writes:
            with _create_scoped_session(self.scoped_session, True) as session:
                self._write_held(session, phase.writes, checked=set())

    def _write_held(
        self, session: Any, writes: dict[tuple[str, int, Any], tuple[Any, Any]], checked: set[int]
    ) -> None:
        """Write held fields in ``session``: new rows as one multi-row INSERT per table."""
        import json

        import sqlalchemy

        rows: dict[Any, list[dict[str, Any]]] = {}
        for (kind, trial_id, name), (value, extra) in writes.items():
            if trial_id not in checked:
                trial = _models.TrialModel.find_or_raise_by_id(trial_id, session)
                self.check_trial_is_updatable(trial_id, trial.state)
                checked.add(trial_id)
            if kind == "param":
                dist, previous = value, extra[1]
                if previous is None:  # the first value of this name in this process
                    super()._set_trial_param_without_commit(
                        session, trial_id, name, extra[0], dist, None
                    )
                    continue
                _dists.check_distribution_compatibility(previous, dist)
                rows.setdefault(_models.TrialParamModel, []).append(
                    {
                        "trial_id": trial_id,
                        "param_name": name,
                        "param_value": extra[0],
                        "distribution_json": _dists.distribution_to_json(dist),
                    }
                )
            elif kind == "system_attr":
                if not extra:  # the key existed: Optuna's upsert
                    super()._set_trial_attr_without_commit(
                        session, _models.TrialSystemAttributeModel, trial_id, name, value
                    )
                    continue
                rows.setdefault(_models.TrialSystemAttributeModel, []).append(
                    {"trial_id": trial_id, "key": name, "value_json": json.dumps(value)}
                )
            else:  # intermediate value
                if not extra:
                    super()._set_trial_intermediate_value_without_commit(
                        session, trial_id, name, value
                    )
                    continue
                stored, value_type = (
                    _models.TrialIntermediateValueModel.intermediate_value_to_stored_repr(value)
                )
                rows.setdefault(_models.TrialIntermediateValueModel, []).append(
                    {
                        "trial_id": trial_id,
                        "step": name,
                        "intermediate_value": stored,
                        "intermediate_value_type": value_type,
                    }
                )
        for model, values in rows.items():
            session.execute(sqlalchemy.insert(model), values)

    def _hold(self, key: tuple[str, int, Any], value: Any, extra: Any) -> bool:
        """Hold a write to an own running trial inside a phase; False: write it now."""
        phase = self._phase
        if phase is None or key[1] not in self._own:
            return False
        if key in phase.writes and key[0] != "param":  # written twice: keep the first "is new"
            extra = phase.writes[key][1]
        phase.writes[key] = (value, extra)
        return True

    # -- reads ---------------------------------------------------------------------------------
    def _get_trials(self, *args: Any, **kwargs: Any) -> list[FrozenTrial]:
        # Optuna's cache (_CachedStorage) asks this for the trials that are new or unfinished
        # since its last read; inside a phase, after the first read, the answer is "none"
        phase = self._phase
        if phase is not None and phase.read:
            return []
        trials = super()._get_trials(*args, **kwargs)
        if phase is not None:
            phase.read = True
        for trial_id in self._finished:  # the cache now has them from the database
            self._own.pop(trial_id, None)
        self._finished.clear()
        return trials

    def get_all_trials(
        self, study_id: int, deepcopy: bool = True, states: Any = None
    ) -> list[FrozenTrial]:
        # a direct read (not through Optuna's cache) is always complete
        saved, self._phase = self._phase, None
        try:
            return super().get_all_trials(study_id, deepcopy=deepcopy, states=states)
        finally:
            self._phase = saved

    def get_trial(self, trial_id: int) -> FrozenTrial:
        own = self._own.get(trial_id)
        if own is not None:
            return _copy_trial(own)
        return super().get_trial(trial_id)

    def get_trial_system_attrs(self, trial_id: int) -> dict[str, Any]:
        own = self._own.get(trial_id)
        if own is not None:
            return copy.deepcopy(own.system_attrs)
        return super().get_trial_system_attrs(trial_id)

    def get_trial_user_attrs(self, trial_id: int) -> dict[str, Any]:
        own = self._own.get(trial_id)
        if own is not None:
            return copy.deepcopy(own.user_attrs)
        return super().get_trial_user_attrs(trial_id)

    # -- writes --------------------------------------------------------------------------------
    def _create_new_trial(
        self, study_id: int, template_trial: FrozenTrial | None = None
    ) -> FrozenTrial:
        frozen = super()._create_new_trial(study_id, template_trial)
        if frozen.state == TrialState.RUNNING:
            self._own[frozen._trial_id] = copy.deepcopy(frozen)
        return frozen

    def _set_trial_param(
        self,
        trial_id: int,
        param_name: str,
        param_value_internal: float,
        distribution: Any,
        previous_distribution: Any,
    ) -> None:
        key = ("param", trial_id, param_name)
        if not self._hold(key, distribution, (param_value_internal, previous_distribution)):
            super()._set_trial_param(
                trial_id, param_name, param_value_internal, distribution, previous_distribution
            )
        own = self._own.get(trial_id)
        if own is not None:
            own.params[param_name] = distribution.to_external_repr(param_value_internal)
            own.distributions[param_name] = distribution

    def set_trial_system_attr(self, trial_id: int, key: str, value: Any) -> None:
        own = self._own.get(trial_id)
        new = own is not None and key not in own.system_attrs
        if not self._hold(("system_attr", trial_id, key), value, new):
            super().set_trial_system_attr(trial_id, key, value)
        if own is not None:
            own.system_attrs[key] = copy.deepcopy(value)

    def set_trial_intermediate_value(
        self, trial_id: int, step: int, intermediate_value: float
    ) -> None:
        own = self._own.get(trial_id)
        new = own is not None and step not in own.intermediate_values
        if not self._hold(("intermediate", trial_id, step), intermediate_value, new):
            super().set_trial_intermediate_value(trial_id, step, intermediate_value)
        if own is not None:
            own.intermediate_values[step] = float(intermediate_value)

    def set_trial_user_attr(self, trial_id: int, key: str, value: Any) -> None:
        super().set_trial_user_attr(trial_id, key, value)
        own = self._own.get(trial_id)
        if own is not None:
            own.user_attrs[key] = copy.deepcopy(value)

    def set_trial_state_values(self, trial_id: int, state: TrialState, values: Any = None) -> bool:
        """As ``RDBStorage``'s; an own trial's held writes, values and state in one transaction."""
        import sqlalchemy.exc

        phase = self._phase
        held = {k: v for k, v in phase.writes.items() if k[1] == trial_id} if phase else {}
        for k in held:
            assert phase is not None
            del phase.writes[k]
        own = self._own.get(trial_id)
        if own is None or trial_id in self._finished or not state.is_finished():
            if held:
                with _create_scoped_session(self.scoped_session, True) as session:
                    self._write_held(session, held, checked=set())
            return bool(super().set_trial_state_values(trial_id, state, values))
        now = dt.datetime.now()
        try:
            with _create_scoped_session(self.scoped_session) as session:
                trial = _models.TrialModel.find_or_raise_by_id(trial_id, session, for_update=True)
                self.check_trial_is_updatable(trial_id, trial.state)
                self._write_held(session, held, checked={trial_id})
                if values is not None:
                    for objective, v in enumerate(values):
                        super()._set_trial_value_without_commit(session, trial, objective, v)
                trial.state = state
                trial.datetime_complete = now
        except sqlalchemy.exc.IntegrityError:
            self._own.pop(trial_id, None)
            return False
        except BaseException:
            self._own.pop(trial_id, None)
            raise
        # until the next read of the study brings it from the database, the finished trial is
        # answered from here (Study.tell reads it back at once)
        own.state = state
        own.values = None if values is None else [float(v) for v in values]
        own.datetime_complete = now
        self._finished.add(trial_id)
        return True


def _copy_trial(trial: FrozenTrial) -> FrozenTrial:
    """A copy whose dictionaries the caller may change (``optuna.Trial`` does)."""
    out = copy.copy(trial)
    out.params = dict(trial.params)
    out.distributions = dict(trial.distributions)
    out.user_attrs = copy.deepcopy(trial.user_attrs)
    out.system_attrs = copy.deepcopy(trial.system_attrs)
    out.intermediate_values = dict(trial.intermediate_values)
    return out


class BatchingJournalStorage(JournalStorage):
    """:class:`optuna.storages.JournalStorage` whose writes inside a phase append as one batch.

    Each journal append takes the file lock and an ``fsync``; a phase's records (a trial's
    parameters, a rung's value and record) are appended together. Reads are already local
    (the journal is replayed in memory).
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._held: list[dict[str, Any]] | None = None

    @contextmanager
    def batched(self, *, read: bool = True) -> Iterator[None]:
        """One phase: records written inside it are appended in one batch at its end (reads
        replay the journal as always; ``read`` is accepted for the RDB storage's sake)."""
        if self._held is not None:
            yield
            return
        held: list[dict[str, Any]] = []
        self._held = held
        try:
            yield
        except BaseException:
            self._held = None
            raise
        self._held = None
        if held:
            with self._thread_lock:
                self._backend.append_logs(held)
                self._sync_with_backend()

    def _write_log(self, op_code: int, extra_fields: dict[str, Any]) -> None:
        # trial creation must be written at once (the storage reads back the new trial's id)
        if self._held is not None and op_code in _HELD_JOURNAL_OPS:
            self._held.append(
                {"op_code": op_code, "worker_id": self._replay_result.worker_id, **extra_fields}
            )
            return
        super()._write_log(op_code, extra_fields)


def _held_journal_ops() -> frozenset[int]:
    from optuna.storages.journal._storage import JournalOperation

    return frozenset(
        {
            JournalOperation.SET_TRIAL_PARAM,
            JournalOperation.SET_TRIAL_SYSTEM_ATTR,
            JournalOperation.SET_TRIAL_INTERMEDIATE_VALUE,
        }
    )


_HELD_JOURNAL_OPS = _held_journal_ops()


@contextmanager
def batched(storage: Any, *, read: bool = True) -> Iterator[None]:
    """A :meth:`BatchingRDBStorage.batched` phase of ``storage`` (an opened storage, or the
    ``_CachedStorage`` Optuna wraps it in); a plain phase-less block for other storages."""
    phase = getattr(storage, "batched", None) or getattr(
        getattr(storage, "_backend", None), "batched", None
    )
    if phase is None:
        yield
        return
    with phase(read=read):
        yield


__all__ = [
    "BatchingJournalStorage",
    "BatchingRDBStorage",
    "batched",
    "batching_available",
    "optuna",
]
