"""Study storages: SQLite file (default), Optuna journal file, PostgreSQL.

URL forms accepted (validated here, so a bad URL is one clear line):

- ``sqlite:///relative/path.db`` or ``sqlite:////absolute/path.db`` — embedded, nothing to
  install; fine for a few processes on one machine;
- ``journal:///path.log`` (or ``journal:////abs/path.log``) — Optuna's journal file, append-only,
  made for several processes on one machine; writers take :class:`JournalFlockLock` (an
  ``flock`` on ``path.log.flock``), which the kernel frees when its holder dies;
- ``postgresql://user@host:port/db`` (``postgresql+psycopg2://`` too) — workers on several
  machines;
- ``memory://NAME`` — Optuna's in-memory storage, shared by name inside one process only
  (tests, previews; never for workers);
- a plain path ending in ``.db``/``.sqlite``/``.sqlite3`` (SQLite) or ``.log``/``.journal``
  (journal).
"""

from __future__ import annotations

import os
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from core.errors import InputError

DEFAULT_STORAGE = "sqlite:///radartune-studies.db"

_SQLITE_SUFFIXES = (".db", ".sqlite", ".sqlite3")
_JOURNAL_SUFFIXES = (".log", ".journal", ".jsonl")


def normalize_url(url: str) -> str:
    """Canonical URL (``sqlite:///…``, ``journal:///…`` or ``postgresql…://…``).

    Raises
    ------
    InputError
        Unknown scheme, or a file URL without a path.
    """
    url = str(url).strip()
    if not url:
        raise InputError("storage URL is empty")
    if "://" not in url:
        suffix = Path(url).suffix.lower()
        if suffix in _SQLITE_SUFFIXES:
            return f"sqlite:///{url}"
        if suffix in _JOURNAL_SUFFIXES:
            return f"journal:///{url}"
        raise InputError(
            f"storage {url!r}: expected sqlite:///FILE.db, journal:///FILE.log, "
            "postgresql://USER@HOST:PORT/DB or a path ending in .db or .log"
        )
    scheme = url.split("://", 1)[0].lower()
    if scheme in ("sqlite", "journal"):
        if not file_path(url).name:
            raise InputError(f"storage {url!r}: no file name after {scheme}:///")
        return url
    if scheme == "memory":
        return url
    if scheme in ("postgresql", "postgres", "postgresql+psycopg2"):
        return "postgresql+psycopg2://" + url.split("://", 1)[1]
    raise InputError(
        f"storage {url!r}: unknown scheme {scheme!r} (use sqlite, journal or postgresql)"
    )


def file_path(url: str) -> Path:
    """The file of a ``sqlite:///`` or ``journal:///`` URL (three slashes: relative path)."""
    rest = url.split("://", 1)[1]
    if not rest.startswith("/"):
        raise InputError(f"storage {url!r}: a file URL needs three slashes, e.g. sqlite:///x.db")
    return Path(rest[1:])


def absolute_url(url: str) -> str:
    """The URL with a file path made absolute (workers may run in another folder)."""
    url = normalize_url(url)
    if kind(url) in ("sqlite", "journal"):
        scheme = url.split("://", 1)[0]
        return f"{scheme}:///{file_path(url).resolve()}"
    return url


def kind(url: str) -> str:
    """``"sqlite"``, ``"journal"`` or ``"postgresql"``."""
    scheme = normalize_url(url).split("://", 1)[0]
    return "postgresql" if scheme.startswith("postgres") else scheme


_MEMORY: dict[str, Any] = {}


