"""Walking person model: 17 articulated segments driven by a global gait model.

The gait follows R. Boulic, N. Magnenat-Thalmann and D. Thalmann, "A global human walking model
with real-time kinematic personification", The Visual Computer 6 (1990) 344-358 (the model
behind MATLAB's ``backscatterPedestrian`` and V. C. Chen, *The Micro-Doppler Effect in Radar*,
Artech House 2011, ch. 4):

- the *relative velocity* ``RV = v / H_t`` (``H_t``: height of the hip joint above the floor,
  "height of the thigh"), the cycle duration ``D_c = 1.346 / sqrt(RV)`` s, the relative stride
  ``RL_c = 1.346 sqrt(RV)`` (stride ``S = v D_c``) and the support duration
  ``D_s = 0.752 D_c - 0.143`` s (Boulic's normalisation);
- the pelvis trajectories: vertical translation twice a cycle with amplitude ``0.015 RV H_t``
  (lowest in double support), lateral sway once a cycle toward the stance leg with amplitude
  ``0.128 RV (1 - RV) H_t`` below ``RV = 0.5`` and ``0.032 H_t`` above, forward/backward
  translation twice a cycle (``0.021 H_t``), pelvis torsion ``+-4 deg * RV`` about the vertical
  (the hip of the leading leg forward) and an opposite thorax torsion;
- shoulder flexion swinging opposite the same-side leg with an amplitude growing linearly with
  ``RV`` (``10 deg * RV``), elbow flexion ``15 deg`` plus up to ``15 deg * RV / 1.5`` with the arm
  forward.

What is approximated (docs/decisions/scene-06-walking-body.md):

- Boulic's joint curves are tables of control points normalised by ``RV``; here the *shapes*
  are smooth periodic functions (single harmonics for the pelvis, shoulder and elbow; the
  vertical translation at twice the cycle frequency).
- The legs are not driven by Boulic's hip/knee/ankle flexion tables (approximated, they slide the
  stance foot over the floor). The ankle follows the stance and swing phases that Boulic's
  timing sets: in stance the foot is flat on the floor (zero velocity) and, after heel-off at
  60 % of stance, rolls over the toe up to ``0.6 rad * RV / 1.5`` (heel rise); in swing the
  ankle moves forward on a cubic Hermite path (end velocities those of the floor) with a
  clearance arc. The knee comes from two-link inverse kinematics (knee forward), which keeps the
  thigh and shank lengths exact and gives the published shape of hip flexion (nearly linear
  extension in stance, flexion in swing) and knee flexion (a large peak in swing). Where the
  pelvis is too high for the leg to reach the stance ankle (long strides) the ankle is pulled
  toward the hip along the leg (the foot lifts and slides a few cm at the ends of stance).
- No pelvis list or tilt, no hands; the legs swing in planes parallel to the walking direction.
- Standing (speed -> 0): every amplitude scales with ``RV`` and the stride with ``sqrt(RV)``, so
  the body comes to rest continuously; a standing person sways (the body above the ankles
  ``+-1 cm`` at ``0.2 Hz``, the legs following by inverse kinematics) and breathes (chest
  ``+-3 mm`` at ``0.25 Hz``), both fading in as the speed falls below 0.3 m/s.
- Sitting (a ``sit`` stop, the trajectory's ``seated`` frames): the body sits down over the first
  :data:`SIT_TRANSITION_S` of the hold and stands up over its last (:func:`sit_transition`; each
  joint moves from the standing to the seated pose along a straight line, the seated fraction a
  smoothstep ``3 s^2 - 2 s^3`` of the elapsed share ``s``, so the motion starts and ends at rest
  and its velocity enters the Doppler), on a seat at knee height: the hip joints at ``0.285 H``
  (0.50 m for 1.75 m), the thighs horizontal forward, the shins vertical to the ankles at
  ``0.039 H``, the feet flat; the torso, neck and head upright above the hips (the head's
  centre at ``(0.285 - 0.530 + 0.935) H = 0.690 H``, 1.21 m; :func:`seated_joints`), the upper
  arms hanging and the forearms forward, horizontal. The body above the seat sways as a standing one
  does (``+-1 cm`` at ``0.2 Hz``; pelvis and legs still) and the chest breathes as standing.

Segment lengths are fractions of the body height (Drillis & Contini 1966, as tabulated in D. A.
Winter, *Biomechanics and Motor Control of Human Movement*, 4th ed., Wiley 2009, fig. 4.1):
hip joint 0.530 H, knee 0.285 H, ankle 0.039 H above the floor, shoulder 0.818 H, chin 0.870 H,
elbow 0.630 H, wrist 0.485 H, shoulder width 0.259 H, hip width 0.191 H, foot length 0.152 H.

Each segment is one scatterer at its centre. Its share of the person's RCS (linear power) is
proportional to its frontal projected area (length x width, widths typical adult values as
fractions of H), the area-weighting of body parts used in the point-scatterer walking-human
radar models (e.g. P. van Dorp and F. C. A. Groen, "Human walking estimation with radar",
IEE Proc. Radar Sonar Navig. 150 (2003) 356-365); the shares are fixed (not aspect dependent)
so that the segments' powers add up to the frame's eq. (5) draw of the person's RCS.

Heights: the chain is three-dimensional (scatterers have z, the IWR6843ISK array measures
elevation), so the segments sit at their real heights above the floor minus the radar's mounting
height :data:`RADAR_HEIGHT_M` (no scene field yet; boresight horizontal, no tilt).

Coordinates: body frame ``(u, w, z)`` (forward along the walk, to the left, up from the floor);
world ``x, y`` from the trajectory and the heading ``h = atan2(vx, vy)``:
``x = x_p + u sin h - w cos h``, ``y = y_p + u cos h + w sin h``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

#: Duration of sitting down and of standing up (s): healthy adults take about 11-15 s for five
#: sit-to-stand-to-sit cycles (R. W. Bohannon, "Reference values for the five-repetition
#: sit-to-stand test", Percept. Mot. Skills 103 (2006) 215-222), i.e. about 1.1-1.5 s a
#: transition; 1 s, shortened to half the hold for short holds.
SIT_TRANSITION_S = 1.0
#: Height of the radar above the floor (m): the segments' z is their height minus this.
RADAR_HEIGHT_M = 1.0
#: Default body height (m); the accepted range is core.limits.PERSON_HEIGHT_RANGE_M.
DEFAULT_HEIGHT_M = 1.75
#: Highest relative velocity RV = v / H_t of the walking model (above it people run).
MAX_RELATIVE_VELOCITY = 2.5
#: Reference relative velocity: amplitudes quoted at RV = 1.5 (about 1.4 m/s for 1.75 m).
RV_REF = 1.5
#: Boulic's cycle-duration constant: D_c = 1.346 / sqrt(RV) s.
CYCLE_CONSTANT_S = 1.346

# body proportions (fractions of H, Drillis & Contini via Winter 2009 fig. 4.1)
HIP_Z, KNEE_Z, ANKLE_Z = 0.530, 0.285, 0.039
SHOULDER_Z, CHIN_Z = 0.818, 0.870
ELBOW_Z, WRIST_Z = 0.630, 0.485
SHOULDER_WIDTH, HIP_WIDTH, FOOT_LENGTH = 0.259, 0.191, 0.152
#: ankle to the toe pivot (metatarsal heads) along the floor, fraction of H
TOE_PIVOT = 0.6 * FOOT_LENGTH

#: Segments: name and (length, width) as fractions of H for the RCS share (frontal area).
SEGMENTS = (
    ("head", 1.0 - CHIN_Z, 0.090),
    ("neck", CHIN_Z - SHOULDER_Z - 0.0, 0.060),
    ("torso", SHOULDER_Z - HIP_Z, 0.170),
    ("shoulder_r", SHOULDER_WIDTH / 2, 0.050),
    ("shoulder_l", SHOULDER_WIDTH / 2, 0.050),
    ("upper_arm_r", SHOULDER_Z - ELBOW_Z, 0.050),
    ("upper_arm_l", SHOULDER_Z - ELBOW_Z, 0.050),
    ("lower_arm_r", ELBOW_Z - WRIST_Z, 0.040),
    ("lower_arm_l", ELBOW_Z - WRIST_Z, 0.040),
    ("hip_r", HIP_WIDTH / 2, 0.080),
    ("hip_l", HIP_WIDTH / 2, 0.080),
    ("upper_leg_r", HIP_Z - KNEE_Z, 0.085),
    ("upper_leg_l", HIP_Z - KNEE_Z, 0.085),
    ("lower_leg_r", KNEE_Z - ANKLE_Z, 0.060),
    ("lower_leg_l", KNEE_Z - ANKLE_Z, 0.060),
    ("foot_r", FOOT_LENGTH, 0.040),
    ("foot_l", FOOT_LENGTH, 0.040),
)
SEGMENT_NAMES = tuple(s[0] for s in SEGMENTS)
N_SEGMENTS = len(SEGMENTS)
_AREA = np.array([length * width for _, length, width in SEGMENTS])
#: Share of the person's RCS (linear power) per segment, proportional to the frontal area; sums
#: to 1.
RCS_SHARES = _AREA / _AREA.sum()

#: Standing: sway amplitude of the pelvis and upper body (m),
#: sway frequency (Hz), breathing chest amplitude (m) and rate (Hz), speed below which they fade
#: in (m/s).
SWAY_AMPLITUDE_M, SWAY_HZ = 0.01, 0.2
BREATH_AMPLITUDE_M, BREATH_HZ = 0.003, 0.25
STANDING_SPEED_MPS = 0.3
#: Time step of the central difference giving segment velocities (s).
VELOCITY_STEP_S = 1e-3


def thigh_height_m(height_m: float) -> float:
    """``H_t``: height of the hip joint above the floor (m), Boulic's "height of the thigh"."""
    return HIP_Z * height_m


