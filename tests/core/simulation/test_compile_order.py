"""Compiled results do not depend on what was compiled before in the process (core/jit_guard.py).

Each check runs in a fresh interpreter with an empty numba cache directory, so that every kernel
is compiled there (a kernel loaded from ``__pycache__`` would hide the compile order).

The arithmetic: with ``a = 1 + 2^-30`` and ``c = 1 - 2^-30``, ``a c = 1 - 2^-60`` rounds to 1.0,
so ``a c - 1`` is exactly 0.0 with a rounded product and ``-2^-60`` when the multiply and the
subtraction are fused (FMA), as ``fastmath`` lets LLVM do on a CPU with FMA.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]

_HELPERS = """
import sys
import numba
from core import jit_guard  # noqa: F401

A, C = 1.0 + 2.0**-30, 1.0 - 2.0**-30

@numba.njit
def mul_sub(a, c, b):
    return a * c - b

@numba.njit(fastmath=True)
def fast_mul_sub(a, c, b):
    return mul_sub(a, c, b)

@numba.njit(fastmath=True)
def fast_complex(z, w):
    return z * w

@numba.njit
def plain_complex(z, w):
    return z * w

# the fastmath functions first: they compile numba's complex product and mul_sub
fast_mul_sub(A, C, 1.0)
fast_complex(complex(A, 1.0), complex(C, 1.0))
print(repr(mul_sub(A, C, 1.0)), repr(plain_complex(complex(A, 1.0), complex(C, 1.0)).real))
"""


def _run(script: str, *args: str, cache_dir: Path) -> str:
    env = dict(os.environ, PYTHONPATH=str(ROOT), NUMBA_CACHE_DIR=str(cache_dir))
    out = subprocess.run(
        [sys.executable, "-c", script, *args],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
        check=True,
    )
    return out.stdout.strip()


def test_fastmath_does_not_leak_into_functions_compiled_later(tmp_path):
    # numba caches its complex product and a called function's code per signature only: without
    # the guard the fastmath caller compiled first decides them for everyone (-2^-60 here)
    called, product = _run(_HELPERS, cache_dir=tmp_path).split()
    a, c = 1.0 + 2.0**-30, 1.0 - 2.0**-30
    assert a * c - 1.0 == 0.0  # Python rounds the product
    assert float(called) == 0.0
    assert float(product) == (complex(a, 1.0) * complex(c, 1.0)).real == 0.0


_FAST_SPECTRUM = """
import hashlib, sys
import numpy as np
from core.config import PAPER_RADAR
from core.simulation import AntennaGain, Scatterers, synthesize_signal
from core.simulation.fast import fast_spectrum

ant = AntennaGain.ideal(PAPER_RADAR)
sc = Scatterers(
    position_m=np.array([[1.0, 4.0, 0.0], [-2.0, 6.0, 0.0], [2.5, 2.0, 0.0]]),
    velocity_mps=np.array([[0.5, -1.2, 0.0], [1.5, 0.3, 0.0], [-3.0, 0.5, 0.0]]),
    rcs_dbsm=np.array([-8.0, 0.0, -5.0]),
    source=np.arange(3, dtype=np.int32),
)
if sys.argv[1] == "exact-first":
    synthesize_signal(PAPER_RADAR, sc, ant)  # compiles the exact level's fastmath kernel first
spec = fast_spectrum(PAPER_RADAR, sc, np.random.default_rng(5), antenna=ant)
h = hashlib.sha256()
for a in spec:
    h.update(np.ascontiguousarray(a).tobytes())
print(h.hexdigest())
"""


@pytest.mark.slow
def test_fast_spectrum_does_not_depend_on_the_exact_level_compiled_first(tmp_path):
    # the reported bug: a test session (or process) that compiled the exact level first wrote
    # fused complex products into the fast level's kernels and its on-disk cache
    alone = _run(_FAST_SPECTRUM, "alone", cache_dir=tmp_path / "alone")
    after = _run(_FAST_SPECTRUM, "exact-first", cache_dir=tmp_path / "exact_first")
    assert after == alone


_CALLEE = """import numba

from core import jit_guard  # noqa: F401


@numba.njit(cache=True)
def value():
    return {value}
"""

_CALLER = """import numba

from core import jit_guard  # noqa: F401
from core.order_callee import value


@numba.njit(cache=True)
def value_plus_one():
    return value() + 1.0
"""


def test_editing_a_called_kernel_module_recompiles_its_callers(tmp_path):
    # numba's cache of value_plus_one holds value() compiled in; keyed on its own file only, it
    # would return the old sum after order_callee.py changed (the salt: jit_guard's stamp)
    shutil.copytree(ROOT / "core", tmp_path / "core", ignore=shutil.ignore_patterns("__pycache__"))
    (tmp_path / "core" / "order_caller.py").write_text(_CALLER)
    script = "from core.order_caller import value_plus_one; print(value_plus_one())"
    env = dict(os.environ, PYTHONPATH=str(tmp_path))
    env.pop("NUMBA_CACHE_DIR", None)  # the in-tree __pycache__ of the copy
    sums = []
    for value in ("1.0", "5.0"):
        (tmp_path / "core" / "order_callee.py").write_text(_CALLEE.format(value=value))
        out = subprocess.run(
            [sys.executable, "-c", script], cwd=tmp_path, env=env, capture_output=True, text=True
        )
        assert out.returncode == 0, out.stderr
        sums.append(float(out.stdout))
    assert list((tmp_path / "core" / "__pycache__").glob("order_caller.*.nbi"))  # it was cached
    assert sums == [2.0, 6.0]
