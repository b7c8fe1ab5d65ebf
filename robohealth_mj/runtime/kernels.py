"""The incremental engine's per-stream work, compiled (numba): one pass over each stream's state.

Written with numpy, one fleet tick is some forty array passes with their temporaries (float64
conversions, concatenations, masks, the seven window statistics and their asinh), and costs as
much as the network itself (``bench streams --profile``). Here each stream is one loop over its
nodes and channels, reading and writing its state once, with the same arithmetic in the same
order (float32 where the numpy code was float32, float64 sums), so the windows' statistics are
the numpy code's. The kernels release the GIL: the fleet's shard threads run them side by side.

Shapes: ``B`` streams this call, ``W`` window, ``N`` nodes, ``F`` features (``f0`` of them
indicators, ``S = F - f0`` signals), ``G`` snapshot-MLP channels, ``R = G + 3S`` record channels
(``g``, ``|step|``, signal, -signal). Rings are time-major ``[W, capacity, N, ...]``.
``first_record``: whether the window pools its oldest snapshot's ``g`` (``g_first``, with a
zero step), as the encoder it serves does.
"""

from __future__ import annotations

import numba as nb
import numpy as np

_ONE = np.float32(1.0)


@nb.njit(cache=True, nogil=True)
def _max(a, b):
    """``np.maximum(a, b)`` for finite values (the first argument on a tie, as numpy)."""
    return a if a >= b else b


@nb.njit(cache=True, nogil=True)
def push_snapshots(
    slots, z_new, g_new, g_first, has_prev,
    z, raw, suffix, prefix, g_fixed, sum_z, sq_z, sum_g, sq_g, sum_d, head, count, phase, f0,
    first_record,
):  # fmt: skip
    """Write each stream's new snapshot (``z_new [B, N, F]``, ``g_new``/``g_first [B, N, G]``)
    into its rings, running sums and block maxima (see
    :class:`~robohealth_mj.runtime.incremental.IncrementalEngine`). Without ``first_record``
    the sums of ``g`` hold the W - 1 newest records only (``g_first`` is not read): the new
    oldest's record leaves them."""
    w = z.shape[0]
    block = w - 1
    n_nodes, n_g = g_new.shape[1], g_new.shape[2]
    n_s = z_new.shape[2] - f0
    record = np.empty((n_nodes, n_g + 3 * n_s), np.float32)
    for i in range(len(slots)):
        slot = slots[i]
        h, c = head[slot], count[slot]
        first = (h + 1) % w  # the window's oldest snapshot once this one is in
        prev = (h - 1) % w
        leaves = c >= w  # the oldest snapshot leaves the window
        fixes = c + 1 >= w  # the new oldest takes its g_first and a zero step
        for n in range(n_nodes):
            for k in range(n_g):
                new = np.float64(g_new[i, n, k])
                if first_record:
                    old = np.float64(g_fixed[slot, n, k]) if leaves else 0.0
                    was = np.float64(raw[first, slot, n, k])
                    fixed = np.float64(g_first[i, n, k]) if fixes else was
                    delta = new - old
                    delta += fixed
                    delta -= was
                    sum_g[slot, n, k] += delta
                    sq_g[slot, n, k] += new * new - old * old + fixed * fixed - was * was
                else:
                    was = np.float64(raw[first, slot, n, k]) if fixes else 0.0
                    sum_g[slot, n, k] += new - was
                    sq_g[slot, n, k] += new * new - was * was
                record[n, k] = g_new[i, n, k]
            for k in range(n_s):
                signal = z_new[i, n, f0 + k]
                step = abs(signal - z[prev, slot, n, f0 + k]) * has_prev[i]
                new = np.float64(step)
                was = np.float64(raw[first, slot, n, n_g + k])
                fixed = 0.0 if fixes else was
                delta = new - 0.0
                delta += fixed
                delta -= was
                sum_d[slot, n, k] += delta
                new = np.float64(signal)
                old = np.float64(z[h, slot, n, f0 + k]) if leaves else 0.0
                sum_z[slot, n, k] += new - old
                sq_z[slot, n, k] += new * new - old * old
                record[n, n_g + k] = step
                record[n, n_g + n_s + k] = signal
                record[n, n_g + 2 * n_s + k] = -signal
        z[h, slot] = z_new[i]
        raw[h, slot] = record[:, : n_g + n_s]
        if first_record:
            g_fixed[slot] = g_first[i]
        p = phase[slot]
        for n in range(n_nodes):
            for k in range(record.shape[1]):
                v = record[n, k]
                prefix[slot, n, k] = v if p == 0 else _max(prefix[slot, n, k], v)
        if p == block - 1:  # the block completes: its suffix maxima, newest first
            for j in range(block - 1, -1, -1):
                pos = (h - (block - 1 - j)) % w
                for n in range(n_nodes):
                    for k in range(n_g + 3 * n_s):
                        if k < n_g + n_s:
                            v = raw[pos, slot, n, k]
                        elif k < n_g + 2 * n_s:
                            v = z[pos, slot, n, f0 + k - n_g - n_s]
                        else:
                            v = -z[pos, slot, n, f0 + k - n_g - 2 * n_s]
                        last_of_block = j == block - 1
                        suffix[j, slot, n, k] = (
                            v if last_of_block else _max(v, suffix[j + 1, slot, n, k])
                        )
        phase[slot] = (p + 1) % block
        head[slot] = (h + 1) % w
        count[slot] = min(c + 1, w)