def max_walking_speed_mps(height_m: float) -> float:
    """The fastest walk of the model for a body of ``height_m``: ``RV_max H_t`` (m/s)."""
    return MAX_RELATIVE_VELOCITY * thigh_height_m(height_m)


def cycle_duration_s(speed_mps: np.ndarray, height_m: float) -> np.ndarray:
    """Boulic's gait cycle ``D_c = 1.346 / sqrt(RV)`` s, ``RV = v / H_t`` (inf when standing)."""
    rv = np.asarray(speed_mps, dtype=np.float64) / thigh_height_m(height_m)
    with np.errstate(divide="ignore"):
        # D_c = 1.346 / sqrt(RV)
        return CYCLE_CONSTANT_S / np.sqrt(rv)


def gait_phase(
    t_s: np.ndarray, speed_mps: np.ndarray, height_m: float, phase0: float
) -> np.ndarray:
    """Gait phase (cycles) per frame: ``phi(t) = phi0 + integral of 1 / D_c(v(t)) dt``.

    Parameters
    ----------
    t_s, speed_mps
        Shape ``(F,)``: frame times (s) and the person's speed (m/s).
    height_m
        Body height (m).
    phase0
        Phase at the first frame, cycles (0 = right heel strike).

    Returns
    -------
    numpy.ndarray
        Shape ``(F,)``, cycles (not wrapped).
    """
    rate = 1.0 / cycle_duration_s(speed_mps, height_m)  # 1/D_c, 0 when standing
    out = np.empty(len(t_s))
    if len(t_s):
        out[0] = phase0
        # trapezoid rule
        np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(t_s), out=out[1:])
        out[1:] += phase0
    return out


