"""The data set a study tracks: a given ``.npz`` or the paper's data set, cached on disk.

Workers are separate processes (possibly on other machines), so they receive a file path, never
an in-memory data set, and a trial never simulates: the paper's data set is simulated once by
:func:`core.pipeline.paper_dataset_file` (cached under its content key) before workers start.
"""

from __future__ import annotations

from pathlib import Path

from core.errors import InputError


def resolve_dataset(dataset: str | None, *, n_trajectories: int = 35) -> str:
    """A data-set argument → an existing ``.npz`` path.

    ``None`` or ``"paper"``: the paper's data set of seed 0; ``"paper:SEED"``: of another seed
    (35 trajectories, 7 per class); anything else: a path to a data-set file.
    """
    if dataset in (None, "", "paper") or str(dataset).startswith("paper:"):
        seed = 0
        if dataset and ":" in dataset:
            try:
                seed = int(dataset.split(":", 1)[1])
            except ValueError:
                raise InputError(f"data set {dataset!r}: expected paper:SEED") from None
        from core.pipeline import paper_dataset_file

        return str(paper_dataset_file(seed, n_trajectories))
    path = Path(dataset)
    if not path.is_file():
        raise InputError(f"data set {dataset!r} does not exist")
    return str(path)
