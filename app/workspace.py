"""Workspaces (Qt-free): the scene, the radar configuration, the tracker parameters and the
study settings (with its storage) in one JSON file, saved atomically and validated whole on
reading, so that a bad file changes nothing and its message names the field.

File layout (``schema: "radartune-workspace"``, ``version: 1``)::

    {"schema": "radartune-workspace", "version": 1,
     "scene": {...scene document...}, "radar": {...RadarConfig...},
     "tracker": {"model": "cv", "values": {...}, "extra": {...}, "tracker": "paper"},
     "study": {"model": "cv", "n_trials": 50, "n_jobs": 1, "storage": "/abs/path.db", ...}}
"""

from __future__ import annotations

import copy
import dataclasses
from dataclasses import dataclass
from pathlib import Path

from app.data import StudyForm
from core.config import RadarConfig
from core.errors import InputError
from core.files import read_json, write_json_atomic

SCHEMA = "radartune-workspace"
VERSION = 1
STUDY_FIELDS = tuple(f.name for f in dataclasses.fields(StudyForm))


@dataclass(frozen=True, slots=True, kw_only=True)
class Workspace:
    """Everything a workspace restores (validated)."""

    scene: dict
    radar: RadarConfig
    tracker_model: str
    tracker_values: dict
    tracker_extra: dict
    study: StudyForm
    #: the tracker the values are for: "paper", "room" or "gtrack" (absent in older files: paper)
    tracker_kind: str = "paper"

    def to_dict(self) -> dict:
        scene = copy.deepcopy(self.scene)
        scene["radar"] = self.radar.to_dict()
        return {
            "schema": SCHEMA,
            "version": VERSION,
            "scene": scene,
            "radar": self.radar.to_dict(),
            "tracker": {
                "model": self.tracker_model,
                "values": dict(self.tracker_values),
                "extra": dict(self.tracker_extra),
                "tracker": self.tracker_kind,
            },
            "study": {name: getattr(self.study, name) for name in STUDY_FIELDS},
        }


def _field(doc: dict, name: str, kind: type, source: str):
    if name not in doc:
        raise InputError(f"workspace field '{name}' is missing", source)
    value = doc[name]
    if not isinstance(value, kind):
        raise InputError(
            f"workspace field '{name}' must be a {kind.__name__}, got {type(value).__name__}",
            source,
        )
    return value


def workspace_from_dict(doc, engine, source: str, base_dir: Path) -> Workspace:
    """Validate a workspace document; any problem raises one :class:`InputError` naming
    ``source`` and the field (``scene``, ``radar``, ``tracker.values.q_coeff``, ``study.n_jobs``
    ...)."""
    if not isinstance(doc, dict):
        raise InputError("a workspace file must hold a JSON object", source)
    if doc.get("schema") != SCHEMA:
        raise InputError(f"workspace field 'schema' must be {SCHEMA!r}", source)
    if doc.get("version") != VERSION:
        raise InputError(f"workspace field 'version' must be {VERSION}", source)
    radar_doc = _field(doc, "radar", dict, source)
    try:
        radar = RadarConfig.from_dict(radar_doc)
    except InputError as exc:
        raise InputError(f"workspace field 'radar': {exc.message}", source) from None
    scene = copy.deepcopy(_field(doc, "scene", dict, source))
    scene["radar"] = radar.to_dict()
    try:
        engine.scene_from_document(scene, base_dir, None)
    except InputError as exc:
        raise InputError(f"workspace field 'scene': {exc.message}", source) from None
    tracker = _field(doc, "tracker", dict, source)
    model = tracker.get("model")
    if model not in ("cv", "ca"):
        raise InputError(
            f"workspace field 'tracker.model' must be 'cv' or 'ca', got {model!r}", source
        )
    kind = tracker.get("tracker", "paper")
    if kind not in ("paper", "room", "gtrack"):
        raise InputError(
            f"workspace field 'tracker.tracker' must be 'paper', 'room' or 'gtrack', got {kind!r}",
            source,
        )
    table, mode = ("gtrack", "paper") if kind == "gtrack" else (model, kind)
    values = tracker.get("values", {})
    extra = tracker.get("extra", {})
    for name, d in (("values", values), ("extra", extra)):
        if not isinstance(d, dict):
            raise InputError(f"workspace field 'tracker.{name}' must be an object", source)
    full = engine.default_values(table, mode)
    for key, v in values.items():
        if key not in full:
            raise InputError(f"workspace field 'tracker.values.{key}': unknown parameter", source)
        if isinstance(v, bool) or not isinstance(v, int | float):
            raise InputError(f"workspace field 'tracker.values.{key}' must be a number", source)
        full[key] = float(v)
    unknown = sorted(set(extra) - set(engine.default_extra()))
    if unknown:
        raise InputError(f"workspace field 'tracker.extra.{unknown[0]}': unknown setting", source)
    try:
        engine.make_params(table, full, extra, mode)
    except (InputError, TypeError, ValueError) as exc:
        msg = exc.message if isinstance(exc, InputError) else str(exc)
        raise InputError(f"workspace field 'tracker': {msg}", source) from None
    study_doc = _field(doc, "study", dict, source)
    unknown = sorted(set(study_doc) - set(STUDY_FIELDS))
    if unknown:
        raise InputError(f"workspace field 'study.{unknown[0]}': unknown setting", source)
    for key, v in study_doc.items():
        want = type(getattr(StudyForm(), key))
        if want is int and (isinstance(v, bool) or not isinstance(v, int)):
            raise InputError(f"workspace field 'study.{key}' must be an integer", source)
        if want is str and not isinstance(v, str):
            raise InputError(f"workspace field 'study.{key}' must be a string", source)
    try:
        study = StudyForm(**study_doc)
    except InputError as exc:
        raise InputError(f"workspace field 'study.{exc.source}': {exc.message}", source) from None
    return Workspace(
        scene=scene,
        radar=radar,
        tracker_model=model,
        tracker_values=full,
        tracker_extra=dict(extra),
        study=study,
        tracker_kind=kind,
    )


def save_workspace(path: str | Path, workspace: Workspace) -> Path:
    """Write the workspace atomically; the study storage is stored as an absolute path."""
    d = workspace.to_dict()
    storage = d["study"]["storage"]
    if "://" not in storage:
        d["study"]["storage"] = str(Path(storage).expanduser().resolve())
    return write_json_atomic(path, d)


def load_workspace(path: str | Path, engine) -> Workspace:
    """Read and validate a workspace file (one :class:`InputError` naming file and field)."""
    path = Path(path)
    doc = read_json(path, what="workspace file")
    return workspace_from_dict(doc, engine, str(path), path.parent)
