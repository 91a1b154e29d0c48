"""``radartune bench gtrack_ti``: RadarTune's gtrack against TI's own tracker on TI's points.

The recording ``pc3_2023-06-21-12-27-01.csv`` (``$RADARTUNE_REAL``, default ``../shared/real``
beside the checkout, folder ``pc3_iwr6843``) holds, per frame, the points of TI's 3-D people
counting firmware (v6), TI's tracks (v7) and TI's point-to-track indices (v8). Its ``.cfg`` is
not known. RadarTune's gtrack runs on TI's points with TI's published default tracker lines
(``resources/gtrack/ti_people_counting_isk.cfg``) under two readings of the unknown pose:

- ``sensor frame``: ``sensorPosition 0 0 0`` and the boxes' z limits widened to [−3, 3] m, because
  TI's tracks in this file lie at the height of their points *in the sensor frame* (the median
  |z_track − z̄_points| is reported; with a 2 m mount and 15° tilt they would be about 1 m
  apart); frame period and radial velocity resolution from the file (time stamps, Doppler step);
- ``sensor frame, moving points only``: as the first, without the zero-Doppler points (TI gave
  none of this file's static points to a track: its v8 marks them 254);
- ``TI default``: the resource's lines as they are (2 m, 15° down).

Figures per reading: the share of frames where the number of ACTIVE tracks equals TI's number of
tracks; the distance between matched tracks (Hungarian on 3-D distance, TI's track of frame f+1
against ours after frame f, as TI's v8 of frame f+1 indexes the points of frame f); the share of
points given to the same track (TI's ids mapped to ours by the largest overlap of points) and
the share left unassigned by both.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

RECORDING = "pc3_iwr6843/pc3_2023-06-21-12-27-01.csv"
#: The folder's other two files: the overhead AOP one carries TI's tracks, the 2021-12 one not.
OTHER_RECORDINGS = (
    "pc3_iwr6843/pc3Aop2021-04-07-23-52-34.csv",
    "pc3_iwr6843/pc3_2021-12-19-21-25-28.csv",
)


def _resource_params():
    from core.files import read_text
    from core.formats.ti_cfg import parse_ti_cfg
    from core.tracking.gtrack.params import params_from_cfg

    path = Path(__file__).resolve().parents[2] / "resources/gtrack/ti_people_counting_isk.cfg"
    return params_from_cfg(parse_ti_cfg(read_text(path), str(path)), str(path)), path


def _compare(rec, res, lag: int) -> dict:
    """Agreement of a gtrack run with TI's tracks and point indices (see the module docstring)."""
    from scipy.optimize import linear_sum_assignment

    ref = rec.ref_tracks
    n = rec.n_frames
    counts_ti = np.bincount(ref["frame"], minlength=n)
    ours = [ft.state[ft.confirmed, :3] for ft in res.frames]
    our_ids = [ft.ids[ft.confirmed] for ft in res.frames]
    same, dists, frames = 0, [], 0
    for f in range(n - lag):
        g = f + lag
        ti = np.column_stack([ref[k][ref["frame"] == g] for k in ("x_m", "y_m", "z_m")])
        frames += 1
        same += int(len(ti) == len(ours[f]))
        if len(ti) and len(ours[f]):
            d = np.linalg.norm(ti[:, None] - ours[f][None], axis=2)
            r, c = linear_sum_assignment(d)
            dists += d[r, c].tolist()
    # points: TI's id per point (its frame's v8), ours from the same frame
    ti_pt, our_pt = rec.ref_point_track, res.point_track
    pairs: dict[tuple[int, int], int] = {}
    for a, b in zip(ti_pt[(ti_pt >= 0) & (our_pt >= 0)], our_pt[(ti_pt >= 0) & (our_pt >= 0)]):
        pairs[(int(a), int(b))] = pairs.get((int(a), int(b)), 0) + 1
    mapping: dict[int, int] = {}
    for (a, b), _ in sorted(pairs.items(), key=lambda kv: -kv[1]):
        if a not in mapping and b not in mapping.values():
            mapping[a] = b
    mapped = np.array([mapping.get(int(a), -2) if a >= 0 else -1 for a in ti_pt])
    ti_assigned = ti_pt >= 0
    d = np.asarray(dists)
    return {
        "frames_compared": frames,
        "count_agreement": same / max(frames, 1),
        "mean_tracks_ti": float(np.mean(counts_ti)),
        "mean_tracks_ours": float(np.mean([len(o) for o in ours])),
        "matched_distance_median_m": float(np.median(d)) if len(d) else None,
        "matched_distance_p90_m": float(np.percentile(d, 90)) if len(d) else None,
        "points_ti_assigned": int(ti_assigned.sum()),
        "points_ours_assigned": int((our_pt >= 0).sum()),
        "share_ti_points_same_track": float(np.mean(our_pt[ti_assigned] == mapped[ti_assigned]))
        if ti_assigned.any()
        else None,
        "share_unassigned_both": float(np.mean(our_pt[~ti_assigned] < 0)),
        "share_points_agree": float(np.mean(np.where(ti_assigned, our_pt == mapped, our_pt < 0))),
        "id_mapping_ti_to_ours": {str(k): int(v) for k, v in mapping.items()},
        "our_track_ids": sorted({int(i) for ids in our_ids for i in ids}),
    }