@nb.njit(cache=True, nogil=True)
def _asinh(x):
    """float32 ``copysign(log(|x| + sqrt(x^2 + 1)), x)``, step by step as the numpy code."""
    a = abs(x)
    y = a * a
    y += _ONE
    y = np.sqrt(y)
    y += a
    return np.copysign(np.log(y), x)


@nb.njit(cache=True, nogil=True)
def fill_views(
    slots, views, last, z, head, prefix, suffix, phase, g_fixed, sum_g, sq_g, sum_z, sq_z, sum_d,
    f0, first_record,
):  # fmt: skip
    """The pooled head's inputs of each (full) window: ``views [B, N, 3G + 7S + f0]`` (mean, std
    and max of ``g``; per signal, statistics-major, the asinh of mean, std, min, max, last -
    first, mean ``|step|``, max ``|step|``; the newest snapshot's indicators) and ``last [B, N,
    F]``, the newest normalised snapshot."""
    w = z.shape[0]
    records = w if first_record else w - 1  # snapshots whose g the window pools
    n_nodes, n_g = g_fixed.shape[1], g_fixed.shape[2]
    n_s = z.shape[3] - f0
    for i in range(len(slots)):
        slot = slots[i]
        h, p = head[slot], phase[slot]
        newest = (h - 1) % w
        last[i] = z[newest, slot]
        for n in range(n_nodes):
            for k in range(n_g):
                mean = sum_g[slot, n, k] / records
                views[i, n, k] = mean
                spread = sq_g[slot, n, k] / records - mean * mean
                views[i, n, n_g + k] = np.sqrt(max(spread, 1e-12))
                peak = _max(prefix[slot, n, k], suffix[p, slot, n, k])
                views[i, n, 2 * n_g + k] = _max(peak, g_fixed[slot, n, k]) if first_record else peak
            for k in range(n_s):
                at = 3 * n_g + 7 * k
                oldest = z[h, slot, n, f0 + k]
                step = _max(prefix[slot, n, n_g + k], suffix[p, slot, n, n_g + k])
                top = _max(prefix[slot, n, n_g + n_s + k], suffix[p, slot, n, n_g + n_s + k])
                bottom = prefix[slot, n, n_g + 2 * n_s + k]
                bottom = _max(bottom, suffix[p, slot, n, n_g + 2 * n_s + k])
                mean = sum_z[slot, n, k] / w
                views[i, n, at] = mean
                views[i, n, at + 1] = np.sqrt(max(sq_z[slot, n, k] / w - mean * mean, 1e-12))
                views[i, n, at + 2] = -_max(bottom, -oldest)  # min
                views[i, n, at + 3] = _max(top, oldest)  # max
                views[i, n, at + 4] = z[newest, slot, n, f0 + k] - oldest
                views[i, n, at + 5] = sum_d[slot, n, k] / (w - 1)
                views[i, n, at + 6] = step  # max |step| (the oldest's zero step never exceeds it)
                for m in range(7):
                    views[i, n, at + m] = _asinh(views[i, n, at + m])
            for k in range(f0):
                views[i, n, 3 * n_g + 7 * n_s + k] = z[newest, slot, n, k]
