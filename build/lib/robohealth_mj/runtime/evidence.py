"""Memory in the diagnosis: per-stream evidence accumulated over windows, vectorised over streams.

One window of 1.6 s decides alone, and forgets at the next tick. A faint fault (a small, steady
extra twist under load) gives windows that lean towards it without ever being sure; a fault on a
joint at rest gives no evidence at all until the joint moves again. Both are what sequential
tests are for. Each tick adds the window's log-probabilities, taken relative to its top class,
to a running sum per class (``none`` included) that forgets with time constant ``horizon_s``::

    l_c = max(log p_c - max_k log p_k, -clip)              (<= 0; the top class adds 0)
    L_c <- max(lambda * L_c + l_c - max_k(...), -floor),   lambda = exp(-tick_s / horizon_s)

and the alarms (:mod:`robohealth_mj.runtime.alarms`) read the *accumulated* probabilities
``softmax(L)`` in place of the window's. It is Bayes' rule over "which class holds now", with
forgetting: ``clip`` bounds what one window can say (overlapping windows are not independent
evidence, and one confident window must not decide alone), and ``floor`` bounds how far behind
any class can fall, so a class that was ruled out for an hour catches up within ``floor / clip``
ticks once the windows start to favour it (with no forgetting, this bound is what makes the test
CUSUM-like: evidence against a hypothesis is forgotten below the bound). ``horizon_s = 0`` is no
memory: the accumulated probabilities are the window's own.

The state is ``C`` floats per stream, updated in O(1) per tick; a gap in the stream or a restart
resets it with the window (the runtime calls :meth:`EvidenceBank.reset`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

_EPS = 1e-12


@dataclass(frozen=True)
class EvidencePolicy:
    """How per-window class probabilities accumulate (log-probabilities in nats)."""

    horizon_s: float = 0.0  # forgetting time constant; 0: no memory (the window's probabilities)
    clip: float = 4.0  # the most one window can count against a class
    floor: float = 8.0  # no class falls further than this behind the leader
    tick_s: float = 0.05

    def __post_init__(self) -> None:
        if self.horizon_s < 0 or self.tick_s <= 0:
            raise ValueError("evidence horizon_s must be >= 0 and tick_s > 0")
        if self.clip <= 0 or self.floor <= 0:
            raise ValueError(f"evidence clip and floor must be > 0, got {self.clip}, {self.floor}")

    @property
    def memory(self) -> bool:
        return self.horizon_s > 0

    @property
    def clearing_ticks(self) -> int:
        """Ticks of healthy windows the evidence needs, at most, to let a fault go (its lead
        falls by up to ``clip`` a tick from at most ``floor``); 0 without memory."""
        return math.ceil(self.floor / self.clip) if self.memory else 0

    @property
    def decay(self) -> float:
        """``lambda``, the share of the accumulated evidence kept from one tick to the next
        (``inf`` horizon: 1, no forgetting)."""
        return math.exp(-self.tick_s / self.horizon_s) if self.memory else 0.0


def window_evidence(probs: np.ndarray, clip: float) -> np.ndarray:
    """``max(log p_c - max_k log p_k, -clip)``: ``probs [B, C]`` -> ``[B, C]``, each <= 0."""
    logp = np.log(np.maximum(probs, _EPS))
    return np.maximum(logp - logp.max(axis=1, keepdims=True), -clip)


def accumulated_probabilities(evidence: np.ndarray) -> np.ndarray:
    """``softmax(L)`` row-wise: ``[B, C]`` -> ``[B, C]``."""
    e = np.exp(evidence - evidence.max(axis=1, keepdims=True))
    return e / e.sum(axis=1, keepdims=True)


class EvidenceBank:
    """Accumulated evidence ``[capacity, C]`` of every stream slot (the leader at 0)."""

    def __init__(self, policy: EvidencePolicy, classes: int, capacity: int) -> None:
        self.policy = policy
        self.evidence = np.zeros((capacity, classes), np.float64)

    def ensure(self, capacity: int) -> None:
        if capacity > len(self.evidence):
            grown = np.zeros((capacity, self.evidence.shape[1]), self.evidence.dtype)
            grown[: len(self.evidence)] = self.evidence
            self.evidence = grown

    def reset(self, slots: np.ndarray) -> None:
        """Forget these slots' evidence (a new stream, a gap, a restart)."""
        self.evidence[slots] = 0.0

    def update(self, slots: np.ndarray, probs: np.ndarray) -> np.ndarray:
        """One decided tick per slot (distinct): window ``probs [B, C]`` -> accumulated
        probabilities ``[B, C]`` (the window's own when the policy has no memory)."""
        p = self.policy
        if not p.memory:
            return probs
        total = p.decay * self.evidence[slots] + window_evidence(probs, p.clip)
        total = np.maximum(total - total.max(axis=1, keepdims=True), -p.floor)
        self.evidence[slots] = total
        return accumulated_probabilities(total).astype(probs.dtype)
