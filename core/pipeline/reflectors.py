"""The reflectors of every frame of a scene: persons (points or walking bodies), clutter and
static reflectors, each frame drawn from its own random streams (stages truth … scatterers of
the plan)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from core.config import ProcessingSettings
from core.pipeline.plan import Plan, plan, processing_settings
from core.pipeline.streams import stage_rng
from core.scene import Scene, draw_clutter
from core.scene.body import N_BODY_SCATTERERS, body_scatterers, walking_headings
from core.scene.scene import person_seed
from core.scene.walking import (
    N_SEGMENTS,
    RADAR_HEIGHT_M,
    RCS_SHARES,
    default_gait_phase,
    gait_phase,
    heading_rates,
    sit_transition,
    walking_scatterers,
)


@dataclass(frozen=True, slots=True, kw_only=True)
class Reflectors:
    """Builds the scatterers of any frame of a scene (stages truth … scatterers of the plan)."""

    scene: Scene
    seed: int
    antenna: Any
    settings: ProcessingSettings
    truth_t_s: np.ndarray  # (F,)
    truth_xy_m: np.ndarray  # (F, n_persons, 2)
    truth_v_mps: np.ndarray  # (F, n_persons, 2)
    fixed_rcs: np.ndarray  # (n_persons,), NaN where drawn
    extended: np.ndarray  # (n_persons,) bool: a body model (blob or walking) applies
    walking: np.ndarray  # (n_persons,) bool: the walking body (else the blob) where extended
    headings: dict[int, np.ndarray]
    # walking: (phase, turn rate, height, seated fraction and rate (F, 2) or None)
    gait: dict[int, tuple[np.ndarray, np.ndarray, float, np.ndarray | None]]
    run_rcs: bool
    run_clutter: bool
    run_static: bool
    _consts: _FrameConstants
    run_multipath: bool = False

    @classmethod
    def build(cls, scene: Scene, p: Plan, seed: int, antenna, settings) -> Reflectors:
        """The builder of a scene's frames under plan ``p`` (``seed``: every stream's seed)."""
        t_s, xy, v = scene.truth()
        extended = np.array([q.kind != "point" for q in scene.persons], dtype=bool)
        if not p.runs("body_model"):
            extended[:] = False
        walking = extended & np.array([q.kind == "walking" for q in scene.persons], dtype=bool)
        headings = {
            i: walking_headings(q.trajectory.velocity_mps)
            for i, q in enumerate(scene.persons)
            if extended[i]
        }
        gait = {}
        for i in np.flatnonzero(walking):
            q = scene.persons[i]
            n = q.trajectory.n_frames
            phase0 = q.gait_phase
            if phase0 is None:
                phase0 = default_gait_phase(person_seed(scene.seed, int(i)))
            gait[int(i)] = (
                gait_phase(t_s[:n], q.trajectory.speed_mps, q.body_height_m, phase0),
                heading_rates(t_s[:n], headings[i]),
                q.body_height_m,
                sit_transition(t_s[:n], q.trajectory.seated),
            )
        fixed_rcs = np.array([np.nan if q.rcs_dbsm is None else q.rcs_dbsm for q in scene.persons])
        return cls(
            scene=scene,
            seed=seed,
            antenna=antenna,
            settings=settings,
            truth_t_s=t_s,
            truth_xy_m=xy,
            truth_v_mps=v,
            fixed_rcs=fixed_rcs,
            extended=extended,
            walking=walking,
            headings=headings,
            gait=gait,
            run_rcs=p.runs("person_rcs"),
            run_clutter=p.runs("clutter"),
            run_static=p.runs("static_reflectors"),
            run_multipath=p.runs("multipath"),
            _consts=cls._constants(scene, fixed_rcs, p.runs("static_reflectors")),
        )

    def frame(self, f: int) -> tuple[Any, int]:
        """Scatterers of frame ``f`` and the number of clutter reflectors among them.

        Bit for bit the reflectors of the straightforward construction (persons, body parts,
        clutter, static reflectors, in this order) with the same per-frame streams (tested).
        """
        out, n_clutter = self.frames_at(np.array([f], dtype=np.int64))
        return out[0], int(n_clutter[0])

    def frames(self, n_frames: int | None = None) -> tuple[list[Any], np.ndarray]:
        """The scatterers of frames ``0 .. n_frames - 1`` and their clutter counts, at once.

        Bit for bit ``[self.frame(f) for f in range(n_frames)]`` (tested): every frame draws
        from its own streams in the same order; what follows the draws (persons' RCS, clutter
        velocities and RCS, assembly, validation) runs once over all frames instead of once per
        frame. The frames are views into shared arrays.
        """
        n_f = len(self.truth_t_s) if n_frames is None else int(n_frames)
        return self.frames_at(np.arange(n_f, dtype=np.int64))

    def frames_at(self, idx: np.ndarray) -> tuple[list[Any], np.ndarray]:
        """Scatterers and clutter counts of the frames ``idx`` (see :meth:`frames`)."""
        from core import simulation as sim

        scene = self.scene
        k = self._consts
        n_f = len(idx)
        n_p = scene.n_persons
        if n_f == 0:
            return [], np.zeros(0, dtype=np.int64)
        rcs = np.broadcast_to(self.fixed_rcs, (n_f, n_p))
        if self.run_rcs:
            # σ_dBsm ~ N(−8, 16), eq. (5), drawn afresh every frame
            drawn = np.empty((n_f, n_p))
            for row, f in enumerate(idx):
                drawn[row] = sim.draw_person_rcs_dbsm(
                    stage_rng(self.seed, "person_rcs", int(f)), n_p
                )
            rcs = np.where(k.drawn_rcs[None, :], drawn, self.fixed_rcs[None, :])
        xy, v = self.truth_xy_m[idx], self.truth_v_mps[idx]
        active = ~np.isnan(xy[:, :, 0])  # (F, n_p)
        point = active & ~self.extended[None, :]
        n_point = point.sum(axis=1)
        # body persons (blob, walking): their scatterers per frame and person (frame order,
        # person order), laid out densely (F, slots) and taken where the person is active
        body = np.flatnonzero(self.extended)
        n_slots = [N_SEGMENTS if self.walking[i] else N_BODY_SCATTERERS for i in body]
        first_slot = np.concatenate([[0], np.cumsum(n_slots)]).astype(np.int64)
        n_body = np.zeros(n_f, dtype=np.int64)
        body_pos = body_vel = body_rcs = body_src = None
        if len(body):
            width = int(first_slot[-1])
            d_pos = np.zeros((n_f, width, 3))
            d_vel = np.zeros((n_f, width, 3))
            d_rcs = np.zeros((n_f, width))
            d_src = np.empty((n_f, width), dtype=np.int32)
            mask = np.zeros((n_f, width), dtype=bool)
            for j, i in enumerate(body):
                sl = slice(first_slot[j], first_slot[j + 1])
                d_src[:, sl] = i
                rows = np.flatnonzero(active[:, i])
                mask[rows, sl] = True
                if self.walking[i]:
                    if len(rows):
                        d_pos[rows, sl], d_vel[rows, sl], d_rcs[rows, sl] = self._walking_rows(
                            i, idx[rows], xy[rows, i], v[rows, i], rcs[rows, i]
                        )
                    continue
                for at_row in rows:
                    fr = int(idx[at_row])
                    bp, bv, frac = body_scatterers(
                        xy[at_row, i], v[at_row, i], self.headings[i][fr], self.truth_t_s[fr]
                    )
                    d_pos[at_row, sl, :2] = bp
                    d_vel[at_row, sl, :2] = bv
                    # σ_part = σ · share (linear power)
                    d_rcs[at_row, sl] = rcs[at_row, i] + 10 * np.log10(frac)
            n_body = mask.sum(axis=1)
            body_pos, body_vel = d_pos[mask], d_vel[mask]
            body_rcs, body_src = d_rcs[mask], d_src[mask]
        n_clutter = np.zeros(n_f, dtype=np.int64)
        c_pos, c_vr, c_snr = [], [], []
        if self.run_clutter:
            for row, f in enumerate(idx):
                c = draw_clutter(
                    scene.aoi,
                    scene.clutter_density_per_m2,
                    scene.radar,
                    stage_rng(self.seed, "clutter", int(f)),
                )
                n_clutter[row] = len(c)
                c_pos.append(c.position_m)
                c_vr.append(c.radial_velocity_mps)
                c_snr.append(c.snr_db)
        n_static = len(k.static_rcs)
        per_frame = n_point + n_body + n_clutter + n_static
        start = np.zeros(n_f + 1, dtype=np.int64)
        np.cumsum(per_frame, out=start[1:])
        n = int(start[-1])
        position = np.zeros((n, 3))
        velocity = np.zeros((n, 3))
        rcs_all = np.empty(n)
        source = np.empty(n, dtype=np.int32)
        # persons as points: frame f's j-th active point person at start[f] + j
        ff, ii = np.nonzero(point)
        at = start[ff] + (np.cumsum(point, axis=1) - 1)[ff, ii]
        position[at, :2] = xy[ff, ii]
        velocity[at, :2] = v[ff, ii]
        rcs_all[at] = rcs[ff, ii]
        source[at] = ii
        # then the body parts, the clutter and the static reflectors of each frame
        frame_of = np.repeat(np.arange(n_f), per_frame)
        slot = np.arange(n) - start[frame_of]  # position within the frame
        first = n_point[frame_of]
        if body_pos is not None and body_src is not None and len(body_pos):
            at = np.flatnonzero((slot >= first) & (slot < first + n_body[frame_of]))
            position[at] = body_pos
            velocity[at] = body_vel
            rcs_all[at] = body_rcs
            source[at] = body_src
        first = first + n_body[frame_of]
        if n_clutter.any():
            at = np.flatnonzero((slot >= first) & (slot < first + n_clutter[frame_of]))
            pos = np.concatenate(c_pos)
            vr = np.concatenate(c_vr)
            # v = vr p / |p|  (ClutterDraw.velocity_mps)
            r = np.hypot(pos[:, 0], pos[:, 1])
            position[at, :2] = pos
            velocity[at, :2] = pos / r[:, None] * vr[:, None]
            rcs_all[at] = self._clutter_rcs_dbsm(pos, np.concatenate(c_snr))
            source[at] = -1
        if n_static:
            at = np.flatnonzero(slot >= first + n_clutter[frame_of])
            j = slot[at] - (first + n_clutter[frame_of])[at]
            position[at] = k.static_position[j]
            rcs_all[at] = k.static_rcs[j]
            source[at] = k.static_source[j]
        if scene.room is not None:
            return self._in_room(
                position, velocity, rcs_all, source, start, n_point + n_body, n_clutter
            ), n_clutter
        whole_ok = _arrays_ok(position, velocity, rcs_all)
        out = []
        for row in range(n_f):
            s = slice(start[row], start[row + 1])
            part = (position[s], velocity[s], rcs_all[s], source[s])
            # an invalid reflector: the frame's validating constructor names the field
            out.append(_checked_scatterers(sim, *part) if whole_ok else _scatterers(sim, *part))
        return out, n_clutter

    def _in_room(self, position, velocity, rcs, source, start, first_clutter, n_clutter):
        """Each frame's reflectors in the scene's room (furniture, bounce paths, sensor pose;
        :func:`core.simulation.multipath.room_frame`), their ``source`` the path labels."""
        from core import simulation as sim
        from core.simulation.multipath import room_frames

        room = self.scene.room
        assert room is not None
        if not self.run_multipath:
            room = dataclasses.replace(room, walls=())
        radar, antenna, settings = self.scene.radar, self.antenna, self.settings

        def snr_db(r, az, rcs_dbsm):
            return sim.post_processing_snr_db(radar, r, az, rcs_dbsm, antenna, settings)

        # the body models put a person's scatterers relative to a radar RADAR_HEIGHT_M above
        # the floor (core.scene.walking); a room's coordinates start at the floor
        position = position.copy()
        position[source >= 0, 2] += RADAR_HEIGHT_M
        n_f = len(start) - 1
        frame = np.repeat(np.arange(n_f), np.diff(start))
        slot = np.arange(len(frame)) - start[frame]
        clutter = (slot >= first_clutter[frame]) & (slot < (first_clutter + n_clutter)[frame])
        pos, vel, rcs_all, labels, at = room_frames(
            room, position, velocity, rcs, source, clutter, frame, n_f, antenna, snr_db
        )
        whole_ok = _arrays_ok(pos, vel, rcs_all)
        out = []
        for row in range(n_f):
            s = slice(at[row], at[row + 1])
            part = (pos[s], vel[s], rcs_all[s], labels[s])
            out.append(_checked_scatterers(sim, *part) if whole_ok else _scatterers(sim, *part))
        return out

    def _walking_rows(self, i, frames, xy, v, rcs):
        """The walking body of person ``i`` in ``frames`` (vectorised over the frames).

        Returns positions and velocities ``(n, N_SEGMENTS, 3)`` and RCS ``(n, N_SEGMENTS)``
        (dBsm).
        """
        phase, turn, height, seated = self.gait[int(i)]
        pos, vel = walking_scatterers(
            xy,
            v,
            self.headings[i][frames],
            turn[frames],
            phase[frames],
            self.truth_t_s[frames],
            height,
            None if seated is None else seated[frames],
        )
        # σ_segment = σ · share (linear power): the shares sum to 1, so the powers add up to σ
        return pos, vel, rcs[:, None] + 10 * np.log10(RCS_SHARES)[None, :]

    @staticmethod
    def _constants(scene: Scene, fixed_rcs, run_static: bool) -> _FrameConstants:
        """What does not change from frame to frame."""
        static = scene.static_reflectors
        run_static = run_static and bool(static)
        return _FrameConstants(
            drawn_rcs=np.isnan(fixed_rcs),
            static_position=np.array([[q.x_m, q.y_m, q.z_m] for q in static], dtype=np.float64)
            if run_static
            else np.zeros((0, 3)),
            static_rcs=np.array([q.rcs_dbsm for q in static], dtype=np.float64)
            if run_static
            else np.zeros(0),
            static_source=np.full(len(static) if run_static else 0, -1, dtype=np.int32),
        )

    def _clutter_rcs_dbsm(self, xy_m: np.ndarray, snr_db: np.ndarray) -> np.ndarray:
        """RCS giving each clutter reflector its drawn SNR (the link budget's inverse)."""
        from core import simulation as sim

        r = np.hypot(xy_m[:, 0], xy_m[:, 1])
        az = np.arctan2(xy_m[:, 0], xy_m[:, 1])
        return sim.rcs_for_snr_db(self.scene.radar, r, az, snr_db, self.antenna, self.settings)


@dataclass(frozen=True, slots=True, kw_only=True)
class _FrameConstants:
    """Frame-independent inputs of :meth:`Reflectors.frame`."""

    drawn_rcs: np.ndarray  # (n_persons,) bool: RCS drawn every frame
    static_position: np.ndarray  # (S, 3)
    static_rcs: np.ndarray  # (S,)
    static_source: np.ndarray  # (S,) int32, -1


def _arrays_ok(position, velocity, rcs_dbsm) -> bool:
    """What the ``Scatterers`` constructor checks, in one pass: finite, off the radar."""
    return bool(
        np.isfinite(position).all()
        and np.isfinite(velocity).all()
        and np.isfinite(rcs_dbsm).all()
        and (len(position) == 0 or np.einsum("ij,ij->i", position, position).min() > 0)
    )


def _scatterers(sim, position, velocity, rcs_dbsm, source):
    """``Scatterers`` of arrays checked here in one pass (finite, off the radar); arrays that
    fail go through the validating constructor, which names the field."""
    if not _arrays_ok(position, velocity, rcs_dbsm):
        return sim.Scatterers(
            position_m=position, velocity_mps=velocity, rcs_dbsm=rcs_dbsm, source=source
        )
    return _checked_scatterers(sim, position, velocity, rcs_dbsm, source)


def _checked_scatterers(sim, position, velocity, rcs_dbsm, source):
    """``Scatterers`` of arrays already checked (:func:`_arrays_ok`), without the constructor."""
    s = object.__new__(sim.Scatterers)
    for name, value in (
        ("position_m", position),
        ("velocity_mps", velocity),
        ("rcs_dbsm", rcs_dbsm),
        ("source", source),
    ):
        object.__setattr__(s, name, value)
    return s


def frame_scatterers(scene: Scene, frame: int, *, seed: int | None = None, the_plan=None):
    """The reflectors of one frame (persons, clutter, static reflectors) as the chain sees them.

    Returns
    -------
    core.simulation.Scatterers
        ``source``: person index, or −1 for clutter and static reflectors. In a room
        (``scene.room``) the reflectors are in sensor coordinates with the room's furniture and
        bounce paths added, and ``source`` holds the path labels
        (:func:`core.simulation.multipath.split_labels` gives person and path order).
    """
    from core import simulation as sim

    p = the_plan or plan(scene)
    seed = scene.seed if seed is None else int(seed)
    antenna = sim.AntennaGain.draw(scene.radar, stage_rng(seed, "antenna"))
    settings = processing_settings(scene)
    return Reflectors.build(scene, p, seed, antenna, settings).frame(frame)[0]
