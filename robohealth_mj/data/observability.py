"""What a window can show, and calling only that.

Friction and backlash act only on a turning joint: friction holds a still joint as firmly as
before, and a backlash gap under a steady load stays closed on one side. On a joint that stood
still through a whole window neither changes anything a channel reads, so a model that calls
one there is guessing from the rest of the window. The training label rule ``visible``
(:func:`robohealth_mj.data.windows.label_windows`) and the evaluation's strata use the same
definition of *moved*; :func:`hide_unobservable` applies it to a model's decisions
(``observability=motion`` in ``evaluate`` and ``monitor``): a model's belief in a motion-only
fault on a joint that did not move goes to ``none``, which is what ``visible`` labels such a
window. Measured on a real arm's healthy running in ``studies/real_arms/README.md``.

Pure numpy: the torch-free runtime applies it per tick, the evaluation per window.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from robohealth_mj.common.errors import InputError

MOVING_RAD_S = 0.05  # a joint turning slower than this (3 deg/s) counts as still
# Faults that act only on a turning joint (see the module docstring).
MOTION_ONLY_FAULTS = ("backlash", "friction")
# ``all``: every class wherever the model calls it; ``motion``: motion-only faults only on a
# joint that turned faster than MOVING_RAD_S in the window.
OBSERVABILITY = ("all", "motion")


def check_observability(value: str, channels: Sequence[str] | None = None) -> str:
    """``value`` if it is a known rule that the model's joint ``channels`` can serve (``motion``
    needs the joint velocity), else a one-line :class:`InputError`."""
    if value not in OBSERVABILITY:
        raise InputError(f"observability must be one of {list(OBSERVABILITY)}, got {value!r}")
    if value == "motion" and channels is not None and "vel" not in channels:
        raise InputError(
            "observability=motion needs the joints' velocity, which this model's sensing "
            f"profile does not read (joint channels {list(channels)}); use observability=all"
        )
    return value


def hide_unobservable(
    probs: np.ndarray, joint_scores: np.ndarray, moved: np.ndarray, classes: Sequence[str]
) -> np.ndarray:
    """Class probabilities with motion-only faults kept only on joints that moved.

    ``probs [B, C]`` (rows sum to 1), ``joint_scores [B, J]`` (>= 0; a softmax or independent
    sigmoids, normalised here into where a fault would be), ``moved [B, J]`` bool. Reading the
    model's belief as ``p(c, j) = p(c) q(j)``, each motion-only class keeps
    ``p(c) * sum_j q(j) moved(j)`` and the rest goes to ``none``; other classes are unchanged, so
    rows still sum to 1 and a window in which every joint moved is left as it was.
    """
    motion_only = [k for k, c in enumerate(classes) if c in MOTION_ONLY_FAULTS]
    if not motion_only:
        return probs
    q = joint_scores / np.maximum(joint_scores.sum(axis=1, keepdims=True), 1e-12)
    seen = (q * moved).sum(axis=1, dtype=np.float64)  # [B] the share of q on moved joints
    out = probs.astype(np.float64, copy=True)
    hidden = out[:, motion_only] * (1.0 - seen)[:, None]
    out[:, motion_only] -= hidden
    out[:, list(classes).index("none")] += hidden.sum(axis=1)
    return out.astype(probs.dtype)
