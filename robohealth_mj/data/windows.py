"""Windows, the run-aware split and normalisation statistics (thesis §2.4.5-2.4.6).

A window is W consecutive snapshots of one run (never across runs or gaps in sample_index),
taken every ``stride`` snapshots and labelled by its *final* snapshot, or (``labels=majority``,
``time_weighted`` or ``visible``, :func:`label_windows`) by what its W snapshots show.
"""

from __future__ import annotations

import itertools
import re
from dataclasses import dataclass, replace

import numpy as np

from robohealth_mj.common.errors import InputError
from robohealth_mj.data.arrays import Recording
from robohealth_mj.data.observability import MOTION_ONLY_FAULTS, MOVING_RAD_S
from robohealth_mj.schema import FAULT_CLASSES, feature_index


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


def joints_moved(rec: Recording, windows: Windows, threshold: float = MOVING_RAD_S) -> np.ndarray:
    """``[K, J]``: each joint turned faster than ``threshold`` at some tick of each window (what
    :mod:`robohealth_mj.data.observability` calls *moved*)."""
    rows = windows.start[:, None] + np.arange(windows.window)[None, :]  # [K, W]
    vel = feature_index("vel")
    # a joint at a time: a [K, W] gather, not [K, W, J] (a whole corpus at stride 1)
    return np.stack(
        [np.abs(rec.x[rows, j, vel]).max(axis=1) > threshold for j in range(rec.graph.n_joints)],
        axis=1,
    )


def target_joint_moved(
    rec: Recording, windows: Windows, threshold: float = MOVING_RAD_S
) -> np.ndarray:
    """Per window ``[K]``: the faulted joint of its final snapshot turned faster than
    ``threshold`` at some tick of the window (False for healthy windows).

    Friction and backlash act only on a moving (or reversing) joint, so their evidence exists only
    in such windows; the evaluation reports both strata.
    """
    joint = rec.fault_joint[windows.end]
    moved = joints_moved(rec, windows, threshold)
    return (joint >= 0) & moved[np.arange(len(joint)), np.maximum(joint, 0)]


SPLITS = ("train", "val", "test")


_RECORDED_RUN_ID = re.compile(r"^[a-z0-9_]+-s(?P<seed>\d+)-[0-9a-f]{10}$")


def recorded_run_id(arm: str, seed: int, digest: str) -> str:
    """The id the recorder gives a simulated session (``digest``: 10 hex digits of its config),
    in the one format :func:`session_of` reads back."""
    return f"{arm}-s{seed}-{digest}"


def session_of(run_id: str) -> str:
    """The simulated session a run id names, whatever arm ran it.

    The recorder names a run ``<arm>-s<seed>-<digest>`` (:func:`recorded_run_id`), and a corpus
    records every arm from the same session seeds: one seed is one program and one fault
    schedule, scaled to the arm. Splitting by run id alone would put the UR10e's session 100
    in validation while the UR5e's session 100 trains. Any other id (an ingested log, a bag, a
    named session) is a session of its own.
    """
    match = _RECORDED_RUN_ID.match(run_id)
    return f"seed {match['seed']}" if match else run_id


def run_aware_split(
    rec: Recording,
    windows: Windows,
    seed: int,
    fractions: tuple[float, float, float] = (0.7, 0.15, 0.15),
) -> dict[str, Windows]:
    """Whole sessions to train/val/test: a window goes where the session of its final snapshot's
    run goes, and runs of one session on several arms (:func:`session_of`) go together.

    Seeded greedy assignment: sessions in a seeded random order (from the order of their first
    run); the first three seed the three splits, each further session goes to the split furthest
    below its target share of windows. One arm's corpus (a session per run) splits as by run.
    """
    run_of = rec.run[windows.end]
    runs = np.unique(run_of)
    names = [session_of(rec.run_ids[r]) for r in runs]
    sessions = list(dict.fromkeys(names))  # in the order of their first run
    if len(sessions) < 3:
        raise InputError(
            f"the run-aware split needs at least 3 recording sessions, got "
            f"{len(sessions)} ({sessions}); record more sessions"
        )
    index = {name: i for i, name in enumerate(sessions)}
    session_of_run = np.full(len(rec.run_ids), -1)
    session_of_run[runs] = [index[n] for n in names]
    session_of_window = session_of_run[run_of]
    counts = np.bincount(session_of_window, minlength=len(sessions))
    order = np.random.default_rng(seed).permutation(len(sessions))
    total = counts.sum()
    assigned = np.zeros(3)
    split_of = np.zeros(len(sessions), int)
    for position, k in enumerate(order):
        if position < 3:
            target = position
        else:
            target = int(np.argmax(np.asarray(fractions) * total - assigned))
        split_of[k] = target
        assigned[target] += counts[k]
    which = split_of[session_of_window]
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


