"""Exit codes of ``radartune``: the one definition (every command uses 0, 2 and 130; ``tune``
adds 3).

The values follow the shell's conventions: 0 success, 2 bad input (argparse uses 2 for a bad
command line too), 128 + 2 = 130 for an interrupt by Ctrl-C (SIGINT). Code 3 is ours: the study
was left unfinished by a worker that died (SIGKILL, the OOM killer, a crash) or was stopped from
outside; every finished trial is stored, the dead worker's running trial is marked FAIL on
resume, and running the same command again completes the study.
"""

from __future__ import annotations

#: the study reached its total (``tune``), or the worker ran until the total or was stopped
#: politely with SIGTERM after finishing its trial (``worker``)
EXIT_OK = 0
#: bad input (or, from a worker, a broken objective): one line on stderr names the file, field
#: or value
EXIT_INPUT_ERROR = 2
#: ``tune`` only: a worker was killed (or stopped from outside) before the total was reached;
#: the study is intact and resumable — run the same command again
EXIT_WORKER_LOST = 3
#: interrupted by Ctrl-C before the total was reached; resumable the same way
EXIT_INTERRUPTED = 130

_TUNE = f"""\
exit codes:
  {EXIT_OK}    the study reached its total (--trials); the best trial is printed as JSON
  {EXIT_INPUT_ERROR}    bad input, or a broken objective (5 failed trials in a row); one line on
       stderr says what
  {EXIT_WORKER_LOST}    a worker was killed (SIGKILL, out of memory, crash) or stopped from outside
       before the total was reached: finished trials are kept, the study is resumable —
       run the same command again
  {EXIT_INTERRUPTED}  interrupted by Ctrl-C before the total was reached; resumable the same way

A worker killed while the others reach the total is reported on stderr; the exit code is then
{EXIT_OK}. Resuming marks the dead worker's RUNNING trial FAIL; it does not count."""

_WORKER = f"""\
exit codes:
  {EXIT_OK}    the study reached its total, or SIGTERM stopped this worker after its trial
  {EXIT_INPUT_ERROR}    bad input or a broken objective (one line on stderr says what)
  {EXIT_INTERRUPTED}  Ctrl-C: the first stops after the running trial, a second aborts it (FAIL)
A worker killed by a signal exits with the shell's 128 + signal (SIGKILL: 137; Python's
subprocess shows -9); the study stays resumable."""


def epilog(command: str) -> str:
    """The ``--help`` epilog listing the exit codes of ``tune`` or ``worker``."""
    return {"tune": _TUNE, "worker": _WORKER}[command]
