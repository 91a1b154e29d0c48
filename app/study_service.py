"""Study service: a helper process that starts, polls, stops and feeds Optuna studies for the GUI.

Run as ``python -m app.study_service`` (the GUI starts it with ``QProcess``). It reads one JSON
request per line on stdin and answers one JSON line on stdout::

    {"id": 1, "op": "start", "form": {...}, "dataset": "/path/scene.npz"}
    {"id": 2, "op": "progress", "form": {...}}     -> {"id": 2, "ok": true, "result": {...}}
    {"id": 3, "op": "stop"}
    {"id": 4, "op": "enqueue", "form": {...}, "values": {...}, "model": "cv"}

Why a process: Optuna, SQLAlchemy and the storage connections then live outside the GUI
process. Inside it, opening a storage every poll filled the heap, and full garbage collections
(which hold the GIL) stopped the event loop for 0.4–1.3 s on the loaded test machine. The worker
processes of a study are children of this service; Qt-free, Optuna only through
:mod:`core.optimization` (via :mod:`app.engine`).
"""

from __future__ import annotations

import json
import sys
import traceback

import app  # noqa: F401  (thread settings before numpy)
from app import engine
from app.data import StudyForm


def progress_to_dict(p) -> dict:
    return {
        "n_complete": p.n_complete,
        "n_pruned": p.n_pruned,
        "n_failed": p.n_failed,
        "n_running": p.n_running,
        "best_loss": None if p.best_loss != p.best_loss else p.best_loss,
        "best_params": p.best_params,
        "best_model": p.best_model,
        "curve_t_s": [float(v) for v in p.curve_t_s],
        "curve_best": [float(v) for v in p.curve_best],
        "failures": [[reason, int(n)] for reason, n in p.failures],
    }


def progress_from_dict(d: dict):
    import numpy as np

    from app.data import StudyProgress

    return StudyProgress(
        n_complete=int(d["n_complete"]),
        n_pruned=int(d["n_pruned"]),
        n_failed=int(d["n_failed"]),
        n_running=int(d["n_running"]),
        best_loss=float("nan") if d["best_loss"] is None else float(d["best_loss"]),
        best_params={k: float(v) for k, v in d["best_params"].items()},
        best_model=str(d["best_model"]),
        curve_t_s=np.asarray(d["curve_t_s"], dtype=float),
        curve_best=np.asarray(d["curve_best"], dtype=float),
        failures=tuple((str(r), int(n)) for r, n in d.get("failures", [])),
    )


class Service:
    def __init__(self) -> None:
        self.handle = None

    def alive(self) -> bool:
        return self.handle is not None and self.handle.alive()

    def handle_request(self, req: dict):
        op = req.get("op")
        if op == "start":
            if self.alive():
                raise engine.InputError("a study is already running", "study")
            form = StudyForm(**req["form"])
            self.handle = engine.start_study(form, req.get("dataset"))
            return {"alive": True}
        if op == "progress":
            form = StudyForm(**req["form"])
            alive = self.alive()  # read before the progress: a final poll sees every trial
            result = progress_to_dict(engine.study_progress(form))
            result["alive"] = alive
            return result
        if op == "stop":
            if self.alive():
                self.handle.stop()
            return {"alive": self.alive()}
        if op == "enqueue":
            form = StudyForm(**req["form"])
            engine.enqueue_trial(form, req["values"], req["model"])
            return {}
        if op == "shutdown":
            if self.alive():
                self.handle.stop()
                self.handle.join(30.0)
            return {}
        raise engine.InputError(f"unknown request {op!r}", "study service")


def main() -> int:
    service = Service()
    for line in sys.stdin:
        line = line.strip()
        if not line:
            continue
        try:
            req = json.loads(line)
        except json.JSONDecodeError as exc:
            print(json.dumps({"id": None, "ok": False, "error": f"bad request: {exc}"}), flush=True)
            continue
        try:
            result = service.handle_request(req)
            out = {"id": req.get("id"), "ok": True, "result": result}
        except Exception as exc:
            traceback.print_exc(file=sys.stderr)
            out = {"id": req.get("id"), "ok": False, "error": engine.describe(exc)}
        print(json.dumps(out), flush=True)
        if req.get("op") == "shutdown":
            break
    if service.alive():
        service.handle.stop()
        service.handle.join(30.0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