def run(quick: bool = False) -> dict:
    from core.benchmarks.clouds import real_data_dir
    from core.recordings import read_recording
    from core.tracking.gtrack.tracker import run_gtrack

    root = real_data_dir()
    path = root / RECORDING
    rec = read_recording(path, fmt=None, cfg=None)
    if rec.ref_tracks is None or rec.ref_point_track is None:
        from core.errors import InputError

        raise InputError("the recording holds no TI tracks (v7) or point indices (v8)", str(path))
    ref, ref_pt = rec.ref_tracks, rec.ref_point_track
    ds_points = _recording_points(rec)
    off = np.concatenate(([0], np.cumsum(rec.counts))).astype(np.int64)
    # evidence for the pose: TI's track height against its points' sensor-frame height
    z_gap = []
    for f in range(1, rec.n_frames):
        for k in np.flatnonzero(ref["frame"] == f):
            tid = ref["track_id"][k]
            sel = ref_pt[off[f - 1] : off[f]] == tid
            if sel.sum() >= 3:
                z_pts = rec.cloud.z_m[off[f - 1] : off[f]][sel]
                z_gap.append(abs(ref["z_m"][k] - float(np.mean(z_pts))))
    vr = np.abs(rec.cloud.radial_velocity_mps)
    step = float(np.min(vr[vr > 1e-6])) if np.any(vr > 1e-6) else 0.1
    period = float(rec.radar.frame_period_s)
    base, cfg_path = _resource_params()
    readings = {"sensor frame": _sensor_frame(base, period, step), "TI default": base}
    out: dict = {
        "recording": str(path),
        "frames": int(rec.n_frames),
        "points": int(len(ds_points)),
        "static_point_share": float(np.mean(vr < 0.5 * step)),
        "doppler_step_mps": step,
        "frame_period_s": period,
        "ti_track_minus_points_z_median_m": float(np.median(z_gap)) if z_gap else None,
        "base_cfg": "resources/gtrack/ti_people_counting_isk.cfg",
        "readings": {},
    }
    readings["sensor frame, moving points only"] = readings["sensor frame"]
    moving = vr >= 0.5 * step
    for name, params in readings.items():
        if name.endswith("moving points only"):
            # TI gave none of the file's static points to a track: leave them out
            frame_of = np.repeat(np.arange(rec.n_frames), rec.counts)
            per_frame = np.bincount(frame_of[moving], minlength=rec.n_frames)
            keep_off = np.concatenate(([0], np.cumsum(per_frame)))
            sub = run_gtrack(ds_points[moving], keep_off.astype(np.int64), params)
            point_track = np.full(len(ds_points), -1, dtype=np.int64)
            point_track[moving] = sub.point_track
            res = replace(sub, point_track=point_track)
        else:
            res = run_gtrack(ds_points, off, params)
        out["readings"][name] = {
            "params": params.to_dict(),
            "lag_1": _compare(rec, res, 1),
            "lag_0": _compare(rec, res, 0),
        }
    out["other_recordings"] = {name: _other(root / name, base) for name in OTHER_RECORDINGS}
    return out


