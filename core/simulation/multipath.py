"""Multipath by the image method: scatterers and walls → the equivalent scatterers of the bounce
paths, with their path order (docs/rooms.md).

A path leaves the radar R towards the scatterer S, directly or by a bounce on wall i, and comes
back directly or by a bounce on wall j. Mirroring S in a wall turns a bounced leg into a straight
one: with ``T`` the transmit image (S, or S mirrored in wall i) and ``Q`` the receive image (S,
or S mirrored in wall j), the path is

    L = |T - R| + |Q - R|                       (length)
    dL/dt = v_T . (T - R)/|T - R| + v_Q . (Q - R)/|Q - R|

(``v_T``, ``v_Q``: S's velocity mirrored like S). Its order is the number of bounces (0, 1, 2):
(i, -) and (-, j) are first order, (i, j) second. The radar sees the path as a point target at
range ``L / 2``, radial velocity ``(dL/dt) / 2``, in the direction of the last leg (from Q).
Eq. (4) with the path's two legs and its bounce losses ``rho`` (linear power factors):

    Pr = Pt Gt(theta_T) Gr(theta_Q) lambda^2 sigma rho_i rho_j / ((4 pi)^3 |T - R|^2 |Q - R|^2)

so the equivalent scatterer at ``Re = L / 2`` in the direction ``theta_Q`` has the RCS

    sigma_e = sigma rho_i rho_j Re^4 / (|T - R|^2 |Q - R|^2) * Gt(theta_T) / Gt(theta_Q)

(the simulator applies ``Gt(theta_Q) Gr(theta_Q)`` to it). The two first-order paths (i, -)
and (-, i) have the same length and Doppler: one ghost whose two contributions arrive from S and
from S's image; likewise (i, j) and (j, i). A bounce counts only where it is specular on the
wall: the leg crosses the wall's line inside the segment, with the radar and S in front of it.
Legs that leave or arrive behind the radar's aperture (sensor ``y <= 0``) carry nothing.
Occlusion is not modelled.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from core.scene.room import N_FURNITURE_SCATTERERS, Room, Wall
from core.simulation.antenna import AntennaGain


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class ImagePaths:
    """The bounce paths of a set of scatterers, as equivalent scatterers (room coordinates).

    Attributes
    ----------
    position_m
        ``(M, 3)`` ``R + (L / 2) u_Q``: range half the path length along the last leg.
    velocity_mps
        ``(M, 3)`` ``(dL/dt / 2) u_Q``: the path's Doppler as a radial velocity.
    rcs_dbsm
        ``(M,)`` equivalent RCS (eq. (4) with the path's legs and bounce losses).
    index
        ``(M,)`` the scatterer each path belongs to.
    path_order
        ``(M,)`` int8: 1 or 2 bounces.
    length_m, rate_mps
        ``(M,)`` path length ``L`` and its rate ``dL/dt``.
    """

    position_m: np.ndarray
    velocity_mps: np.ndarray
    rcs_dbsm: np.ndarray
    index: np.ndarray
    path_order: np.ndarray
    length_m: np.ndarray
    rate_mps: np.ndarray

    def __len__(self) -> int:
        return len(self.index)


def _wall_arrays(walls: Sequence[Wall]):
    """Per wall: a point ``a`` (W, 2), unit normal ``n`` (W, 2), unit direction ``e`` (W, 2),
    length (W,) and linear reflection (W,)."""
    a = np.array([w.from_m for w in walls], dtype=np.float64).reshape(-1, 2)
    b = np.array([w.to_m for w in walls], dtype=np.float64).reshape(-1, 2)
    length = np.hypot(*(b - a).T)
    e = (b - a) / length[:, None]
    n = np.column_stack((-e[:, 1], e[:, 0]))
    rho = np.array([w.reflection for w in walls], dtype=np.float64)
    return a, n, e, length, rho


def mirror(points: np.ndarray, a: np.ndarray, n: np.ndarray) -> np.ndarray:
    """``points`` ``(..., 3)`` mirrored in the vertical plane through ``a`` (x, y) with unit
    normal ``n`` (x, y): ``p' = p - 2 ((p - a) . n) n`` in x-y, z unchanged."""
    out = np.array(points, dtype=np.float64, copy=True)
    d = (out[..., 0] - a[0]) * n[0] + (out[..., 1] - a[1]) * n[1]
    out[..., 0] -= 2 * d * n[0]
    out[..., 1] -= 2 * d * n[1]
    return out


def mirror_velocity(velocity: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Velocities ``(..., 3)`` mirrored like positions (no translation)."""
    out = np.array(velocity, dtype=np.float64, copy=True)
    d = out[..., 0] * n[0] + out[..., 1] * n[1]
    out[..., 0] -= 2 * d * n[0]
    out[..., 1] -= 2 * d * n[1]
    return out


def _specular(radar_xy, s_xy, a, n, e, length) -> np.ndarray:
    """``(N,)`` whether the bounce of the leg between the radar and ``s`` on this wall is
    specular: the radar and ``s`` strictly in front of the wall's line (the same side) and the
    reflection point inside the segment."""
    d_r = (radar_xy[0] - a[0]) * n[0] + (radar_xy[1] - a[1]) * n[1]
    d_s = (s_xy[:, 0] - a[0]) * n[0] + (s_xy[:, 1] - a[1]) * n[1]
    same = d_r * d_s > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        t = d_r / (d_r + d_s)  # fraction of the way from the radar to the image of s
    # reflection point P = R + t (S' - R); S' = s - 2 d_s n
    img = s_xy - 2 * d_s[:, None] * n[None, :]
    p = radar_xy[None, :] + t[:, None] * (img - radar_xy[None, :])
    u = (p[:, 0] - a[0]) * e[0] + (p[:, 1] - a[1]) * e[1]
    return same & (u >= 0) & (u <= length)


def image_paths(
    room: Room,
    position_m: np.ndarray,
    velocity_mps: np.ndarray,
    rcs_dbsm: np.ndarray,
    antenna: AntennaGain,
    *,
    max_order: int = 2,
    floor_rcs_dbsm: float = -np.inf,
) -> ImagePaths:
    """The first- (and second-) order bounce paths of scatterers in a room.

    Parameters
    ----------
    room
        Walls and sensor pose.
    position_m, velocity_mps
        ``(N, 3)`` scatterers in room coordinates (z above the floor).
    rcs_dbsm
        ``(N,)`` their RCS.
    antenna
        The radar's azimuth gain (departure and arrival directions differ on a bounced path).
    max_order
        1: only single bounces; 2: also a bounce on the way out and one on the way back.
    floor_rcs_dbsm
        Paths whose equivalent RCS is below this are left out (-inf: none).

    Returns
    -------
    ImagePaths
        Every contribution: (i, -) then (-, j) per wall, then (i, j) per wall pair, each block
        in scatterer order; absorbing walls (``-inf`` dB) and non-specular bounces give none.
    """
    pos = np.asarray(position_m, dtype=np.float64).reshape(-1, 3)
    vel = np.asarray(velocity_mps, dtype=np.float64).reshape(-1, 3)
    rcs = np.asarray(rcs_dbsm, dtype=np.float64).reshape(-1)
    walls = [w for w in room.walls if w.reflection > 0]
    if not walls or not len(pos):
        return _empty()
    a, n, e, length, rho = _wall_arrays(walls)
    radar = room.sensor.position_m
    rot = room.sensor.rotation()
    n_s, n_w = len(pos), len(walls)
    # images of every scatterer in every wall: (W, N, 3), and where the bounce is specular
    img = np.stack([mirror(pos, a[w], n[w]) for w in range(n_w)])
    img_v = np.stack([mirror_velocity(vel, n[w]) for w in range(n_w)])
    ok = np.stack(
        [_specular(radar[:2], pos[:, :2], a[w], n[w], e[w], length[w]) for w in range(n_w)]
    )
    # candidate legs: 0 = direct (S), 1 + w = by wall w (image in w)
    legs_p = np.concatenate((pos[None], img))  # (W + 1, N, 3)
    legs_v = np.concatenate((vel[None], img_v))
    legs_ok = np.concatenate((np.ones((1, n_s), dtype=bool), ok))
    legs_rho = np.concatenate(([1.0], rho))
    d = legs_p - radar  # (W + 1, N, 3)
    dist = np.linalg.norm(d, axis=2)
    u = d / dist[..., None]
    rate = np.einsum("lnk,lnk->ln", legs_v, u)  # d|leg|/dt
    u_s = u @ rot.T  # sensor axes: azimuth and whether in front of the aperture
    az = np.arctan2(u_s[..., 0], u_s[..., 1])
    front = u_s[..., 1] > 0
    gain_db = antenna.gain_db(az)
    usable = legs_ok & front & (dist > 0)
    tx, rx = np.meshgrid(np.arange(n_w + 1), np.arange(n_w + 1), indexing="ij")
    order = (tx > 0).astype(np.int8) + (rx > 0).astype(np.int8)
    keep = (order > 0) & (order <= max_order)
    # (i, -) and (-, j) first, then (i, j): first order before second
    pairs = sorted(zip(tx[keep].tolist(), rx[keep].tolist()), key=lambda p: (p[0] > 0) + (p[1] > 0))
    parts = []
    for i, j in pairs:
        good = usable[i] & usable[j]
        if not good.any():
            continue
        k = np.flatnonzero(good)
        length_m = dist[i, k] + dist[j, k]  # L = |T - R| + |Q - R|
        rate_mps = rate[i, k] + rate[j, k]  # dL/dt
        re = length_m / 2
        # sigma_e = sigma rho_i rho_j Re^4 / (|T-R|^2 |Q-R|^2) Gt(theta_T) / Gt(theta_Q)
        rcs_e = (
            rcs[k]
            + 10 * np.log10(legs_rho[i] * legs_rho[j])
            + 40 * np.log10(re)
            - 20 * np.log10(dist[i, k] * dist[j, k])
            + gain_db[i, k]
            - gain_db[j, k]
        )
        bright = rcs_e >= floor_rcs_dbsm
        if not bright.any():
            continue
        k, length_m, rate_mps, re, rcs_e = (
            k[bright],
            length_m[bright],
            rate_mps[bright],
            re[bright],
            rcs_e[bright],
        )
        uq = u[j, k]
        parts.append(
            (
                radar + re[:, None] * uq,
                (rate_mps / 2)[:, None] * uq,
                rcs_e,
                k,
                np.full(len(k), (i > 0) + (j > 0), dtype=np.int8),
                length_m,
                rate_mps,
            )
        )
    if not parts:
        return _empty()
    cols = [np.concatenate(c) for c in zip(*parts)]
    return ImagePaths(
        position_m=cols[0],
        velocity_mps=cols[1],
        rcs_dbsm=cols[2],
        index=cols[3].astype(np.int64),
        path_order=cols[4].astype(np.int8),
        length_m=cols[5],
        rate_mps=cols[6],
    )


def _empty() -> ImagePaths:
    z = np.zeros(0)
    return ImagePaths(
        position_m=np.zeros((0, 3)),
        velocity_mps=np.zeros((0, 3)),
        rcs_dbsm=z,
        index=np.zeros(0, dtype=np.int64),
        path_order=np.zeros(0, dtype=np.int8),
        length_m=z,
        rate_mps=z,
    )


# ---- a frame's reflectors in a room -------------------------------------------------------------

#: Bounce paths whose post-processing SNR (eq. (4) and the FFT gains, on-bin) is below this are
#: left out of the frame: docs/decisions/rooms-01-multipath.md measures what that leaves out.
GHOST_FLOOR_SNR_DB = 0.0
#: ``source`` labels of non-person reflectors that are not clutter (furniture, static
#: reflectors): ``STATIC_LABEL - path_order`` (see :func:`path_labels`).
STATIC_LABEL = -10


def path_labels(source: np.ndarray, path_order: np.ndarray, clutter: np.ndarray) -> np.ndarray:
    """The labels a frame's reflectors carry through a fidelity level: the person and the path
    order in one int32, decoded by :func:`split_labels`.

    Person ``p`` by a path of ``k`` bounces: ``3 p + k`` (>= 0, so the levels still see a
    person); another reflector: ``STATIC_LABEL - k``; clutter: -1.
    """
    source = np.asarray(source, dtype=np.int64)
    k = np.asarray(path_order, dtype=np.int64)
    out = np.where(source >= 0, 3 * source + k, STATIC_LABEL - k)
    return np.where(clutter, -1, out).astype(np.int32)


def split_labels(labels: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(source, path_order)`` of :func:`path_labels`' labels; -1 (clutter) and -2 (noise, no
    reflector) keep their source and get path order -1."""
    labels = np.asarray(labels, dtype=np.int64)
    person = labels >= 0
    static = labels <= STATIC_LABEL
    source = np.where(person, labels // 3, np.where(static, -1, labels))
    order = np.where(person, labels % 3, np.where(static, STATIC_LABEL - labels, -1))
    return source.astype(np.int32), order.astype(np.int8)


#: The bounce paths of a person's body start from this many proxies (docs/rooms.md): its
#: scatterers sorted by speed and cut into groups of consecutive speeds.
GHOST_GROUPS = 3


def ghost_groups(
    source: np.ndarray,
    velocity_mps: np.ndarray,
    furniture: np.ndarray,
    frame: np.ndarray | None = None,
) -> np.ndarray:
    """``(N,)`` the proxy each reflector's bounce paths start from (the index of the proxy's
    first member).

    A person's scatterers (``source >= 0``) of one frame (``frame``, default all one frame)
    are sorted by speed and split into :data:`GHOST_GROUPS` groups of (nearly) equal counts,
    as ``numpy.array_split`` cuts them; a piece of furniture (five consecutive ``furniture``
    reflectors) is one group; any other reflector is its own group.
    """
    n = len(source)
    source = np.asarray(source, dtype=np.int64)
    frame = np.zeros(n, dtype=np.int64) if frame is None else np.asarray(frame, dtype=np.int64)
    group = np.arange(n, dtype=np.int64)
    person = np.flatnonzero(source >= 0)
    if len(person):
        speed = np.linalg.norm(velocity_mps[person], axis=1)
        order = person[np.lexsort((speed, source[person], frame[person]))]
        key = frame[order] * (int(source.max()) + 1) + source[order]
        first = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
        count = np.diff(np.r_[first, len(order)])
        rank = np.arange(len(order)) - np.repeat(first, count)
        size = np.repeat(count, count)
        g = np.minimum(GHOST_GROUPS, size)
        # numpy.array_split: the first (size % g) parts have one more member
        big, small = size // g + 1, size // g
        n_big = size % g
        part = np.where(rank < n_big * big, rank // big, n_big + (rank - n_big * big) // small)
        # a group is named by its first member in the sorted order
        start = np.repeat(first, count) + np.where(
            part < n_big, part * big, n_big * big + (part - n_big) * small
        )
        group[order] = order[start]
    f = np.flatnonzero(furniture)
    if len(f):
        group[f] = f[(np.arange(len(f)) // N_FURNITURE_SCATTERERS) * N_FURNITURE_SCATTERERS]
    return group


def group_proxies(group, position_m, velocity_mps, rcs_dbsm, source):
    """One proxy per group: the RCS the group's powers sum to, ``sigma_g = sum sigma_k``, at the
    power-weighted mean position and velocity. Returns ``(G, 3)``, ``(G, 3)``, ``(G,)``,
    ``(G,)`` and the groups' keys ``(G,)`` (sorted)."""
    keys, inverse = np.unique(group, return_inverse=True)
    w = 10 ** (np.asarray(rcs_dbsm) / 10)
    total = np.bincount(inverse, weights=w, minlength=len(keys))
    cols = [
        np.bincount(inverse, weights=w * a[:, c], minlength=len(keys))
        for a in (position_m, velocity_mps)
        for c in range(3)
    ]
    return (
        np.column_stack(cols[:3]) / total[:, None],
        np.column_stack(cols[3:]) / total[:, None],
        10 * np.log10(total),
        np.asarray(source)[keys],
        keys,
    )


def room_frames(
    room: Room,
    position_m: np.ndarray,
    velocity_mps: np.ndarray,
    rcs_dbsm: np.ndarray,
    source: np.ndarray,
    clutter: np.ndarray,
    frame: np.ndarray,
    n_frames: int,
    antenna: AntennaGain,
    snr_db,
):
    """Every frame's reflectors in a room, in sensor coordinates, with their path labels.

    ``position_m``, ``velocity_mps`` ``(N, 3)``: persons and static reflectors in room
    coordinates; clutter (``clutter`` ``(N,)`` bool) is already in sensor coordinates (it stands
    for returns drawn around the radar); ``frame`` ``(N,)`` each reflector's frame
    (non-decreasing, ``0 .. n_frames - 1``). Each frame gets the room's furniture (static, label
    ``STATIC_LABEL``), then the bounce paths (:func:`image_paths`) of its non-clutter
    reflectors' proxies (:func:`ghost_groups`) whose post-processing SNR
    ``snr_db(range_m, azimuth_rad, rcs_dbsm)`` reaches :data:`GHOST_FLOOR_SNR_DB`.

    Returns positions and velocities ``(M, 3)`` (sensor coordinates), RCS ``(M,)``, labels
    ``(M,)`` (:func:`path_labels`) and ``start`` ``(n_frames + 1,)``: frame ``f`` is
    ``start[f]:start[f + 1]``, in the order direct reflectors, furniture, clutter, paths.
    """
    pos = np.asarray(position_m, dtype=np.float64)
    vel = np.asarray(velocity_mps, dtype=np.float64)
    rcs = np.asarray(rcs_dbsm, dtype=np.float64)
    src = np.asarray(source, dtype=np.int64)
    clutter = np.asarray(clutter, dtype=bool)
    frame = np.asarray(frame, dtype=np.int64)
    f_pos, f_rcs = room.furniture_scatterers()
    n_fur = len(f_rcs)
    real = ~clutter
    # the frame's real reflectors, then its furniture
    fr_fur = np.repeat(np.arange(n_frames), n_fur)
    b_frame = np.concatenate((frame[real], fr_fur))
    b_block = np.concatenate((np.zeros(int(real.sum()), np.int64), np.ones(len(fr_fur), np.int64)))
    b_pos = np.concatenate((pos[real], np.tile(f_pos, (n_frames, 1))))
    b_vel = np.concatenate((vel[real], np.zeros((len(fr_fur), 3))))
    b_rcs = np.concatenate((rcs[real], np.tile(f_rcs, n_frames)))
    b_src = np.concatenate((src[real], np.full(len(fr_fur), -1, dtype=np.int64)))
    by = np.lexsort((b_block, b_frame))  # frame by frame: real reflectors, then furniture
    b_frame, b_pos, b_vel, b_rcs, b_src = b_frame[by], b_pos[by], b_vel[by], b_rcs[by], b_src[by]
    is_fur = b_block[by] == 1
    group = ghost_groups(b_src, b_vel, is_fur, b_frame)
    p_pos, p_vel, p_rcs, p_src, keys = group_proxies(group, b_pos, b_vel, b_rcs, b_src)
    p_frame = b_frame[keys]
    paths = image_paths(room, p_pos, p_vel, p_rcs, antenna)
    g_pos, g_vel = room.sensor.to_sensor(paths.position_m, paths.velocity_mps)
    bright = np.zeros(len(paths), dtype=bool)
    if len(paths):
        r = np.linalg.norm(g_pos, axis=1)
        az = np.arctan2(g_pos[:, 0], g_pos[:, 1])
        bright = snr_db(r, az, paths.rcs_dbsm) >= GHOST_FLOOR_SNR_DB
    g_frame = p_frame[paths.index[bright]]
    g_labels = path_labels(
        p_src[paths.index[bright]], paths.path_order[bright], np.zeros(int(bright.sum()), bool)
    )
    d_pos, d_vel = room.sensor.to_sensor(b_pos, b_vel)
    d_labels = path_labels(b_src, np.zeros(len(b_src)), np.zeros(len(b_src), dtype=bool))
    all_frame = np.concatenate((b_frame, frame[clutter], g_frame))
    all_block = np.concatenate(
        (
            np.zeros(len(b_frame), np.int64),
            np.ones(int(clutter.sum()), np.int64),
            np.full(len(g_frame), 2, np.int64),
        )
    )
    order = np.lexsort((all_block, all_frame))  # stable: each block keeps its order
    out_pos = np.concatenate((d_pos, pos[clutter], g_pos[bright]))[order]
    out_vel = np.concatenate((d_vel, vel[clutter], g_vel[bright]))[order]
    out_rcs = np.concatenate((b_rcs, rcs[clutter], paths.rcs_dbsm[bright]))[order]
    labels = np.concatenate((d_labels, np.full(int(clutter.sum()), -1, dtype=np.int32), g_labels))[
        order
    ]
    start = np.zeros(n_frames + 1, dtype=np.int64)
    np.cumsum(np.bincount(all_frame, minlength=n_frames), out=start[1:])
    return out_pos, out_vel, out_rcs, labels, start
