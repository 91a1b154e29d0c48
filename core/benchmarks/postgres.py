"""A PostgreSQL server for a benchmark: the one ``RADARTUNE_BENCH_POSTGRES`` names, or a throwaway
cluster (``initdb`` + ``postgres`` on a free localhost port, as the ``postgres`` user when run as
root) where the server binaries are installed (``.ci/run`` installs them); None otherwise."""

from __future__ import annotations

import glob
import os
import shutil
import signal
import socket
import subprocess
import tempfile
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

ENV = "RADARTUNE_BENCH_POSTGRES"


def server_binaries() -> Path | None:
    """Folder of ``initdb`` and ``postgres``, or None."""
    found = sorted(glob.glob("/usr/lib/postgresql/*/bin/initdb"))
    if found:
        return Path(found[-1]).parent
    initdb = shutil.which("initdb")
    return Path(initdb).parent if initdb else None


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on now."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@contextmanager
def postgres_server() -> Iterator[str | None]:
    """Yield a PostgreSQL URL (``$RADARTUNE_BENCH_POSTGRES`` or a throwaway cluster with the
    server's default durability settings), or None when neither is available."""
    if os.environ.get(ENV):
        yield os.environ[ENV]
        return
    with throwaway_postgres() as url:
        yield url


@contextmanager
def throwaway_postgres(settings: Sequence[str] = ()) -> Iterator[str | None]:
    """Yield the URL of a new PostgreSQL cluster in a temporary folder, started with the server
    settings ``settings`` (``"name=value"``, e.g. ``"fsync=off"``), stopped and removed on exit;
    None when the server binaries are missing or it did not accept connections within 10 s."""
    bindir = server_binaries()
    if bindir is None:
        yield None
        return
    tmp = Path(tempfile.mkdtemp(prefix="radartune-bench-pg-"))
    preexec: Callable[[], None] | None = None
    if os.geteuid() == 0:  # initdb and postgres refuse to run as root
        import pwd

        pw = pwd.getpwnam("postgres")
        os.chown(tmp, pw.pw_uid, pw.pw_gid)

        def preexec() -> None:
            os.setgid(pw.pw_gid)
            os.setuid(pw.pw_uid)

    data = tmp / "data"
    server = None
    url: str | None = None
    try:
        subprocess.run(
            [str(bindir / "initdb"), "-D", str(data), "-A", "trust", "-U", "postgres"],
            check=True,
            capture_output=True,
            preexec_fn=preexec,
            cwd=tmp,
        )
        port = free_port()
        options = [a for v in ("listen_addresses=127.0.0.1", *settings) for a in ("-c", v)]
        server = subprocess.Popen(
            [str(bindir / "postgres"), "-D", str(data), "-p", str(port), "-k", str(tmp),
             *options],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            preexec_fn=preexec,
            cwd=tmp,
        )  # fmt: skip
        import psycopg2  # type: ignore[import-untyped]

        candidate = f"postgresql://postgres@127.0.0.1:{port}/postgres"
        for _ in range(100):
            try:
                psycopg2.connect(candidate).close()
                url = candidate
                break
            except psycopg2.OperationalError:
                time.sleep(0.1)
    except (OSError, subprocess.CalledProcessError, KeyError):
        url = None
    try:
        yield url
    finally:
        if server is not None:
            server.send_signal(signal.SIGINT)  # fast shutdown
            try:
                server.wait(20)
            except subprocess.TimeoutExpired:
                server.kill()
                server.wait()
        shutil.rmtree(tmp, ignore_errors=True)
