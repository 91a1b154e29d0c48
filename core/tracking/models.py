"""Motion models (SPEC §4): direct discrete-time kinematic models (Bar-Shalom et al. 2001, §6.3).

State order: CV ``[x, y, vx, vy]``, CA ``[x, y, vx, vy, ax, ay]`` (the order of the paper's P0).
Per axis the noise gain is CV ``Γ = [T²/2, T]ᵀ``, CA ``Γ = [T²/2, T, 1]ᵀ``; ``Q0 = Γ·Γᵀ`` placed
into the state order and ``Q = q_coeff · Q0``.
"""

from __future__ import annotations

import numpy as np

from core.errors import InputError

__all__ = ["transition_matrix", "process_noise", "noise_gain"]


def _order(model: str) -> int:
    if model == "cv":
        return 2
    if model == "ca":
        return 3
    raise InputError(f"model must be 'cv' or 'ca', got model={model!r}")


def noise_gain(model: str, period_s: float) -> np.ndarray:
    """Per-axis noise gain Γ, shape (2,) for CV or (3,) for CA (units m, m/s, m/s² per noise)."""
    T = float(period_s)
    # Γ = [T²/2, T]ᵀ (CV), [T²/2, T, 1]ᵀ (CA)
    g = np.array([T * T / 2.0, T, 1.0])
    return g[: _order(model)]


def transition_matrix(model: str, period_s: float) -> np.ndarray:
    """State transition F over one step T, shape (n, n), n = 4 (CV) or 6 (CA)."""
    k = _order(model)
    T = float(period_s)
    # per axis: [[1, T, T²/2], [0, 1, T], [0, 0, 1]] truncated to the model's order
    f1 = np.array([[1.0, T, T * T / 2.0], [0.0, 1.0, T], [0.0, 0.0, 1.0]])[:k, :k]
    # state order is derivative-major ([x, y, vx, vy, ...]): F = f1 ⊗ I₂
    return np.kron(f1, np.eye(2))


def process_noise(model: str, period_s: float, q_coeff: float) -> np.ndarray:
    """Process noise covariance Q = q_coeff · Γ Γᵀ ⊗ I₂, shape (n, n)."""
    g = noise_gain(model, period_s)
    # Q0 = Γ Γᵀ per axis, axes independent
    q0 = np.kron(np.outer(g, g), np.eye(2))
    return float(q_coeff) * q0
