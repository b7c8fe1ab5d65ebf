"""Small numerical helpers shared by the torch-free layers (runtime, prognostics)."""

from __future__ import annotations

import numpy as np


def softmax(z: np.ndarray) -> np.ndarray:
    """Softmax over the last axis, shifted by the maximum so large logits do not overflow."""
    e = np.exp(z - z.max(axis=-1, keepdims=True))
    return e / e.sum(axis=-1, keepdims=True)


def joint_scores_from_logits(logits: np.ndarray, kind: str) -> np.ndarray:
    """``[B, J]`` joint logits -> scores as the model was trained: ``softmax`` over the joints
    (which joint is at fault) or ``sigmoid`` per joint (is this joint at fault)."""
    if kind == "softmax":
        return softmax(logits)
    return 0.5 * (1.0 + np.tanh(0.5 * logits))  # sigmoid, no overflow
