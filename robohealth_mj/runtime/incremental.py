"""Per-stream model state for the fleet runtime, in preallocated arrays indexed by stream slot.

Two engines, one interface (``reset``, ``push``, ``infer``), chosen by what the exported model
carries:

- :class:`IncrementalEngine` (models with the incremental form, see
  :mod:`robohealth_mj.models.incremental`): a ring of per-snapshot records per stream and running
  float64 sums, so a tick runs the network on one snapshot and one pooled window. Mean and std
  come from the sums (float64: drift stays below 1e-12 for years of ticks), maxima (and minima)
  from blocks of running maxima (three records a tick, not a scan of the window), ``last - first``
  from the ring's two ends.
- :class:`WindowedEngine` (any other model): a ring of raw snapshots written twice, so each
  stream's window is one contiguous slice, and the windowed ONNX model on the gathered windows.

Both hold ``[capacity, ...]`` arrays allocated once (grown by doubling when more streams register),
so memory does not grow with time.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from robohealth_mj.runtime import kernels
from robohealth_mj.runtime.phases import NO_CLOCK
from robohealth_mj.schema import WINDOW_STATISTICS

NUM_STATISTICS = len(WINDOW_STATISTICS)


def _grow(array: np.ndarray, capacity: int) -> np.ndarray:
    out = np.zeros((capacity, *array.shape[1:]), dtype=array.dtype)
    out[: len(array)] = array
    return out


class _Engine:
    """Shared bookkeeping: per-slot ring position and fill count."""

    _arrays: tuple[str, ...] = ()

    def __init__(self, window: int, capacity: int) -> None:
        self.window = window
        self.clock = NO_CLOCK  # where push and infer spend their time (bench streams --profile)
        self.head = np.zeros(capacity, dtype=np.int64)  # next ring position to write
        self.count = np.zeros(capacity, dtype=np.int64)  # snapshots in the window (<= W)

    @property
    def capacity(self) -> int:
        return len(self.head)

    def ensure(self, capacity: int) -> None:
        if capacity <= self.capacity:
            return
        for name in ("head", "count", *self._arrays):
            setattr(self, name, _grow(getattr(self, name), capacity))

    def reset(self, slots: np.ndarray) -> None:
        """Start these streams' windows again (a gap, a new stream)."""
        self.head[slots] = 0
        self.count[slots] = 0

    def full(self, slots: np.ndarray) -> np.ndarray:
        return self.count[slots] >= self.window


