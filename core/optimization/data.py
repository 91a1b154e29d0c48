"""The data set a study tracks: a given ``.npz`` or the paper's data set, cached on disk.

Workers are separate processes (possibly on other machines), so they receive a file path, never
an in-memory data set, and a trial never simulates.
"""

from __future__ import annotations

from pathlib import Path

from core.errors import InputError

DEFAULT_CACHE_DIR = Path(".radartune-cache")


def paper_dataset_path(
    seed: int = 0, n_trajectories: int = 35, *, cache_dir: str | Path = DEFAULT_CACHE_DIR
) -> Path:
    """Path of the paper's data set for ``seed``, simulated once and saved if not cached.

    Returns
    -------
    Path
        ``<cache_dir>/paper-seed<seed>-n<n_trajectories>.npz``.
    """
    cache_dir = Path(cache_dir)
    path = cache_dir / f"paper-seed{int(seed)}-n{int(n_trajectories)}.npz"
    if path.is_file():
        return path
    try:
        from core.pipeline import paper_dataset
    except ImportError as exc:
        raise InputError(
            "the paper data set needs core.pipeline (branch scene); pass --dataset PATH"
        ) from exc
    cache_dir.mkdir(parents=True, exist_ok=True)
    ds = paper_dataset(seed, n_trajectories, cache_dir=cache_dir)
    ds.save(path)  # atomic: temporary name, then rename
    return path


def resolve_dataset(dataset: str | None, *, cache_dir: str | Path = DEFAULT_CACHE_DIR) -> str:
    """A data-set argument → an existing ``.npz`` path (None or ``"paper"``: seed 0, 35)."""
    if dataset in (None, "", "paper"):
        return str(paper_dataset_path(0, 35, cache_dir=cache_dir))
    if dataset.startswith("paper:"):
        try:
            seed = int(dataset.split(":", 1)[1])
        except ValueError:
            raise InputError(f"data set {dataset!r}: expected paper:SEED") from None
        return str(paper_dataset_path(seed, 35, cache_dir=cache_dir))
    path = Path(dataset)
    if not path.is_file():
        raise InputError(f"data set {dataset!r} does not exist")
    return str(path)
