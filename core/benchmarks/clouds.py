"""Cloud statistics benchmark: simulated person clouds against a real recording (issue 13)."""

from __future__ import annotations

import os
from pathlib import Path

#: The RadHAR walking recording inside the real-data folder.
RADHAR_WALK = Path("radhar_walk") / "__20_walk_6.txt"


def real_data_dir() -> Path:
    """The folder of real recordings: ``$RADARTUNE_REAL_DATA``, else the first of
    ``<repo>/../shared/real`` and ``<repo>/../../shared/real`` that exists (a worktree sits one
    level deeper than the main checkout)."""
    env = os.environ.get("RADARTUNE_REAL_DATA")
    if env:
        return Path(env)
    repo = Path(__file__).resolve().parents[2]
    for cand in (repo.parent / "shared" / "real", repo.parent.parent / "shared" / "real"):
        if cand.is_dir():
            return cand
    return repo.parent / "shared" / "real"
