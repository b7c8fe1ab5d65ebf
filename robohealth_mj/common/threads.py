"""One ``threads`` setting for every compute library the project drives.

LightGBM, torch and onnxruntime each default to every core of the machine. On a machine another
job is already using, that oversubscribes it: measured in issue 68, a `gbdt` training beside one
busy job went from 10 to more than 46 minutes. ``threads: auto`` (the default of the entry points
that compute) takes the cores the machine has free when the command starts: the cores this process
may run on less the cores other work kept busy over half a second, at least one. A number is
taken as given.

Thread counts do not change a `gbdt` model (its boosters are built deterministically whatever the
count), but torch's float reductions may round differently with another count, so the count a run
used is recorded beside its results; give a number to rerun byte for byte.
"""

from __future__ import annotations

import os
import time
from typing import Any

from robohealth_mj.common.errors import InputError

AUTO = "auto"


def usable_cores() -> int:
    """The cores this process may run on (its CPU affinity, else the machine's count)."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # not Linux
        return os.cpu_count() or 1


def busy_cores(interval_s: float = 0.5) -> float | None:
    """How many cores the machine kept busy over the next ``interval_s`` (Linux ``/proc/stat``;
    None where it cannot be read). Measured, not the load average: that trails by about a
    minute, so a job that has just ended would still be counted and the next step of a pipeline
    would start on one thread."""

    def sample() -> tuple[int, int]:
        with open("/proc/stat") as f:
            ticks = [int(v) for v in f.readline().split()[1:]]
        return sum(ticks), ticks[3] + (ticks[4] if len(ticks) > 4 else 0)  # total, idle + iowait

    try:
        total0, idle0 = sample()
        time.sleep(interval_s)
        total1, idle1 = sample()
    except (OSError, ValueError, IndexError):
        return None
    elapsed = total1 - total0
    if elapsed <= 0:
        return None
    return (1.0 - (idle1 - idle0) / elapsed) * (os.cpu_count() or 1)


def free_cores(busy: float | None = None) -> int:
    """The usable cores less those other work keeps busy (``busy``, measured when not given:
    :func:`busy_cores`, else the one-minute load average), rounded, at least one."""
    if busy is None:
        busy = busy_cores()
    if busy is None:
        try:
            busy = os.getloadavg()[0]
        except (AttributeError, OSError):  # no load average on this platform
            busy = 0.0
    return max(1, usable_cores() - round(max(0.0, busy)))


def resolve_threads(value: Any, key: str = "threads") -> int:
    """``value`` as a thread count: ``auto`` (or null) -> :func:`free_cores`; a positive
    integer as given; anything else is the user's mistake, named by ``key``."""
    if value is None or value == AUTO:
        return free_cores()
    try:
        count = int(value)
    except (TypeError, ValueError):
        count = 0
    if isinstance(value, bool) or count < 1 or str(count) != str(value).strip():
        raise InputError(f"{key}: {value!r} is not a thread count (a positive integer or auto)")
    return count


def use_torch_threads(count: int) -> None:
    """torch's intra-op threads (torch is imported only when the caller already has it)."""
    import torch

    torch.set_num_threads(count)


def onnx_session_options(count: int) -> Any:
    """onnxruntime ``SessionOptions`` with ``count`` intra-op threads and one inter-op thread."""
    import onnxruntime as ort

    options = ort.SessionOptions()
    options.intra_op_num_threads = count
    options.inter_op_num_threads = 1
    return options
