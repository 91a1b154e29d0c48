"""Optuna tuning of the IPDA tracker (SPEC §5): search space, objective, studies, storages.

The public API is Qt-free and Optuna-free at its surface: the GUI uses :class:`StudySettings`,
:class:`TrialSummary`, :func:`start_study` (→ :class:`StudyHandle` with ``stop()`` and
``is_running()``), :func:`study_progress`, :func:`enqueue_params` and :data:`SEARCH_SPACE`.
"""

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
    flat_params,
    search_space,
    suggest_params,
    tracker_params_dict,
)
from core.optimization.storage import DEFAULT_STORAGE, normalize_url, open_storage
from core.optimization.study import (
    PRUNERS,
    SAMPLERS,
    StudyHandle,
    StudySettings,
    fail_stale_trials,
    make_pruner,
    make_sampler,
    prepare_study,
    run_worker,
    start_study,
)

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
    "flat_params",
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
    "tracker_params_dict",
]
