"""Models: the single source of truth of each panel, with Qt signals.

Widgets bind both ways: they call the setters here, and they listen to the ``changed`` signals
and update themselves with their own signals blocked. Models validate through :mod:`core`
(a bad value raises :class:`core.errors.InputError` and leaves the model unchanged).
"""

from __future__ import annotations

import copy
import dataclasses
import json
from pathlib import Path

from PySide6 import QtCore

from app.data import FrameData, ParamSpec, TrackingResult
from core.config import PAPER_CHAIN, PAPER_RADAR, ChainConfig, RadarConfig
from core.errors import InputError
from core.files import read_json, write_json_atomic


class RadarModel(QtCore.QObject):
    """The radar configuration (a frozen :class:`RadarConfig`); edits go through ``replace``."""

    changed = QtCore.Signal(object)  # RadarConfig
    chain_changed = QtCore.Signal(object)  # ChainConfig

    def __init__(self, radar: RadarConfig = PAPER_RADAR, parent=None) -> None:
        super().__init__(parent)
        self._radar = radar
        self._chain = PAPER_CHAIN

    @property
    def chain(self) -> ChainConfig:
        """The detection chain (``paper``, ``oob``, ``people-counting``) and its settings."""
        return self._chain

    def set_chain(self, chain: ChainConfig) -> None:
        if chain != self._chain:
            self._chain = chain
            self.chain_changed.emit(chain)

    @property
    def radar(self) -> RadarConfig:
        return self._radar

    def set_radar(self, radar: RadarConfig) -> None:
        if radar != self._radar or radar.name != self._radar.name:
            self._radar = radar
            self.changed.emit(radar)

    def set_field(self, name: str, value) -> None:
        """Replace one field; an invalid value raises :class:`InputError` and changes nothing."""
        try:
            new = dataclasses.replace(self._radar, **{name: value})
        except TypeError as exc:
            raise InputError(str(exc), f"radar.{name}") from None
        self.set_radar(new)


class SceneModel(QtCore.QObject):
    """The scene as its JSON document (SPEC §6), validated by :mod:`core.scene` on every edit.

    The document is what the user edits and saves; ``scene`` is the validated core object.
    """

    changed = QtCore.Signal()
    selection_changed = QtCore.Signal(int)

    def __init__(self, engine, parent=None) -> None:
        super().__init__(parent)
        self._engine = engine
        self._doc: dict = {}
        self._scene = None
        self._base_dir = Path.cwd()
        self._path: Path | None = None
        self._selected = 0

    # ---- access -------------------------------------------------------------------------------
    @property
    def document(self) -> dict:
        """A deep copy of the scene document (edit it and pass it to :meth:`set_document`)."""
        return copy.deepcopy(self._doc)

    @property
    def scene(self):
        return self._scene

    @property
    def path(self) -> Path | None:
        return self._path

    @property
    def selected_person(self) -> int:
        return self._selected

    @property
    def n_persons(self) -> int:
        return len(self._doc.get("persons", []))

    def person(self, index: int) -> dict:
        return copy.deepcopy(self._doc["persons"][index])

    # ---- edits -------------------------------------------------------------------------------
    def set_document(
        self, doc: dict, *, base_dir: Path | None = None, source: str | None = None
    ) -> None:
        """Validate and adopt a document; on error raise :class:`InputError`, keep the old one."""
        base = base_dir if base_dir is not None else self._base_dir
        scene = self._engine.scene_from_document(doc, base, source)
        self._doc = copy.deepcopy(doc)
        self._scene = scene
        self._base_dir = base
        if self._selected >= self.n_persons:
            self._selected = max(0, self.n_persons - 1)
        self.changed.emit()

    def edit(self, **top_level) -> None:
        doc = self.document
        doc.update(top_level)
        self.set_document(doc)

    def set_person(self, index: int, person: dict) -> None:
        doc = self.document
        doc["persons"][index] = person
        self.set_document(doc)

    def add_person(self, person: dict) -> None:
        doc = self.document
        doc.setdefault("persons", []).append(person)
        self.set_document(doc)
        self.select_person(self.n_persons - 1)

    def remove_person(self, index: int) -> None:
        doc = self.document
        if len(doc.get("persons", [])) <= 1:
            raise InputError("a scene needs at least one person", "persons")
        del doc["persons"][index]
        self.set_document(doc)

    def select_person(self, index: int) -> None:
        index = max(0, min(index, self.n_persons - 1))
        if index != self._selected:
            self._selected = index
            self.selection_changed.emit(index)

    # ---- files -------------------------------------------------------------------------------
    def load(self, path: str | Path) -> None:
        """Load a scene file; a malformed file raises :class:`InputError`, the scene stays."""
        path = Path(path)
        doc = read_json(path, what="scene file")
        if not isinstance(doc, dict):
            raise InputError("a scene file must hold a JSON object", str(path))
        self.set_document(doc, base_dir=path.parent, source=str(path))
        self._path = path

    def save(self, path: str | Path) -> None:
        """Write the document atomically (temporary file, then rename)."""
        path = Path(path)
        try:
            write_json_atomic(path, self._doc)
        except OSError as exc:
            raise InputError(f"cannot write scene ({exc.strerror})", str(path)) from None
        self._path = path


