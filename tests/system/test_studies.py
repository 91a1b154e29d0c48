"""Studies end to end through the CLI, on SQLite, the journal file and a real PostgreSQL server.

The PostgreSQL server is a throwaway cluster started by the fixture (``initdb`` + ``postgres`` on a
free localhost port, run as the ``postgres`` user when we are root). When ``CI`` is set and the
server binaries are missing the test fails; elsewhere it is skipped with the reason.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from core.benchmarks.postgres import free_port, server_binaries, throwaway_postgres
from core.optimization import study_progress

ROOT = Path(__file__).resolve().parents[2]
QUAD = ["--objective", "quadratic", "--objective-option", "n_trajectories=5", "--no-progress"]


def cli(*args: str, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "core.cli", *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=timeout,
    )


# ---- PostgreSQL ---------------------------------------------------------------------------------
@pytest.fixture(scope="session")
def postgres_url() -> Iterator[str]:
    if server_binaries() is None:
        if os.environ.get("CI"):
            pytest.fail("CI is set but PostgreSQL server binaries (initdb) are missing")
        pytest.skip("PostgreSQL server binaries (initdb) not installed")
    with throwaway_postgres(("fsync=off",)) as url:
        if url is None:
            pytest.fail("PostgreSQL did not start or accept connections within 10 s")
        yield url


@pytest.fixture(params=["sqlite", "journal", "postgresql"])
def storage(request: pytest.FixtureRequest, tmp_path: Path) -> str:
    if request.param == "sqlite":
        return f"sqlite:///{tmp_path}/studies.db"
    if request.param == "journal":
        return f"journal:///{tmp_path}/studies.log"
    return request.getfixturevalue("postgres_url")


def _states(storage: str, name: str) -> dict[int, tuple[str, float | None]]:
    summaries, _ = study_progress(storage, name)
    return {t.number: (t.state, t.value) for t in summaries}


def _counted(states: dict) -> int:
    return sum(1 for s, _ in states.values() if s in ("COMPLETE", "PRUNED"))


# ---- tests --------------------------------------------------------------------------------------
def test_two_workers_reach_exactly_the_asked_total(storage: str, request) -> None:
    name = f"two-{request.node.callspec.id}-{os.getpid()}"
    # trials of 5 x 60 ms so that both workers overlap even when one starts late
    out = cli("tune", "--model", "cv", "--trials", "10", "--jobs", "2", "--storage", storage,
              "--study", name, *QUAD, "--objective-option", "delay_s=0.06")  # fmt: skip
    assert out.returncode == 0, out.stderr
    summaries, best = study_progress(storage, name)
    states = [t.state for t in summaries]
    assert states.count("COMPLETE") + states.count("PRUNED") == 10
    assert "RUNNING" not in states and "WAITING" not in states
    # both processes ran trials
    assert len({t.worker.rsplit(":", 2)[1] for t in summaries if t.state != "FAIL"}) == 2
    assert best is not None and best.value == min(
        t.value for t in summaries if t.state == "COMPLETE"
    )


def test_sigkill_mid_study_then_resume_loses_nothing(storage: str, request) -> None:
    name = f"kill-{request.node.callspec.id}-{os.getpid()}"
    args = ["tune", "--model", "cv", "--trials", "10", "--jobs", "2", "--storage", storage,
            "--study", name, "--objective", "quadratic", "--objective-option", "n_trajectories=5",
            "--objective-option", "delay_s=0.25", "--no-progress"]  # fmt: skip
    # 1.25 s a trial: after the third finished trial the two workers stay mid-trial for seconds,
    # wide enough for the 0.2 s polls below even on a loaded machine (0.3 s trials were missed)
    parent = subprocess.Popen(
        [sys.executable, "-m", "core.cli", *args],
        cwd=ROOT,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    deadline = time.monotonic() + 180
    victims: set[int] = set()
    try:
        while time.monotonic() < deadline:
            time.sleep(0.2)
            try:
                summaries, _ = study_progress(storage, name)
            except Exception:
                continue
            done = [t for t in summaries if t.state in ("COMPLETE", "PRUNED")]
            running = [t for t in summaries if t.state == "RUNNING" and t.worker]
            if len(done) >= 3 and running:
                victims = {int(t.worker.rsplit(":", 2)[1]) for t in running}
                break
            if len(done) >= 10:
                break  # finished before a poll caught a running trial
        assert victims, "no running trial to kill"
        # the whole machine dies: workers mid-trial, and the parent
        for pid in victims:
            os.kill(pid, signal.SIGKILL)
        os.killpg(parent.pid, signal.SIGKILL)
    finally:
        parent.wait(30)
    before = _states(storage, name)
    assert any(s == "RUNNING" for s, _ in before.values())
    finished_before = {n: v for n, v in before.items() if v[0] in ("COMPLETE", "PRUNED")}
    assert 3 <= len(finished_before) < 10

    out = cli(*args)  # resume
    assert out.returncode == 0, out.stderr
    after = _states(storage, name)
    assert "RUNNING" not in {s for s, _ in after.values()}
    for n, v in finished_before.items():
        assert after[n] == v  # no completed trial lost or changed
    for n, (s, _) in before.items():
        if s == "RUNNING":
            assert after[n][0] == "FAIL"
    assert _counted(after) == 10


# ---- bad input ----------------------------------------------------------------------------------
def _one_line_exit_2(out: subprocess.CompletedProcess, needle: str) -> None:
    assert out.returncode == 2, out.stderr
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1, out.stderr
    assert needle in lines[0]


def test_bad_input_is_one_line_exit_2_and_damages_nothing(tmp_path: Path) -> None:
    url = f"sqlite:///{tmp_path}/s.db"
    _one_line_exit_2(cli("tune", "--model", "ct", "--storage", url, *QUAD), "model must be one")
    _one_line_exit_2(cli("tune", "--model", "cv", "--storage", "mysql://x@y/z", *QUAD), "scheme")
    assert not (tmp_path / "s.db").exists()
    ok = cli("tune", "--model", "cv", "--trials", "3", "--storage", url, "--study", "s", *QUAD)
    assert ok.returncode == 0, ok.stderr
    before = _states(url, "s")
    _one_line_exit_2(
        cli("tune", "--model", "ca", "--trials", "9", "--storage", url, "--study", "s", *QUAD),
        "has model='cv', asked 'ca'",
    )
    assert _states(url, "s") == before
    _one_line_exit_2(cli("worker", "--storage", url, "--study", "nope"), "no study 'nope'")


def test_unreachable_database_is_one_line_exit_2() -> None:
    port = free_port()  # nothing listens there
    out = cli("tune", "--model", "cv", "--storage", f"postgresql://u:pw@127.0.0.1:{port}/x", *QUAD)
    _one_line_exit_2(out, "cannot open")
    assert "pw" not in out.stderr


def test_gui_handle_stops_workers_cleanly(tmp_path: Path) -> None:
    from core.optimization import StudySettings, start_study

    url = f"sqlite:///{tmp_path}/gui.db"
    s = StudySettings(model="ca", n_trials=500, n_jobs=2, storage=url, objective="quadratic",
                      objective_options={"n_trajectories": 5, "delay_s": 0.05})  # fmt: skip
    handle = start_study(s, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            summaries, best = study_progress(url, s.name)
            if best is not None:
                break
            time.sleep(0.2)
        assert handle.is_running()
    finally:
        handle.stop(timeout=60)
    assert not handle.is_running()
    assert handle.returncodes() == [0, 0]  # SIGTERM: finish the trial, exit normally
    states = [t.state for t in study_progress(url, s.name)[0]]
    assert "RUNNING" not in states and 0 < states.count("COMPLETE") < 500


# ---- exit codes, seeds --------------------------------------------------------------------------
def test_killed_worker_exits_3_resumable_and_the_same_command_completes(tmp_path: Path) -> None:
    from core.cli.exit_codes import EXIT_OK, EXIT_WORKER_LOST
    from core.optimization import StudySettings, prepare_study

    url = f"sqlite:///{tmp_path}/k.db"
    # created before tune starts, so that polling never races tune's creation of the schema
    # the objective's options are the study's (a worker reads them from the storage), so the
    # study is created with the trial delay the command line repeats
    prepare_study(StudySettings(model="cv", n_trials=6, storage=url, study_name="k",
                                objective="quadratic",
                                objective_options={"delay_s": 0.3}))  # fmt: skip
    # one worker, trials of 5 x 0.3 s: it is mid-trial for most of the time, and a poll that
    # takes a second on a loaded machine still finds a running trial after a complete one
    args = ["tune", "--model", "cv", "--trials", "6", "--jobs", "1", "--storage", url,
            "--study", "k", *QUAD, "--objective-option", "delay_s=0.3"]  # fmt: skip
    parent = subprocess.Popen(
        [sys.executable, "-m", "core.cli", *args],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    victim = None
    try:
        deadline = time.monotonic() + 40
        while victim is None and time.monotonic() < deadline and parent.poll() is None:
            time.sleep(0.1)
            try:
                summaries, _ = study_progress(url, "k")
            except Exception:
                continue
            running = [t for t in summaries if t.state == "RUNNING" and t.worker]
            if any(t.state == "COMPLETE" for t in summaries) and running:
                victim = int(running[0].worker.rsplit(":", 2)[1])
        if victim is None:
            parent.kill()
            pytest.fail(f"no running trial to kill: {parent.communicate()[1]}")
        os.kill(victim, signal.SIGKILL)
        out, err = parent.communicate(timeout=30)
    finally:
        if parent.poll() is None:
            parent.kill()
            parent.wait()
    assert parent.returncode == EXIT_WORKER_LOST, err
    last = err.strip().splitlines()[-1]
    assert f"worker {victim} was killed by SIGKILL" in last
    assert "resumable" in last and "run the same command again" in last
    assert "Traceback" not in err
    # the best trial so far is still printed (not validated: the study is unfinished)
    (study,) = json.loads(out)["studies"]
    assert study["study"] == "k" and study["best_trial"] in {
        n for n, (state, _) in _states(url, "k").items() if state == "COMPLETE"
    }

    again = cli(*args)
    assert again.returncode == EXIT_OK, again.stderr
    after = _states(url, "k")
    assert _counted(after) == 6
    # the killed worker's trial (none if the kill fell between two of its trials)
    assert [s for s, _ in after.values()].count("FAIL") <= 1


def test_two_tune_runs_on_one_study_repeat_no_parameter_set(tmp_path: Path) -> None:
    url = f"sqlite:///{tmp_path}/r.db"
    common = ["tune", "--model", "cv", "--storage", url, "--study", "r", "--sampler", "random",
              "--pruner", "none", *QUAD, "--objective-option", "delay_s=0.1"]  # fmt: skip
    from core.optimization import StudySettings, prepare_study

    prepare_study(StudySettings(model="cv", storage=url, study_name="r", sampler="random",
                                pruner="none", objective="quadratic",
                                objective_options={"delay_s": 0.1}))  # fmt: skip
    # two runs on the study at once, each with 2 workers and the same --seed; trials of 0.5 s,
    # so neither run can finish the 16 before the other's workers (slow to start under load) join
    runs = [
        subprocess.Popen(
            [sys.executable, "-m", "core.cli", *common, "--trials", "16", "--jobs", "2"],
            cwd=ROOT,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
        )
        for _ in range(2)
    ]
    for run in runs:
        _, err = run.communicate(timeout=120)
        assert run.returncode == 0, err
    summaries, _ = study_progress(url, "r")
    points = [tuple(sorted(t.params.items())) for t in summaries if t.state == "COMPLETE"]
    assert len(points) == 16
    assert len(set(points)) == 16, "a parameter set was sampled twice"
    workers = {t.worker for t in summaries if t.state == "COMPLETE"}
    assert len(workers) >= 3  # the runs' workers did share the study


@pytest.mark.parametrize(
    ("codes", "counted", "interrupted", "expected", "says"),
    [
        ([0, 0], 10, False, 0, None),
        ([0, -9], 10, False, 0, "worker 2 was killed by SIGKILL; the other workers reached"),
        ([-9, 0], 7, False, 3, "worker 1 was killed by SIGKILL; study 'x' is resumable"),
        ([1, 0], 7, False, 3, "worker 1 exited with code 1; study 'x' is resumable"),
        ([0, 0], 7, False, 3, "the workers stopped before the total"),
        ([2, -9], 7, False, 2, None),
        ([130, 130], 7, True, 130, None),
        ([0, 0], 10, True, 0, None),
    ],
)
def test_tune_exit_code_from_worker_codes(
    codes: list[int], counted: int, interrupted: bool, expected: int, says: str | None, capsys
) -> None:
    from core.cli.tune import exit_code

    assert exit_code(codes, [1, 2], counted, 10, "x", interrupted=interrupted) == expected
    err = capsys.readouterr().err
    if says is None:
        assert err == ""
    else:
        assert len(err.strip().splitlines()) == 1 and says in err


@pytest.mark.parametrize("command", ["tune", "worker"])
def test_help_lists_the_exit_codes(command: str) -> None:
    from core.cli import exit_codes

    out = cli(command, "--help")
    assert out.returncode == 0
    assert "exit codes:" in out.stdout
    codes = [exit_codes.EXIT_OK, exit_codes.EXIT_INPUT_ERROR, exit_codes.EXIT_INTERRUPTED]
    if command == "tune":
        codes.append(exit_codes.EXIT_WORKER_LOST)
    for code in codes:
        assert f"\n  {code} " in out.stdout
