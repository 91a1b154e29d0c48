"""The scores and per-frame counts every ``radartune track`` run reports, whichever tracker
(the paper's (J)IPDA or gtrack): count, fragmentation and NIS without positions, and the
JSON's per-frame confirmed and tentative track counts."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from core.dataset import Dataset
    from core.evaluation.counting import RecordingScores
    from core.tracking import DatasetEstimates

__all__ = ["per_frame", "scores_without_positions"]


def scores_without_positions(
    ds: Dataset, est: DatasetEstimates, people: int | None, nis_dof: int | None = None
) -> RecordingScores:
    """Count, fragmentation and NIS of the run (:mod:`core.evaluation.counting`; ``nis_dof``:
    the measurement's dimension when not the paper tracker's 3)."""
    from core.evaluation.counting import recording_scores
    from core.tracking.batch import dataset_frame_period_s

    period = dataset_frame_period_s(ds)
    if nis_dof is None:
        return recording_scores(ds, est, period, people=people)
    return recording_scores(ds, est, period, people=people, nis_dof=nis_dof)


def per_frame(est: DatasetEstimates) -> dict:
    """The JSON's per-frame counts: global frame index, confirmed and tentative tracks."""
    return {
        "per_frame": {
            "frame": est.frame_index.tolist(),
            "confirmed": est.n_confirmed.tolist(),
            "tentative": (est.n_tracks - est.n_confirmed).tolist(),
        }
    }
