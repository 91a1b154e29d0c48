"""Every unexpected exception in the app becomes one line in a message box (the file named when a
file is involved) and is logged with its traceback; a bad ``--scene`` is one line and exit 2."""

from __future__ import annotations

import logging
import subprocess
import sys
import threading
from pathlib import Path
from types import SimpleNamespace

import pytest
from PySide6 import QtCore, QtWidgets

from app import engine
from app.engine import Engine
from app.errors import install_excepthooks

ROOT = Path(__file__).resolve().parents[2]

#: Files that are not scenes, as a new user might pass them (the kinds the input fuzzing found).
BAD_SCENES = {
    "binary.json": b"\x89PNG\r\n\x1a\n\x00\x00\xff\xfe\x00binary",
    "latin1.json": b'{"schema_version": 1, "name": "caf\xe9", "persons": []}',
    "deep.json": b'{"schema_version": 1, "persons": ' + b"[" * 1000 + b"]" * 1000 + b"}",
    "null_radar.json": b'{"schema_version": 1, "radar": "\\u0000", "persons": []}',
    "surrogate.json": b'{"schema_version": 1, "radar": "\\ud800", "persons": []}',
    "truncated.json": b'{"schema_version": 1, "persons": [',
}


@pytest.fixture
def boxes(monkeypatch):
    """What the message boxes showed, recorded instead of shown: (text, shown in GUI thread)."""
    shown: list[tuple[str, bool]] = []

    def record(box) -> None:
        gui = QtCore.QThread.currentThread() == QtWidgets.QApplication.instance().thread()
        shown.append((box.text(), gui))

    monkeypatch.setattr(QtWidgets.QMessageBox, "show", record)
    monkeypatch.setattr(QtWidgets.QMessageBox, "exec", record)
    return shown


def one_line_naming(text: str, name: str) -> bool:
    return "\n" not in text and name in text and "Traceback" not in text


def tracebacks(caplog, exc_type: type[BaseException]) -> list[logging.LogRecord]:
    return [
        r
        for r in caplog.records
        if r.name == "radartune.app" and r.exc_info and issubclass(r.exc_info[0], exc_type)
    ]


@pytest.mark.qt_no_exception_capture
def test_exception_in_a_slot_is_a_message_box_and_a_logged_traceback(
    window, qtbot, boxes, caplog, monkeypatch
) -> None:
    def broken_view(_frame) -> None:
        raise ZeroDivisionError("the view divided by zero")

    monkeypatch.setattr(window.rd_view, "show_frame", broken_view)
    restore = install_excepthooks(window.show_error)
    try:
        window._mark_dirty()  # the draw timer's slot calls the broken view
        qtbot.waitUntil(lambda: len(boxes) >= 1, timeout=5000)
    finally:
        restore()
    text, in_gui_thread = boxes[0]
    assert in_gui_thread
    assert text.startswith("internal error: ZeroDivisionError: the view divided by zero")
    assert "\n" not in text and window.errors[-1] == text
    [record] = tracebacks(caplog, ZeroDivisionError)[:1]
    assert record.exc_info[2] is not None  # with its traceback
    assert sys.excepthook is not None and window.isEnabled()


@pytest.mark.qt_no_exception_capture
def test_exception_in_a_python_thread_reaches_the_gui_thread(window, qtbot, boxes, caplog) -> None:
    restore = install_excepthooks(window.show_error)
    try:
        t = threading.Thread(target=lambda: {}["missing key"], name="helper")
        t.start()
        t.join()
        qtbot.waitUntil(lambda: len(boxes) >= 1, timeout=5000)
    finally:
        restore()
    text, in_gui_thread = boxes[0]
    assert in_gui_thread  # queued to the window's thread, never a widget touched from another
    assert text.startswith("internal error: KeyError: 'missing key'")
    assert tracebacks(caplog, KeyError)


class FailingSimulation(Engine):
    @staticmethod
    def simulate(scene, *, fidelity: str = "exact"):
        raise MemoryError("cannot allocate 1.2 TiB for the frame")
        yield  # a generator, as the real one


def test_simulation_worker_failure_is_one_line_and_logged(qtbot, settings, boxes, caplog) -> None:
    from app.window import MainWindow

    w = MainWindow(settings, FailingSimulation(), load_scene=False)
    qtbot.addWidget(w)
    try:
        w.scene_model.set_document(engine.PAPER_SCENE_DOCUMENT)
        qtbot.waitUntil(lambda: len(boxes) >= 1, timeout=10000)
    finally:
        w.shutdown()
    text, _ = boxes[0]
    assert text == "simulation failed: MemoryError: cannot allocate 1.2 TiB for the frame"
    assert tracebacks(caplog, MemoryError)
    assert len(w.cache) == 0 and not w.sim.running