def open_storage(url: str, *, create: bool = True) -> Any:
    """Open (and for files create) an Optuna storage; one clear :class:`InputError` on failure.

    SQLite gets a 60 s busy timeout so that several processes can share the file. The schema
    is created on open (optuna-dashboard crashes on an empty SQLite file otherwise).

    Parameters
    ----------
    url
        Storage URL, see the module docstring.
    create
        If false, a missing SQLite or journal file is an error instead of being created.
    """
    import optuna
    import sqlalchemy.exc

    url = normalize_url(url)
    k = kind(url)
    if k == "memory":
        return _MEMORY.setdefault(url, optuna.storages.InMemoryStorage())
    if k in ("sqlite", "journal"):
        path = file_path(url)
        if not path.parent.is_dir():
            raise InputError(f"storage {url!r}: folder {str(path.parent)!r} does not exist")
        if not create and not path.exists():
            raise InputError(f"storage {url!r}: file {str(path)!r} does not exist")
        if path.exists() and path.is_dir():
            raise InputError(f"storage {url!r}: {str(path)!r} is a folder")
    from core.optimization import batching

    # fewer round trips for workers (decision tuning-07); Optuna's own classes if its internals
    # are not the ones the batching storages know
    rdb: type[Any] = optuna.storages.RDBStorage
    if batching.batching_available("rdb"):
        rdb = batching.BatchingRDBStorage
    journal: type[Any] = optuna.storages.JournalStorage
    if batching.batching_available("journal"):
        journal = batching.BatchingJournalStorage
    try:
        if k == "journal":
            from optuna.storages.journal import JournalFileBackend

            path = file_path(url)
            backend = JournalFileBackend(str(path), lock_obj=journal_lock(path))
            return journal(backend)
        if k == "sqlite":
            path = file_path(url)
            # RDBStorage creates the schema table by table on open; two processes opening a new
            # file at once (two tune runs, a progress poll while tune starts) failed with
            # "table studies already exists" in 4 of 8 tries: opening is serialised per file
            with _flocked(Path(str(path) + LOCK_SUFFIX)):
                return rdb(url, engine_kwargs={"creator": _sqlite_connector(path)})
        engine_kwargs = {"connect_args": {"connect_timeout": 10}, "pool_pre_ping": True}
        return rdb(url, engine_kwargs=engine_kwargs)
    except (sqlalchemy.exc.SQLAlchemyError, OSError) as exc:
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise InputError(f"storage {redact(url)!r}: cannot open: {first}") from None
    except Exception as exc:  # optuna raises RuntimeError / ValueError for bad databases
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise InputError(f"storage {redact(url)!r}: cannot open: {first}") from None


def load_existing_study(storage: Any, name: str) -> Any | None:
    """The study ``name`` in an opened ``storage`` (see :func:`open_storage`), None if absent."""
    import optuna

    try:
        return optuna.load_study(study_name=name, storage=storage)
    except KeyError:
        return None


#: the lock file beside a journal or SQLite file: ``studies.log.flock``, ``studies.db.flock``
LOCK_SUFFIX = ".flock"


@contextmanager
def _flocked(lock_file: Path) -> Iterator[None]:
    """Hold an exclusive ``flock`` on ``lock_file`` (freed by the kernel if this process dies)."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - Windows: no lock
        yield
        return
    try:
        fd = os.open(lock_file, os.O_RDWR | os.O_CREAT, 0o644)
    except OSError:  # a read-only folder: readers there cannot race a writer creating the file
        yield
        return
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # closing the file releases the flock


def journal_lock(path: Path) -> Any:
    """The writers' lock of the journal file ``path``: :class:`JournalFlockLock` where the OS
    has ``flock`` (Linux, macOS), else Optuna's lock-file lock (30 s grace period)."""
    try:
        import fcntl  # noqa: F401
    except ImportError:  # pragma: no cover - Windows
        from optuna.storages.journal import JournalFileOpenLock

        return JournalFileOpenLock(str(path))
    return JournalFlockLock(path)


