"""Unexpected errors in the app: one line for the user, the traceback in the log.

Where an exception nobody expected ends up:

- raised in a slot or an event handler: PySide6 hands it to :data:`sys.excepthook`;
- raised in a Python thread: :data:`threading.excepthook`;
- raised in a worker (simulation thread, re-track job): the worker catches it, logs it with
  :func:`log_exception` and emits its ``failed`` signal.

Qt is imported only by :func:`install_excepthooks`.

:func:`install_excepthooks` points both hooks at the window: the traceback goes to the log
(:data:`LOG_FILE`; stderr too with ``radartune gui --debug``) and the user sees one line in the
window's message box, delivered in the GUI thread whichever thread raised. Code that reads or
writes a file catches its own errors and names the file with :func:`one_line`.
"""

from __future__ import annotations

import logging
import sys
import tempfile
import threading
from collections.abc import Callable
from pathlib import Path

from core.errors import InputError

#: The app's log: every unexpected exception with its traceback.
LOG_FILE = Path(tempfile.gettempdir()) / "radartune-app.log"

log = logging.getLogger("radartune.app")


def one_line(exc: BaseException, source: str | None = None) -> str:
    """The error as one line for the user, naming ``source`` (a file) when it is not named yet.

    An :class:`InputError` is shown as it is (it names its file and field); anything else with
    its type (:func:`app.engine.describe`), since it is a fault of ours rather than of the input.
    """
    from app.engine import describe

    text = " ".join(describe(exc).split())  # one line, whatever the message holds
    if source and source not in text:
        text = f"{source}: {text}"
    return text


def log_exception(what: str, exc: BaseException) -> None:
    """Log ``exc`` with its traceback (an expected :class:`InputError` without one)."""
    if isinstance(exc, InputError):
        log.warning("%s: %s", what, exc)
    else:
        log.error("%s", what, exc_info=(type(exc), exc, exc.__traceback__))


def setup_logging(*, debug: bool = False) -> None:
    """Send the app's log to :data:`LOG_FILE`, and with ``debug`` also to stderr (once per
    process). Without ``debug`` the terminal gets no traceback: the user's answer is one line."""
    if log.handlers:
        return
    fmt = logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s")
    handlers: list[logging.Handler] = [logging.StreamHandler(sys.stderr)] if debug else []
    try:
        handlers.append(logging.FileHandler(LOG_FILE, encoding="utf-8"))
    except OSError:
        if not debug:  # an unwritable temporary folder: stderr it is
            handlers.append(logging.StreamHandler(sys.stderr))
    for h in handlers:
        h.setFormatter(fmt)
        log.addHandler(h)
    log.setLevel(logging.INFO)


def install_excepthooks(report: Callable[[str], None]) -> Callable[[], None]:
    """Route uncaught exceptions (GUI thread and Python threads) to ``report``.

    ``report`` must be a method of a QObject living in the GUI thread (``window.show_error``): a
    line from another thread is then queued to it. Returns a function restoring the old hooks.
    """
    from PySide6 import QtCore

    class Relay(QtCore.QObject):  # carries a line from the raising thread to the GUI thread
        message = QtCore.Signal(str)

    relay = Relay()
    relay.message.connect(report)
    old_sys, old_threading = sys.excepthook, threading.excepthook

    def deliver(exc_type, exc, tb, where: str) -> None:
        if exc is None:
            exc = exc_type()
        log.error("unexpected error in %s", where, exc_info=(exc_type, exc, tb))
        relay.message.emit(f"internal error: {one_line(exc)} (details in {LOG_FILE})")

    def sys_hook(exc_type, exc, tb) -> None:
        if issubclass(exc_type, KeyboardInterrupt):
            old_sys(exc_type, exc, tb)
            return
        deliver(exc_type, exc, tb, "the GUI thread")

    def threading_hook(args: threading.ExceptHookArgs) -> None:
        if issubclass(args.exc_type, SystemExit):
            return
        name = args.thread.name if args.thread is not None else "a thread"
        deliver(args.exc_type, args.exc_value, args.exc_traceback, f"thread {name}")

    sys.excepthook = sys_hook
    threading.excepthook = threading_hook

    def restore() -> None:
        sys.excepthook, threading.excepthook = old_sys, old_threading

    return restore
