"""The paper data set, simulated once per test session and kept under pytest's tmp dir.

The full set (35 trajectories, ~5400 frames) costs ~70 s of CPU on this machine, too much for
the suite; the tests use the first ``N_TRAJECTORIES`` of the same round-robin set (one of each
class a–e, ~750 frames). ``radartune dataset`` measures the full set (see docs/scenes.md).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from core.dataset import Dataset
from core.pipeline import paper_dataset

N_TRAJECTORIES = 5
SEED = 0


@pytest.fixture(scope="session")
def paper_cache(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The cache folder the session's paper subset is simulated into."""
    return tmp_path_factory.mktemp("radartune-cache")


@pytest.fixture(scope="session")
def paper_subset(paper_cache: Path) -> Dataset:
    ds = paper_dataset(SEED, N_TRAJECTORIES, cache_dir=paper_cache, jobs=2)
    # the second call reads the cached file: what the tests see is what the cache holds
    again = paper_dataset(SEED, N_TRAJECTORIES, cache_dir=paper_cache, jobs=2)
    assert again.n_frames == ds.n_frames
    return again