def default_gait_phase(seed: int) -> float:
    """A person's phase at the first frame when its JSON gives none, from its seed (cycles)."""
    return float(np.random.default_rng(np.random.SeedSequence([int(seed), 13])).random())


def _hermite(p0: Any, p1: Any, m0: Any, m1: Any, s: np.ndarray) -> np.ndarray:
    """Cubic Hermite ``p(s)`` on ``s`` in [0, 1] with end slopes ``m0, m1`` (per unit s)."""
    s2, s3 = s * s, s * s * s
    return (
        (2 * s3 - 3 * s2 + 1) * p0
        + (s3 - 2 * s2 + s) * m0
        + (-2 * s3 + 3 * s2) * p1
        + (s3 - s2) * m1
    )


def _stance_geometry(
    stance_len: np.ndarray, rho_max: np.ndarray, hip_fwd: np.ndarray, height_m: float
) -> tuple[np.ndarray, np.ndarray]:
    """Where the stance is placed and how low the pelvis must go for the leg to reach it.

    The foot is flat from heel strike (ankle ``x0`` ahead of the pelvis centre) and rolls over
    the toe at the end of stance (the ankle moves forward by ``r_u`` and up by ``r_z``); the
    pelvis torsion brings the hip ``hip_fwd`` forward at heel strike and about as far back at
    toe-off. ``x0`` balances the front and rear reach, ``Z`` is the hip's height above the
    ankle that reaches both: ``x0^2 + Z^2 = L^2`` and ``(S' - x0)^2 + (Z - r_z)^2 = L^2``.
    """
    h = height_m
    leg = (HIP_Z - ANKLE_Z) * h * 0.999
    h_a, l_t = ANKLE_Z * h, TOE_PIVOT * h
    r_u = l_t * (1 - np.cos(rho_max)) + h_a * np.sin(rho_max)
    r_z = l_t * np.sin(rho_max) + h_a * np.cos(rho_max) - h_a
    s_eff = np.maximum(stance_len - r_u - 1.7 * hip_fwd, 0.0)
    z = np.full_like(s_eff, leg)
    x0 = np.zeros_like(s_eff)
    ok = s_eff > 1e-6
    for _ in range(4):  # fixed point: x0 = (S'^2 + r_z^2 - 2 Z r_z) / (2 S')
        x0 = np.where(ok, (s_eff**2 + r_z**2 - 2 * z * r_z) / (2 * np.where(ok, s_eff, 1.0)), 0.0)
        x0 = np.clip(x0, 0.0, 0.9 * leg)
        z = np.sqrt(leg**2 - x0**2)
    return x0 + hip_fwd, z


