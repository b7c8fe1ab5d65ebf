"""Where a fleet tick's time goes: wall time per named phase, for ``bench streams --profile``.

The runtime calls :meth:`PhaseClock.start` when a piece of work begins and :meth:`PhaseClock.mark`
when each phase ends; a mark charges the time since the previous mark (or the start) on the same
thread to its phase. Shard threads keep their own clocks, so with several shards a phase's total
is thread time (it can exceed the tick's wall time). The default clock, :data:`NO_CLOCK`, does
nothing, so the production path pays two no-op calls per phase.
"""

from __future__ import annotations

import threading
import time
from collections import defaultdict


class NoClock:
    """The clock that measures nothing (the runtime's default)."""

    def start(self) -> None:
        """Begin timing on this thread."""

    def mark(self, phase: str) -> None:
        """Charge the time since the last mark to ``phase``."""


NO_CLOCK = NoClock()


class PhaseClock(NoClock):
    """Accumulated seconds per phase, summed over ticks and threads."""

    def __init__(self) -> None:
        self._local = threading.local()
        self._lock = threading.Lock()
        self.seconds: dict[str, float] = defaultdict(float)

    def start(self) -> None:
        self._local.last = time.perf_counter()

    def mark(self, phase: str) -> None:
        now = time.perf_counter()
        elapsed = now - getattr(self._local, "last", now)
        self._local.last = now
        with self._lock:
            self.seconds[phase] += elapsed

    def reset(self) -> None:
        with self._lock:
            self.seconds.clear()
