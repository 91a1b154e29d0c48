"""Fuzz profiles: a short one in ``make test`` (deterministic, a few hundred inputs) and a long
one behind ``RADARTUNE_FUZZ_INPUTS=10000 pytest tests/fuzz -p no:randomly -s`` (random, prints
the tally). See ``tests/fuzz/harness.py`` for what is checked per input."""

from __future__ import annotations

import json
import os
import resource
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

from core.cli import main
from tests.fuzz.harness import BAD_KINDS, TALLY, format_tally, inputs_budget
from tests.scenes import small_scene

#: Fuzz tests in tests/fuzz/test_fuzz_inputs.py and test_fuzz_recordings.py (the long profile
#: shares its budget among them).
N_FUZZ_TESTS = 13
#: Examples per test in the short profile.
SHORT_EXAMPLES = 40
#: Address-space limit of the long profile's process: a limit that failed to reject an input
#: ends in a MemoryError (counted) instead of exhausting the machine.
LONG_ADDRESS_SPACE_BYTES = 12 * 1024**3

_common = {
    "deadline": None,
    "database": None,
    "suppress_health_check": [HealthCheck.too_slow, HealthCheck.data_too_large],
}
settings.register_profile("fuzz-short", max_examples=SHORT_EXAMPLES, derandomize=True, **_common)
_budget = inputs_budget()
settings.register_profile(
    "fuzz-long", max_examples=max(1, (_budget or 0) // N_FUZZ_TESTS), derandomize=False, **_common
)
FUZZ_SETTINGS = settings.get_profile("fuzz-long" if _budget else "fuzz-short")

SCENE = small_scene(velocity_mps=(0.4, -1.0), frames=12)


@pytest.fixture(scope="session")
def fuzz_files(tmp_path_factory) -> dict[str, Path]:
    """A small simulated data set (fast fidelity, 12 frames) and a valid parameter file."""
    if _budget:
        soft, hard = resource.getrlimit(resource.RLIMIT_AS)
        if soft == resource.RLIM_INFINITY:
            resource.setrlimit(resource.RLIMIT_AS, (LONG_ADDRESS_SPACE_BYTES, hard))
    folder = tmp_path_factory.mktemp("fuzz-seed")
    scene = folder / "scene.json"
    scene.write_text(json.dumps(SCENE, indent=2))
    data = folder / "small.npz"
    argv = ["simulate", "--scene", str(scene), "--out", str(data), "--fidelity", "fast"]
    assert main(argv) == 0
    params = folder / "params.json"
    assert (
        main(["track", "--data", str(data), "--model", "ca", "--out", str(folder / "t.json")]) == 0
    )
    params.write_text(json.dumps(json.loads((folder / "t.json").read_text())["params"], indent=2))
    return {"scene": scene, "data": data, "params": params}


def pytest_sessionfinish(session, exitstatus) -> None:
    """The long profile counts instead of failing per input: fail here on any bad outcome."""
    if _budget and any(TALLY[k] for k in BAD_KINDS) and exitstatus == 0:
        session.exitstatus = 1


def pytest_terminal_summary(terminalreporter) -> None:
    if not TALLY["inputs"]:
        return
    text = format_tally()
    terminalreporter.write_line(text)
    path = os.environ.get("RADARTUNE_FUZZ_TALLY")
    if path:
        doc = {k: TALLY[k] for k in TALLY} | {"bad": {k: TALLY[k] for k in BAD_KINDS}}
        Path(path).write_text(json.dumps(doc, indent=2) + "\n")