def _ankle_path(
    psi: np.ndarray,
    v: np.ndarray,
    dc: np.ndarray,
    beta: np.ndarray,
    rho_max: np.ndarray,
    x0: np.ndarray,
    rv_w: np.ndarray,
    height_m: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Ankle ``(u, z)`` and the ankle->toe vector of one leg in the body frame's (u, z) plane.

    ``psi``: the leg's phase in cycles, ``[0, 1)`` (0 = its heel strike); ``x0``: the ankle at
    heel strike, ahead of the pelvis centre (:func:`_stance_geometry`); all arrays ``(F,)``.
    """
    h = height_m
    h_a, l_t = ANKLE_Z * h, TOE_PIVOT * h
    with np.errstate(invalid="ignore"):  # standing: v * inf
        # floor travelled under the body in stance
        stance_len = np.where(np.isfinite(dc), v * beta * dc, 0.0)
    in_stance = psi < beta
    tau = np.where(in_stance, psi / beta, 0.0)
    # stance: the toe pivot moves back with the floor; after heel-off the foot rolls over it
    toe_u = x0 + l_t - stance_len * tau
    roll = np.clip((tau - 0.6) / 0.4, 0.0, 1.0)
    rho_st = rho_max * roll * roll
    # toe-off state (tau = 1)
    toe_off_toe = x0 + l_t - stance_len
    # swing: the ankle from toe-off to the next heel strike, the foot unrolling
    sw = np.where(in_stance, 0.0, (psi - beta) / (1.0 - beta))
    t_sw = (1.0 - beta) * dc  # swing duration, s
    t_sw = np.where(np.isfinite(t_sw), t_sw, 0.0)
    a_off_u = toe_off_toe - l_t * np.cos(rho_max) + h_a * np.sin(rho_max)
    a_off_z = l_t * np.sin(rho_max) + h_a * np.cos(rho_max)
    # end slopes: the floor's velocity (-v) in the body frame at toe-off, per unit of swing;
    # at heel strike 0.3 of it (a little swing retraction, no overshoot out of reach)
    m = -v * t_sw
    a_sw_u = _hermite(a_off_u, x0, m, 0.3 * m, sw)
    clearance = 0.05 * h * rv_w
    a_sw_z = _hermite(a_off_z, h_a, 0.0, 0.0, sw) + clearance * np.sin(np.pi * sw) ** 2
    rho_sw = rho_max * (1.0 - sw) ** 2
    rho = np.where(in_stance, rho_st, rho_sw)
    c, s = np.cos(rho), np.sin(rho)
    # ankle = toe + R(-rho) (-l_t, h_a) in stance
    a_st_u = toe_u - l_t * c + h_a * s
    a_st_z = l_t * s + h_a * c
    ank_u = np.where(in_stance, a_st_u, a_sw_u)
    ank_z = np.where(in_stance, a_st_z, a_sw_z)
    # foot: ankle -> toe = R(-rho) (l_t, -h_a)
    foot_u = l_t * c - h_a * s
    foot_z = -l_t * s - h_a * c
    return ank_u, ank_z, foot_u, foot_z


def _knee(hip: np.ndarray, ankle: np.ndarray, height_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Two-link inverse kinematics in 3-D, the knee forward.

    ``hip``, ``ankle``: ``(F, 3)`` in the body frame. Returns the knee and the reachable ankle
    (pulled toward the hip along the leg where it is out of reach), ``(F, 3)`` each; thigh and
    shank keep their lengths exactly.
    """
    h = height_m
    l_thigh, l_shank = (HIP_Z - KNEE_Z) * h, (KNEE_Z - ANKLE_Z) * h
    dv = ankle - hip
    d = np.linalg.norm(dv, axis=-1)
    e = dv / d[:, None]
    d_max = (l_thigh + l_shank) * (1 - 1e-3)
    d_min = abs(l_thigh - l_shank) + 1e-6 * h
    # smooth saturation below d_max (5 mm softplus): no kink where the leg straightens
    k = 0.005
    d_c = np.maximum(d_max - k * np.logaddexp(0.0, (d_max - d) / k), d_min)
    # law of cosines: angle between the thigh and the hip-ankle line
    delta = np.arccos(np.clip((l_thigh**2 + d_c**2 - l_shank**2) / (2 * l_thigh * d_c), -1.0, 1.0))
    # the knee bends toward the walking direction: f = u - (u . e) e, normalised
    f = np.zeros_like(e)
    f[:, 0] = 1.0
    f -= e[:, 0:1] * e
    f /= np.linalg.norm(f, axis=-1, keepdims=True)
    knee = hip + l_thigh * (np.cos(delta)[:, None] * e + np.sin(delta)[:, None] * f)
    return knee, hip + d_c[:, None] * e


def body_frame_joints(
    phase: np.ndarray,
    speed_mps: np.ndarray,
    t_s: np.ndarray,
    height_m: float,
    seated: np.ndarray | None = None,
) -> dict[str, np.ndarray]:
    """Joint positions in the body frame ``(u, w, z)`` (z above the floor).

    Parameters
    ----------
    phase
        Shape ``(F,)``: gait phase, cycles (:func:`gait_phase`).
    speed_mps
        Shape ``(F,)``: walking speed, m/s.
    t_s
        Shape ``(F,)``: time, s (sway and breathing).
    height_m
        Body height, m.
    seated
        ``None``, shape ``(F,)`` bool (frames where the body sits, :func:`seated_joints`), or
        shape ``(F,)`` float in ``[0, 1]``: the seated fraction (each joint at ``(1 - f)`` times
        its standing place plus ``f`` times its seated place; :func:`sit_transition`).

    Returns
    -------
    dict
        Joint name (``pelvis``, ``neck_base``, ``chin``, ``head_top``, ``shoulder_r``,
        ``elbow_r``, ``wrist_r``, ``hip_r``, ``knee_r``, ``ankle_r``, ``toe_r`` and the left
        ones) -> shape ``(F, 3)``, m.
    """
    h = float(height_m)
    phi = np.mod(np.asarray(phase, dtype=np.float64), 1.0)
    v = np.asarray(speed_mps, dtype=np.float64)
    t = np.asarray(t_s, dtype=np.float64)
    h_t = thigh_height_m(h)
    rv = v / h_t
    rv_w = np.minimum(rv / RV_REF, MAX_RELATIVE_VELOCITY / RV_REF)  # amplitude scale
    dc = cycle_duration_s(v, h)
    # Boulic: D_s = 0.752 D_c - 0.143 s, so the stance fraction beta = D_s / D_c
    with np.errstate(invalid="ignore", divide="ignore"):
        beta = np.clip(0.752 - 0.143 / dc, 0.55, 0.752)
    beta = np.where(np.isfinite(beta), beta, 0.752)
    two_pi = 2 * math.pi
    # pelvis: vertical 0.015 RV H_t twice a cycle, lowest in double support (phi ~ 0.06)
    a_v = 0.015 * rv * h_t
    lat = np.where(rv < 0.5, 0.128 * rv * (1 - rv), 0.032) * h_t
    pel_u = 0.021 * h_t * np.minimum(rv, 1.0) * np.sin(2 * two_pi * (phi - 0.06))
    pel_w = -lat * np.sin(two_pi * phi)  # toward the right (stance) leg in its mid-stance
    # pelvis torsion: the right hip forward at the right heel strike (phi = 0), +-4 deg * RV
    a_t = np.radians(4.0) * rv
    alpha_p = a_t * np.cos(two_pi * phi)
    alpha_t = -0.6 * alpha_p  # thorax against the pelvis
    hw = 0.5 * HIP_WIDTH * h
    # the leg's reach sets the stance placement x0 and the pelvis height in double support
    rho_max = 0.9 * np.minimum(rv_w, 1.0)  # heel-rise angle at toe-off, rad
    with np.errstate(invalid="ignore"):  # standing: v * inf
        stance_len = np.where(np.isfinite(dc), v * beta * dc, 0.0)
    x0, reach_z = _stance_geometry(stance_len, rho_max, hw * np.sin(a_t), h)
    legs = {}
    for side, sign in (("r", -1.0), ("l", 1.0)):
        # hip joint: (0, sign * hw) turned by the pelvis torsion
        j_u = pel_u - sign * hw * np.sin(alpha_p)
        j_w = pel_w + sign * hw * np.cos(alpha_p)
        psi = phi if side == "r" else np.mod(phi + 0.5, 1.0)
        legs[side] = (j_u, j_w, *_ankle_path(psi, v, dc, beta, rho_max, x0, rv_w, h), psi / beta)
    # pelvis: Boulic's vertical oscillation (lowest in double support at phi ~ 0.06, 0.56),
    # lowered where a stance leg could not reach its ankle otherwise (a smooth minimum, 5 mm;
    # a swing leg out of reach has its ankle pulled toward the hip instead)
    # the top of the oscillation such that the leg reaches its heel strike (phi = 0)
    z_top = np.minimum(
        h_t, ANKLE_Z * h + reach_z - 0.005 * h + a_v * (1 + math.cos(2 * two_pi * 0.06))
    )
    z_boulic = z_top - a_v * (1 + np.cos(2 * two_pi * (phi - 0.06)))
    leg_len = (HIP_Z - ANKLE_Z) * h * 0.999
    cands = [z_boulic]
    for j_u, _, a_u, a_z, _, _, tau in legs.values():
        du = np.minimum(np.abs(a_u - j_u), 0.99 * leg_len)
        # the constraint fades out over the last 20 % of stance (heel off, toe-off near)
        fade = np.clip((tau - 0.8) / 0.2, 0.0, 1.0)
        release = 0.1 * h * fade * fade * (3 - 2 * fade)
        # and fades in over the last 30 % of swing
        tau_sw = (tau - 1) * beta / (1 - beta)
        fade_in = np.clip((1 - tau_sw) / 0.3, 0.0, 1.0)
        arrive = 0.1 * h * fade_in * fade_in * (3 - 2 * fade_in)
        cands.append(a_z + np.sqrt(leg_len**2 - du**2) + np.where(tau < 1, release, arrive))
    k = 0.005
    zs = np.stack(cands)
    lo = zs.min(axis=0)
    # soft minimum: -k log sum exp(-z_i / k), never above the minimum
    pel_z = lo - k * np.log(np.exp(-(zs - lo) / k).sum(axis=0))
    # standing sway and breathing fade in below STANDING_SPEED_MPS
    still = np.clip(1.0 - v / STANDING_SPEED_MPS, 0.0, 1.0)
    sway_u = still * SWAY_AMPLITUDE_M * np.sin(two_pi * SWAY_HZ * t)
    sway_w = still * 0.5 * SWAY_AMPLITUDE_M * np.sin(two_pi * SWAY_HZ * 0.7 * t + 1.0)

    j = _joints(h, phi, rv, rv_w, legs, pel_u + sway_u, pel_w + sway_w, pel_z, alpha_p, alpha_t)
    if seated is not None:
        frac = np.asarray(seated, dtype=np.float64)
        sit = frac > 0
        if sit.any():
            # seated: full sway of the body above the seat (the person is still)
            u = SWAY_AMPLITUDE_M * np.sin(two_pi * SWAY_HZ * t[sit])
            w = 0.5 * SWAY_AMPLITUDE_M * np.sin(two_pi * SWAY_HZ * 0.7 * t[sit] + 1.0)
            f = frac[sit][:, None]
            full = f == 1.0
            for name, rows in seated_joints(u, w, h).items():
                j[name][sit] = np.where(full, rows, (1.0 - f) * j[name][sit] + f * rows)
    return j


def sit_transition(t_s: np.ndarray, seated: np.ndarray | None) -> np.ndarray | None:
    """The seated fraction and its rate at frame times ``t_s`` (shape ``(F, 2)``: fraction in
    ``[0, 1]``, rate in 1/s), or None when ``seated`` is None or has no seated frame.

    ``seated`` (shape ``(F,)`` bool): the frames of each seated hold. Over the first
    ``T = min(SIT_TRANSITION_S, D / 2)`` of a hold from ``t_a`` (its first seated frame) to
    ``t_b`` (its last; ``D = t_b - t_a``) the fraction rises as ``3 s^2 - 2 s^3``,
    ``s = (t - t_a) / T``, and over the last ``T`` falls symmetrically; 1 between, 0 outside.
    """
    if seated is None:
        return None
    m = np.asarray(seated, dtype=bool)
    if not m.any():
        return None
    t = np.asarray(t_s, dtype=np.float64)
    out = np.zeros((len(t), 2))
    edges = np.diff(np.concatenate(([0], m.view(np.int8), [0])))
    for a, b in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1):
        ta, tb = t[a], t[b]
        ramp = min(SIT_TRANSITION_S, 0.5 * (tb - ta))
        rows = slice(a, b + 1)
        if ramp <= 0:
            out[rows, 0] = 1.0
            continue
        down = np.clip((t[rows] - ta) / ramp, 0.0, 1.0)
        up = np.clip((tb - t[rows]) / ramp, 0.0, 1.0)
        s = np.minimum(down, up)
        sign = np.where(down <= up, 1.0, -1.0)
        out[rows, 0] = s * s * (3.0 - 2.0 * s)
        out[rows, 1] = sign * 6.0 * s * (1.0 - s) / ramp
    return out


