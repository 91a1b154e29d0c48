"""Evaluation of tracker output against the truth (SPEC §5), one role per module.

- :mod:`~core.evaluation.loss` — the paper's loss L(k) and L_t (eqs. 12–14)
- :mod:`~core.evaluation.metrics` — OSPA, GOSPA and the far-frame threshold
- :mod:`~core.evaluation.assignment` — tracks assigned to people, identity switches
- :mod:`~core.evaluation.people` — GOSPA, count error, identities per frame and per person
  (:func:`people_run`: one run, for the GUI)
- :mod:`~core.evaluation.table` — :func:`evaluate`: the loss table (Table I) and every metric of
  one run (:class:`Evaluation`)
- :mod:`~core.evaluation.comparison` — two runs compared: loss breakdown by kind of frame,
  paired bootstrap ratio and Wilcoxon test
- :mod:`~core.evaluation.spread` — spread of the person-labelled points around the truth
- :mod:`~core.evaluation.consistency` — filter consistency: NEES and NIS of the track paired
  with each person against their χ² bands, per class (Bar-Shalom's ANEES test)
- :mod:`~core.evaluation.reference` — agreement with a recording's reference layer (TI's own
  tracks): GOSPA and count difference per frame
- :mod:`~core.evaluation.intervals` — runs over noise seeds compared: ratio of mean losses with a
  paired bootstrap interval and its verdict, rates of runs without a track and of tail events
"""

from core.evaluation.assignment import IDENTITY_CUTOFF_M, IdentityAssignment, assign_identities
from core.evaluation.comparison import (
    CATEGORIES,
    LossBreakdown,
    PairedComparison,
    loss_breakdown,
    paired_comparison,
    track_with_ids,
)
from core.evaluation.consistency import (
    ConsistencyReport,
    ConsistencyStat,
    average_band,
    chi2_band,
    dataset_consistency,
    nees,
)
from core.evaluation.loss import (
    CLASSES,
    NO_CONFIRMATION_LOSS,
    PeopleLoss,
    people_trajectory_loss,
    person_estimates,
    tracked_person_xy,
    trajectory_loss,
    trajectory_loss_terms,
    trajectory_losses,
)
from core.evaluation.metrics import (
    FAR_DISTANCE_M,
    GOSPA_C_M,
    GOSPA_P,
    OSPA_C_M,
    OSPA_P,
    GospaTerms,
    gospa,
    ospa,
)
from core.evaluation.people import FrameMetrics, PeopleRun, frame_metrics, people_run
from core.evaluation.spread import PointSpread, person_point_spread
from core.evaluation.table import ClassRow, Evaluation, PersonMetrics, evaluate

__all__ = [
    "CATEGORIES",
    "CLASSES",
    "FAR_DISTANCE_M",
    "GOSPA_C_M",
    "GOSPA_P",
    "IDENTITY_CUTOFF_M",
    "NO_CONFIRMATION_LOSS",
    "OSPA_C_M",
    "OSPA_P",
    "ClassRow",
    "ConsistencyReport",
    "ConsistencyStat",
    "Evaluation",
    "FrameMetrics",
    "PeopleRun",
    "GospaTerms",
    "IdentityAssignment",
    "LossBreakdown",
    "PairedComparison",
    "PeopleLoss",
    "PersonMetrics",
    "PointSpread",
    "assign_identities",
    "average_band",
    "chi2_band",
    "dataset_consistency",
    "evaluate",
    "frame_metrics",
    "gospa",
    "loss_breakdown",
    "nees",
    "ospa",
    "paired_comparison",
    "people_run",
    "people_trajectory_loss",
    "person_estimates",
    "person_point_spread",
    "track_with_ids",
    "tracked_person_xy",
    "trajectory_loss",
    "trajectory_loss_terms",
    "trajectory_losses",
]