class IncrementalEngine(_Engine):
    """Per-snapshot records in rings + running sums; ``encode`` and ``head`` are the exported
    ``SnapshotStep`` and ``PooledHead`` sessions.

    A window's statistics come from float64 running sums (means, stds, mean ``|step|``) and from
    maxima (the snapshot MLP ``g``, ``|step|``, the signals and their negation: a minimum is the
    negated maximum of the negation). The W - 1 newest snapshots' ``g`` count as recorded; the
    window's oldest counts with a zero step and its own ``g_first`` where the encoder pools it
    (``first_record``: the exported ``encode`` then takes ``z_first``), and not at all otherwise.
    Their maximum is kept by blocks of W - 1 snapshots (van Herk / Gil-Werman): a running maximum
    of the current block (``prefix``) and the suffix maxima of the previous block (``suffix``,
    computed once when a block completes), so a tick reads three records per stream instead of
    scanning W. Each stream's block phase is staggered by its slot, so the completions, which
    cost W - 1 records each, spread evenly over the ticks.

    Rings are time-major (``[W, capacity, ...]``): ``z`` holds the normalised snapshots (for the
    step to the next one, the signals, the window's two ends), ``raw`` each snapshot's ``g`` and
    ``|step|`` as recorded (what the sums take back when it becomes the oldest).
    """

    _arrays = ("sum_z", "sq_z", "sum_g", "sq_g", "sum_d", "g_fixed", "prefix", "phase")

    def __init__(
        self,
        encode: Any,
        head: Any,
        window: int,
        nodes: int,
        features: int,
        channels: int,
        first_signal: int,
        capacity: int,
    ) -> None:
        if window < 2:
            raise ValueError(f"the incremental form needs a window of at least 2, not {window}")
        super().__init__(window, capacity)
        self.encode, self.head_session = encode, head
        self.first_record = "z_first" in {i.name for i in encode.get_inputs()}
        self.g, self.first, self.s = channels, first_signal, features - first_signal
        self.block = window - 1
        record = channels + 3 * self.s  # g, |step|, signal, -signal
        self.z = np.zeros((window, capacity, nodes, features), np.float32)
        self.raw = np.zeros((window, capacity, nodes, channels + self.s), np.float32)
        # suffix[j]: max over the previous block's positions j..W-2 (the block completed last)
        self.suffix = np.zeros((self.block, capacity, nodes, record), np.float32)
        # the current block's running maximum (a block cut short by a reset is never read: a
        # window fills in W pushes, by when the block it ends in started after the reset)
        self.prefix = np.zeros((capacity, nodes, record), np.float32)
        # the oldest's g_first (written and read only with first_record)
        self.g_fixed = np.zeros((capacity, nodes, channels), np.float32)
        self.phase = np.arange(capacity, dtype=np.int64) % self.block  # next block position
        self.sum_z = np.zeros((capacity, nodes, self.s))
        self.sq_z = np.zeros((capacity, nodes, self.s))
        self.sum_g = np.zeros((capacity, nodes, channels))
        self.sq_g = np.zeros((capacity, nodes, channels))
        self.sum_d = np.zeros((capacity, nodes, self.s))
        self._compile()

    def _compile(self) -> None:
        """Run both kernels on no stream: numba compiles them now (or loads its cache), not
        inside the first tick."""
        none, nodes, f = np.zeros(0, np.int64), self.z.shape[2], self.z.shape[3]
        g = np.zeros((0, nodes, self.g), np.float32)
        self._push_state(none, np.zeros((0, nodes, f), np.float32), g, g, np.zeros(0, np.float32))
        self.views(none)

    def _push_state(self, slots, z_new, g_new, g_first, has_prev) -> None:
        """The push kernel on this engine's state (see :func:`kernels.push_snapshots`)."""
        kernels.push_snapshots(
            slots, z_new, g_new, g_first, has_prev, self.z, self.raw, self.suffix, self.prefix,
            self.g_fixed, self.sum_z, self.sq_z, self.sum_g, self.sq_g, self.sum_d, self.head,
            self.count, self.phase, self.first, self.first_record,
        )  # fmt: skip

    def ensure(self, capacity: int) -> None:
        old = self.capacity
        super().ensure(capacity)
        for name in ("z", "raw", "suffix"):
            ring = getattr(self, name)
            if ring.shape[1] < capacity:
                grown = np.zeros((ring.shape[0], capacity, *ring.shape[2:]), ring.dtype)
                grown[:, :old] = ring
                setattr(self, name, grown)

    def reset(self, slots: np.ndarray) -> None:
        super().reset(slots)
        for name in ("sum_z", "sq_z", "sum_g", "sq_g", "sum_d", "g_fixed"):
            getattr(self, name)[slots] = 0.0
        self.phase[slots] = np.asarray(slots) % self.block

    def push(self, slots: np.ndarray, x: np.ndarray) -> None:
        """Add one raw snapshot ``x [B, 2J, F]`` to each stream in ``slots`` (distinct)."""
        w = self.window
        h = self.head[slots]
        has_prev = (self.count[slots] > 0).astype(np.float32)
        feeds = {"x_new": x, "z_prev": self.z[(h - 1) % w, slots], "has_prev": has_prev}
        if self.first_record:
            feeds["z_first"] = self.z[(h + 1) % w, slots]
        z_new, g_new, *first = self.encode.run(None, feeds)
        self.clock.mark("encode (ONNX)")
        self._push_state(slots, z_new, g_new, first[0] if first else g_new, has_prev)
        self.clock.mark("rings, sums")

    def views(self, slots: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The pooled head's inputs for the (full) windows of ``slots``: ``views [B, N, 3G +
        7S + f0]`` and the newest normalised snapshot ``z_last [B, N, F]``."""
        b, n, f = len(slots), self.z.shape[2], self.z.shape[3]
        views = np.empty((b, n, 3 * self.g + 7 * self.s + self.first), np.float32)
        last = np.empty((b, n, f), np.float32)
        kernels.fill_views(
            slots, views, last, self.z, self.head, self.prefix, self.suffix, self.phase,
            self.g_fixed, self.sum_g, self.sq_g, self.sum_z, self.sq_z, self.sum_d, self.first,
            self.first_record,
        )  # fmt: skip
        return views, last

    def infer(self, slots: np.ndarray) -> list[np.ndarray]:
        """The model's outputs for the (full) windows of ``slots``."""
        views, last = self.views(np.asarray(slots, np.int64))
        self.clock.mark("views")
        outputs = self.head_session.run(None, {"views": views, "z_last": last})
        self.clock.mark("head (ONNX)")
        return outputs


class WindowedEngine(_Engine):
    """Raw snapshots in a ring written twice (positions ``p`` and ``p + W``), so the window that
    ends at the newest snapshot is the contiguous slice ``[head, head + W)``."""

    _arrays = ("ring",)

    def __init__(self, session: Any, window: int, nodes: int, features: int, capacity: int):
        super().__init__(window, capacity)
        self.session = session
        self.ring = np.zeros((capacity, 2 * window, nodes, features), np.float32)

    def push(self, slots: np.ndarray, x: np.ndarray) -> None:
        h = self.head[slots]
        self.ring[slots, h] = x
        self.ring[slots, h + self.window] = x
        self.head[slots] = (h + 1) % self.window
        self.count[slots] = np.minimum(self.count[slots] + 1, self.window)
        self.clock.mark("rings, sums")

    def windows(self, slots: np.ndarray) -> np.ndarray:
        """``[B, W, 2J, F]``, oldest first."""
        idx = self.head[slots][:, None] + np.arange(self.window)
        return self.ring[slots[:, None], idx]

    def infer(self, slots: np.ndarray) -> list[np.ndarray]:
        windows = self.windows(slots)
        self.clock.mark("views")
        outputs = self.session.run(None, {"x": windows})
        self.clock.mark("head (ONNX)")
        return outputs


assert NUM_STATISTICS == 7, "IncrementalEngine.infer fills in the seven window statistics"
