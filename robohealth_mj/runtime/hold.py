"""Decisions every ``k`` ticks: the model runs on a stream every ``k``-th tick and its outputs are
held in between.

Why: on a CPU the network and the pooled views it reads are most of a tick's cost, and a window
of 1.6 s moves little in 50 ms: consecutive windows share W - 1 of their W snapshots. Holding a
decision for ``k`` ticks divides that cost by ``k``; the evidence and the alarms still update
every tick (on the held outputs), so their settings keep their meaning in ticks, and a fault is
seen at most ``k - 1`` ticks later. Streams are staggered by slot, so each tick runs the model on
about ``1/k`` of them. The window itself still takes every sample (a decision is always on the
newest window).
"""

from __future__ import annotations

import threading
from collections.abc import Callable

import numpy as np


class DecisionHold:
    """Per-slot held outputs and the ticks since the model last ran on each slot."""

    def __init__(self, every: int, capacity: int) -> None:
        if every < 1:
            raise ValueError(f"decide_every must be at least 1 tick, not {every}")
        self.every = every
        self.age = np.zeros(capacity, np.int64)
        self.valid = np.zeros(capacity, bool)  # a held output of the current window run
        self.outputs: list[np.ndarray] | None = None
        self._first = threading.Lock()

    def ensure(self, capacity: int) -> None:
        n = capacity - len(self.age)
        if n <= 0:
            return
        self.age = np.concatenate([self.age, np.zeros(n, np.int64)])
        self.valid = np.concatenate([self.valid, np.zeros(n, bool)])
        if self.outputs is not None:
            self.outputs = [np.concatenate([o, np.zeros((n, *o.shape[1:]), o.dtype)])
                            for o in self.outputs]  # fmt: skip

    def reset(self, slots: np.ndarray) -> None:
        """These slots' windows restarted: their next decision runs the model."""
        self.valid[slots] = False

    def decide(
        self, slots: np.ndarray, infer: Callable[[np.ndarray], list[np.ndarray]]
    ) -> list[np.ndarray]:
        """The outputs for ``slots`` (distinct, windows full): ``infer`` on those due, the held
        ones for the rest."""
        if self.every == 1:
            return infer(slots)
        self.age[slots] += 1
        due = ~self.valid[slots] | (self.age[slots] >= self.every)
        run = slots[due]
        if len(run):
            got = infer(run)
            with self._first:  # shard threads decide disjoint slots; the arrays are made once
                if self.outputs is None:
                    cap = len(self.age)
                    self.outputs = [np.zeros((cap, *o.shape[1:]), o.dtype) for o in got]
            for held, new in zip(self.outputs, got, strict=True):
                held[run] = new
            first = ~self.valid[run]
            # a stream's first decision sets its phase by slot: the streams' model calls
            # spread over the k ticks instead of all falling on the same one
            self.age[run] = np.where(first, run % self.every, 0)
            self.valid[run] = True
        if self.outputs is None:  # no slot asked for: nothing was ever run
            return infer(slots)
        return [held[slots] for held in self.outputs]