def seated_joints(
    sway_u_m: np.ndarray, sway_w_m: np.ndarray, height_m: float
) -> dict[str, np.ndarray]:
    """Joint positions of the seated body in the body frame ``(u, w, z)``, shape ``(n, 3)``.

    The hip joints on a seat at knee height ``KNEE_Z H`` (thighs horizontal forward, shins
    vertical to the ankles at ``ANKLE_Z H``, feet flat forward), the pelvis at the origin of
    ``(u, w)``; the trunk, neck and head upright above it, moved by the sway ``(sway_u_m,
    sway_w_m)`` (shape ``(n,)``, m); the upper arms hanging, the forearms forward, horizontal.
    """
    h = float(height_m)
    du = np.asarray(sway_u_m, dtype=np.float64)
    dw = np.asarray(sway_w_m, dtype=np.float64)
    n = len(du)
    z_seat = KNEE_Z * h
    hw, sw_half = 0.5 * HIP_WIDTH * h, 0.5 * SHOULDER_WIDTH * h
    l_thigh = (HIP_Z - KNEE_Z) * h
    l_ua, l_la = (SHOULDER_Z - ELBOW_Z) * h, (ELBOW_Z - WRIST_Z) * h

    def at(u: float | np.ndarray, w: float | np.ndarray, z: float) -> np.ndarray:
        out = np.empty((n, 3))
        out[:, 0], out[:, 1], out[:, 2] = u, w, z
        return out

    z_neck = z_seat + (SHOULDER_Z - HIP_Z) * h
    z_chin = z_neck + (CHIN_Z - SHOULDER_Z) * h
    j = {
        "pelvis": at(0.0, 0.0, z_seat),
        "neck_base": at(du, dw, z_neck),
        "chin": at(du, dw, z_chin),
        "head_top": at(du, dw, z_chin + (1 - CHIN_Z) * h),
    }
    for side, sign in (("r", -1.0), ("l", 1.0)):
        j[f"shoulder_{side}"] = at(du, dw + sign * sw_half, z_neck)
        j[f"elbow_{side}"] = at(du, dw + sign * sw_half, z_neck - l_ua)
        j[f"wrist_{side}"] = at(du + l_la, dw + sign * sw_half, z_neck - l_ua)
        j[f"hip_{side}"] = at(0.0, sign * hw, z_seat)
        j[f"knee_{side}"] = at(l_thigh, sign * hw, z_seat)
        j[f"ankle_{side}"] = at(l_thigh, sign * hw, ANKLE_Z * h)
        j[f"toe_{side}"] = at(l_thigh + TOE_PIVOT * h, sign * hw, 0.0)
    return j


