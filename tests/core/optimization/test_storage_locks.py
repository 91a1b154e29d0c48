"""Storage locks: a dead journal writer frees its lock at once, a torn last line is cut, and
processes opening a new SQLite file at once all succeed."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import optuna

from core.optimization.storage import JournalFlockLock, open_storage

ROOT = Path(__file__).resolve().parents[3]
#: a surviving worker's next write must go through this soon after the holder is killed
#: (Optuna's lock-file locks wait their 30 s grace period; the flock is free at once)
MAX_WAIT_S = 5.0

# A worker process that takes the journal lock through open_storage() for a real storage write
# (creating a study), says so, and then hangs inside the critical section until it is killed.
_HOLDER = textwrap.dedent(
    """
    import sys, time
    import optuna
    from core.optimization import storage as st

    original = st.JournalFlockLock.acquire

    def acquire_and_hang(self):
        original(self)
        print("locked", flush=True)
        time.sleep(600)

    st.JournalFlockLock.acquire = acquire_and_hang
    optuna.create_study(storage=st.open_storage(sys.argv[1]), study_name="holder")
    """
)


def _holder(url: str) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen(
        [sys.executable, "-c", _HOLDER, url], cwd=ROOT, env=env, stdout=subprocess.PIPE, text=True
    )
    assert proc.stdout is not None
    assert proc.stdout.readline().strip() == "locked"
    return proc


def test_worker_killed_holding_the_lock_does_not_stall_the_others(tmp_path: Path) -> None:
    url = f"journal:///{tmp_path}/s.log"
    study = optuna.create_study(storage=open_storage(url), study_name="s")
    holder = _holder(url)
    try:
        # while the holder lives, a write waits for it
        done = threading.Event()
        waiter = threading.Thread(
            target=lambda: (study.set_user_attr("during", 1), done.set()), daemon=True
        )
        waiter.start()
        assert not done.wait(1.0)
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait(10)
    t0 = time.monotonic()
    assert done.wait(MAX_WAIT_S), f"write still blocked {MAX_WAIT_S} s after the holder died"
    waited = time.monotonic() - t0
    t0 = time.monotonic()
    trial = study.ask()
    study.tell(trial, 1.0)
    after = time.monotonic() - t0
    print(f"write released {waited * 1e3:.1f} ms after SIGKILL; ask+tell then {after * 1e3:.1f} ms")
    assert waited < MAX_WAIT_S and after < MAX_WAIT_S
    fresh = optuna.load_study(study_name="s", storage=open_storage(url))
    assert fresh.user_attrs["during"] == 1 and fresh.trials[0].value == 1.0


def test_a_torn_last_line_is_cut_before_the_next_write(tmp_path: Path) -> None:
    # a writer killed in the middle of its write leaves a line without its newline; glued to
    # the next record it would make the journal unreadable from there on
    url = f"journal:///{tmp_path}/t.log"
    path = tmp_path / "t.log"
    optuna.create_study(storage=open_storage(url), study_name="t").set_user_attr("a", 1)
    good = path.read_bytes()
    record = json.dumps({"op_code": 8, "worker_id": "x", "study_id": 0, "user_attr": {"b": 2}})
    path.write_bytes(good + record[:25].encode())
    study = optuna.load_study(study_name="t", storage=open_storage(url))
    study.set_user_attr("c", 3)
    study.set_user_attr("d", 4)
    assert path.read_bytes().startswith(good) and path.read_bytes().endswith(b"\n")
    fresh = optuna.load_study(study_name="t", storage=open_storage(url))
    assert fresh.user_attrs == {"a": 1, "c": 3, "d": 4}


def test_threads_of_one_process_exclude_each_other(tmp_path: Path) -> None:
    lock = JournalFlockLock(tmp_path / "x.log")
    inside, overlaps = [0], []

    def work() -> None:
        for _ in range(200):
            lock.acquire()
            inside[0] += 1
            overlaps.append(inside[0])
            time.sleep(0.0005)
            inside[0] -= 1
            lock.release()

    threads = [threading.Thread(target=work) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(overlaps) == 800 and max(overlaps) == 1


_OPENER = textwrap.dedent(
    """
    import sys, time
    from pathlib import Path
    import optuna, sqlalchemy  # imported before the start, so that the four opens coincide
    from core.optimization.storage import open_storage

    go = Path(sys.argv[2])
    print("ready", flush=True)
    while not go.exists():
        time.sleep(0.001)
    open_storage(sys.argv[1])
    """
)


def test_processes_opening_a_new_sqlite_file_at_once_all_succeed(tmp_path: Path) -> None:
    # RDBStorage creates the schema table by table; unserialised, four openers of a new file
    # failed with "table ... already exists" in every try of this test
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    url, go = f"sqlite:///{tmp_path}/new.db", tmp_path / "go"
    procs = [
        subprocess.Popen(
            [sys.executable, "-c", _OPENER, url, str(go)],
            cwd=ROOT,
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for _ in range(4)
    ]
    for p in procs:
        assert p.stdout is not None and p.stdout.readline().strip() == "ready"
    go.touch()
    errors = [p.communicate(timeout=60)[1] for p in procs]
    assert [p.returncode for p in procs] == [0, 0, 0, 0], errors
