"""The healthy operating point, matched on an arm's healthy running at commissioning.

A model is trained to call healthy running healthy at some rate (its validation session's, about
0.98). On an arm or a program it has not seen, healthy running can look a little unlike any it
was trained on, and the rate falls (0.84-0.89 on pick-and-place programs): the loss is healthy
running called a fault. Commissioning measures this on the arm's healthy running and moves the
class logits by constants, only ever towards healthy, and nothing else: which fault, and where,
are as the model had them. Two recipes (``operating_point=``):

- per class (default): each fault class's logit is lowered until the arm's healthy windows are
  called that class no more often than the validation session's are. Only the classes the new
  running is mistaken for pay: on pick-and-place the false calls are jam (the starts and stops
  of point-to-point moves), and friction keeps its recall.
- healthy: the healthy logit is raised by the one constant that brings the healthy rate back to
  the validation session's; every fault class pays, friction most (0.68 -> 0.45 recall).

Chosen on a labelled validation session of an unseen program (``val_unseen_program``), see
``studies/stock_arm/README.md``.

Matching validation's rate keeps the false calls validation has (a few per cent of healthy
windows). A user who wants a quieter monitor names the healthy rate instead (``healthy_rate``,
e.g. 0.99): the per-class recipe then allows each fault class its share of ``1 - healthy_rate``
at most, and the record says what it costs: the share of validation's faulted windows still
called a fault, before and after.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import torch

from robohealth_mj.common.errors import InputError
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


RECIPES = ("per_class", "healthy")
ROUNDS = 20  # per-class matching: lowering one class can hand windows to another; repeat


def class_rates(logits: np.ndarray, classes: int) -> np.ndarray:
    """How often ``[C]`` windows with class ``logits [K, C]`` are called each class."""
    return np.bincount(logits.argmax(1), minlength=classes) / max(len(logits), 1)


def per_class_offset(
    validation: np.ndarray, arm: np.ndarray, healthy_rate: float | None = None
) -> np.ndarray:
    """Offsets ``[C]`` (``<= 0``, none on healthy) that lower each fault class's logit until
    the arm's healthy windows (``arm [K, C]`` logits) are called it no more often than the
    validation session's healthy windows (``validation``) are, and, with ``healthy_rate``, no
    more often than an equal share of ``1 - healthy_rate``."""
    classes = arm.shape[1]
    # a rate below one validation window is not measured: it would let one outlier of the
    # arm's windows set a class's whole offset
    allowed = np.maximum(class_rates(validation, classes), 1.0 / len(validation))
    if healthy_rate is not None:
        allowed = np.minimum(allowed, (1.0 - healthy_rate) / (classes - 1))
    offset = np.zeros(classes)
    for _ in range(ROUNDS):
        moved = False
        for k in range(1, classes):
            shifted = arm + offset
            margin = shifted[:, k] - np.delete(shifted, k, axis=1).max(axis=1)
            if (margin > 0).mean() <= allowed[k]:
                continue
            # lower k just past the margin of the window ranked at the allowed rate
            offset[k] -= float(np.quantile(margin, 1.0 - allowed[k])) + 1e-6
            moved = True
        if not moved:
            break
    return offset.astype(np.float32)


def healthy_offset(validation: np.ndarray, arm: np.ndarray) -> np.ndarray:
    """The offset ``[C]`` that raises only the healthy logit, by the one constant that has the
    arm's healthy windows (``arm [K, C]`` logits) called healthy as often as the validation
    session's (``validation``)."""
    offset = np.zeros(arm.shape[1], np.float32)
    rate = float((validation.argmax(1) == 0).mean())
    margins = arm[:, 0] - arm[:, 1:].max(axis=1)
    # only ever towards healthy: healthy running called healthy more often than in validation
    # says nothing about faults missed, so it is no reason to call more
    offset[0] = max(0.0, -float(np.quantile(margins, 1.0 - rate)))
    return offset