LABEL_RULES = ("last", "majority", "time_weighted", "visible")


def _hidden_as_healthy(rec: Recording, window: int) -> Recording:
    """``rec`` with the motion-only faults of a joint that stood still through the window ending
    at a snapshot relabelled healthy (the ``visible`` rule of :func:`label_windows`): every
    snapshot that ends a whole window, judged as the evaluation's strata are
    (:func:`target_joint_moved`)."""
    ending = make_windows(rec, window, stride=1)
    motion_only = np.isin(
        rec.fault_class[ending.end], [FAULT_CLASSES.index(c) for c in MOTION_ONLY_FAULTS]
    )
    hidden = np.zeros(len(rec), bool)
    hidden[ending.end] = motion_only & ~target_joint_moved(rec, ending)
    return replace(
        rec,
        fault_class=np.where(hidden, 0, rec.fault_class).astype(rec.fault_class.dtype),
        fault_joint=np.where(hidden, -1, rec.fault_joint).astype(rec.fault_joint.dtype),
        severity=np.where(hidden, 0.0, rec.severity).astype(rec.severity.dtype),
        active=np.where(hidden, False, rec.active),
    )


def label_windows(rec: Recording, window: int, rule: str = "last") -> Recording:
    """``rec`` with each snapshot's label replaced by that of the window of ``window`` snapshots
    ending there, so that every consumer that labels a window by its final snapshot gets ``rule``.

    - ``last``: the final snapshot's label (``rec`` itself);
    - ``majority``: the fault (class and joint) most of the window's snapshots carry (a tie goes to
      the later label); its severity the mean over the snapshots that carry it;
    - ``time_weighted``: the majority's fault, its severity weighted by the share of the window it
      covers (a window half inside a 0.6 fault: 0.3);
    - ``visible``: the final snapshot's label, except that a fault that acts only on a turning
      joint (:data:`MOTION_ONLY_FAULTS`) on a joint that never turned faster than
      :data:`MOVING_RAD_S` in the window is labelled healthy: the window is what a healthy joint
      shows (36-43 % of those classes' windows in the quick corpus, where single-joint sweeps
      leave the other joints still).

    A window that lies inside one fault interval keeps its label under every rule; only windows
    that straddle a change differ. Snapshots that end no whole window keep their own label.
    """
    if rule not in LABEL_RULES:
        raise InputError(f"labels must be one of {list(LABEL_RULES)}, got {rule!r}")
    if rule == "last" or len(rec) < window:
        return rec
    if rule == "visible":
        return _hidden_as_healthy(rec, window)
    per_class = rec.graph.n_joints + 1
    code = rec.fault_class * per_class + (rec.fault_joint + 1)  # one id per (class, joint)
    codes = np.unique(code)

    def rolling(values: np.ndarray, width: int = window) -> np.ndarray:
        """``[T]``: the sum of ``values`` over the ``width`` snapshots ending at each t."""
        c = np.concatenate([[0.0], np.cumsum(values, dtype=np.float64)])
        out = np.zeros(len(values))
        out[width - 1 :] = c[width:] - c[:-width]
        return out

    counts = np.stack([rolling(code == k) for k in codes])  # [K, T]
    # the latest snapshot's own code wins ties: add a fraction smaller than one count to it
    counts += 0.5 * (code[None, :] == codes[:, None])
    best = codes[np.argmax(counts, axis=0)]
    severity = np.stack([rolling(np.where(code == k, rec.severity, 0.0)) for k in codes])
    pick = np.searchsorted(codes, best)
    total = severity[pick, np.arange(len(rec))]
    carried = np.floor(counts[pick, np.arange(len(rec))])
    # only a snapshot that ends a whole window of one run, with no gap, gets the window's label
    joins = np.concatenate([[0.0], (np.diff(rec.run) != 0) | (np.diff(rec.sample_index) != 1)])
    ends = rolling(joins, window - 1) == 0  # no break between the window's snapshots
    ends[: window - 1] = False
    sev = total / (np.maximum(carried, 1.0) if rule == "majority" else window)
    fault_class = np.where(ends, best // per_class, rec.fault_class)
    fault_joint = np.where(ends, best % per_class - 1, rec.fault_joint)
    return replace(
        rec,
        fault_class=fault_class.astype(rec.fault_class.dtype),
        fault_joint=fault_joint.astype(rec.fault_joint.dtype),
        severity=np.where(ends, sev, rec.severity).astype(rec.severity.dtype),
        active=np.where(ends, fault_class > 0, rec.active),
    )
