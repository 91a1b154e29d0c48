"""Tracker parameters (SPEC §4, §6): the paper's 14 optimised parameters plus the fixed ones.

JSON keys exactly as SPEC §6; missing keys take the defaults, unknown keys are an error that
names them. Every field is validated in ``__post_init__`` with a message naming the field.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, fields
from pathlib import Path

from core.errors import InputError
from core.files import read_json, write_json_atomic
from core.limits import CLUTTER_DENSITY_RANGE, MAX_TRACKS, VARIANCE_RANGE
from core.tracking.jipda import ASSOCIATIONS
from core.tracking.space import (
    MODELS,
    MODES,
    P0_NAMES,
    ROOM_NAMES,
    STATE_DIM,
    defaults,
    p0_names,
    parameter,
)

NONPARAMETRIC = "nonparametric"

#: Default initial standard deviations p0,ii per model, from the table (core/tracking/space.py).
DEFAULT_P0 = {m: tuple(defaults(m)[n] for n in p0_names(m)) for m in MODELS}


@dataclass(frozen=True, slots=True, kw_only=True)
class TrackerParams:
    """Parameters of the IPDA tracker.

    Attributes
    ----------
    model
        Motion model, ``"cv"`` (state ``[x, y, vx, vy]``) or ``"ca"`` (``[x, y, vx, vy, ax, ay]``).
    q_coeff
        Process-noise scale: ``Q = q_coeff · Q0`` with the direct discrete-time kinematic ``Q0``,
        in m²/s⁴: for CV the variance of the acceleration, for CA the variance of the acceleration
        increment over one frame (see :mod:`core.tracking.space`).
    r11, r22, r33
        Measurement noise standard deviations of range (m), azimuth (rad) and radial velocity
        (m/s): ``R = diag(r11², r22², r33²)``.
    p0
        Initial state standard deviations ``p0,ii`` (4 for CV, 6 for CA), SI units of the state.
    p_d
        Detection probability P_D.
    p_te
        Existence probability ψ of a new (tentative) track.
    p11, p21
        Markov chain of existence, eq. (9): ψ⁻ = p11·ψ + p21·(1 − ψ).
    p_g
        Gate probability P_G (gate threshold γ = χ²₃⁻¹(P_G)). Fixed, not optimised.
    confirm_threshold, delete_threshold
        A tentative track is confirmed when ψ ≥ confirm_threshold (after at least one update);
        any track is deleted when ψ < delete_threshold.
    clutter_density
        Clutter density ρ in measurement space (per m · rad · m/s), or ``"nonparametric"``
        (ρ̂ = m̂ / V estimated per track and frame).
    max_tracks
        Track cap; beyond it the tracks with the lowest ψ are removed.
    association
        ``"jipda"`` (joint IPDA over tracks whose gates share measurements, the default) or
        ``"ipda"`` (independent IPDA per track); not optimised (docs/decisions/tracker-06).
    mode
        ``"paper"`` (the paper's one-point IPDA, :mod:`core.tracking.tracker`) or ``"room"``
        (people as groups of points, static points, ghosts: :mod:`core.tracking.room`).
    static_velocity … ghost_radius
        The room tracker's own parameters (rows of :mod:`core.tracking.space`, units there);
        ignored by the paper mode and left out of its JSON.
    """

    model: str = "cv"
    q_coeff: float = parameter("q_coeff").default
    r11: float = parameter("r11").default
    r22: float = parameter("r22").default
    r33: float = parameter("r33").default
    #: ``None`` takes the model's default (4 entries for CV, 6 for CA).
    p0: tuple[float, ...] | None = None
    p_d: float = parameter("p_d").default
    p_te: float = parameter("p_te").default
    p11: float = parameter("p11").default
    p21: float = parameter("p21").default
    p_g: float = 0.99
    confirm_threshold: float = 0.9
    delete_threshold: float = 0.1
    clutter_density: float | str = 0.0073
    max_tracks: int = 20
    association: str = "jipda"
    mode: str = "paper"
    static_velocity: float = parameter("static_velocity").default
    static_time: float = parameter("static_time").default
    body_sigma: float = parameter("body_sigma").default
    body_velocity_sigma: float = parameter("body_velocity_sigma").default
    alloc_points: float = parameter("alloc_points").default
    alloc_snr: float = parameter("alloc_snr").default
    alloc_distance: float = parameter("alloc_distance").default
    alloc_velocity: float = parameter("alloc_velocity").default
    ghost_gap: float = parameter("ghost_gap").default
    ghost_bearing: float = parameter("ghost_bearing").default
    ghost_velocity: float = parameter("ghost_velocity").default
    ghost_radius: float = parameter("ghost_radius").default

    def __post_init__(self) -> None:
        if self.model not in MODELS:
            raise InputError(f"model must be one of {MODELS}, got model={self.model!r}")
        if self.p0 is None:
            object.__setattr__(self, "p0", DEFAULT_P0[self.model])
        try:
            p0 = tuple(float(v) for v in self.p0)
        except (TypeError, ValueError):
            raise InputError(f"p0 must be a list of numbers, got p0={self.p0!r}") from None
        object.__setattr__(self, "p0", p0)
        n = STATE_DIM[self.model]
        if len(p0) != n:
            raise InputError(
                f"p0 must have {n} entries for model {self.model!r}, got {len(p0)}: p0={p0}"
            )
        lo, hi = VARIANCE_RANGE
        for i, v in enumerate(p0):
            if not (math.isfinite(v) and v > 0):
                raise InputError(f"p0[{i}] must be a positive finite number, got {v}")
            if not lo <= v <= hi:
                raise InputError(f"p0[{i}] must be in [{lo:g}, {hi:g}], got {v}")
        for name in ("q_coeff", "r11", "r22", "r33"):
            v = getattr(self, name)
            if not _is_number(v) or not (math.isfinite(v) and v > 0):
                raise InputError(f"{name} must be a positive finite number, got {name}={v!r}")
            if not lo <= v <= hi:
                raise InputError(f"{name} must be in [{lo:g}, {hi:g}], got {name}={v!r}")
        unit = ("p_d", "p_te", "p11", "p21", "p_g", "confirm_threshold", "delete_threshold")
        for name in unit:
            v = getattr(self, name)
            if not _is_number(v) or not (0.0 <= v <= 1.0):
                raise InputError(f"{name} must be in [0, 1], got {name}={v!r}")
        for name in ("p_d", "p_g"):
            if getattr(self, name) <= 0.0:
                raise InputError(f"{name} must be > 0, got {name}={getattr(self, name)!r}")
        if self.p_g >= 1.0:
            raise InputError(f"p_g must be < 1 (finite gate), got p_g={self.p_g!r}")
        if self.delete_threshold > self.confirm_threshold:
            raise InputError(
                "delete_threshold must not exceed confirm_threshold, got "
                f"delete_threshold={self.delete_threshold}, "
                f"confirm_threshold={self.confirm_threshold}"
            )
        rho = self.clutter_density
        if isinstance(rho, str):
            if rho != NONPARAMETRIC:
                raise InputError(
                    f"clutter_density must be a positive number or {NONPARAMETRIC!r}, "
                    f"got clutter_density={rho!r}"
                )
        elif not _is_number(rho) or not (math.isfinite(rho) and rho > 0):
            raise InputError(
                f"clutter_density must be a positive number or {NONPARAMETRIC!r}, "
                f"got clutter_density={rho!r}"
            )
        elif not CLUTTER_DENSITY_RANGE[0] <= rho <= CLUTTER_DENSITY_RANGE[1]:
            raise InputError(
                f"clutter_density must be in [{CLUTTER_DENSITY_RANGE[0]:g}, "
                f"{CLUTTER_DENSITY_RANGE[1]:g}], got clutter_density={rho!r}"
            )
        if self.association not in ASSOCIATIONS:
            raise InputError(
                f"association must be one of {ASSOCIATIONS}, got association={self.association!r}"
            )
        if self.mode not in MODES:
            raise InputError(f"mode must be one of {MODES}, got mode={self.mode!r}")
        for name in ROOM_NAMES:
            v, row = getattr(self, name), parameter(name)
            if not _is_number(v) or not (math.isfinite(v) and row.low <= v <= row.high):
                raise InputError(
                    f"{name} must be a number in [{row.low:g}, {row.high:g}], got {name}={v!r}"
                )
        if isinstance(self.max_tracks, bool) or not isinstance(self.max_tracks, int):
            raise InputError(f"max_tracks must be an integer, got max_tracks={self.max_tracks!r}")
        if not 1 <= self.max_tracks <= MAX_TRACKS:
            raise InputError(
                f"max_tracks must be in [1, {MAX_TRACKS}], got max_tracks={self.max_tracks}"
            )

    # ---- derived -----------------------------------------------------------------------------
    @property
    def state_dim(self) -> int:
        """Number of state components (4 for CV, 6 for CA)."""
        return STATE_DIM[self.model]

    @property
    def nonparametric(self) -> bool:
        """True when the clutter density is estimated per track and frame."""
        return self.clutter_density == NONPARAMETRIC

    # ---- construction ------------------------------------------------------------------------
    @classmethod
    def default(cls, model: str = "cv", mode: str = "paper") -> TrackerParams:
        """The default parameters of a motion model and mode (see docs/tracker.md)."""
        if model not in MODELS:
            raise InputError(f"model must be one of {MODELS}, got model={model!r}")
        return cls(model=model, p0=DEFAULT_P0[model], mode=mode)

    def to_dict(self) -> dict:
        """JSON-ready dict with the SPEC §6 keys (``p0`` as a list); the mode and the room
        tracker's keys only in the room mode (a paper-mode file is as it was)."""
        d = {f.name: getattr(self, f.name) for f in fields(self)}
        d["p0"] = list(self.p0)
        if self.mode == "paper":
            for name in ("mode", *ROOM_NAMES):
                del d[name]
        return d

    @classmethod
    def from_dict(cls, data: dict, source: str | None = None) -> TrackerParams:
        """Build from a SPEC §6 dict; missing keys take the defaults of the given model.

        ``p0`` may also be given as ``p0_00 … p0_55`` (the optimiser's names).
        """
        if not isinstance(data, dict):
            raise InputError("tracker parameters must be a JSON object", source)
        data = dict(data)
        p0_keys = sorted(k for k in data if k.startswith("p0_"))
        known = {f.name for f in fields(cls)}
        valid_p0 = set(P0_NAMES)
        unknown = sorted(k for k in data if k not in known and k not in valid_p0)
        if unknown:
            raise InputError(f"unknown tracker parameter keys {unknown}", source)
        model = data.get("model", "cv")
        if model not in MODELS:
            raise InputError(f"model must be one of {MODELS}, got model={model!r}", source)
        if p0_keys:
            if "p0" in data:
                raise InputError("give either p0 or p0_ii keys, not both", source)
            want = list(p0_names(model))
            if p0_keys != want:
                raise InputError(
                    f"p0 keys for model {model!r} must be {want}, got {p0_keys}", source
                )
            data["p0"] = [data.pop(k) for k in want]
        data.setdefault("p0", DEFAULT_P0[model])
        if "max_tracks" in data and isinstance(data["max_tracks"], float):
            if data["max_tracks"].is_integer():
                data["max_tracks"] = int(data["max_tracks"])
        try:
            return cls(**data)
        except InputError as exc:
            raise InputError(exc.message, source) from None
        except TypeError as exc:
            raise InputError(str(exc), source) from None

    @classmethod
    def load(cls, path: str | os.PathLike) -> TrackerParams:
        """Read a JSON parameter file; errors name the file (and line for syntax)."""
        data = read_json(path, what="parameter file")
        return cls.from_dict(data, source=str(path))

    def save(self, path: str | os.PathLike) -> Path:
        """Write atomically (temporary file in the same folder, then rename)."""
        return write_json_atomic(path, self.to_dict())


def _is_number(v: object) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)
