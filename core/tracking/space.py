"""The tracker's optimised parameters: one table, the paper's eq. (15), everything else derives.

One :class:`Parameter` row per optimised parameter: its name (the TrackerParams JSON key and the
Optuna parameter name), the paper's symbol, the SI unit, the closed search interval, the sampling
scale, the motion models that use it and its default. From this table derive
:class:`core.tracking.TrackerParams`' defaults, the GUI's sliders (labels with units), the Optuna
``suggest_float`` calls (:mod:`core.optimization.space`), the stability sweep's corners
(:mod:`core.tracking.stability`) and the flat ⇄ JSON key mapping. No other module lists the
parameters or their numbers.

Units. ``q_coeff`` scales ``Q = q_coeff · Γ Γᵀ`` (:mod:`core.tracking.models`) and is the variance
of the scalar process noise per axis, m²/s⁴ for both models: for CV (Γ = [T²/2, T]ᵀ, Bar-Shalom
§6.3.2) the noise is the acceleration, constant over a frame; for CA (Γ = [T²/2, T, 1]ᵀ, §6.3.3)
it is the acceleration *increment* over one frame (so not a jerk variance in m²/s⁶; a jerk of
spectral density S gives roughly S·T per frame). ``r11, r22, r33`` are measurement standard
deviations of range (m), azimuth (rad) and radial velocity (m/s); ``p0_ii`` are the initial state
standard deviations in the state's units; the four probabilities have no unit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from core.errors import InputError

__all__ = [
    "MODELS",
    "GTRACK",
    "GTRACK_SPACE",
    "GTRACK_LEGACY_NAMES",
    "MODES",
    "STATE_DIM",
    "Parameter",
    "SEARCH_SPACE",
    "P0_NAMES",
    "ROOM_NAMES",
    "check_model",
    "check_tuned",
    "check_mode",
    "parameter",
    "search_space",
    "p0_names",
    "defaults",
    "tracker_params_dict",
    "flat_params",
]

#: Motion models: constant velocity and constant acceleration.
MODELS = ("cv", "ca")
#: The key of TI's tracker's table (:data:`GTRACK_SPACE`), beside the motion models.
GTRACK = "gtrack"
#: Tracker modes: the paper's one-point IPDA, and the tracker for real rooms (groups of points,
#: zones, static points, ghosts; :mod:`core.tracking.room`).
MODES = ("paper", "room")
#: State dimension per motion model: CV [x, y, vx, vy], CA [x, y, vx, vy, ax, ay].
STATE_DIM = {"cv": 4, "ca": 6}


@dataclass(frozen=True, slots=True, kw_only=True)
class Parameter:
    """One optimised tracker parameter (one row of eq. 15).

    Attributes
    ----------
    name
        TrackerParams JSON key and Optuna parameter name; the initial standard deviations are
        ``p0_ii`` (entry ``i`` of the ``p0`` list).
    symbol
        As the paper writes it (plain text: ``r11``, ``p0,00``, ``P_D``).
    meaning
        A few words for labels (``range σ``).
    unit
        SI unit (``""`` for probabilities).
    low, high
        Closed search interval of eq. (15).
    log
        Sampled on a log scale (the interval spans a decade or more).
    models
        The motion models that use it (``("gtrack",)``: a row of gtrack's table).
    modes
        The tracker modes that use it (the paper's rows: both; the room tracker's own: room).
    default
        The default value (docs/decisions/tracker-03), inside ``[low, high]``.
    integer
        Takes whole numbers only (gtrack's counters and point threshold).
    """

    name: str
    symbol: str
    meaning: str
    unit: str
    low: float
    high: float
    log: bool
    models: tuple[str, ...] = MODELS
    modes: tuple[str, ...] = MODES
    default: float
    integer: bool = False

    def __post_init__(self) -> None:
        if not self.low < self.high:
            raise InputError(f"{self.name}: low must be < high, got {self.low}, {self.high}")
        if self.log and self.low <= 0:
            raise InputError(f"{self.name}: a log scale needs low > 0, got {self.low}")
        if not self.models or not set(self.models) <= {*MODELS, GTRACK}:
            raise InputError(
                f"{self.name}: models must be some of {(*MODELS, GTRACK)}, got {self.models}"
            )
        if not self.modes or not set(self.modes) <= set(MODES):
            raise InputError(f"{self.name}: modes must be some of {MODES}, got {self.modes}")
        if not (math.isfinite(self.default) and self.low <= self.default <= self.high):
            raise InputError(
                f"{self.name}: default must lie in [{self.low}, {self.high}], got {self.default}"
            )

    @property
    def label(self) -> str:
        """``symbol meaning [unit]`` for sliders, tables and plots."""
        text = f"{self.symbol} {self.meaning}"
        return f"{text} [{self.unit}]" if self.unit else text


#: eq. (15) of the paper, in the order the paper lists them (the Optuna suggest order: keep it).
# fmt: off
SEARCH_SPACE: tuple[Parameter, ...] = (
    # q_coeff: CV acceleration variance, CA per-frame acceleration-increment variance (see above)
    Parameter(name="q_coeff", symbol="q_coeff", meaning="process noise", unit="m²/s⁴",
              low=0.1, high=30.0, log=True, default=2.0),
    Parameter(name="r11", symbol="r11", meaning="range σ", unit="m",
              low=0.01, high=0.5, log=True, default=0.05),
    Parameter(name="r22", symbol="r22", meaning="azimuth σ", unit="rad",
              low=0.01, high=0.2, log=True, default=0.03),
    Parameter(name="r33", symbol="r33", meaning="radial velocity σ", unit="m/s",
              low=0.1, high=3.0, log=True, default=0.3),
    Parameter(name="p0_00", symbol="p0,00", meaning="initial x σ", unit="m",
              low=0.1, high=10.0, log=True, default=0.3),
    Parameter(name="p0_11", symbol="p0,11", meaning="initial y σ", unit="m",
              low=0.1, high=10.0, log=True, default=0.3),
    Parameter(name="p0_22", symbol="p0,22", meaning="initial vx σ", unit="m/s",
              low=0.01, high=10.0, log=True, default=1.0),
    Parameter(name="p0_33", symbol="p0,33", meaning="initial vy σ", unit="m/s",
              low=0.01, high=10.0, log=True, default=1.0),
    Parameter(name="p0_44", symbol="p0,44", meaning="initial ax σ", unit="m/s²",
              low=0.001, high=10.0, log=True, models=("ca",), default=0.5),
    Parameter(name="p0_55", symbol="p0,55", meaning="initial ay σ", unit="m/s²",
              low=0.001, high=10.0, log=True, models=("ca",), default=0.5),
    Parameter(name="p_d", symbol="P_D", meaning="detection probability", unit="",
              low=0.8, high=0.99, log=False, default=0.9),
    Parameter(name="p_te", symbol="P_te", meaning="initial existence ψ", unit="",
              low=0.2, high=1.0, log=False, default=0.2),
    Parameter(name="p11", symbol="p11", meaning="existence survival", unit="",
              low=0.7, high=1.0, log=False, default=0.98),
    Parameter(name="p21", symbol="p21", meaning="existence appearance", unit="",
              low=0.0, high=0.4, log=False, default=0.0),
    # the room tracker's own rows (docs/tracker.md "Tracking in rooms"; defaults chosen on TI's
    # people-counting recording and two walking recordings, a third held out); appended: the
    # paper's order is kept
    Parameter(name="static_velocity", symbol="v_static", meaning="zero-Doppler limit",
              unit="m/s", low=0.001, high=0.3, log=True, modes=("room",), default=0.02),
    Parameter(name="static_time", symbol="t_static", meaning="time kept on static points",
              unit="s", low=0.5, high=600.0, log=True, modes=("room",), default=60.0),
    Parameter(name="body_sigma", symbol="σ_body", meaning="body spread", unit="m",
              low=0.05, high=1.0, log=True, modes=("room",), default=0.5),
    Parameter(name="body_velocity_sigma", symbol="σ_vbody", meaning="body velocity spread",
              unit="m/s", low=0.05, high=2.0, log=True, modes=("room",), default=1.0),
    Parameter(name="alloc_points", symbol="n_alloc", meaning="points to start a track",
              unit="", low=1.0, high=30.0, log=True, modes=("room",), default=18.0),
    Parameter(name="alloc_snr", symbol="SNR_alloc", meaning="SNR sum to start a track",
              unit="dB", low=1.0, high=1000.0, log=True, modes=("room",), default=60.0),
    Parameter(name="alloc_distance", symbol="d_alloc", meaning="group radius", unit="m",
              low=0.1, high=2.0, log=True, modes=("room",), default=0.9),
    Parameter(name="alloc_velocity", symbol="v_alloc", meaning="group velocity spread",
              unit="m/s", low=0.05, high=3.0, log=True, modes=("room",), default=1.0),
    Parameter(name="ghost_gap", symbol="Δr_ghost", meaning="ghost range gap", unit="m",
              low=0.1, high=3.0, log=True, modes=("room",), default=0.5),
    Parameter(name="ghost_bearing", symbol="Δaz_ghost", meaning="ghost bearing", unit="rad",
              low=0.02, high=0.8, log=True, modes=("room",), default=0.5),
    Parameter(name="ghost_velocity", symbol="Δv_ghost", meaning="ghost velocity match",
              unit="m/s", low=0.05, high=2.0, log=True, modes=("room",), default=1.5),
    # used only where the room's walls are known (Zones.walls): a tentative track this close to
    # a confirmed track's predicted wall ghost is a ghost candidate (default: tracker-09)
    Parameter(name="ghost_radius", symbol="r_ghost", meaning="predicted-ghost match radius",
              unit="m", low=0.05, high=2.0, log=True, modes=("room",), default=1.0),
)
# fmt: on


def _g(name: str, meaning: str, unit: str, low: float, high: float, default: float, *,
       log: bool = False, integer: bool = False) -> Parameter:  # fmt: skip
    return Parameter(name=name, symbol=name, meaning=meaning, unit=unit, low=low, high=high,
                     log=log, models=(GTRACK,), default=default, integer=integer)  # fmt: skip


#: gtrack's tuned parameters (core.tracking.gtrack.GtrackParams fields; the cfg lines in
#: docs/tracking/gtrack.md). Defaults: TI's published people-counting lines. TI documents the
#: defaults and meanings, not search intervals: the intervals are RadarTune's, a decade or more
#: around TI's default where TI's tuning advice moves the value.
# fmt: off
GTRACK_SPACE: tuple[Parameter, ...] = (
    _g("gating_gain", "gating gain", "", 1.0, 10.0, 3.0, log=True),
    _g("gating_width_m", "gating width limit", "m", 0.5, 4.0, 2.0),
    _g("gating_depth_m", "gating depth limit", "m", 0.5, 4.0, 2.0),
    _g("gating_height_m", "gating height limit", "m", 0.5, 4.0, 2.0),
    _g("gating_velocity_mps", "gating velocity limit", "m/s", 0.5, 20.0, 4.0, log=True),
    _g("det2act", "DETECT to ACTIVE hits", "", 1, 20, 3, integer=True),
    _g("det2free", "DETECT to FREE misses", "", 1, 20, 3, integer=True),
    _g("active2free", "ACTIVE to FREE misses", "", 1, 100, 12, log=True, integer=True),
    _g("static2free", "static to FREE misses", "", 10, 2000, 500, log=True, integer=True),
    _g("exit2free", "exit to FREE misses", "", 1, 50, 5, log=True, integer=True),
    _g("sleep2free", "sleep to FREE frames", "", 50, 10000, 6000, log=True, integer=True),
    _g("snr_thre", "allocation SNR sum", "", 5.0, 1000.0, 40.0, log=True),
    _g("snr_thre_obscured", "obscured allocation SNR sum", "", 10.0, 2000.0, 100.0, log=True),
    _g("velocity_thre_mps", "allocation radial velocity", "m/s", 0.0, 1.0, 0.1),
    _g("points_thre", "allocation points", "", 2, 50, 20, integer=True),
    _g("max_distance_thre_m2", "allocation squared distance", "m²", 0.05, 4.0, 0.5, log=True),
    _g("max_vel_thre_mps", "allocation velocity spread", "m/s", 0.2, 20.0, 20.0,
       log=True),
    _g("max_accel_x_mps2", "maximum acceleration x", "m/s²", 0.01, 10.0, 0.1, log=True),
    _g("max_accel_y_mps2", "maximum acceleration y", "m/s²", 0.01, 10.0, 0.1, log=True),
    _g("max_accel_z_mps2", "maximum acceleration z", "m/s²", 0.01, 10.0, 0.1, log=True),
)
# fmt: on

#: Earlier names of the allocation fields (read from older JSON files; the fields now carry
#: TI's allocationParam names, apart from the room tracker's own allocation rows).
GTRACK_LEGACY_NAMES = {
    "alloc_snr": "snr_thre",
    "alloc_snr_obscured": "snr_thre_obscured",
    "alloc_velocity_mps": "velocity_thre_mps",
    "alloc_points": "points_thre",
    "alloc_distance_m2": "max_distance_thre_m2",
    "alloc_velocity_spread_mps": "max_vel_thre_mps",
}

_BY_NAME = {p.name: p for p in SEARCH_SPACE}

#: The initial standard deviations, in state order (``p0_ii`` is entry ``i`` of ``p0``).
P0_NAMES: tuple[str, ...] = tuple(p.name for p in SEARCH_SPACE if p.name.startswith("p0_"))


def check_model(model: str) -> str:
    """Return ``model`` if it is a known motion model, else raise :class:`InputError`."""
    if model not in MODELS:
        raise InputError(f"model must be one of {', '.join(MODELS)}, got {model!r}")
    return model


def check_tuned(model: str) -> str:
    """``model`` if it names a table of the search space (a motion model or ``"gtrack"``)."""
    if model != GTRACK:
        check_model(model)
    return model


def parameter(name: str) -> Parameter:
    """The row of ``name``; :class:`InputError` naming it if it is not optimised."""
    try:
        return _BY_NAME[name]
    except KeyError:
        raise InputError(f"{name!r} is not an optimised tracker parameter") from None


def check_mode(mode: str) -> str:
    """Return ``mode`` if it is a known tracker mode, else raise :class:`InputError`."""
    if mode not in MODES:
        raise InputError(f"mode must be one of {', '.join(MODES)}, got {mode!r}")
    return mode


def search_space(model: str, mode: str = "paper") -> tuple[Parameter, ...]:
    """The rows ``model`` uses in ``mode``, in table order (paper CV: 12, CA: 14; room: + 11;
    ``"gtrack"``: gtrack's 20, whatever the mode)."""
    if model == GTRACK:
        return GTRACK_SPACE
    check_model(model)
    check_mode(mode)
    return tuple(p for p in SEARCH_SPACE if model in p.models and mode in p.modes)


#: The room tracker's own parameters (table order).
ROOM_NAMES: tuple[str, ...] = tuple(p.name for p in SEARCH_SPACE if p.modes == ("room",))


def p0_names(model: str) -> tuple[str, ...]:
    """``p0_ii`` names of ``model``, in state order (one per state component)."""
    return tuple(p.name for p in search_space(model) if p.name in P0_NAMES)


def defaults(model: str, mode: str = "paper") -> dict[str, float]:
    """Default value of every parameter ``model`` uses in ``mode``, by name (flat: ``p0_ii``)."""
    return {p.name: p.default for p in search_space(model, mode)}


def tracker_params_dict(flat: dict[str, Any], model: str, mode: str = "paper") -> dict[str, Any]:
    """Flat parameters (by table name) → TrackerParams JSON (SPEC §6): ``p0_ii`` become ``p0``.

    Keys not in the search space (``p_g``, thresholds, clutter density) are left out so that
    they take the TrackerParams defaults. In the room mode the JSON carries ``"mode": "room"``
    and the room rows; a paper-mode JSON is as it was (no ``mode`` key).
    """
    names = [b.name for b in search_space(model, mode)]
    missing = [n for n in names if n not in flat]
    if missing:
        raise InputError(f"parameters missing for model {model}: {', '.join(missing)}")
    if model == GTRACK:  # GtrackParams JSON: the rows by name, counters as integers
        return {
            b.name: int(round(float(flat[b.name]))) if b.integer else float(flat[b.name])
            for b in search_space(model)
        }
    out: dict[str, Any] = {"model": model}
    if mode == "room":
        out["mode"] = mode
    for n in names:
        if n not in P0_NAMES:
            out[n] = float(flat[n])
    out["p0"] = [float(flat[p]) for p in p0_names(model)]
    return out


def flat_params(params: dict[str, Any]) -> dict[str, float]:
    """TrackerParams JSON → flat parameters by table name (inverse of :func:`tracker_params_dict`).

    Used to enqueue known parameters in a study and to put a parameter file on the app's
    sliders; values outside the bounds are an error naming the field.
    """
    tracker_names = {b.name for b in SEARCH_SPACE}
    gtrack_only = [b.name for b in GTRACK_SPACE if b.name not in tracker_names]
    # a GtrackParams JSON: no model or mode key, and a name only gtrack's table has
    if "model" not in params and "mode" not in params and any(n in params for n in gtrack_only):
        params = {GTRACK_LEGACY_NAMES.get(k, k): v for k, v in params.items()}
        flat_g: dict[str, float] = {}
        for b in search_space(GTRACK):
            if b.name not in params:
                raise InputError(f"parameter {b.name} missing")
            value = float(params[b.name])
            if not b.low <= value <= b.high:
                raise InputError(f"{b.name} must be in [{b.low}, {b.high}], got {value}")
            flat_g[b.name] = value
        return flat_g
    model = check_model(str(params.get("model", "cv")))
    mode = check_mode(str(params.get("mode", "paper")))
    p0 = list(params.get("p0", []))
    n_p0 = STATE_DIM[model]
    if len(p0) != n_p0:
        raise InputError(f"p0 must have {n_p0} entries for model {model}, got {len(p0)}")
    flat: dict[str, float] = {}
    for b in search_space(model, mode):
        if b.name in P0_NAMES:
            value = float(p0[P0_NAMES.index(b.name)])
        elif b.name in params:
            value = float(params[b.name])
        else:
            raise InputError(f"parameter {b.name} missing")
        if not b.low <= value <= b.high:
            raise InputError(f"{b.name} must be in [{b.low}, {b.high}], got {value}")
        flat[b.name] = value
    return flat
