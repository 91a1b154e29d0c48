"""gtrack-compatible group tracker, readable form: one frame at a time, one track at a time.

Written from TI's documentation of its people-counting tracker (docs/tracking/gtrack.md gives
each rule with its source and every choice made where the documents are silent). Per frame:

1. **Points.** Each point ``[r, az, el, vr]`` (sensor frame) with its linear SNR is placed in the
   world (:mod:`~core.tracking.gtrack.geometry`); points outside the boundary box are not used.
   A point is *static* when |vr| < half the radial velocity resolution.
2. **Predict** every track: ``x⁻ = F x``, ``P⁻ = F P Fᵀ + Q`` (constant acceleration, Q from the
   maximum accelerations).
3. **Gate and associate.** For track i, with ``C_i = H P⁻ Hᵀ + R + D_i`` (R one point's noise,
   D_i the track's group dispersion), a point is in the gate when the partial distance over the
   position rows, ``ν_pᵀ (C_i⁻¹)_pp ν_p ≤ G²`` (G the gating gain; Doppler left out, as TI's
   gate), and it lies within the gating limits (full extents) around the predicted
   centroid in world x, y, z and in radial velocity. A point in several gates goes to the track
   of the smallest score ``νᵀ C_i⁻¹ ν + ln det C_i``.
4. **Allocate** the points left (in the box, not static), in their order: a point seeds a set,
   later points join while within ``max_distance_thre_m2`` (squared distance) and
   ``max_vel_thre_mps`` of the set's running centroid; a set of at least
   ``points_thre`` points, centroid |vr| ≥ ``velocity_thre_mps`` and SNR sum ≥ ``snr_thre``
   (``snr_thre_obscured`` when a track is nearer the sensor at about its bearing) starts a
   track in DETECT, at the set's centroid moving radially with its mean vr.
5. **Update** each track that took a moving point with the centroid of its m points: ``ν̄``
   the mean innovation, ``S = H P⁻ Hᵀ + (R + D)/m``, Kalman gain, Joseph form; D follows the
   points' spread. The
   radial-velocity row is the moving points' centroid vr, unrolled in TI's stages
   (:meth:`GtrackTracker._velocity_stage`): against a filtered range rate (the range change
   since allocation) until that rate settles and the prediction agrees, then against the
   prediction. A track without moving points is not updated: its prediction's acceleration is
   zeroed and its velocity halved, or zeroed below 0.1 m/s (TI's erasure handling).
6. **States.** DETECT → ACTIVE after ``det2act`` consecutive hits (allocation is the first),
   DETECT → FREE after ``det2free`` consecutive misses; an ACTIVE track is freed after
   ``static2free`` misses in the static box when stopped (step 5), ``active2free`` in the static box
   when moving (obscured), ``exit2free`` outside it, and after ``sleep2free`` consecutive frames
   of only static points in the static box.

``run_gtrack`` returns :class:`GtrackResult`: per frame :class:`core.tracking.results.FrameTracks`
(ψ is NaN: gtrack has no existence probability; ``confirmed`` means ACTIVE), the track given to
every point (as TI's point-to-track list) and the presence flag.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from core.tracking import ekf
from core.tracking.gtrack import geometry as geo
from core.tracking.gtrack.params import GtrackParams
from core.tracking.results import FrameTracks

__all__ = ["DETECT", "ACTIVE", "GtrackResult", "run_gtrack", "GtrackTracker", "P0_SIGMA"]

DETECT, ACTIVE = 1, 2
#: A new track's radial-velocity stages (TI's velocity handling). The allocation frame is TI's
#: INIT stage (the centroid's vr is the allocation's range rate); then RATE_FILTER (unroll
#: against the filtered range rate), TRACKING (the same, until the prediction agrees), LOCKED
#: (unroll against the prediction).
RATE_FILTER, TRACKING, LOCKED = 1, 2, 3
#: TI's unrolling parameters (its library's defaults; no .cfg line sets them): the range-rate
#: filter's weight of the old estimate, and the relative error below which the rate is trusted.
UNROLL_ALPHA = 0.5
UNROLL_CONFIDENCE = 0.1
#: Relative disagreement of the predicted and the unrolled vr below which the track locks (TI's
#: constant).
LOCK_TOLERANCE = 0.1
#: TI's initialRadialVelocity for people counting (the module's configuration, no .cfg line):
#: the reference a new track's vr is unrolled against.
INITIAL_RADIAL_VELOCITY_MPS = 0.0
#: TI's handling of a frame without moving points (its minStaticVelocityOne/Two, internal): below
#: this speed the track stops (velocity and acceleration zero); above it the velocity is halved
#: and the acceleration zeroed, and the track is not updated.
MIN_STATIC_VELOCITY_MPS = 0.1
ERASURE_VELOCITY_FACTOR = 0.5
#: Initial state standard deviations (position m, velocity m/s, acceleration m/s²): a choice.
P0_SIGMA = (0.5, 1.0, 1.0)
#: Weight of one frame's sample spread in the group dispersion D (exponential forgetting).
DISPERSION_WEIGHT = 0.1


@dataclass(slots=True)
class _Track:
    id: int
    x: np.ndarray
    P: np.ndarray
    D: np.ndarray  # diagonal group dispersion in measurement space (m,)
    state: int
    birth: int
    hits: int = 1
    misses: int = 0
    sleeps: int = 0
    vstate: int = RATE_FILTER  # radial-velocity stage
    rate: float = 0.0  # filtered range rate (m/s)
    r_alloc: float = 0.0  # centroid range at allocation (m)
    still: bool = False  # TI's static target: stopped on a frame without moving points


@dataclass(frozen=True, slots=True, kw_only=True)
class GtrackResult:
    """gtrack over F frames and P points.

    Attributes
    ----------
    frames
        Live tracks after each frame (:class:`FrameTracks`; ``confirmed`` = ACTIVE, ψ NaN,
        ``n_associated`` the points the track took, ``nis`` its centroid update's ν̄ᵀ S⁻¹ ν̄).
    point_track
        (P,) id of the track each point was given to in its frame (associated, or allocated into
        a new track), −1 for none.
    presence
        (F,) an ACTIVE track is inside the presence box.
    """

    frames: tuple[FrameTracks, ...]
    point_track: np.ndarray
    presence: np.ndarray
    n_active: np.ndarray = field(repr=False)
    n_detect: np.ndarray = field(repr=False)


def unroll(v: np.ndarray | float, ref: np.ndarray | float, v_max: float) -> np.ndarray:
    """Radial velocity ``v`` moved by whole multiples of ``2 v_max`` (the unambiguous span) to
    the alias nearest ``ref``: ``v + 2 v_max ⌊(ref − v + v_max) / (2 v_max)⌋``."""
    span = 2.0 * v_max
    return np.asarray(v) + span * np.floor((np.asarray(ref) - v + v_max) / span)


def _in_box(p: np.ndarray, box: tuple[float, ...], dims: int) -> np.ndarray:
    """(n,) bool: rows of p (n, ≥dims) inside the box (x, y; and z in 3-D)."""
    inside = (p[:, 0] >= box[0]) & (p[:, 0] <= box[1]) & (p[:, 1] >= box[2]) & (p[:, 1] <= box[3])
    if dims == 3:
        inside &= (p[:, 2] >= box[4]) & (p[:, 2] <= box[5])
    return inside


class GtrackTracker:
    """The tracker's state between frames; :meth:`step` runs one frame."""

    def __init__(self, params: GtrackParams) -> None:
        self.p = params
        d = params.dims
        self.dims = d
        self.m = geo.meas_dim(d)
        self.M = geo.pose_matrix(
            params.sensor_azimuth_tilt_deg, 0.0 if d == 2 else params.sensor_elevation_tilt_deg
        )
        self.h = params.sensor_height_m if d == 3 else 0.0
        self.F = geo.transition(d, params.frame_period_s)
        self.Q = geo.process_noise(d, params.frame_period_s, params.max_acceleration_mps2)
        sig = [params.range_sigma_m] + [params.angle_sigma_rad] * (d - 1)
        sig.append(params.doppler_sigma_mps)
        self.R = np.diag(np.square(sig))
        self.P0 = np.diag(np.repeat(np.square(P0_SIGMA), d))
        self.angles = geo.ANGLE_ROWS[d]
        self.tracks: list[_Track] = []
        self.next_id = 0
        self.frame = 0

    # -- helpers -------------------------------------------------------------------------------
    def _innovations(self, z: np.ndarray, zp: np.ndarray) -> np.ndarray:
        nu = z - zp
        for a in self.angles:
            nu[:, a] = ekf.wrap_angle(nu[:, a])
        # radial velocity unrolled to the alias nearest the prediction
        nu[:, -1] = unroll(z[:, -1], zp[-1], self.p.max_radial_velocity_mps) - zp[-1]
        return nu

    def _meas(self, r, az, el, vr) -> np.ndarray:
        if self.dims == 2:
            return np.stack([r, az, vr], axis=-1)
        return np.stack([r, az, el, vr], axis=-1)

    # -- one frame -----------------------------------------------------------------------------
    def step(
        self, r: np.ndarray, az: np.ndarray, el: np.ndarray, vr: np.ndarray, snr: np.ndarray
    ) -> tuple[FrameTracks, np.ndarray, bool]:
        """Track one frame of n points (sensor-frame r, az, el, vr; linear SNR).

        Returns the live tracks after the frame, the track id given to each point (−1 none) and
        the presence flag.
        """
        p, d = self.p, self.dims
        n = len(r)
        z = self._meas(r, az, el, vr)
        # 2-D: the points in the horizontal plane (no elevation, no height)
        el_w = el if d == 3 else np.zeros_like(el)
        pw = geo.sensor_to_world(geo.spherical_to_sensor(r, az, el_w), self.M, self.h)
        static = np.abs(vr) < 0.5 * p.radial_velocity_resolution_mps
        # a static point counts only inside the static box (outside it: "behind the wall")
        usable = _in_box(pw, p.box("boundary"), d) & (~static | _in_box(pw, p.box("static"), d))
        half = np.array([p.gating_width_m, p.gating_depth_m, p.gating_height_m])[:d] / 2.0
        # 2. predict
        preds = []
        for t in self.tracks:
            x_pred, P_pred = ekf.predict(t.x, t.P, self.F, self.Q)
            H = geo.jacobian(x_pred, d, self.M, self.h)
            zp = geo.measure(x_pred, d, self.M, self.h)
            C = ekf.symmetrize(H @ P_pred @ H.T + self.R + np.diag(t.D))
            preds.append((x_pred, P_pred, H, zp, C))
        # 3. gate and associate
        best = np.full(n, np.inf)
        owner = np.full(n, -1)
        for i, (x_pred, _, _, zp, C) in enumerate(preds):
            nu = self._innovations(z, zp)
            Ci = np.linalg.inv(C)
            d2 = np.einsum("ij,jk,ik->i", nu, Ci, nu)
            # the gate: the partial distance over the position rows (Doppler left out)
            q = self.m - 1
            d2p = np.einsum("ij,jk,ik->i", nu[:, :q], Ci[:q, :q], nu[:, :q])
            ok = usable & (d2p <= p.gating_gain**2)
            ok &= np.all(np.abs(pw[:, :d] - x_pred[:d]) <= half, axis=1)
            if p.gating_velocity_mps > 0:
                ok &= np.abs(nu[:, -1]) <= p.gating_velocity_mps / 2.0
            score = d2 + math.log(np.linalg.det(C))
            take = ok & (score < best)
            best[take] = score[take]
            owner[take] = i
        point_track = np.full(n, -1, dtype=np.int64)
        # 5. update (before allocation in code; allocation uses only points no track took)
        n_assoc = np.zeros(len(self.tracks), dtype=np.int64)
        nis = np.full(len(self.tracks), np.nan)
        for i, t in enumerate(self.tracks):
            x_pred, P_pred, H, zp, _ = preds[i]
            sel = np.flatnonzero(owner == i)
            n_assoc[i] = len(sel)
            point_track[sel] = t.id
            mov = sel[~static[sel]]
            if len(mov) == 0:
                # no moving point: no update; the track slows down or stops
                t.x, t.P = x_pred, P_pred
                if not t.still:
                    self._erasure(t, len(sel))
                continue
            t.still = False
            nu = self._innovations(z[sel], zp)
            nu_bar = nu.mean(axis=0)
            # the radial-velocity row: the moving points' centroid, unrolled by stage
            vr_c = self._velocity_stage(t, z[mov, 0], z[mov, -1], zp[-1])
            nu_bar[-1] = vr_c - zp[-1]
            Rc = (self.R + np.diag(t.D)) / len(sel)
            # S = H P⁻ Hᵀ + (R + D)/m
            S = ekf.symmetrize(H @ P_pred @ H.T + Rc)
            Si = np.linalg.inv(S)
            # K = P⁻ Hᵀ S⁻¹
            K = P_pred @ H.T @ Si
            t.x = x_pred + K @ nu_bar
            t.P = ekf.joseph_update(P_pred, K, H, Rc)
            nis[i] = float(nu_bar @ Si @ nu_bar)
            if len(sel) > 1:
                spread = np.mean(np.square(nu - nu_bar), axis=0)
                t.D = (1.0 - DISPERSION_WEIGHT) * t.D + DISPERSION_WEIGHT * spread
        gate_center = np.array([pr[0][:2] for pr in preds]).reshape(-1, 2)
        gate_shape = np.array([self._gate_xy(pr[3], pr[4]) for pr in preds]).reshape(-1, 2, 2)
        # 6. states of the existing tracks
        keep = []
        for i, t in enumerate(self.tracks):
            if self._transition(t, n_assoc[i], static[owner == i]):
                keep.append(i)
        # 4. allocation
        born = self._allocate(pw, z, vr, snr, usable & ~static & (owner < 0), point_track)
        old = [self.tracks[i] for i in keep]
        gc = np.concatenate([gate_center[keep], np.array([t.x[:2] for t in born]).reshape(-1, 2)])
        gs = np.concatenate(
            [gate_shape[keep], np.array([self._born_gate(t) for t in born]).reshape(-1, 2, 2)]
        )
        nas = np.concatenate([n_assoc[keep], np.zeros(len(born), np.int64)])
        nis_all = np.concatenate([nis[keep], np.full(len(born), np.nan)])
        self.tracks = old + born
        self.frame += 1
        ft = self._frame_tracks(gc, gs, nas, nis_all)
        presence = bool(
            any(
                t.state == ACTIVE and _in_box(t.x[None, :], p.box("presence"), d)[0]
                for t in self.tracks
            )
        )
        return ft, point_track, presence

    def _erasure(self, t: _Track, n_static: int) -> None:
        """TI's frame without moving points for a moving track (its state the prediction): the
        acceleration zeroed and the velocity halved or, below ``MIN_STATIC_VELOCITY_MPS``,
        zeroed; then the track is still, on static points only when more than 3 of them."""
        d = self.dims
        x = t.x.copy()
        speed = float(np.linalg.norm(x[d : 2 * d]))
        if speed < MIN_STATIC_VELOCITY_MPS:
            x[d : 2 * d] = 0.0
            t.still = n_static == 0 or n_static > 3
        else:
            x[d : 2 * d] *= ERASURE_VELOCITY_FACTOR
        x[2 * d :] = 0.0
        t.x = x

    def _velocity_stage(self, t: _Track, r: np.ndarray, vr: np.ndarray, vr_pred: float) -> float:
        """The centroid radial velocity of a track's moving points (ranges r, raw vr) after TI's
        staged unrolling; advances the track's stage.

        The points' vr are unrolled to the first one (TI's pilot) and averaged to ``v̄``, their
        range to ``r̄``. With k frames since allocation, the instantaneous range rate is
        ``ṙ = (r̄ − r_alloc)/(k T)`` and the filtered one ``ρ ← α ρ + (1 − α) ṙ``. RATE_FILTER
        and TRACKING return ``v̄`` unrolled to ρ; RATE_FILTER moves on when
        ``|ṙ − ρ| < confidence·|ρ|``, TRACKING when ``|v̂ − v| < 0.1 |v|`` (v̂ the predicted vr,
        v the unrolled centroid). LOCKED unrolls ``v̄`` to the prediction.
        """
        vmax = self.p.max_radial_velocity_mps
        pilot = float(vr[0])
        v_bar = float(np.mean(unroll(vr, pilot, vmax)))
        if t.vstate == LOCKED:
            return float(unroll(v_bar, vr_pred, vmax))
        k = self.frame - t.birth
        inst = (float(np.mean(r)) - t.r_alloc) / (k * self.p.frame_period_s)
        t.rate = UNROLL_ALPHA * t.rate + (1.0 - UNROLL_ALPHA) * inst
        v = float(unroll(v_bar, t.rate, vmax))
        if t.vstate == RATE_FILTER:
            if abs(inst - t.rate) < UNROLL_CONFIDENCE * abs(t.rate):
                t.vstate = TRACKING
        elif abs(vr_pred - v) < LOCK_TOLERANCE * abs(v):
            t.vstate = LOCKED
        return v

    def _born_gate(self, t: _Track) -> np.ndarray:
        H = geo.jacobian(t.x, self.dims, self.M, self.h)
        C = H @ t.P @ H.T + self.R + np.diag(t.D)
        return self._gate_xy(geo.measure(t.x, self.dims, self.M, self.h), C)

    def _gate_xy(self, zp: np.ndarray, C: np.ndarray) -> np.ndarray:
        """The gate in x–y: G² J C_(r,az) Jᵀ, J = ∂(x, y)/∂(r, az) in the horizontal plane."""
        r, az = zp[0], zp[1]
        ce = math.cos(zp[2]) if self.dims == 3 else 1.0
        c, s = math.cos(az), math.sin(az)
        J = np.array([[s * ce, r * ce * c], [c * ce, -r * ce * s]])
        a = math.radians(self.p.sensor_azimuth_tilt_deg)
        rot = np.array([[math.cos(a), math.sin(a)], [-math.sin(a), math.cos(a)]])
        J = rot @ J
        return self.p.gating_gain**2 * J @ C[:2, :2] @ J.T

    def _transition(self, t: _Track, m: int, static_points: np.ndarray) -> bool:
        """Count the frame's hit or miss; False when the track is freed."""
        p = self.p
        if t.state == DETECT:
            if m > 0 and not np.all(static_points):  # a hit needs a moving point
                t.hits += 1
                t.misses = 0
                if t.hits >= p.det2act:
                    t.state = ACTIVE
                return True
            t.hits = 0
            t.misses += 1
            return t.misses < p.det2free
        in_static = bool(_in_box(t.x[None, :], p.box("static"), self.dims)[0])
        if m > 0:
            t.misses = 0
            if in_static and np.all(static_points):
                t.sleeps += 1
                return t.sleeps < p.sleep2free
            t.sleeps = 0
            return True
        t.misses += 1
        if not in_static:
            limit = p.exit2free
        elif t.still:
            limit = p.static2free
        else:
            limit = p.active2free
        return t.misses < limit

    def _allocate(self, pw, z, vr, snr, candidate, point_track) -> list[_Track]:
        p, d = self.p, self.dims
        born: list[_Track] = []
        free = candidate.copy()
        live = len(self.tracks)
        idx = np.flatnonzero(free)
        for i in idx:
            if live + len(born) >= p.max_tracks:
                break
            if not free[i]:
                continue
            members = [i]
            c = pw[i, :d].copy()
            cv = float(vr[i])
            for j in idx[idx > i]:
                if not free[j]:
                    continue
                vj = float(unroll(vr[j], cv, p.max_radial_velocity_mps))
                if (
                    abs(vj - cv) < p.max_vel_thre_mps
                    and float(np.sum(np.square(pw[j, :d] - c))) < p.max_distance_thre_m2
                ):
                    members.append(j)
                    k = len(members)
                    c += (pw[j, :d] - c) / k
                    cv += (vj - cv) / k
            # TI's comparisons are strict: more than pointsThre points, |v̄| and SNR above
            if len(members) <= p.points_thre or not abs(cv) > p.velocity_thre_mps:
                continue
            snr_sum = float(np.sum(snr[members]))
            threshold = p.snr_thre_obscured if self._obscured(c) else p.snr_thre
            if not snr_sum > threshold:
                continue
            sel = np.asarray(members)
            free[sel] = False
            t = self._new_track(c, cv, z[sel])
            t.r_alloc = float(np.mean(z[sel, 0]))
            point_track[sel] = t.id
            born.append(t)
        return born

    def _obscured(self, c: np.ndarray) -> bool:
        """A live track nearer the sensor within half the gating width of the set's bearing."""
        d = self.dims
        ps = self._to_sensor(c)
        r_c = float(np.linalg.norm(ps))
        az_c = math.atan2(ps[0], ps[1])
        for t in self.tracks:
            pt = self._to_sensor(t.x[:d])
            r_t = float(np.linalg.norm(pt))
            if r_t >= r_c or r_t == 0.0:
                continue
            half_width = math.atan2(self.p.gating_width_m / 2.0, r_t)
            if abs(float(ekf.wrap_angle(math.atan2(pt[0], pt[1]) - az_c))) <= half_width:
                return True
        return False

    def _to_sensor(self, pos: np.ndarray) -> np.ndarray:
        p3 = np.array([pos[0], pos[1], (pos[2] - self.h) if self.dims == 3 else 0.0])
        return self.M.T @ p3

    def _new_track(self, c: np.ndarray, vr: float, z: np.ndarray) -> _Track:
        d = self.dims
        x = np.zeros(3 * d)
        x[:d] = c
        ps = self._to_sensor(c)
        u = ps / max(float(np.linalg.norm(ps)), ekf.MIN_RANGE_M)
        # TI's INIT stage: the set's vr unrolled to the initial radial velocity is the range rate
        rate = float(unroll(vr, INITIAL_RADIAL_VELOCITY_MPS, self.p.max_radial_velocity_mps))
        x[d : 2 * d] = (self.M @ (rate * u))[:d]  # radial motion, back in world axes
        D = np.var(z, axis=0) if len(z) > 1 else np.zeros(self.m)
        t = _Track(id=self.next_id, x=x, P=self.P0.copy(), D=D, state=DETECT, birth=self.frame)
        t.rate = rate
        self.next_id += 1
        if t.hits >= self.p.det2act:
            t.state = ACTIVE
        return t

    def _frame_tracks(self, gc, gs, nas, nis) -> FrameTracks:
        ts = self.tracks
        n, k = len(ts), 3 * self.dims
        confirmed = np.array([t.state == ACTIVE for t in ts], dtype=bool)
        order = sorted(
            (i for i in range(n) if confirmed[i]), key=lambda i: (-int(nas[i]), ts[i].id)
        )
        return FrameTracks(
            ids=np.array([t.id for t in ts], dtype=np.int64),
            state=np.array([t.x for t in ts]).reshape(n, k),
            covariance=np.array([t.P for t in ts]).reshape(n, k, k),
            psi=np.full(n, np.nan),
            confirmed=confirmed,
            gate_center_xy=gc,
            gate_shape_xy=gs,
            birth_frame=np.array([t.birth for t in ts], dtype=np.int64),
            n_associated=np.asarray(nas, dtype=np.int64),
            nis=np.asarray(nis, dtype=float),
            estimate=order[0] if order else -1,
        )


def run_gtrack(points: np.ndarray, frame_offsets: np.ndarray, params: GtrackParams) -> GtrackResult:
    """Run gtrack over F frames from scratch.

    Parameters
    ----------
    points
        (P, 5) per point ``[r (m), az (rad), el (rad), vr (m/s), snr (linear)]`` in the sensor
        frame, frames one after another.
    frame_offsets
        (F + 1,) points of frame f are ``points[frame_offsets[f]:frame_offsets[f + 1]]``.
    params
        :class:`GtrackParams`.
    """
    pts = np.asarray(points, dtype=float).reshape(-1, 5)
    off = np.asarray(frame_offsets, dtype=np.int64)
    tr = GtrackTracker(params)
    frames = []
    point_track = np.full(len(pts), -1, dtype=np.int64)
    presence = np.zeros(len(off) - 1, dtype=bool)
    for f in range(len(off) - 1):
        a, b = off[f], off[f + 1]
        q = pts[a:b]
        ft, pt, pr = tr.step(q[:, 0], q[:, 1], q[:, 2], q[:, 3], q[:, 4])
        frames.append(ft)
        point_track[a:b] = pt
        presence[f] = pr
    return GtrackResult(
        frames=tuple(frames),
        point_track=point_track,
        presence=presence,
        n_active=np.array([int(ft.confirmed.sum()) for ft in frames], dtype=np.int64),
        n_detect=np.array([int((~ft.confirmed).sum()) for ft in frames], dtype=np.int64),
    )
