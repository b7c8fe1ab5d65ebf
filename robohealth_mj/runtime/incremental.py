"""Per-stream model state for the fleet runtime, in preallocated arrays indexed by stream slot.

Two engines, one interface (``reset``, ``push``, ``infer``), chosen by what the exported model
carries:

- :class:`IncrementalEngine` (models with the incremental form, see
  :mod:`robohealth_mj.models.incremental`): a ring of per-snapshot records per stream and running
  float64 sums, so a tick runs the network on one snapshot and one pooled window. Mean and std
  come from the sums (float64: drift stays below 1e-12 for years of ticks), min and max from a
  scan of the ring, ``last - first`` from the ring's two ends.
- :class:`WindowedEngine` (any other model): a ring of raw snapshots written twice, so each
  stream's window is one contiguous slice, and the windowed ONNX model on the gathered windows.

Both hold ``[capacity, ...]`` arrays allocated once (grown by doubling when more streams register),
so memory does not grow with time.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from robohealth_mj.schema import WINDOW_STATISTICS

NUM_STATISTICS = len(WINDOW_STATISTICS)


def rows(slots: np.ndarray) -> slice | np.ndarray:
    """``slots`` as a slice when it is one ascending run (the whole fleet, usually), so state is
    read as views instead of gathered copies."""
    n = len(slots)
    if n and slots[-1] - slots[0] == n - 1 and (n == 1 or np.all(np.diff(slots) == 1)):
        return slice(int(slots[0]), int(slots[0]) + n)
    return slots


def _grow(array: np.ndarray, capacity: int) -> np.ndarray:
    out = np.zeros((capacity, *array.shape[1:]), dtype=array.dtype)
    out[: len(array)] = array
    return out


class _Engine:
    """Shared bookkeeping: per-slot ring position and fill count."""

    _arrays: tuple[str, ...] = ()

    def __init__(self, window: int, capacity: int) -> None:
        self.window = window
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

    Rings are time-major (``[W, capacity, ...]``), so a window's extremes are elementwise maxima
    over W contiguous blocks. ``z`` holds the normalised snapshots (for the step to the next one
    and the window's two ends); ``peaks`` holds what the window takes maxima of, side by side so
    one scan serves all: the snapshot MLP ``g``, the signals' ``|step|``, the signals and their
    negation (a minimum is the negated maximum of the negation).
    """

    _arrays = ("sum_z", "sq_z", "sum_g", "sq_g", "sum_d")

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
        super().__init__(window, capacity)
        self.encode, self.head_session = encode, head
        self.g, self.first, self.s = channels, first_signal, features - first_signal
        self.z = np.zeros((window, capacity, nodes, features), np.float32)
        self.peaks = np.zeros((window, capacity, nodes, channels + 3 * self.s), np.float32)
        self.sum_z = np.zeros((capacity, nodes, self.s))
        self.sq_z = np.zeros((capacity, nodes, self.s))
        self.sum_g = np.zeros((capacity, nodes, channels))
        self.sq_g = np.zeros((capacity, nodes, channels))
        self.sum_d = np.zeros((capacity, nodes, self.s))

    def ensure(self, capacity: int) -> None:
        old = self.capacity
        super().ensure(capacity)
        for name in ("z", "peaks"):
            ring = getattr(self, name)
            if ring.shape[1] < capacity:
                grown = np.zeros((ring.shape[0], capacity, *ring.shape[2:]), ring.dtype)
                grown[:, :old] = ring
                setattr(self, name, grown)

    def reset(self, slots: np.ndarray) -> None:
        super().reset(slots)
        for name in self._arrays:
            getattr(self, name)[slots] = 0.0

    def push(self, slots: np.ndarray, x: np.ndarray) -> None:
        """Add one raw snapshot ``x [B, 12, F]`` to each stream in ``slots`` (distinct)."""
        w, g, f0 = self.window, self.g, self.first
        gd = g + self.s  # the part of a peak record that enters the sums: g and |step|
        r = rows(slots)
        h, c = self.head[r], self.count[r]
        first_pos = (h + 1) % w  # the window's first snapshot once this one is in (when full)
        z_prev, z_first = self.z[(h - 1) % w, slots], self.z[first_pos, slots]
        has_prev = (c > 0).astype(np.float32)
        z_new, g_new, g_first = self.encode.run(
            None,
            {"x_new": x, "z_prev": z_prev, "z_first": z_first, "has_prev": has_prev},
        )
        signal = z_new[..., f0:]
        step = np.abs(signal - z_prev[..., f0:]) * has_prev[:, None, None]
        record = np.concatenate([g_new, step, signal, -signal], axis=-1)
        # the record written now replaces the oldest one (nothing while the window fills)
        old = self.peaks[h, slots]
        if not (c >= w).all():
            old = np.where((c >= w)[:, None, None], old, 0.0)
        self.z[h, slots] = z_new
        self.peaks[h, slots] = record
        # the new first snapshot gets a zero step, as the windowed encoder gives it
        was = self.peaks[first_pos, slots]
        fixed = np.concatenate([g_first, np.zeros_like(step), was[..., gd:]], axis=-1)
        if not (c + 1 >= w).all():
            fixed = np.where((c + 1 >= w)[:, None, None], fixed, was)
        self.peaks[first_pos, slots] = fixed
        self._add(r, signal, old[..., gd : gd + self.s])
        self._add_records(r, record[..., :gd], old[..., :gd], fixed[..., :gd], was[..., :gd])
        self.head[r] = (h + 1) % w
        self.count[r] = np.minimum(c + 1, w)

    def _add(self, r: slice | np.ndarray, new: np.ndarray, old: np.ndarray) -> None:
        """Signal sums += new - old (float64)."""
        n, o = new.astype(np.float64), old.astype(np.float64)
        self.sum_z[r] += n - o
        self.sq_z[r] += n * n - o * o

    def _add_records(self, r: slice | np.ndarray, new, old, fixed, was) -> None:
        """Record sums (g, g^2, |step|) += (new - old) + (fixed - was), in float64."""
        g = self.g
        n, o = new.astype(np.float64), old.astype(np.float64)
        f, v = fixed.astype(np.float64), was.astype(np.float64)
        delta = n - o
        delta += f
        delta -= v
        self.sum_g[r] += delta[..., :g]
        self.sum_d[r] += delta[..., g:]
        ng, og, fg, vg = n[..., :g], o[..., :g], f[..., :g], v[..., :g]
        self.sq_g[r] += ng * ng - og * og + fg * fg - vg * vg

    def infer(self, slots: np.ndarray) -> list[np.ndarray]:
        """The model's outputs for the (full) windows of ``slots``."""
        w, g, f0, s = self.window, self.g, self.first, self.s
        r = rows(slots)
        head = self.head[r]
        last = self.z[(head - 1) % w, slots]
        first = self.z[head, slots]  # the oldest slot is the next to write
        peak = _ring_max(self.peaks, slots, r)  # [B, N, G + 3S]
        b, n = peak.shape[:2]
        views = np.empty((b, n, 3 * g + 7 * s + f0), np.float32)  # the encoder's views, in order
        mean_g = self.sum_g[r] / w
        views[..., :g] = mean_g
        views[..., g : 2 * g] = _std(self.sq_g[r] / w, mean_g)
        views[..., 2 * g : 3 * g] = peak[..., :g]
        stats = views[..., 3 * g : 3 * g + 7 * s]
        per_channel = stats.reshape(b, n, s, 7)  # statistics-major within each channel
        mean_z = self.sum_z[r] / w
        per_channel[..., 0] = mean_z
        per_channel[..., 1] = _std(self.sq_z[r] / w, mean_z)
        per_channel[..., 2] = -peak[..., g + 2 * s :]  # min
        per_channel[..., 3] = peak[..., g + s : g + 2 * s]  # max
        per_channel[..., 4] = last[..., f0:] - first[..., f0:]
        per_channel[..., 5] = self.sum_d[r] / (w - 1)
        per_channel[..., 6] = peak[..., g : g + s]  # max |step|
        _asinh(stats)
        views[..., 3 * g + 7 * s :] = last[..., :f0]
        return self.head_session.run(None, {"views": views, "z_last": last})


