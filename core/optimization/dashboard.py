"""optuna-dashboard for a storage, served from a thread on 127.0.0.1 (no blocking ``run_server``).

The dashboard is a WSGI app (``optuna_dashboard.wsgi(storage)``) served by the standard library's
``wsgiref`` in a daemon thread, so the caller (CLI or GUI) stays in control and can stop it.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass
from typing import Any
from wsgiref.simple_server import WSGIRequestHandler, WSGIServer, make_server

from core.optimization.storage import open_storage


class _QuietHandler(WSGIRequestHandler):
    def log_message(self, format: str, *args: Any) -> None:  # noqa: A002 - wsgiref's name
        pass


@dataclass(slots=True)
class DashboardServer:
    """A running dashboard: ``url`` to open, ``stop()`` to shut it down."""

    server: WSGIServer
    thread: threading.Thread

    @property
    def url(self) -> str:
        host, port = self.server.server_address[:2]
        return f"http://{host}:{port}/dashboard/"

    def stop(self) -> None:
        self.server.shutdown()
        self.server.server_close()
        self.thread.join(5)


def serve_dashboard(storage: str, *, port: int = 8080, host: str = "127.0.0.1") -> DashboardServer:
    """Start optuna-dashboard for ``storage`` in a daemon thread; port 0 picks a free port.

    The storage's schema is created first (the dashboard crashes on an empty SQLite file); a
    missing journal file is an error rather than a new empty study list.
    """
    import optuna_dashboard

    store = open_storage(storage, create=not storage.startswith("journal"))
    app = optuna_dashboard.wsgi(store)
    server = make_server(host, port, app, handler_class=_QuietHandler)
    thread = threading.Thread(target=server.serve_forever, name="optuna-dashboard", daemon=True)
    thread.start()
    return DashboardServer(server=server, thread=thread)
