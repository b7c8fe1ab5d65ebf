"""Windows, the run-aware split and normalisation statistics (thesis §2.4.5-2.4.6).

A window is W consecutive snapshots of one run (never across runs or gaps in sample_index),
taken every ``stride`` snapshots and labelled by its *final* snapshot.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from robohealth_mj.common.errors import InputError
from robohealth_mj.data.arrays import Recording
from robohealth_mj.schema import feature_index


@dataclass
class Windows:
    start: np.ndarray  # [K] index of the first snapshot of each window
    window: int

    @property
    def end(self) -> np.ndarray:
        """Index of each window's final (labelling) snapshot."""
        return self.start + self.window - 1

    def __len__(self) -> int:
        return len(self.start)

    def subset(self, mask: np.ndarray) -> Windows:
        return Windows(self.start[mask], self.window)


def make_windows(rec: Recording, window: int, stride: int | None = None) -> Windows:
    if window < 2:
        raise InputError(f"window must be >= 2, got {window}")
    stride = stride or max(1, window // 4)
    # contiguous blocks: same run and consecutive sample indices
    breaks = np.flatnonzero((np.diff(rec.run) != 0) | (np.diff(rec.sample_index) != 1)) + 1
    bounds = np.concatenate([[0], breaks, [len(rec)]])
    starts = [np.arange(a, b - window + 1, stride) for a, b in itertools.pairwise(bounds)]
    return Windows(np.concatenate(starts).astype(np.int64), window)


MOVING_RAD_S = 0.05  # a joint turning slower than this (3 deg/s) counts as still


def target_joint_moved(
    rec: Recording, windows: Windows, threshold: float = MOVING_RAD_S
) -> np.ndarray:
    """Per window ``[K]``: the faulted joint of its final snapshot turned faster than
    ``threshold`` at some tick of the window (False for healthy windows).

    Friction and backlash act only on a moving (or reversing) joint, so their evidence exists only
    in such windows; the evaluation reports both strata.
    """
    joint = rec.fault_joint[windows.end]
    offsets = np.arange(windows.window)
    rows = windows.start[:, None] + offsets[None, :]  # [K, W]
    speed = np.abs(rec.x[rows, np.maximum(joint, 0)[:, None], feature_index("vel")])
    return (joint >= 0) & (speed.max(axis=1) > threshold)


SPLITS = ("train", "val", "test")


def run_aware_split(
    rec: Recording,
    windows: Windows,
    seed: int,
    fractions: tuple[float, float, float] = (0.7, 0.15, 0.15),
) -> dict[str, Windows]:
    """Whole sessions (by the run id of each window's final snapshot) to train/val/test.

    Seeded greedy assignment: sessions in a seeded random order; the first three seed the three
    splits, each further session goes to the split furthest below its target share of windows.
    """
    run_of = rec.run[windows.end]
    runs, counts = np.unique(run_of, return_counts=True)
    if len(runs) < 3:
        raise InputError(
            f"the run-aware split needs at least 3 recording sessions, got "
            f"{len(runs)} ({[rec.run_ids[r] for r in runs]}); record more sessions"
        )
    order = np.random.default_rng(seed).permutation(len(runs))
    total = counts.sum()
    assigned = np.zeros(3)
    split_of: dict[int, int] = {}
    for position, k in enumerate(order):
        if position < 3:
            target = position
        else:
            target = int(np.argmax(np.asarray(fractions) * total - assigned))
        split_of[int(runs[k])] = target
        assigned[target] += counts[k]
    which = np.array([split_of[int(r)] for r in run_of])
    return {name: windows.subset(which == i) for i, name in enumerate(SPLITS)}


def covered(windows: Windows, length: int) -> np.ndarray:
    """``[length]`` bool: the snapshots some window of ``windows`` covers."""
    mask = np.zeros(length, bool)
    for offset in range(windows.window):
        mask[windows.start + offset] = True
    return mask


def normalisation(x: np.ndarray, windows: Windows) -> tuple[np.ndarray, np.ndarray]:
    """Per-node, per-feature mean and std ``[N, F]`` over every snapshot the (training) windows
    cover, and nothing else: no held-out information leaks through the z-scoring."""
    x = x[covered(windows, len(x))].astype(np.float64)
    mean = x.mean(axis=0)
    std = x.std(axis=0)
    std[std < 1e-6] = 1.0  # constant channels (type indicators, zeroed channels) pass through
    return mean.astype(np.float32), std.astype(np.float32)