def body_frame_segments(
    phase: np.ndarray,
    speed_mps: np.ndarray,
    t_s: np.ndarray,
    height_m: float,
    seated: np.ndarray | None = None,
) -> np.ndarray:
    """Segment centres in the body frame ``(u, w, z)`` (z above the floor).

    Parameters
    ----------
    phase, speed_mps, t_s, height_m, seated
        As :func:`body_frame_joints`.

    Returns
    -------
    numpy.ndarray
        Shape ``(F, N_SEGMENTS, 3)``, m, in the order of :data:`SEGMENT_NAMES`: the midpoints
        of :data:`SEGMENT_ENDS` (the torso's moved by the breathing chest wall).
    """
    joints = body_frame_joints(phase, speed_mps, t_s, height_m, seated)
    out = np.empty((len(joints["pelvis"]), N_SEGMENTS, 3))
    for k, name in enumerate(SEGMENT_NAMES):
        a, b = SEGMENT_ENDS[name]
        out[:, k] = 0.5 * (joints[a] + joints[b])
    v = np.asarray(speed_mps, dtype=np.float64)
    still = np.clip(1.0 - v / STANDING_SPEED_MPS, 0.0, 1.0)
    # the chest wall moves with the breath (forward)
    out[:, SEGMENT_NAMES.index("torso"), 0] += (
        still * BREATH_AMPLITUDE_M * np.sin(2 * math.pi * BREATH_HZ * np.asarray(t_s))
    )
    return out


