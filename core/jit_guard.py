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

numba's on-disk cache (``cache=True``) keys a kernel on its own file's content and signature,
but the cached code includes the kernels it calls from other modules: after an edit of
``rng_kernels.py`` the kernels of ``fast.py`` would still load their old copy. :func:`install`
also puts first a cache locator for the kernels under ``core/`` whose source stamp adds the hash
of every ``core`` module that uses numba (:func:`kernel_sources_hash`): editing any of them
recompiles all of RadarTune's kernels once (about a minute on the development machine).
Module-level constants imported from modules without kernels (``core.config``) are frozen into
the compiled code and still not covered.
"""

from __future__ import annotations

import functools
import hashlib
import threading
from pathlib import Path
from typing import Any

from numba.core import base, cpu
from numba.core import caching as numba_caching

#: the package whose kernels get the salted cache stamp
CORE_DIR = Path(__file__).resolve().parent

_lock = threading.Lock()
#: per (shared helper cache, fastmath flags): the helper cache used by contexts with those flags
_fastmath_caches: dict[tuple[int, frozenset[str]], tuple[dict, dict]] = {}
_own_caches: set[int] = set()
_installed = False


def _fastmath_flags(context: Any) -> frozenset[str]:
    """The fastmath flags of a target context (empty when off)."""
    fm = getattr(context, "fastmath", False)
    return frozenset(getattr(fm, "flags", ()) or ())


@functools.lru_cache(maxsize=1)
def kernel_sources_hash() -> str:
    """sha256 over the path and content of every module under ``core/`` that uses numba."""
    h = hashlib.sha256()
    for path in sorted(CORE_DIR.rglob("*.py")):
        text = path.read_bytes()
        if b"import numba" in text or b"from numba" in text:
            h.update(path.relative_to(CORE_DIR).as_posix().encode())
            h.update(hashlib.sha256(text).digest())
    return h.hexdigest()


class _SaltedStamp:
    """Locator mixin: the kernel's file stamp and :func:`kernel_sources_hash`, for core only."""

    def get_source_stamp(self):
        return (super().get_source_stamp(), kernel_sources_hash())  # type: ignore[misc]

    @classmethod
    def from_function(cls, py_func, py_file):
        if not Path(py_file).resolve().is_relative_to(CORE_DIR):
            return None
        return super().from_function(py_func, py_file)  # type: ignore[misc]


class _SaltedUserProvidedLocator(_SaltedStamp, numba_caching.UserProvidedCacheLocator):
    """``NUMBA_CACHE_DIR`` set: that directory, salted stamp."""


class _SaltedInTreeLocator(_SaltedStamp, numba_caching.InTreeCacheLocator):
    """The module's ``__pycache__``, salted stamp."""


def install() -> None:
    """Helper caches that respect ``fastmath``, salted on-disk stamps for core (idempotent)."""
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

        base.BaseContext.compile_subroutine = compile_subroutine  # type: ignore[method-assign]
        cpu.CPUTargetOptions.finalize = finalize  # type: ignore[method-assign]
        salted = [_SaltedUserProvidedLocator, _SaltedInTreeLocator]
        numba_caching.CacheImpl._locator_classes[:0] = salted
        _installed = True


install()