class TrackerParamsModel(QtCore.QObject):
    """Tracker parameters as flat search-space values (``q_coeff``, ``p0_00`` …) plus the model
    and the tracker (``"paper"``, ``"room"`` or ``"gtrack"``: the values are that tracker's
    search-space rows, :func:`core.tracking.space.search_space`).

    ``changed`` fires on every edit. Every edit builds (and so validates) the core
    ``TrackerParams`` once; :meth:`params` returns that object.
    """

    changed = QtCore.Signal()

    def __init__(self, engine, parent=None) -> None:
        super().__init__(parent)
        self._engine = engine
        self._model = "cv"
        self._tracker = "paper"
        self._values: dict[str, float] = engine.default_values("cv")
        self._extra: dict = {}
        self._params = engine.make_params(self._model, self._values, self._extra)

    @property
    def model(self) -> str:
        return self._model

    @property
    def values(self) -> dict[str, float]:
        return dict(self._values)

    @property
    def tracker(self) -> str:
        """``"paper"`` (the paper's IPDA), ``"room"`` (the tracker for real rooms) or
        ``"gtrack"`` (TI's people tracker rebuilt)."""
        return self._tracker

    def _table(self, tracker: str, model: str) -> tuple[str, str]:
        """(table, mode) of core's search space for ``tracker`` with motion ``model``."""
        return ("gtrack", "paper") if tracker == "gtrack" else (model, tracker)

    def _defaults(self, tracker: str, model: str) -> dict[str, float]:
        return self._engine.default_values(*self._table(tracker, model))

    def specs(self) -> list[ParamSpec]:
        return self._engine.param_specs(*self._table(self._tracker, self._model))

    def set_tracker(self, tracker: str) -> None:
        """Switch trackers: the sliders become its search space (shared rows keep their
        values, the others take the table's defaults)."""
        if tracker not in ("paper", "room", "gtrack"):
            raise InputError(
                f"tracker must be 'paper', 'room' or 'gtrack', got {tracker!r}", "tracker"
            )
        if tracker == self._tracker:
            return
        defaults = self._defaults(tracker, self._model)
        values = {k: self._values.get(k, v) for k, v in defaults.items()}
        try:
            self._set(self._model, values, self._extra, tracker)
        except InputError:  # a shared name with another meaning out of range: the defaults
            self._set(self._model, defaults, self._extra, tracker)

    def set_model(self, model: str) -> None:
        if model not in ("cv", "ca"):
            raise InputError(f"model must be 'cv' or 'ca', got {model!r}", "model")
        if model == self._model:
            return
        defaults = self._defaults(self._tracker, model)
        # keep what both models share, take defaults for the rest (p0_44, p0_55 for CA)
        self._set(model, {k: self._values.get(k, v) for k, v in defaults.items()}, self._extra)

    def set_value(self, name: str, value: float) -> None:
        if name not in self._values:
            raise InputError(f"unknown tracker parameter {name!r}", name)
        value = float(value)
        if value != self._values[name]:
            self._set(self._model, {**self._values, name: value}, self._extra)

    def set_values(
        self, values: dict[str, float], model: str | None = None, extra: dict | None = None
    ) -> None:
        """Set the flat values (missing ones take the table's defaults), the model and (merged
        into the current ones) the non-optimised settings, in one edit."""
        model = model or self._model
        full = self._defaults(self._tracker, model)
        unknown = sorted(set(values) - set(full))
        if unknown:
            raise InputError(f"unknown tracker parameter(s) {unknown}", "tracker parameters")
        full.update({k: float(v) for k, v in values.items()})
        self._set(model, full, self._extra if extra is None else {**self._extra, **extra})

    def set_extra(self, **extra) -> None:
        """Non-optimised settings (thresholds, clutter density)."""
        self._set(self._model, self._values, {**self._extra, **extra})

    def _set(
        self, model: str, values: dict[str, float], extra: dict, tracker: str | None = None
    ) -> None:
        """Build the ``TrackerParams`` (InputError, nothing changed, if invalid), then take it."""
        tracker = tracker or self._tracker
        table, mode = self._table(tracker, model)
        if tracker == "paper":
            params = self._engine.make_params(model, values, extra)
        else:
            params = self._engine.make_params(table, values, extra, mode)
        self._model, self._values, self._extra, self._params = model, values, extra, params
        self._tracker = tracker
        self.changed.emit()

    @property
    def extra(self) -> dict:
        return dict(self._extra)

    def extra_effective(self) -> dict:
        """The non-optimised settings with defaults filled in."""
        return {**self._engine.default_extra(), **self._extra}

    def reset(self) -> None:
        self._set(self._model, self._defaults(self._tracker, self._model), self._extra)

    def params(self):
        """The core ``TrackerParams`` of the current values (built at the last edit)."""
        return self._params

    def key(self) -> str:
        return json.dumps(
            [self._tracker, self._model, sorted(self._values.items()), sorted(self._extra.items())]
        )


