"""Joint integrated probabilistic data association (JIPDA; Mušicki & Evans, IEEE TAES 40(3), 2004).

The association role when several tracks' gates share measurements. Tracks are grouped into
clusters (connected components of the graph "track τ and track σ validate a common
measurement"); within a cluster every joint association event ε is enumerated: each track takes
at most one of its validated measurements, each measurement goes to at most one track. With
ψ⁻_τ the predicted existence and Λ_τi the IPDA likelihood ratio (:mod:`core.tracking.ipda`):

- joint event weight: p(ε) ∝ Π_{τ∉ε} (1 − P_D·P_G·ψ⁻_τ) · Π_{(τ,i)∈ε} P_D·P_G·ψ⁻_τ·Λ_τi
- marginals: β'_τi = Σ_{ε∋(τ,i)} p(ε),  β'_τ0 = Σ_{ε: τ takes none} p(ε)
- existence: ψ_τ = Σ_i β'_τi + β'_τ0 · (1 − P_D·P_G)·ψ⁻_τ / (1 − P_D·P_G·ψ⁻_τ)
- association given existence: β_τi = β'_τi / ψ_τ,
  β_τ0 = β'_τ0 · (1 − P_D·P_G)·ψ⁻_τ / (1 − P_D·P_G·ψ⁻_τ) / ψ_τ

and the PDA state update of each track uses its β (:func:`core.tracking.ipda.pda_update`). For a
cluster of one track these are algebraically the IPDA equations; the tracker then calls the IPDA
functions themselves, so a lone track (one track, or tracks whose gates share nothing) gets
exactly today's IPDA update, bit for bit.

Bound: a cluster whose event count bound Π_τ (1 + m_τ) (m_τ validated measurements of track τ)
exceeds :data:`MAX_JOINT_EVENTS` is not enumerated: each of its tracks gets the independent
IPDA update instead (today's behaviour), so the cost per frame stays below about
MAX_JOINT_EVENTS × (tracks in the cluster) operations.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = [
    "ASSOCIATIONS",
    "MAX_JOINT_EVENTS",
    "clusters",
    "event_bound",
    "joint_events",
    "JointAssociation",
    "joint_associate",
]

#: The association options of the tracker: independent IPDA per track, or joint IPDA.
ASSOCIATIONS = ("ipda", "jipda")

#: Largest event-count bound Π (1 + m_τ) of a cluster that is enumerated; beyond it the cluster's
#: tracks fall back to the independent IPDA update.
MAX_JOINT_EVENTS = 10_000


def clusters(gated: np.ndarray) -> np.ndarray:
    """Cluster labels of the tracks: tracks sharing a validated measurement, transitively.

    Parameters
    ----------
    gated
        (n_tracks, m) bool, track τ validates measurement j.

    Returns
    -------
    numpy.ndarray
        (n_tracks,) int64 label per track: the smallest track index of its cluster.
    """
    n = gated.shape[0]
    label = np.arange(n, dtype=np.int64)

    def root(a: int) -> int:
        while label[a] != a:
            a = int(label[a])
        return a

    for j in range(gated.shape[1]):
        owners = np.flatnonzero(gated[:, j])
        for b in owners[1:]:
            ra, rb = root(int(owners[0])), root(int(b))
            # union: the smaller index becomes the root
            label[max(ra, rb)] = min(ra, rb)
    return np.array([root(a) for a in range(n)], dtype=np.int64)


def event_bound(n_validated: np.ndarray) -> int:
    """Upper bound Π_τ (1 + m_τ) on the number of joint events of a cluster."""
    bound = 1
    for m in n_validated:
        bound *= 1 + int(m)
    return bound


def joint_events(options: list[np.ndarray]):
    """Every joint event of a cluster, depth first (track 0 slowest, option 0 = no measurement).

    Parameters
    ----------
    options
        Per track of the cluster, the (m_τ,) measurement indices it validates.

    Yields
    ------
    tuple[int, ...]
        Per track the option taken: 0 for none, k ≥ 1 for ``options[τ][k − 1]``; no measurement
        is taken twice.
    """
    n = len(options)
    used: set[int] = set()
    choice = [0] * n

    def descend(level: int):
        if level == n:
            yield tuple(choice)
            return
        for k in range(len(options[level]) + 1):
            if k:
                j = int(options[level][k - 1])
                if j in used:
                    continue
                used.add(j)
            choice[level] = k
            yield from descend(level + 1)
            if k:
                used.discard(j)

    yield from descend(0)


@dataclass(frozen=True, slots=True, kw_only=True)
class JointAssociation:
    """Result of the JIPDA step of one cluster of n tracks.

    Attributes
    ----------
    psi
        (n,) updated existence ψ_τ.
    beta0
        (n,) probability, given existence, that none of the validated measurements is the
        target's.
    beta
        Per track the (m_τ,) association probabilities given existence; β₀ + Σβ = 1 (β₀ = 1,
        β = 0 when ψ_τ = 0).
    marginal0
        (n,) β'_τ0, the probability of the events in which τ takes no measurement.
    marginal
        Per track the (m_τ,) β'_τi, the probability of the events in which τ takes measurement i.
    n_events
        Number of joint events enumerated.
    """

    psi: np.ndarray
    beta0: np.ndarray
    beta: tuple[np.ndarray, ...]
    marginal0: np.ndarray
    marginal: tuple[np.ndarray, ...]
    n_events: int


def joint_associate(
    psi_pred: np.ndarray,
    log_lr: list[np.ndarray],
    options: list[np.ndarray],
    pdpg: float,
) -> JointAssociation:
    """JIPDA marginals and existence of one cluster (the equations of the module docstring).

    Parameters
    ----------
    psi_pred
        (n,) predicted existence ψ⁻_τ.
    log_lr
        Per track the (m_τ,) log Λ_τi of its validated measurements.
    options
        Per track the (m_τ,) indices (in the frame) of the same measurements.
    pdpg
        P_D·P_G < 1.

    Returns
    -------
    JointAssociation
    """
    n = len(psi_pred)
    # log of the per-track factors: w_τ0 = 1 − P_D P_G ψ⁻_τ, w_τi = P_D P_G ψ⁻_τ Λ_τi
    log_w0 = np.array([math.log1p(-pdpg * float(p)) for p in psi_pred])
    log_w = [
        (math.log(pdpg * float(p)) if p > 0.0 else -math.inf) + np.asarray(lr, dtype=np.float64)
        for p, lr in zip(psi_pred, log_lr)
    ]
    events = list(joint_events(options))
    # log p(ε) up to the normalisation: Σ_τ log w_τ,ε(τ)
    log_p = np.array(
        [sum(log_w0[t] if k == 0 else log_w[t][k - 1] for t, k in enumerate(e)) for e in events]
    )
    top = float(np.max(log_p))
    p = np.exp(log_p - top)
    p /= p.sum()
    marginal0 = np.zeros(n)
    marginal = [np.zeros(len(o)) for o in options]
    for e, pe in zip(events, p):
        for t, k in enumerate(e):
            if k == 0:
                marginal0[t] += pe
            else:
                marginal[t][k - 1] += pe
    psi = np.zeros(n)
    beta0 = np.ones(n)
    beta = []
    for t in range(n):
        pp = float(psi_pred[t])
        # q_τ = (1 − P_D P_G) ψ⁻_τ / (1 − P_D P_G ψ⁻_τ): P(exists | no measurement is its own)
        q = (1.0 - pdpg) * pp / (1.0 - pdpg * pp)
        # ψ_τ = Σ_i β'_τi + β'_τ0 q_τ
        ps = float(np.sum(marginal[t])) + marginal0[t] * q
        if ps > 0.0:
            psi[t] = min(1.0, ps)
            # β_τ0 = β'_τ0 q_τ / ψ_τ, β_τi = β'_τi / ψ_τ
            beta0[t] = marginal0[t] * q / ps
            beta.append(marginal[t] / ps)
        else:
            beta.append(np.zeros(len(options[t])))
    return JointAssociation(
        psi=psi,
        beta0=beta0,
        beta=tuple(beta),
        marginal0=marginal0,
        marginal=tuple(marginal),
        n_events=len(events),
    )
