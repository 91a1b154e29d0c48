"""Compiled code that depends only on the kernel's own source and flags, not on compile order.

numba 0.68 keeps two in-process caches whose keys ignore the ``fastmath`` flags:

* the target context's ``cached_internal_func`` (helpers numba compiles for its own operations,
  e.g. complex multiplication or ``cmath.exp``), keyed on the helper's code and signature;
* every dispatcher's compiled overloads (``@overload`` implementations and our own ``njit``
  callees), keyed on the signature, while ``fastmath`` is inherited from the calling function.

So the first kernel to need a helper decides its flags for the rest of the process. With
``fastmath=True`` on ``baseband._synthesize_kernel`` compiled first (an exact-level data set or a
test), the complex products of the ``fast`` level's FFT came out fused (FMA) and its data sets
differed in the last bits; ``cache=True`` then wrote that code to ``__pycache__`` for every later
process (docs/decisions/simulation-13-numba-cache.md).

:func:`install` (run when this module is imported; every module defining kernels imports it)
gives helpers compiled for a ``fastmath`` function their own cache per set of flags, and stops
``fastmath`` from being inherited by called dispatchers: a function's code then depends on its
own flags only, whatever was compiled before it in the process.
"""

from __future__ import annotations

import threading
from typing import Any

from numba.core import base, cpu

_lock = threading.Lock()
#: per (shared helper cache, fastmath flags): the helper cache used by contexts with those flags
_fastmath_caches: dict[tuple[int, frozenset[str]], tuple[dict, dict]] = {}
_own_caches: set[int] = set()
_installed = False


def _fastmath_flags(context: Any) -> frozenset[str]:
    """The fastmath flags of a target context (empty when off)."""
    fm = getattr(context, "fastmath", False)
    return frozenset(getattr(fm, "flags", ()) or ())


def install() -> None:
    """Make numba's in-process helper caches respect ``fastmath`` (idempotent)."""
    global _installed
    with _lock:
        if _installed:
            return
        original_subroutine = base.BaseContext.compile_subroutine
        original_finalize = cpu.CPUTargetOptions.finalize

        def compile_subroutine(self, builder, impl, sig, locals=None, flags=None, caching=True):
            fm = _fastmath_flags(self)
            shared = self.cached_internal_func
            if not fm or id(shared) in _own_caches:
                return original_subroutine(self, builder, impl, sig, locals, flags, caching)
            key = (id(shared), fm)
            with _lock:
                # the shared dict is kept in the value so its id is never reused
                own = _fastmath_caches.setdefault(key, (shared, {}))[1]
                _own_caches.add(id(own))
            self.cached_internal_func = own
            try:
                return original_subroutine(self, builder, impl, sig, locals, flags, caching)
            finally:
                self.cached_internal_func = shared

        def finalize(self, flags, options):
            own = flags.is_set("fastmath")
            original_finalize(self, flags, options)
            if not own:
                # a dispatcher's overloads are cached per signature: inheriting the caller's
                # fastmath would let the first caller decide the code every caller gets
                flags.fastmath = False

        base.BaseContext.compile_subroutine = compile_subroutine
        cpu.CPUTargetOptions.finalize = finalize
        _installed = True


install()