class FrameCache(QtCore.QObject):
    """Simulated frames of the current scene, filled progressively by the simulation worker."""

    frames_added = QtCore.Signal(int)  # number of frames now cached
    reset = QtCore.Signal()
    finished = QtCore.Signal()

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.frames: list[FrameData] = []
        self.expected = 0
        self.complete = False
        self.truth_paths: list = []
        self.generation = 0

    def clear(self, expected: int = 0, truth_paths=()) -> None:
        self.frames = []
        self.expected = expected
        self.complete = False
        self.truth_paths = list(truth_paths)
        self.generation += 1
        self.reset.emit()

    def append(self, frame: FrameData) -> None:
        self.frames.append(frame)
        self.frames_added.emit(len(self.frames))

    def mark_complete(self) -> None:
        self.complete = True
        self.finished.emit()

    def __len__(self) -> int:
        return len(self.frames)


class TrackingModel(QtCore.QObject):
    """The latest tracker run over the cache."""

    changed = QtCore.Signal(object)  # TrackingResult | None

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.result: TrackingResult | None = None

    def set_result(self, result: TrackingResult | None) -> None:
        self.result = result
        self.changed.emit(result)


class PlaybackModel(QtCore.QObject):
    """Current frame, play state and speed."""

    frame_changed = QtCore.Signal(int)
    playing_changed = QtCore.Signal(bool)
    speed_changed = QtCore.Signal(float)

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self._frame = 0
        self._playing = False
        self._speed = 1.0
        self.n_available = 0
        self.loop = True

    @property
    def frame(self) -> int:
        return self._frame

    @property
    def playing(self) -> bool:
        return self._playing

    @property
    def speed(self) -> float:
        return self._speed

    def set_frame(self, index: int) -> None:
        index = max(0, min(int(index), max(self.n_available - 1, 0)))
        if index != self._frame:
            self._frame = index
            self.frame_changed.emit(index)

    def step(self, delta: int) -> None:
        self.set_frame(self._frame + delta)

    def set_playing(self, playing: bool) -> None:
        if playing != self._playing:
            self._playing = bool(playing)
            self.playing_changed.emit(self._playing)

    def set_speed(self, speed: float) -> None:
        speed = float(speed)
        if not (0.05 <= speed <= 16.0):
            raise InputError(f"playback speed must be in [0.05, 16], got {speed}", "speed")
        if speed != self._speed:
            self._speed = speed
            self.speed_changed.emit(speed)

    def set_available(self, n: int) -> None:
        self.n_available = n
        if self._frame >= n and n > 0:
            self.set_frame(n - 1)
