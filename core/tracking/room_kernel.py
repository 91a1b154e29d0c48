"""The room tracker compiled: :func:`core.tracking.room_loop.room_frames` under numba.

The room tracker's loop and its roles (zones, groups, allocation, ghost rule, the EKF maths) are
written once, as plain Python marked ``register_jitable``; this module compiles the loop with
them (docs/decisions/tracker-08-room-mode.md). numba's on-disk cache keys on this file only; the
kernel source hash of :mod:`core.jit_guard` covers the role modules it inlines.
"""

from __future__ import annotations

from numba import njit

from core import jit_guard  # noqa: F401  (before any kernel compiles: see core/jit_guard.py)
from core.tracking.room_loop import room_frames

__all__ = ["room_kernel"]

room_kernel = njit(cache=True)(room_frames)
