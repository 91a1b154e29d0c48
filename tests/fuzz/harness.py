"""Run the real CLI entry point (``core.cli.main``) in-process on one input and check the promise:
exit 0, or exit 2 with exactly one line on stderr; never a traceback, never ``nan`` printed, no
output file (or temporary) left behind on failure, at most :data:`TIME_LIMIT_S` per input.

Every run is counted in :data:`TALLY`, which ``tests/fuzz/conftest.py`` prints at the end.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import resource
import tempfile
import time
import warnings
from collections import Counter
from collections.abc import Callable
from pathlib import Path

from core.cli import main

#: The longest one input may run, s.
TIME_LIMIT_S = 30.0
#: Progress-bar lines a long command writes to stderr before it may fail (not error lines).
_PROGRESS = re.compile(r"^\w+ \[[#-]+\] \d+/\d+ ")
_NAN = re.compile(r"\bnan\b", re.IGNORECASE)

TALLY: Counter[str] = Counter()
#: The first few bad outcomes, for the report: (kind, argv, stderr/stdout excerpt).
FAILURES: list[tuple[str, list[str], str]] = []


def record_failure(kind: str, argv: list[str], text: str, problems: list[str]) -> None:
    TALLY[kind] += 1
    problems.append(f"{kind}: {text[-800:]}")
    if len(FAILURES) < 50:
        FAILURES.append((kind, argv, text[-2000:]))


def run_input(write: Callable[[Path], list[str]], *, label: str) -> list[str]:
    """Make a fresh folder, let ``write(folder)`` put the input there and return the CLI
    arguments (any ``--out`` inside ``folder/out``), run the CLI, check and count the outcome.

    Returns the problems found (empty: the promise held)."""
    problems: list[str] = []
    with tempfile.TemporaryDirectory(prefix="radartune-fuzz-") as tmp:
        folder = Path(tmp)
        (folder / "out").mkdir()
        argv = write(folder)
        out, err = io.StringIO(), io.StringIO()
        t0 = time.perf_counter()
        with (
            contextlib.redirect_stdout(out),
            contextlib.redirect_stderr(err),
            warnings.catch_warnings(record=True) as caught,
        ):
            warnings.simplefilter("always")  # the CLI would print each: count them
            try:
                code = main(argv)
            except SystemExit as exc:  # argparse: bad arguments (never our generated ones)
                code = exc.code if isinstance(exc.code, int) else 1
        elapsed = time.perf_counter() - t0
        stdout, stderr = out.getvalue(), err.getvalue()
        TALLY["inputs"] += 1
        TALLY[f"inputs {label}"] += 1
        TALLY[f"exit {code}"] += 1
        if caught:
            TALLY["warnings"] += 1
        if elapsed > TIME_LIMIT_S:
            record_failure(f"> {TIME_LIMIT_S:g} s", argv, f"{elapsed:.1f} s", problems)
        if "Traceback" in stderr or "Traceback" in stdout:
            record_failure("tracebacks", argv, stderr, problems)
        if _NAN.search(stdout):
            record_failure("nan printed", argv, stdout, problems)
        left = sorted(p.name for p in (folder / "out").iterdir())
        if code == 0:
            stray = [n for n in left if n.endswith(".tmp")]
            if stray:
                record_failure("half-written files", argv, str(stray), problems)
        elif code == 2:
            lines = [ln for ln in stderr.splitlines() if not _PROGRESS.match(ln)]
            if len(lines) + len(caught) != 1:
                record_failure("not one line", argv, stderr, problems)
            if "MemoryError" in stderr:
                record_failure("memory errors", argv, stderr, problems)
            if left:
                record_failure("half-written files", argv, str(left), problems)
        else:
            record_failure("other exit codes", argv, f"exit {code}: {stderr}", problems)
        return problems


def check(problems: list[str]) -> None:
    """Fail the example at once in the short profile (Hypothesis then shrinks it); in the long
    profile only count, so that every input of the budget runs and the tally is complete
    (``conftest.py`` fails the session if the tally shows any bad outcome)."""
    if inputs_budget() is None:
        assert not problems, problems


def peak_rss_mb() -> float:
    """Peak resident memory of this process so far, MB (Linux reports kB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


BAD_KINDS = (
    "tracebacks",
    "not one line",
    "other exit codes",
    f"> {TIME_LIMIT_S:g} s",
    "nan printed",
    "half-written files",
    "memory errors",
)


def format_tally() -> str:
    lines = ["fuzz tally (radartune CLI, in-process)"]
    lines.append(f"  {'inputs':28s} {TALLY['inputs']}")
    for key in sorted(k for k in TALLY if k.startswith("inputs ")):
        lines.append(f"    {key[7:]:26s} {TALLY[key]}")
    for key in sorted(k for k in TALLY if k.startswith("exit ")):
        lines.append(f"  {key:28s} {TALLY[key]}")
    for key in BAD_KINDS:
        lines.append(f"  {key:28s} {TALLY[key]}")
    lines.append(f"  {'runs with a warning':28s} {TALLY['warnings']}")
    lines.append(f"  {'peak RSS (MB)':28s} {peak_rss_mb():.0f}")
    for kind, argv, text in FAILURES[:10]:
        lines.append(f"  FAIL {kind}: {' '.join(argv)}\n    {text.strip()[:500]}")
    return "\n".join(lines)


def inputs_budget() -> int | None:
    """Total inputs of the long profile (``RADARTUNE_FUZZ_INPUTS``), else None (short)."""
    value = os.environ.get("RADARTUNE_FUZZ_INPUTS")
    return int(value) if value else None
