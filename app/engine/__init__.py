"""The app's only door into :mod:`core`: adapters for scenes, simulation, tracking and studies.

Qt-free: every function here can run in a worker thread. It adapts core results into the
frozen snapshots of :mod:`app.data`, so that views draw and never compute; the computing is
core's. Optuna is never imported here (studies go through :mod:`core.optimization`).

- :mod:`app.engine.scenes`: the default scene, scene documents, class parameters, TI radar files;
- :mod:`app.engine.simulation`: frames of a scene through the radar chain;
- :mod:`app.engine.tracking`: tracker parameters, the compiled tracker's warm-up, re-tracking;
- :mod:`app.engine.studies`: study processes and progress, the dashboard.

:class:`Engine` gathers them as one object (tests and the replay substitute parts of it).
"""

from __future__ import annotations

from app.engine.scenes import (
    PAPER_SCENE_DOCUMENT,
    PAPER_SCENE_FILE,
    ROOT,
    ClassParamSpec,
    SceneInfo,
    class_param_names,
    class_param_specs,
    default_aoi,
    paper_document,
    read_ti_cfg,
    read_ti_chain,
    scene_from_document,
    scene_info,
)
from app.engine.simulation import fidelity_levels, frame_views, processing_settings, simulate
from app.engine.studies import (
    Dashboard,
    StudyProcesses,
    enqueue_trial,
    failure_reasons,
    scene_dataset,
    serve_dashboard,
    start_study,
    storage_url,
    study_progress,
)
from app.engine.tracking import (
    EXTRA_FIELDS,
    TRACKER_COMPILED,
    TRACKERS,
    default_extra,
    default_values,
    load_params,
    load_tracker_file,
    make_params,
    param_specs,
    track,
    track_frame,
    tracker_compiled,
    warm_up_tracker,
)
from core.errors import InputError


def describe(exc: BaseException) -> str:
    """One line for the user: an InputError as is, anything else with its type."""
    if isinstance(exc, InputError):
        return str(exc)
    return f"{type(exc).__name__}: {exc}"


class Engine:
    """The functions above as one object (tests may substitute parts of it)."""

    #: whether the frames carry ground truth (a simulation always; a recording when imported
    #: with it): without it the app shows "no ground truth" instead of a loss or an OSPA
    has_truth = True

    paper_document = staticmethod(paper_document)
    scene_from_document = staticmethod(scene_from_document)
    scene_info = staticmethod(scene_info)
    default_aoi = staticmethod(default_aoi)
    class_param_specs = staticmethod(class_param_specs)
    class_param_names = staticmethod(class_param_names)
    param_specs = staticmethod(param_specs)
    default_values = staticmethod(default_values)
    default_extra = staticmethod(default_extra)
    make_params = staticmethod(make_params)
    load_params = staticmethod(load_params)
    load_tracker_file = staticmethod(load_tracker_file)
    simulate = staticmethod(simulate)
    fidelity_levels = staticmethod(fidelity_levels)
    processing_settings = staticmethod(processing_settings)
    track = staticmethod(track)
    warm_up_tracker = staticmethod(warm_up_tracker)
    tracker_compiled = staticmethod(tracker_compiled)
    read_ti_cfg = staticmethod(read_ti_cfg)
    read_ti_chain = staticmethod(read_ti_chain)
    scene_dataset = staticmethod(scene_dataset)
    start_study = staticmethod(start_study)
    study_progress = staticmethod(study_progress)
    enqueue_trial = staticmethod(enqueue_trial)
    serve_dashboard = staticmethod(serve_dashboard)


__all__ = [
    "EXTRA_FIELDS",
    "PAPER_SCENE_DOCUMENT",
    "PAPER_SCENE_FILE",
    "ROOT",
    "TRACKER_COMPILED",
    "TRACKERS",
    "ClassParamSpec",
    "Dashboard",
    "Engine",
    "SceneInfo",
    "StudyProcesses",
    "class_param_names",
    "class_param_specs",
    "default_aoi",
    "default_extra",
    "default_values",
    "describe",
    "enqueue_trial",
    "failure_reasons",
    "fidelity_levels",
    "frame_views",
    "load_params",
    "load_tracker_file",
    "make_params",
    "paper_document",
    "param_specs",
    "processing_settings",
    "read_ti_cfg",
    "read_ti_chain",
    "scene_dataset",
    "scene_from_document",
    "scene_info",
    "serve_dashboard",
    "simulate",
    "start_study",
    "storage_url",
    "study_progress",
    "track",
    "track_frame",
    "tracker_compiled",
    "warm_up_tracker",
]
