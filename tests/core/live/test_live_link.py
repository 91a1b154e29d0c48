"""The live link against the sensor emulator on pseudo-terminals: the cfg dialogue, frames
tracked as they arrive, the recording byte for byte, sensorStop, and each fault."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from core.errors import InputError
from core.formats.recording import to_dataset
from core.live import LinkError, LinkSettings, LiveLink
from core.live.dialogue import classify
from core.live.emulator import Faults, SensorEmulator
from core.recordings import read_recording
from core.tracking import TrackerParams, run_tracker
from tests.live_capture import VELOCITY_XY_MPS, person_xy

FAST = 0.004  # s between packets where the test is not about timing


def run_link(em, cfg, record=None, n=None, **settings):
    link = LiveLink(
        LinkSettings(cli_port=em.cli_port, data_port=em.data_port, cfg=str(cfg), **settings),
        record=record,
    )
    frames, err = [], None
    try:
        link.start()
        for f in link.frames():
            frames.append(f)
            if n is not None and len(frames) >= n:
                break
    except LinkError as exc:
        err = exc
    finally:
        link.close()
    return link, frames, err


def cfg_lines(cfg):
    return [
        " ".join(ln.split())
        for ln in cfg.read_text().splitlines()
        if ln.strip() and not ln.startswith("%")
    ]


def test_answers_are_classified_as_ti_firmware_prints_them() -> None:
    assert classify("sensorStop", "sensorStop\r\nDone\r\n").accepted
    ok = classify("sensorStop", "sensorStop\r\nIgnored: Sensor is already stopped\r\nDone\r\n")
    assert ok.accepted and ok.lines == ("Ignored: Sensor is already stopped", "Done")
    bad = classify("fooCfg 1", "fooCfg 1\r\n'fooCfg' is not recognized as a CLI command\r\n")
    assert not bad.accepted and bad.error == "'fooCfg' is not recognized as a CLI command"
    err = classify("profileCfg 0 61", "profileCfg 0 61\r\nError -1\r\n")
    assert not err.accepted and err.error == "Error -1"
    # an error line beside Done is still a rejection; silence is not an acceptance
    assert not classify("x", "x\r\nError -2\r\nDone\r\n").accepted
    assert not classify("x", "x\r\n").accepted


def test_happy_path_tracks_records_and_stops(capture, tmp_path) -> None:
    data, cfg = capture
    rec = tmp_path / "rec.dat"
    with SensorEmulator(data, faults=Faults(frame_period_s=FAST)) as em:
        link, frames, err = run_link(em, cfg, record=rec, n=60)
        assert err is None
        # the cfg went line by line, in order, then sensorStop on the way out
        assert em.commands == [*cfg_lines(cfg), "sensorStop"]
        assert em.stopped.is_set()
        assert bytes(em.sent) == data
    assert [f.index for f in frames] == list(range(60))
    assert [f.frame_number for f in frames] == list(range(1, 61))
    assert all(len(f.cloud) == 3 for f in frames)
    # the recording is the data port's bytes, unchanged
    assert rec.read_bytes() == data
    # the person is tracked: a confirmed track within 0.3 m and 0.3 m/s of the truth
    for f in frames[20:]:
        t = f.tracks
        assert t.confirmed.any()
        d = np.hypot(*(t.state[t.confirmed, :2] - person_xy(f.t_s)).T)
        k = np.argmin(d)
        assert d[k] < 0.3
        assert np.hypot(*(t.state[t.confirmed][k, 2:4] - VELOCITY_XY_MPS)) < 0.3
    # importable, and re-tracking the import gives the live tracks (same frames, same numbers)
    ds = to_dataset(read_recording(rec, fmt=None, cfg=cfg), source_name=str(rec))
    assert ds.n_frames == 60
    ref = run_tracker(
        [ds.point_cloud(k).measurements() for k in range(60)],
        TrackerParams.default("cv"),
        link.radar.frame_period_s,
    )
    for f, r in zip(frames, ref.frames):
        np.testing.assert_array_equal(f.tracks.ids, r.ids)
        np.testing.assert_allclose(f.tracks.state, r.state, rtol=0, atol=1e-9)
        np.testing.assert_array_equal(f.tracks.confirmed, r.confirmed)


def test_frames_arrive_at_the_cfgs_frame_rate(capture) -> None:
    data, cfg = capture  # frameCfg: 50 ms
    with SensorEmulator(data) as em:
        _, frames, err = run_link(em, cfg, n=15)
    assert err is None and em.frame_period_s == pytest.approx(0.05)
    dt = np.diff([f.received_s for f in frames])
    assert np.median(dt) == pytest.approx(0.05, abs=0.005)


def test_error_answer_stops_at_that_line(capture, tmp_path) -> None:
    data, cfg = capture
    rec = tmp_path / "rec.dat"
    with SensorEmulator(data, faults=Faults(error_on="profileCfg")) as em:
        _, frames, err = run_link(em, cfg, record=rec)
        sent = em.commands
    lines = cfg.read_text().splitlines()
    k = next(i for i, ln in enumerate(lines) if ln.startswith("profileCfg"))
    assert err is not None and frames == []
    assert str(err).startswith(f"{cfg}:{k + 1}: the sensor rejected 'profileCfg ")
    assert "Error -1" in str(err) and "\n" not in str(err)
    # nothing after the rejected line (but the sensorStop of the way out)
    before = cfg_lines(cfg)
    assert sent == [*before[: before.index(" ".join(lines[k].split())) + 1], "sensorStop"]
    assert not rec.exists()


def test_unknown_command_is_named(capture) -> None:
    data, cfg = capture
    cfg.write_text(cfg.read_text().replace("lowPower 0 0", "lowPower 0 0\nfancyCfg 1 2"))
    n = next(i for i, ln in enumerate(cfg.read_text().splitlines(), 1) if "fancyCfg" in ln)
    with SensorEmulator(data) as em:
        _, _, err = run_link(em, cfg)
    assert str(err) == (
        f"{cfg}:{n}: the sensor rejected 'fancyCfg 1 2': 'fancyCfg' is not recognized as a CLI "
        "command (no line after it was sent)"
    )


def test_garbage_bytes_are_skipped_and_recorded(capture, tmp_path) -> None:
    data, cfg = capture
    rec = tmp_path / "rec.dat"
    with SensorEmulator(data, faults=Faults(frame_period_s=FAST, garbage_before=10)) as em:
        link, frames, err = run_link(em, cfg, record=rec, n=60)
        sent = bytes(em.sent)
    assert err is None and len(frames) == 60
    assert link.report.bytes_skipped == 37 and link.report.n_damaged == 0
    assert len(sent) == len(data) + 37 and rec.read_bytes() == sent


def test_a_frame_cut_short_is_skipped_and_counted(capture, tmp_path) -> None:
    data, cfg = capture
    rec = tmp_path / "rec.dat"
    with SensorEmulator(data, faults=Faults(frame_period_s=FAST, cut=10)) as em:
        link, frames, err = run_link(em, cfg, record=rec, n=59)
        sent = bytes(em.sent)
    assert err is None
    numbers = [f.frame_number for f in frames]
    assert 11 not in numbers and len(numbers) == 59  # packet 10 holds frame number 11
    assert link.report.n_damaged == 1 and link.report.n_dropped == 1
    # the frame after the lost one keeps its place on the frame grid
    assert frames[10].index == 11 and frames[10].frame_number == 12
    assert rec.read_bytes() == sent and len(sent) < len(data)
    ds = to_dataset(read_recording(rec, fmt=None, cfg=cfg), source_name=str(rec))
    assert ds.n_frames == 60  # the lost frame is an empty frame of the import too


def test_vanished_port_ends_with_one_line_and_the_record_whole(capture, tmp_path) -> None:
    data, cfg = capture
    rec = tmp_path / "rec.dat"
    with SensorEmulator(data, faults=Faults(frame_period_s=FAST, vanish_after=20)) as em:
        _, frames, err = run_link(em, cfg, record=rec)
        sent = bytes(em.sent)
    assert len(frames) == 20
    assert err is not None and "\n" not in str(err)
    assert str(err).startswith(f"{em.data_port}: the data port vanished after {len(sent)} bytes")
    assert rec.read_bytes() == sent
    ds = to_dataset(read_recording(rec, fmt=None, cfg=cfg), source_name=str(rec))
    assert ds.n_frames == 20


def test_a_silent_data_port_ends_the_link(capture) -> None:
    data, cfg = capture
    with SensorEmulator(data[: len(data) // 6], faults=Faults(frame_period_s=FAST)) as em:
        _, frames, err = run_link(em, cfg, silence_timeout_s=0.3)
    assert len(frames) == 10
    assert "no data for 0.3 s" in str(err)


def test_reconnect_after_stop(capture, tmp_path) -> None:
    data, cfg = capture
    rec = tmp_path / "rec.dat"
    with SensorEmulator(data, faults=Faults(frame_period_s=FAST)) as em:
        link = LiveLink(
            LinkSettings(cli_port=em.cli_port, data_port=em.data_port, cfg=str(cfg)), record=rec
        )
        for session in range(2):
            try:
                link.start()
                frames = []
                for f in link.frames():
                    frames.append(f)
                    if f.frame_number == 5 or len(frames) == 10:
                        break
            finally:
                link.close()
            # a packet in flight when the last session stopped may come first (a new run)
            numbers = [f.frame_number for f in frames]
            assert numbers[-5:] == [1, 2, 3, 4, 5] and len(numbers) <= 6
            assert em.commands.count("sensorStop") == 2 * (session + 1)
            # each session's recording starts at the first packet
            assert rec.read_bytes()[:8] == data[:8]


def test_no_answer_names_the_line_and_the_likely_cause(capture) -> None:
    data, cfg = capture
    with SensorEmulator(data) as em:
        # the ports swapped: the cfg goes to the data port, which never answers
        link = LiveLink(
            LinkSettings(
                cli_port=em.data_port, data_port=em.cli_port, cfg=str(cfg), answer_timeout_s=0.3
            )
        )
        with pytest.raises(LinkError) as info:
            try:
                link.start()
            finally:
                link.close()
    first = next(i for i, ln in enumerate(cfg.read_text().splitlines(), 1) if ln == "sensorStop")
    assert str(info.value) == (
        f"{cfg}:{first}: no answer from the sensor to 'sensorStop' within 0.3 s (got: 'nothing'); "
        "is this the CLI port (not the data port), at its baud rate (115200 by default)?"
    )


def test_gtrack_tracks_live_as_on_the_imported_recording(capture, tmp_path) -> None:
    """With gtrack's parameters the link tracks frame by frame with gtrack: the tracks of every
    frame are those of gtrack run over the recording's import (same ids, states to 1e-9 m)."""
    from core.tracking.gtrack import GtrackParams, run_gtrack
    from core.tracking.gtrack.batch import dataset_points

    data, cfg = capture
    rec = tmp_path / "rec.dat"
    # the capture's walker is two points a frame in the ground plane (SNR 15 dB each): gtrack
    # in 2-D with allocation thresholds that small a cluster passes (its defaults ask 20 points)
    params = GtrackParams(dims=2, points_thre=1, snr_thre=1.0, max_distance_thre_m2=2.0)
    with SensorEmulator(data, faults=Faults(frame_period_s=FAST)) as em:
        link = LiveLink(
            LinkSettings(cli_port=em.cli_port, data_port=em.data_port, cfg=str(cfg)),
            params,
            record=rec,
        )
        frames = []
        try:
            link.start()
            for f in link.frames():
                frames.append(f)
                if len(frames) >= 60:
                    break
        finally:
            link.close()
    ds = to_dataset(read_recording(rec, fmt=None, cfg=cfg), source_name=str(rec))
    assert ds.n_frames == 60
    period = link.radar.frame_period_s
    ref = run_gtrack(
        dataset_points(ds), ds.frame_offsets, dataclasses.replace(params, frame_period_s=period)
    )
    for f, r in zip(frames, ref.frames, strict=True):
        np.testing.assert_array_equal(f.tracks.ids, r.ids)
        np.testing.assert_allclose(f.tracks.state, r.state, rtol=0, atol=1e-9)
        np.testing.assert_array_equal(f.tracks.confirmed, r.confirmed)
    # the walker is tracked: an active (confirmed) gtrack track within 0.3 m of the truth
    last = frames[-1].tracks
    d = np.hypot(*(last.state[last.confirmed, :2] - person_xy(frames[-1].t_s)).T)
    assert d.size and d.min() < 0.3


def test_the_room_mode_is_refused_in_one_line(capture) -> None:
    data, cfg = capture
    with pytest.raises(InputError, match="not the room mode"):
        LiveLink(
            LinkSettings(cli_port="/dev/null-a", data_port="/dev/null-b", cfg=str(cfg)),
            TrackerParams(mode="room"),
        )
