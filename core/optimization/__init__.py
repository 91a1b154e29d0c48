"""Optuna tuning of the IPDA tracker (SPEC §5): search space, objective, studies, storages.

The public API is Qt-free and Optuna-free at its surface: the GUI uses :class:`StudySettings`,
:class:`TrialSummary`, :func:`start_study` (→ :class:`StudyHandle` with ``stop()`` and
``is_running()``), :func:`study_progress`, :func:`enqueue_params` and :data:`SEARCH_SPACE`.

The names are imported on first use (PEP 562), so that commands which never tune (``radartune
--help``, ``track``) do not import scipy's optimisers and Optuna through this package.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from core.optimization.data import resolve_dataset
    from core.optimization.objective import (
        QuadraticLosses,
        TrackerLosses,
        TrialResult,
        evaluate,
        make_losses,
        round_robin_order,
    )
    from core.optimization.progress import (
        TrialSummary,
        counted,
        enqueue_params,
        list_studies,
        study_model,
        study_progress,
    )
    from core.optimization.space import (
        MODELS,
        SEARCH_SPACE,
        Parameter,
        search_space,
        suggest_params,
    )
    from core.optimization.storage import DEFAULT_STORAGE, normalize_url, open_storage
    from core.optimization.study import (
        PRUNERS,
        SAMPLERS,
        StudyHandle,
        StudySettings,
        fail_stale_trials,
        loss_of_study,
        make_pruner,
        make_sampler,
        prepare_study,
        run_worker,
        start_study,
    )

#: public name -> the module that defines it
_EXPORTS = {
    "resolve_dataset": "core.optimization.data",
    "QuadraticLosses": "core.optimization.objective",
    "TrackerLosses": "core.optimization.objective",
    "TrialResult": "core.optimization.objective",
    "evaluate": "core.optimization.objective",
    "make_losses": "core.optimization.objective",
    "round_robin_order": "core.optimization.objective",
    "TrialSummary": "core.optimization.progress",
    "counted": "core.optimization.progress",
    "enqueue_params": "core.optimization.progress",
    "list_studies": "core.optimization.progress",
    "study_model": "core.optimization.progress",
    "study_progress": "core.optimization.progress",
    "MODELS": "core.optimization.space",
    "SEARCH_SPACE": "core.optimization.space",
    "Parameter": "core.optimization.space",
    "search_space": "core.optimization.space",
    "suggest_params": "core.optimization.space",
    "DEFAULT_STORAGE": "core.optimization.storage",
    "normalize_url": "core.optimization.storage",
    "open_storage": "core.optimization.storage",
    "PRUNERS": "core.optimization.study",
    "SAMPLERS": "core.optimization.study",
    "StudyHandle": "core.optimization.study",
    "StudySettings": "core.optimization.study",
    "fail_stale_trials": "core.optimization.study",
    "loss_of_study": "core.optimization.study",
    "make_pruner": "core.optimization.study",
    "make_sampler": "core.optimization.study",
    "prepare_study": "core.optimization.study",
    "run_worker": "core.optimization.study",
    "start_study": "core.optimization.study",
}


def __getattr__(name: str) -> Any:
    """Import a public name from its module on first use (PEP 562)."""
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_EXPORTS})


__all__ = [
    "DEFAULT_STORAGE",
    "MODELS",
    "PRUNERS",
    "Parameter",
    "SAMPLERS",
    "SEARCH_SPACE",
    "QuadraticLosses",
    "StudyHandle",
    "StudySettings",
    "TrackerLosses",
    "TrialResult",
    "TrialSummary",
    "counted",
    "enqueue_params",
    "evaluate",
    "fail_stale_trials",
    "loss_of_study",
    "list_studies",
    "make_losses",
    "make_pruner",
    "make_sampler",
    "normalize_url",
    "open_storage",
    "prepare_study",
    "resolve_dataset",
    "round_robin_order",
    "run_worker",
    "search_space",
    "start_study",
    "study_model",
    "study_progress",
    "suggest_params",
]