#: Each segment between two joints (its scatterer at the midpoint).
SEGMENT_ENDS = {
    "head": ("chin", "head_top"),
    "neck": ("neck_base", "chin"),
    "torso": ("pelvis", "neck_base"),
    **{
        f"{seg}_{s}": ends
        for s in "rl"
        for seg, ends in (
            ("shoulder", ("neck_base", f"shoulder_{s}")),
            ("upper_arm", (f"shoulder_{s}", f"elbow_{s}")),
            ("lower_arm", (f"elbow_{s}", f"wrist_{s}")),
            ("hip", ("pelvis", f"hip_{s}")),
            ("upper_leg", (f"hip_{s}", f"knee_{s}")),
            ("lower_leg", (f"knee_{s}", f"ankle_{s}")),
            ("foot", (f"ankle_{s}", f"toe_{s}")),
        )
    },
}


def _joints(
    h: float,
    phi: np.ndarray,
    rv: np.ndarray,
    rv_w: np.ndarray,
    legs: dict[str, tuple[np.ndarray, ...]],
    pel_u: np.ndarray,
    pel_w: np.ndarray,
    pel_z: np.ndarray,
    alpha_p: np.ndarray,
    alpha_t: np.ndarray,
) -> dict[str, np.ndarray]:
    """Joint positions ``name -> (F, 3)`` in the body frame (u, w, z)."""
    two_pi = 2 * math.pi
    hw, sw_half = 0.5 * HIP_WIDTH * h, 0.5 * SHOULDER_WIDTH * h
    j: dict[str, np.ndarray] = {}
    pelvis = np.stack([pel_u, pel_w, pel_z], axis=-1)
    j["pelvis"] = pelvis
    up = np.array([0.0, 0.0, 1.0])
    j["neck_base"] = pelvis + (SHOULDER_Z - HIP_Z) * h * up
    j["chin"] = j["neck_base"] + (CHIN_Z - SHOULDER_Z) * h * up
    j["head_top"] = j["chin"] + (1 - CHIN_Z) * h * up
    l_ua, l_la = (SHOULDER_Z - ELBOW_Z) * h, (ELBOW_Z - WRIST_Z) * h
    a_s = np.radians(10.0) * rv  # shoulder flexion amplitude
    a_e = np.radians(15.0) * rv_w  # elbow flexion amplitude
    zero = np.zeros_like(pel_u)
    for side, sign in (("r", -1.0), ("l", 1.0)):
        # shoulder joint: (0, sign * sw_half) turned by the thorax torsion
        sh = j["neck_base"] + np.stack(
            [-sign * sw_half * np.sin(alpha_t), sign * sw_half * np.cos(alpha_t), zero], axis=-1
        )
        j[f"shoulder_{side}"] = sh
        # the right arm forward at the left heel strike (phi = 0.5)
        swing = -np.cos(two_pi * phi) if side == "r" else np.cos(two_pi * phi)
        th_s = a_s * swing
        th_e = np.radians(15.0) + a_e * 0.5 * (1 + swing)
        el = sh + l_ua * np.stack([np.sin(th_s), zero, -np.cos(th_s)], axis=-1)
        j[f"elbow_{side}"] = el
        j[f"wrist_{side}"] = el + l_la * np.stack(
            [np.sin(th_s + th_e), zero, -np.cos(th_s + th_e)], axis=-1
        )
        # hip joint: (0, sign * hw) turned by the pelvis torsion
        hip = pelvis + np.stack(
            [-sign * hw * np.sin(alpha_p), sign * hw * np.cos(alpha_p), zero], axis=-1
        )
        j[f"hip_{side}"] = hip
        _, _, a_u, a_z, f_u, f_z, _ = legs[side]
        ankle = np.stack([a_u, np.full_like(a_u, sign * hw), a_z], axis=-1)
        knee, ankle = _knee(hip, ankle, h)
        j[f"knee_{side}"] = knee
        j[f"ankle_{side}"] = ankle
        j[f"toe_{side}"] = ankle + np.stack([f_u, zero, f_z], axis=-1)
    return j