class JournalFlockLock:
    """Exclusive ``flock`` on ``<journal>.flock``, held while one batch of logs is appended.

    Passed as ``lock_obj`` to Optuna's ``JournalFileBackend``, which only calls ``acquire()``
    and ``release()``. Optuna's own locks (``JournalFileOpenLock``, ``JournalFileSymlinkLock``)
    are a file that exists while the lock is held: a writer killed inside the append leaves it
    behind, and every other worker waits the 30 s grace period before breaking it. An ``flock``
    belongs to the open file, which the kernel closes when the process dies, so a dead holder
    frees the lock at once. The lock file stays (deleting it would let two writers lock two
    different files). Threads of one process serialise on a ``threading.Lock`` first.

    Taking the lock also cuts off a line left half-written by a writer killed during its write
    (no newline at the end of the file): the next append would otherwise glue its first record
    onto it and leave a line no reader can decode.

    ``flock`` works on local file systems and, on Linux, on NFS (as a whole-file POSIX lock).
    It does not exclude writers that use Optuna's lock-file locks on the same journal; every
    RadarTune process opens journals through :func:`open_storage`.
    """

    def __init__(self, journal: Path | str) -> None:
        self.journal = Path(journal)
        self.lock_file = Path(str(journal) + LOCK_SUFFIX)
        self._thread_lock = threading.Lock()
        self._fd: int | None = None

    def acquire(self) -> bool:
        """Block until this process holds the lock; return True."""
        import fcntl

        self._thread_lock.acquire()
        try:
            fd = os.open(self.lock_file, os.O_RDWR | os.O_CREAT, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX)
                _cut_partial_line(self.journal)
            except BaseException:
                os.close(fd)  # closing the file releases the flock
                raise
        except BaseException:
            self._thread_lock.release()
            raise
        self._fd = fd
        return True

    def release(self) -> None:
        """Release the lock (RuntimeError if this object does not hold it)."""
        import fcntl

        fd, self._fd = self._fd, None
        if fd is None:
            raise RuntimeError("journal lock released without being held")
        try:
            fcntl.flock(fd, fcntl.LOCK_UN)
        finally:
            os.close(fd)
            self._thread_lock.release()


def _cut_partial_line(path: Path) -> None:
    """Truncate ``path`` after its last newline if it does not end with one (lock held)."""
    try:
        fh = open(path, "rb+")
    except FileNotFoundError:
        return
    with fh:
        end = fh.seek(0, os.SEEK_END)
        if end == 0:
            return
        fh.seek(end - 1)
        if fh.read(1) == b"\n":
            return
        keep, step = 0, 1 << 16
        pos = end
        while pos > 0:  # search backwards for the last newline
            start = max(0, pos - step)
            fh.seek(start)
            i = fh.read(pos - start).rfind(b"\n")
            if i >= 0:
                keep = start + i + 1
                break
            pos = start
        fh.truncate(keep)
        fh.flush()
        os.fsync(fh.fileno())


def _sqlite_connector(path: Path) -> Any:
    """SQLite connections in WAL mode with ``synchronous=NORMAL`` and a 60 s busy timeout.

    WAL lets readers (progress polling, the dashboard) run beside the writing workers, and
    NORMAL syncs at checkpoints instead of every commit: each trial makes ~30 small commits
    (parameters, intermediate values, state), which cost ~2 ms each with a full fsync. A
    process crash (SIGKILL) loses nothing committed; a power cut may lose the last commits.
    WAL needs a local file system (not NFS).
    """
    import sqlite3

    def connect() -> sqlite3.Connection:
        conn = sqlite3.connect(str(path), timeout=60.0, check_same_thread=False)
        conn.execute("PRAGMA journal_mode=WAL")
        conn.execute("PRAGMA synchronous=NORMAL")
        return conn

    return connect


def redact(url: str) -> str:
    """URL with any password replaced by ``***`` (for messages and logs)."""
    if "://" not in url or "@" not in url:
        return url
    scheme, rest = url.split("://", 1)
    creds, host = rest.rsplit("@", 1)
    if ":" in creds:
        creds = creds.split(":", 1)[0] + ":***"
    return f"{scheme}://{creds}@{host}"
