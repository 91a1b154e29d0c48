"""``radartune dashboard --storage URL``: optuna-dashboard for a study storage, in the browser."""

from __future__ import annotations

import argparse
import sys
import time


def add_parser(sub: argparse._SubParsersAction) -> None:
    from core.optimization.storage import DEFAULT_STORAGE

    p = sub.add_parser("dashboard", help="serve optuna-dashboard for a storage on 127.0.0.1")
    p.add_argument("--storage", default=DEFAULT_STORAGE, help="storage URL (default: %(default)s)")
    p.add_argument("--port", type=int, default=8080, help="port (default: %(default)s, 0: free)")
    p.add_argument("--no-browser", action="store_true", help="do not open the browser")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from core.errors import InputError
    from core.limits import PORT_RANGE
    from core.optimization.dashboard import serve_dashboard

    if not PORT_RANGE[0] <= args.port <= PORT_RANGE[1]:
        raise InputError(
            f"--port must be in [{PORT_RANGE[0]}, {PORT_RANGE[1]}] (0: any free port), "
            f"got {args.port}"
        )
    try:
        server = serve_dashboard(args.storage, port=args.port)
    except OSError as exc:
        raise InputError(
            f"--port {args.port}: cannot listen on 127.0.0.1: {exc.strerror}"
        ) from None
    print(f"optuna-dashboard: {server.url} (Ctrl-C stops)", file=sys.stderr)
    if not args.no_browser:
        import webbrowser

        webbrowser.open(server.url)
    try:
        while server.thread.is_alive():
            time.sleep(0.5)
    except KeyboardInterrupt:
        pass
    finally:
        server.stop()
    return 0