def _ring_max(ring: np.ndarray, slots: np.ndarray, r: slice | np.ndarray) -> np.ndarray:
    """Max over the window axis of the rings of ``slots``. For a selection with few holes (a
    fleet tick minus its flagged rows) the scan runs over the covering span, contiguous, and the
    rows are picked afterwards: gathering W records per stream would cost more than the holes."""
    if isinstance(r, slice):
        return ring[:, r].max(axis=0)
    lo, hi = int(slots.min()), int(slots.max()) + 1
    if hi - lo <= 1.25 * len(slots):
        return ring[:, lo:hi].max(axis=0)[slots - lo]
    return ring[:, slots].max(axis=0)


def _asinh(x: np.ndarray) -> None:
    """float32 asinh in place, as ``copysign(log(|x| + sqrt(x^2 + 1)), x)``: numpy's arcsinh is
    a scalar loop, ten times slower at fleet sizes; within 3e-7 of it."""
    a = np.abs(x)
    y = np.multiply(a, a)
    y += 1.0
    np.sqrt(y, out=y)
    y += a
    np.log(y, out=y)
    np.copysign(y, x, out=x)


def _std(mean_square: np.ndarray, mean: np.ndarray) -> np.ndarray:
    """Population std as the windowed encoder has it: ``sqrt(max(var, 1e-12))``."""
    return np.sqrt(np.maximum(mean_square - np.square(mean), 1e-12))


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

    def windows(self, slots: np.ndarray) -> np.ndarray:
        """``[B, W, 12, F]``, oldest first."""
        idx = self.head[slots][:, None] + np.arange(self.window)
        return self.ring[slots[:, None], idx]

    def infer(self, slots: np.ndarray) -> list[np.ndarray]:
        return self.session.run(None, {"x": self.windows(slots)})


assert NUM_STATISTICS == 7, "IncrementalEngine.infer fills in the seven window statistics"