def _sensor_frame(base, period: float, step: float):
    """The 'sensor frame' reading of TI's lines: no pose, the boxes' z limits [−3, 3] m, the
    file's frame period and Doppler step."""
    return replace(
        base,
        sensor_height_m=0.0,
        sensor_azimuth_tilt_deg=0.0,
        sensor_elevation_tilt_deg=0.0,
        boundary_z_min_m=-3.0,
        boundary_z_max_m=3.0,
        static_z_min_m=-3.0,
        static_z_max_m=3.0,
        presence_z_min_m=-3.0,
        presence_z_max_m=3.0,
        frame_period_s=period,
        radial_velocity_resolution_mps=step,
    )


def _other(path: Path, base) -> dict:
    """One of the folder's other files: its size and, when it carries TI's tracks, the
    'sensor frame' reading's agreement (same figures as the main file)."""
    from core.recordings import read_recording
    from core.tracking.gtrack.tracker import run_gtrack

    if not path.is_file():
        return {"missing": True}
    rec = read_recording(path, fmt=None, cfg=None)
    doc: dict = {
        "frames": int(rec.n_frames),
        "points": int(len(rec.cloud.range_m)),
        "max_points_a_frame": int(np.max(rec.counts, initial=0)),
        "ti_tracks": rec.ref_tracks is not None and rec.ref_point_track is not None,
    }
    if not doc["ti_tracks"]:
        return doc
    vr = np.abs(rec.cloud.radial_velocity_mps)
    step = float(np.min(vr[vr > 1e-6])) if np.any(vr > 1e-6) else 0.1
    params = _sensor_frame(base, float(rec.radar.frame_period_s), step)
    off = np.concatenate(([0], np.cumsum(rec.counts))).astype(np.int64)
    res = run_gtrack(_recording_points(rec), off, params)
    ref = rec.ref_tracks
    assert ref is not None
    doc["ti_track_ids"] = sorted({int(i) for i in ref["track_id"]})
    doc["sensor frame"] = {"lag_1": _compare(rec, res, 1)}
    return doc


def _recording_points(rec) -> np.ndarray:
    c = rec.cloud
    snr = 10.0 ** (np.nan_to_num(np.asarray(c.snr_db, float), nan=-np.inf) / 10.0)
    return np.column_stack([c.range_m, c.azimuth_rad, c.elevation_rad, c.radial_velocity_mps, snr])


def summary(result: dict) -> str:
    lines = [
        f"gtrack against TI's tracker on {result['recording']} ({result['frames']} frames, "
        f"{result['points']} points, {result['static_point_share']:.0%} static); TI's track z "
        f"minus its points' sensor-frame z: median {result['ti_track_minus_points_z_median_m']:.2f}"
        " m",
    ]
    for name, r in result["readings"].items():
        a = r["lag_1"]
        med = a["matched_distance_median_m"]
        lines.append(
            f"  {name}: same track count in {a['count_agreement']:.0%} of frames (tracks a frame: "
            f"TI {a['mean_tracks_ti']:.2f}, ours {a['mean_tracks_ours']:.2f}); matched distance "
            + (f"median {med:.2f} m, 90 % {a['matched_distance_p90_m']:.2f} m" if med else "n/a")
            + "; points: TI's tracked points on our same track "
            + (
                f"{a['share_ti_points_same_track']:.0%}"
                if a["share_ti_points_same_track"] is not None
                else "n/a"
            )
            + f", unassigned by both {a['share_unassigned_both']:.0%}"
        )
    for name, o in result.get("other_recordings", {}).items():
        if o.get("missing"):
            lines.append(f"  {name}: not found")
            continue
        head = f"  {name}: {o['frames']} frames, {o['points']} points (at most "
        head += f"{o['max_points_a_frame']} a frame)"
        if not o["ti_tracks"]:
            lines.append(head + "; no TI tracks: not compared")
            continue
        a = o["sensor frame"]["lag_1"]
        lines.append(
            head + f"; TI's track ids {o['ti_track_ids']}; sensor frame: same track count in "
            f"{a['count_agreement']:.0%} of frames (TI {a['mean_tracks_ti']:.2f}, ours "
            f"{a['mean_tracks_ours']:.2f} a frame)"
        )
    return "\n".join(lines)
