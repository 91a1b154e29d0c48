"""Fill numba's on-disk cache for what the app runs first, so that the first start after an
install does not compile: ``make`` runs it after ``pip install`` (``python -m app.warm_up``).

Simulates two frames of the paper scene through the GUI's plan at the default (exact) fidelity
and runs the compiled tracker once; prints what it took. Qt is not imported. A second run (warm
cache) takes a few seconds.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import app  # noqa: F401  (thread settings before numpy)


def main(argv: list[str] | None = None) -> int:
    from app import engine

    t0 = time.perf_counter()
    scene = engine.scene_from_document(engine.paper_document(), Path.cwd())
    frames = engine.simulate(scene)
    for _ in range(2):
        next(frames)
    t1 = time.perf_counter()
    engine.warm_up_tracker()
    t2 = time.perf_counter()
    print(f"numba cache warm: radar chain {t1 - t0:.1f} s, tracker {t2 - t1:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
