"""Frozen, Qt-free snapshots that workers hand to the GUI thread.

Views only draw these; they never compute physics or tracking. All arrays are numpy, SI units,
and the x-y plane is the radar's (x to the right, y along boresight).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from core.errors import InputError
from core.pointcloud import PointCloud


@dataclass(frozen=True, slots=True, kw_only=True)
class FrameData:
    """One simulated radar frame as the GUI needs it.

    Attributes
    ----------
    index
        Frame index within the scene (0-based).
    t_s
        Frame time in s.
    cloud
        The frame's point cloud (with the ground-truth ``source`` label).
    truth_xy_m
        Person positions, shape ``(n_persons, 2)`` in m (NaN where a person has no position).
    rd_map_db
        Range-Doppler map in dB, shape ``(n_range_bins, n_doppler_bins)``, zero velocity
        centred, or ``None`` when maps were not kept.
    detections
        CFAR detections, shape ``(n_det, 2)`` int: range bin, Doppler bin index into the map.
    ra_map_db
        Range-azimuth map in dB, ``(n_range_bins, n_angle_bins)``, angle index centred
        (``u = sin(az) = 2 (i - N/2) / N``), or ``None`` (levels without a Doppler cube).
    cfar_threshold_db
        The two-stage CFAR threshold of every cell of ``rd_map_db`` in dB (the larger of the
        two stages'), NaN where the detector does not test; ``None`` without a map.
    person_doppler_db
        ``(n_persons, n_doppler_bins)`` dB: the map's Doppler spectrum at each person's range
        (one column of that person's micro-Doppler spectrogram); NaN rows for absent persons.
    """

    index: int
    t_s: float
    cloud: PointCloud
    truth_xy_m: np.ndarray
    rd_map_db: np.ndarray | None = None
    detections: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), dtype=np.int64))
    ra_map_db: np.ndarray | None = None
    cfar_threshold_db: np.ndarray | None = None
    person_doppler_db: np.ndarray | None = None
    #: wall-clock seconds of the radar chain's synthesis and processing halves of this frame
    #: where the fidelity level runs them apart (exact), else NaN
    synthesis_s: float = float("nan")
    processing_s: float = float("nan")
    #: ``(n_points,)`` int: the id of TI's track the sensor's firmware gave each point (-1: none),
    #: for a recording that carries it; ``None`` otherwise
    point_track: np.ndarray | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class TrackFrame:
    """Every live track at one frame (n tracks).

    Attributes
    ----------
    track_id
        ``(n,)`` int, unique over the run.
    xy_m
        ``(n, 2)`` estimated position in m.
    gate_center_xy_m
        ``(n, 2)`` centre of the gate in x-y (the predicted position), m.
    gate_shape_xy_m2
        ``(n, 2, 2)`` gate ellipse G in x-y: the points d with dᵀ G⁻¹ d ≤ 1 (γ included), m².
    psi
        ``(n,)`` existence probability ψ in [0, 1].
    confirmed
        ``(n,)`` bool, True once the track is confirmed.
    velocity_xy_mps
        ``(n, 2)`` estimated velocity in m/s.
    sigma_xy_m
        ``(n, 2)`` standard deviations of the position estimate (√P_xx, √P_yy) in m.
    birth_frame
        ``(n,)`` int frame in which each track was born (age = frame − birth).
    n_associated
        ``(n,)`` int measurements in each track's gate this frame; −1 where the tracker does
        not report it.
    nis
        ``(n,)`` normalised innovation squared ε = ν̃ᵀ S⁻¹ ν̃ of this frame's update (ν̃ = Σ βᵢ νᵢ,
        see ``core.tracking.results.FrameTracks``); NaN where none or not reported.
    """

    track_id: np.ndarray
    xy_m: np.ndarray
    gate_center_xy_m: np.ndarray
    gate_shape_xy_m2: np.ndarray
    psi: np.ndarray
    confirmed: np.ndarray
    velocity_xy_mps: np.ndarray | None = None
    sigma_xy_m: np.ndarray | None = None
    birth_frame: np.ndarray | None = None
    n_associated: np.ndarray | None = None
    nis: np.ndarray | None = None

    @classmethod
    def empty(cls) -> TrackFrame:
        return cls(
            track_id=np.zeros(0, dtype=np.int64),
            xy_m=np.zeros((0, 2)),
            gate_center_xy_m=np.zeros((0, 2)),
            gate_shape_xy_m2=np.zeros((0, 2, 2)),
            psi=np.zeros(0),
            confirmed=np.zeros(0, dtype=bool),
        )

    def __len__(self) -> int:
        return len(self.track_id)


@dataclass(frozen=True, slots=True, kw_only=True)
class TrackingResult:
    """A tracker run over the cached frames, prepared for drawing.

    Attributes
    ----------
    frames
        One :class:`TrackFrame` per tracked frame (length F).
    estimate_xy_m
        ``(F, 2)`` the scene estimate (confirmed track with the highest ψ), NaN when none.
    truth_xy_m
        ``(F, 2)`` position of person 0 in m (the paper's single-person loss).
    running_loss
        ``(F,)`` eq. (13) over frames ``0..k``: L = MSE / N_c (1.0 m² while N_c = 0).
    running_rmse_m
        ``(F,)`` position RMSE over the frames with an estimate so far (NaN while none).
    ospa_m
        ``(F,)`` OSPA distance (c = 1 m, p = 2) between confirmed tracks and persons per frame.
    psi_t_s, psi_value
        ψ of every track against time, one NaN-separated curve (tracks in id order).
    psi_confirmed_t_s, psi_confirmed_value
        The same restricted to frames where the track is confirmed.
    trail_id, trail_t_index, trail_xy_m
        Position of every track at every frame it lived, sorted by (id, frame).
    params_key
        Identifies the parameter vector the run used (drop stale results).
    elapsed_s
        Wall-clock time of the tracker run plus preparation, in s.
    engine
        ``"numba"`` or ``"numpy"`` (the readable tracker, equal to round-off, while the
        compiled kernel is still being compiled on a cold start).
    people
        Every several-person metric of the run (:class:`core.evaluation.people.PeopleRun`: the
        paper's loss per person, GOSPA and its decomposition per frame, the people-count error,
        identity switches); None for a scene without persons.
    """

    frames: tuple[TrackFrame, ...]
    estimate_xy_m: np.ndarray
    truth_xy_m: np.ndarray
    running_loss: np.ndarray
    running_rmse_m: np.ndarray
    ospa_m: np.ndarray
    psi_t_s: np.ndarray
    psi_value: np.ndarray
    psi_confirmed_t_s: np.ndarray
    psi_confirmed_value: np.ndarray
    trail_t_index: np.ndarray
    trail_xy_m: np.ndarray
    trail_id: np.ndarray
    params_key: str = ""
    elapsed_s: float = 0.0
    #: the tracker that ran: "numba" (compiled kernel) or "numpy" (readable, until compiled)
    engine: str = "numba"
    people: Any = None

    @property
    def n_frames(self) -> int:
        return len(self.frames)


@dataclass(frozen=True, slots=True, kw_only=True)
class ParamSpec:
    """One slider: a tracker parameter with its search-space range.

    ``name`` uses the search-space naming (``q_coeff``, ``p0_00`` …); ``log`` selects a
    logarithmic slider.
    """

    name: str
    low: float
    high: float
    log: bool
    label: str = ""
    #: SI unit of the value ("" for probabilities), from core/tracking/space.py
    unit: str = ""
    #: ``symbol meaning`` without the unit (the slider's first line)
    title: str = ""


@dataclass(frozen=True, slots=True, kw_only=True)
class StudyForm:
    """What the study panel edits."""

    model: str = "cv"
    n_trials: int = 50
    n_jobs: int = 1
    storage: str = "radartune-studies.db"
    study_name: str = ""
    seed: int = 0
    #: "scene": the current scene's cached point clouds; "paper": the paper's 35 trajectories
    dataset: str = "scene"
    #: the tracker tuned: "paper" (the one-point IPDA with ``model``), "room" (the room mode with
    #: ``model``) or "gtrack" (TI's tracker, its own table; ``model`` unused), as ``radartune
    #: tune --mode room`` / ``--tracker gtrack``
    tracker: str = "paper"

    def __post_init__(self) -> None:
        if self.model not in ("cv", "ca"):
            raise InputError(f"model must be 'cv' or 'ca', got {self.model!r}", "model")
        if self.n_trials < 1:
            raise InputError(f"trials must be >= 1, got {self.n_trials}", "trials")
        if self.n_jobs < 1:
            raise InputError(f"jobs must be >= 1, got {self.n_jobs}", "jobs")
        if not self.storage.strip():
            raise InputError("storage must not be empty", "storage")
        if self.tracker not in ("paper", "room", "gtrack"):
            raise InputError(
                f"tracker must be 'paper', 'room' or 'gtrack', got {self.tracker!r}", "tracker"
            )
        if self.dataset not in ("scene", "paper"):
            raise InputError(
                f"data set must be 'scene' or 'paper', got {self.dataset!r}", "dataset"
            )

    @property
    def study_model(self) -> str:
        """The study's ``model`` (:class:`core.optimization.StudySettings`): ``gtrack`` for TI's
        tracker, else the motion model."""
        return "gtrack" if self.tracker == "gtrack" else self.model

    @property
    def mode(self) -> str:
        """The IPDA's mode the study tunes (``room`` or ``paper``)."""
        return "room" if self.tracker == "room" else "paper"

    @property
    def effective_name(self) -> str:
        """The study's name: ``radartune-<model>`` as the CLI's, ``-room`` for the room mode
        (so that a paper study of the same model on the storage is not resumed as one)."""
        suffix = "-room" if self.tracker == "room" else ""
        return self.study_name or f"radartune-{self.study_model}{suffix}"


@dataclass(frozen=True, slots=True, kw_only=True)
class StudyProgress:
    """A snapshot of a study (from its storage)."""

    n_complete: int = 0
    n_pruned: int = 0
    n_failed: int = 0
    n_running: int = 0
    best_loss: float = float("nan")
    best_params: dict = field(default_factory=dict)
    best_model: str = "cv"
    #: best-so-far loss against the study's busy time (s since its first trial started, the
    #: idle gaps between runs left out: core.optimization.progress.busy_time_s)
    curve_t_s: np.ndarray = field(default_factory=lambda: np.zeros(0))
    curve_best: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: why trials failed: (reason, number of trials), most frequent first
    failures: tuple[tuple[str, int], ...] = ()

    @property
    def n_finished(self) -> int:
        return self.n_complete + self.n_pruned + self.n_failed