def walking_scatterers(
    position_m: np.ndarray,
    velocity_mps: np.ndarray,
    heading_rad: np.ndarray,
    heading_rate_rps: np.ndarray,
    phase: np.ndarray,
    t_s: np.ndarray,
    height_m: float,
    seated: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Segment centres and velocities in the radar's frame for frames of one person.

    Parameters
    ----------
    position_m, velocity_mps
        Shape ``(F, 2)``: the trajectory's ``[x, y]`` and ``[vx, vy]`` (m, m/s).
    heading_rad, heading_rate_rps
        Shape ``(F,)``: walking direction ``atan2(vx, vy)`` (rad) and its rate (rad/s).
    phase
        Shape ``(F,)``: gait phase (cycles, :func:`gait_phase`).
    t_s
        Shape ``(F,)``: frame times (s).
    height_m
        Body height (m).
    seated
        ``None``, shape ``(F,)`` bool (frames where the body sits at once), or shape ``(F, 2)``:
        the seated fraction and its rate (1/s) from :func:`sit_transition`, the rate moving
        the fraction of the neighbouring instants of the velocity's central difference.

    Returns
    -------
    position_m, velocity_mps
        Shape ``(F, N_SEGMENTS, 3)`` each; ``z`` relative to the radar (height above the floor
        minus :data:`RADAR_HEIGHT_M`). The velocity is ``v_traj + R(h) d(local)/dt +
        h' dR/dh local``, the local part by a central difference of ``VELOCITY_STEP_S``.
    """
    p = np.asarray(position_m, dtype=np.float64)
    v = np.asarray(velocity_mps, dtype=np.float64)
    h = np.asarray(heading_rad, dtype=np.float64)
    speed = np.hypot(v[:, 0], v[:, 1])
    rate = 1.0 / cycle_duration_s(speed, height_m)  # dphi/dt
    dt = VELOCITY_STEP_S
    now = ahead_sit = behind_sit = seated
    if seated is not None and np.ndim(seated) == 2:
        sit = np.asarray(seated, dtype=np.float64)
        now = sit[:, 0]
        ahead_sit = np.clip(sit[:, 0] + sit[:, 1] * dt, 0.0, 1.0)
        behind_sit = np.clip(sit[:, 0] - sit[:, 1] * dt, 0.0, 1.0)
    local = body_frame_segments(phase, speed, t_s, height_m, now)
    ahead = body_frame_segments(phase + rate * dt, speed, t_s + dt, height_m, ahead_sit)
    behind = body_frame_segments(phase - rate * dt, speed, t_s - dt, height_m, behind_sit)
    d_local = (ahead - behind) / (2 * dt)
    sh, ch = np.sin(h)[:, None], np.cos(h)[:, None]
    lu, lw = local[..., 0], local[..., 1]
    pos = np.empty_like(local)
    # x = x_p + u sin h - w cos h,  y = y_p + u cos h + w sin h
    pos[..., 0] = p[:, 0:1] + lu * sh - lw * ch
    pos[..., 1] = p[:, 1:2] + lu * ch + lw * sh
    pos[..., 2] = local[..., 2] - RADAR_HEIGHT_M
    du, dw = d_local[..., 0], d_local[..., 1]
    hr = np.asarray(heading_rate_rps, dtype=np.float64)[:, None]
    vel = np.empty_like(local)
    # d/dt of the above: R du/dt + h' (dR/dh) (u, w)
    vel[..., 0] = v[:, 0:1] + du * sh - dw * ch + hr * (lu * ch + lw * sh)
    vel[..., 1] = v[:, 1:2] + du * ch + dw * sh + hr * (-lu * sh + lw * ch)
    vel[..., 2] = d_local[..., 2]
    return pos, vel


def heading_rates(t_s: np.ndarray, heading_rad: np.ndarray) -> np.ndarray:
    """Rate of turn (rad/s) per frame from the (forward-filled) headings, shape ``(F,)``."""
    if len(t_s) < 2:
        return np.zeros(len(t_s))
    return np.gradient(np.unwrap(heading_rad), t_s)
