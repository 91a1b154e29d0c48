"""Scenes: the app's default scene, scene documents checked by core, what the views need of a
scene, the trajectory-class parameters the editor offers, TI radar files."""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from core.config import (
    PAPER_CLUTTER_DENSITY_PER_M2,
    PAPER_MAX_AZIMUTH_DEG,
    PAPER_MAX_RANGE_M,
    PAPER_MIN_RANGE_M,
    RadarConfig,
)

ROOT = Path(__file__).resolve().parents[2]
PAPER_SCENE_FILE = ROOT / "resources" / "scenes" / "paper_class_c.json"

#: The paper scene (SPEC §6 example, one person of class c; the area and λ from
#: :mod:`core.config`): used when the resource is missing.
PAPER_SCENE_DOCUMENT = {
    "schema_version": 1,
    "radar": "paper",
    "seed": 7,
    "clutter_density_per_m2": PAPER_CLUTTER_DENSITY_PER_M2,
    "aoi": {
        "min_range_m": PAPER_MIN_RANGE_M,
        "max_range_m": PAPER_MAX_RANGE_M,
        "max_azimuth_deg": PAPER_MAX_AZIMUTH_DEG,
    },
    "static_reflectors": [],
    "persons": [{"trajectory": {"class": "c", "seed": 3}}],
}


@dataclass(frozen=True, slots=True, kw_only=True)
class SceneInfo:
    """What the views need of a scene before any frame is simulated."""

    n_frames: int
    frame_period_s: float
    truth_paths: tuple[np.ndarray, ...]  # per person (F_i, 2), m
    reflectors_xy_m: np.ndarray  # (n, 2)
    aoi: dict
    radar: RadarConfig
    #: (n, 2) m: the room's walls and the furniture's footprints as one NaN-separated outline
    #: (empty in the open field)
    room_outline_xy_m: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))


def room_outline(room) -> np.ndarray:
    """Walls (segments) and furniture (footprint rectangles) of a ``core.scene.Room`` as one
    NaN-separated x–y polyline, m; empty for ``None``."""
    if room is None:
        return np.zeros((0, 2))
    gap = [np.full((1, 2), np.nan)]
    parts: list[np.ndarray] = []
    for w in room.walls:
        parts += [np.array([w.from_m, w.to_m], dtype=float), *gap]
    for f in room.furniture:
        hx, hy = f.width_m / 2, f.depth_m / 2
        corners = [(-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy), (-hx, -hy)]
        parts += [np.array([(f.x_m + dx, f.y_m + dy) for dx, dy in corners]), *gap]
    return np.concatenate(parts) if parts else np.zeros((0, 2))


@dataclass(frozen=True, slots=True, kw_only=True)
class ClassParamSpec:
    """A trajectory-class parameter the scene editor offers (float-valued)."""

    name: str
    label: str
    unit: str
    low: float
    high: float
    step: float
    decimals: int
    help: str = ""


def paper_document() -> dict:
    """The app's default scene: the paper scene (``resources/scenes/paper_class_c.json``) with
    the default person model (a walking body, decision scene-07) where its file names none."""
    from core.scene.scene import DEFAULT_PERSON_MODEL

    if PAPER_SCENE_FILE.is_file():
        doc = json.loads(PAPER_SCENE_FILE.read_text())
    else:
        doc = json.loads(json.dumps(PAPER_SCENE_DOCUMENT))
    for person in doc.get("persons", []):
        person.setdefault("model", DEFAULT_PERSON_MODEL)
    return doc


def scene_from_document(doc: dict, base_dir: Path, source: str | None = None):
    """Validate a scene document with :mod:`core.scene`; raises :class:`InputError` naming
    ``source`` (the file) and the field."""
    from core.scene import Scene

    return Scene.from_dict(doc, source=source, base_dir=base_dir)


def scene_info(scene) -> SceneInfo:
    paths = tuple(np.asarray(p.trajectory.position_m, dtype=float) for p in scene.persons)
    refl = np.array([[r.x_m, r.y_m] for r in scene.static_reflectors], dtype=float).reshape(-1, 2)
    return SceneInfo(
        n_frames=scene.n_frames,
        frame_period_s=scene.radar.frame_period_s,
        truth_paths=paths,
        reflectors_xy_m=refl,
        aoi=scene.aoi.to_dict(),
        radar=scene.radar,
        room_outline_xy_m=room_outline(scene.room),
    )


def default_aoi() -> dict:
    from core.scene import AOI

    return AOI().to_dict()


_CLASS_PARAM_UI = {
    # name: label, unit, step, decimals, help
    "speed_mps": ("speed", "m/s", 0.05, 2, "walking speed"),
    "start_x_m": ("start x", "m", 0.1, 2, "start position x (needs start y too)"),
    "start_y_m": ("start y", "m", 0.1, 2, "start position y (needs start x too)"),
    "duration_s": ("duration", "s", 0.5, 1, "length of the walk"),
    "turn_rate_hz": ("turn rate", "1/s", 0.05, 2, "mean number of turns per second (c, d)"),
    "stop_rate_hz": ("stop rate", "1/s", 0.05, 2, "mean number of stops per second (d)"),
    "radius_m": ("circle radius", "m", 0.1, 2, "radius of the circle (e)"),
}


def class_param_specs() -> list[ClassParamSpec]:
    """Float parameters of the trajectory classes (union over a–e), from core's table."""
    from core.scene import CLASS_PARAMETERS

    bounds: dict[str, tuple[float, float]] = {}
    for params in CLASS_PARAMETERS.values():
        for name, (kind, lo, hi) in params.items():
            if kind is float and name in _CLASS_PARAM_UI:
                bounds[name] = (lo, hi)
    out = []
    for name, (label, unit, step, dec, help_) in _CLASS_PARAM_UI.items():
        if name in ("start_x_m", "start_y_m"):
            lo, hi = -100.0, 100.0
        elif name in bounds:
            lo, hi = bounds[name]
        else:
            continue
        out.append(
            ClassParamSpec(
                name=name,
                label=label,
                unit=unit,
                low=lo,
                high=hi,
                step=step,
                decimals=dec,
                help=help_,
            )
        )
    return out


def class_param_names(trajectory_class: str) -> set[str]:
    """Parameters (as the editor names them) that class ``trajectory_class`` accepts."""
    from core.scene import CLASS_PARAMETERS

    names = set(CLASS_PARAMETERS.get(trajectory_class, {}))
    if "start_m" in names:
        names |= {"start_x_m", "start_y_m"}
    return names


def read_ti_cfg(path: str | os.PathLike) -> RadarConfig:
    from core.formats.ti_cfg import read_ti_cfg as _read

    return _read(path)


def read_ti_chain(path: str | os.PathLike):
    """The detection chain a TI .cfg selects (``core.config.ChainConfig``)."""
    from core.formats.ti_cfg import read_ti_chain as _read

    return _read(path)
