"""The healthy operating point, matched on an arm's healthy running at commissioning.

A model is trained to call healthy running healthy at some rate (its validation session's, about
0.98). On an arm or a program it has not seen, healthy running can look a little unlike any it
was trained on, and the rate falls (0.84-0.89 on pick-and-place programs): the loss is healthy
running called a fault. Commissioning measures the rate on the arm's healthy running and raises
the healthy class's logit by the one constant that brings it back to the validation session's
rate (never lowers it). It moves nothing else: which fault, and where, are as the model had
them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import torch

from robohealth_mj.data.arrays import Recording
from robohealth_mj.data.graphs import GraphSpec
from robohealth_mj.data.windows import make_windows
from robohealth_mj.learn.data import WindowTensors
from robohealth_mj.learn.predict import predict


@dataclass(frozen=True)
class Reading:
    """A recording as a model reads it: through a graph (profile, commissioning shift,
    placement) and a normalisation ``[N, F]``."""

    rec: Recording
    graph: GraphSpec
    mean: np.ndarray
    std: np.ndarray


def healthy_margins(
    model: torch.nn.Module, reading: Reading, window: int, runs: list[str] | None = None
) -> np.ndarray:
    """How far each healthy window (of ``runs`` only, where given) is called healthy: the
    healthy logit minus the largest fault logit ``[K]`` (> 0: called healthy)."""
    rec = reading.graph.relabel(reading.rec)
    windows = make_windows(rec, window)
    keep = ~rec.active[windows.end]
    if runs is not None:
        keep &= np.isin(np.asarray(rec.run_ids)[rec.run[windows.end]], runs)
    windows = windows.subset(keep)
    if not len(windows):
        return np.zeros(0)
    x = reading.graph.transform(rec.x)
    tensors = WindowTensors(x, rec, reading.mean, reading.std, torch.device("cpu"))
    logits = predict(model, tensors, windows).class_logits
    return logits[:, 0] - logits[:, 1:].max(axis=1)


def match_operating_point(
    model: torch.nn.Module,
    window: int,
    validation: Reading,
    validation_runs: list[str],
    arm: Reading,
) -> tuple[np.ndarray, dict[str, Any]]:
    """The class offset ``[C]`` that has ``arm``'s healthy windows called healthy at the rate
    the model calls its validation session's (``validation_runs`` of ``validation``, read as
    in training) healthy windows healthy. Sets it on ``model``; returns it with a record."""
    model.class_offset.zero_()
    target = healthy_margins(model, validation, window, validation_runs)
    margins = healthy_margins(model, arm, window)
    offset = np.zeros(len(model.class_offset), np.float32)
    record: dict[str, Any] = {"validation_windows": len(target), "arm_windows": len(margins)}
    if not len(target) or not len(margins):
        record["skipped"] = "no healthy windows to match"
        return offset, record
    rate = float((target > 0).mean())
    # only ever towards healthy: healthy running called healthy more often than in validation
    # says nothing about faults missed, so it is no reason to call more
    offset[0] = max(0.0, -float(np.quantile(margins, 1.0 - rate)))
    model.class_offset.copy_(torch.from_numpy(offset))
    record.update({
        "validation_healthy_rate": rate,
        "arm_healthy_rate_before": float((margins > 0).mean()),
        "arm_healthy_rate_after": float((margins + offset[0] > 0).mean()),
        "healthy_offset": float(offset[0]),
    })  # fmt: skip
    return offset, record