def test_tracking_worker_failure_is_one_line_and_logged(qtbot, caplog) -> None:
    from app.models import FrameCache, TrackerParamsModel, TrackingModel
    from app.workers import TrackingController

    class FailingTracker(Engine):
        @staticmethod
        def track(frames, params, frame_period_s, *, key="", engine="numba"):
            raise OverflowError("r22 = 3e298 overflows the kernel")

    eng = FailingTracker()
    cache = FrameCache()
    cache.append(SimpleNamespace(index=0))
    tracking = TrackingModel()
    tracker = TrackingController(eng, cache, TrackerParamsModel(eng), tracking, debounce_ms=1)
    with qtbot.waitSignal(tracker.failed, timeout=10000) as blocker:
        tracker.request()
    tracker.wait()
    assert blocker.args == ["OverflowError: r22 = 3e298 overflows the kernel"]
    assert tracking.result is None
    assert tracebacks(caplog, OverflowError)


@pytest.mark.parametrize("name", sorted(BAD_SCENES))
def test_bad_scene_file_in_the_window_is_one_line_naming_it(window, tmp_path, boxes, name) -> None:
    window.scene_model.set_document(engine.PAPER_SCENE_DOCUMENT)
    before, scene_before = window.scene_model.document, window.scene_model.scene
    bad = tmp_path / name
    bad.write_bytes(BAD_SCENES[name])
    assert not window.load_scene(bad)
    text, _ = boxes[-1]
    assert one_line_naming(text, str(bad)), text
    assert window.errors[-1] == text
    assert window.scene_model.document == before and window.scene_model.scene is scene_before


def test_bad_cfg_and_parameter_files_are_one_line_naming_them(window, tmp_path, boxes) -> None:
    window.scene_model.set_document(engine.PAPER_SCENE_DOCUMENT)
    radar = window.radar_model.radar
    cfg = tmp_path / "radar.cfg"
    cfg.write_bytes(b"\xff\xfe\x00profileCfg 0 60 \x00\x89")
    assert not window.load_cfg(cfg)
    assert one_line_naming(boxes[-1][0], str(cfg)), boxes[-1]
    assert window.radar_model.radar == radar
    values = dict(window.params_model.values)
    for name, data in (
        ("latin1.json", b'{"model": "cv", "q_coeff": 1.0, "note": "caf\xe9"}'),
        ("deep.json", b'{"model": ' + b"[" * 1000 + b"]" * 1000 + b"}"),
    ):
        path = tmp_path / name
        path.write_bytes(data)
        assert not window.load_params(path)
        assert one_line_naming(boxes[-1][0], str(path)), boxes[-1]
        assert window.params_model.values == values


def _gui(*args: str, tmp_path: Path) -> subprocess.CompletedProcess:
    env = {"QT_QPA_PLATFORM": "offscreen", "PATH": "/usr/bin:/bin", "HOME": str(tmp_path)}
    return subprocess.run(
        [sys.executable, "-m", "core.cli", "gui", *args, "--settings", str(tmp_path / "s.ini")],
        cwd=ROOT, env=env, capture_output=True, text=True, timeout=120,
    )  # fmt: skip


def test_gui_with_a_settings_value_nested_100000_deep_is_one_line_and_exit_2(tmp_path) -> None:
    path = tmp_path / "s.ini"
    text = "[tracker]\nmodel=cv\nvalues=" + "[" * 100_000 + "]" * 100_000 + "\n"
    path.write_text(text)
    out = _gui("--quit-after", "0", tmp_path=tmp_path)
    assert out.returncode == 2, out.stderr
    assert out.stderr.startswith("radartune gui: error: ")
    line = out.stderr.rstrip("\n")
    assert one_line_naming(line, str(path)), out.stderr
    assert "tracker/values" in line and "nested deeper" in line
    assert "Traceback" not in out.stderr and out.stdout == ""
    assert path.read_text() == text  # no window: nothing written back


@pytest.mark.parametrize("name", ["binary.json", "deep.json", "truncated.json"])
def test_gui_with_a_bad_scene_is_one_line_and_exit_2(tmp_path, name) -> None:
    bad = tmp_path / name
    bad.write_bytes(BAD_SCENES[name])
    out = _gui("--scene", str(bad), "--quit-after", "0", tmp_path=tmp_path)
    assert out.returncode == 2, out.stderr
    assert out.stderr.startswith("radartune gui: error: ")
    assert one_line_naming(out.stderr.rstrip("\n"), str(bad)), out.stderr
    assert out.stdout == ""
    assert not (tmp_path / "s.ini").exists()  # no window: nothing written