def check_recipe(recipe: str, healthy_rate: float | None = None) -> None:
    if recipe not in RECIPES:
        raise InputError(f"operating_point must be one of {RECIPES}, got {recipe!r}")
    if healthy_rate is not None and not (
        recipe == "per_class" and isinstance(healthy_rate, (int, float)) and 0 < healthy_rate < 1
    ):
        raise InputError(f"healthy_rate: a number in (0, 1) with operating_point=per_class, "
                         f"got {healthy_rate!r} with {recipe}")  # fmt: skip


def healthy_logits(
    model: torch.nn.Module,
    reading: Reading,
    window: int,
    runs: list[str] | None = None,
    faulted: bool = False,
) -> np.ndarray:
    """The class logits ``[K, C]`` of the healthy windows (``faulted``: of the faulted ones)
    (of ``runs`` only, where given)."""
    rec = reading.graph.relabel(reading.rec)
    windows = make_windows(rec, window)
    keep = rec.active[windows.end] == faulted
    if runs is not None:
        keep &= np.isin(np.asarray(rec.run_ids)[rec.run[windows.end]], runs)
    windows = windows.subset(keep)
    if not len(windows):
        return np.zeros((0, len(model.class_offset)))
    x = reading.graph.transform(rec.x)
    tensors = WindowTensors(x, rec, reading.mean, reading.std, torch.device("cpu"))
    return predict(model, tensors, windows).class_logits


def match_operating_point(
    model: torch.nn.Module,
    window: int,
    validation: Reading,
    validation_runs: list[str],
    arm: Reading,
    recipe: str = "per_class",
    healthy_rate: float | None = None,
    validation_model: torch.nn.Module | None = None,
) -> tuple[np.ndarray, dict[str, Any]]:
    """The class offset ``[C]`` that has ``arm``'s healthy windows called healthy (``recipe``
    ``healthy``; ``per_class``: called each fault class) at the rate the model calls its
    validation session's (``validation_runs`` of ``validation``, read as in training) healthy
    windows, or at ``healthy_rate`` where that is stricter. Sets it on ``model``; returns it
    with a record. ``validation_model``: the model that reads the validation session where it
    is another arm's graph (a model read on another arm: its source, whose weights it shares)."""
    check_recipe(recipe, healthy_rate)
    model.class_offset.zero_()
    reader = model if validation_model is None else validation_model
    reader.class_offset.zero_()
    target = healthy_logits(reader, validation, window, validation_runs)
    logits = healthy_logits(model, arm, window)
    offset = np.zeros(len(model.class_offset), np.float32)
    record: dict[str, Any] = {"validation_windows": len(target), "arm_windows": len(logits),
                              "recipe": recipe}  # fmt: skip
    if not len(target) or not len(logits):
        record["skipped"] = "no healthy windows to match"
        return offset, record
    rate = float((target.argmax(1) == 0).mean())
    if recipe == "per_class":
        offset = per_class_offset(target, logits, healthy_rate)
    else:
        offset = healthy_offset(target, logits)
    if healthy_rate is not None:  # what the quieter operating point costs, on validation
        faulted = healthy_logits(reader, validation, window, validation_runs, faulted=True)
        record["healthy_rate_asked"] = healthy_rate
        record["validation_fault_recall_before"] = float((faulted.argmax(1) != 0).mean())
        record["validation_fault_recall_after"] = float(((faulted + offset).argmax(1) != 0).mean())
    model.class_offset.copy_(torch.from_numpy(offset))
    record.update({
        "validation_healthy_rate": rate,
        "arm_healthy_rate_before": float((logits.argmax(1) == 0).mean()),
        "arm_healthy_rate_after": float(((logits + offset).argmax(1) == 0).mean()),
        "healthy_offset": float(offset[0]),
        "class_offset": offset.round(5).tolist(),
    })  # fmt: skip
    return offset, record
