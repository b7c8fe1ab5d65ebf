"""Held-out evaluation of a checkpoint on whole recordings (thesis §2.6.3)."""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import torch

from robohealth_mj import schema
from robohealth_mj.common.atomic import atomic_write_json, atomic_write_text
from robohealth_mj.common.numeric import joint_scores_from_logits, softmax
from robohealth_mj.data.arrays import Recording, expand_paths
from robohealth_mj.data.observability import check_observability, hide_unobservable
from robohealth_mj.data.sensing import load_profile
from robohealth_mj.data.windows import (
    Windows,
    joints_moved,
    label_windows,
    make_windows,
    target_joint_moved,
)
from robohealth_mj.learn.checkpoint import (
    graph_from_checkpoint,
    joint_score_kind,
    load_checked,
    load_checkpoint,
    model_from_checkpoint,
)
from robohealth_mj.learn.data import WindowTensors
from robohealth_mj.learn.metrics import flat_rows, metrics_of
from robohealth_mj.learn.placements import healthy_sensor_statistics
from robohealth_mj.learn.predict import Predictions, predict
from robohealth_mj.learn.trainer import coupling_report, gamma_of, pick_device


@dataclass
class Scored:
    """A checkpoint's model rebuilt and run over every window of some recordings."""

    ckpt: dict[str, Any]
    graph: Any  # GraphSpec
    files: list[Path]
    rec: Any  # the recordings, relabelled for the checkpoint's profile
    windows: Any
    model: Any
    predictions: Predictions


def score_checkpoint(
    ckpt_path: Path | str,
    data: list[str] | str,
    device: str = "auto",
    labels: str | None = None,
    observability: str = "all",
) -> Scored:
    """Rebuild the exact model from its checkpoint and predict every window of ``data`` (what
    evaluation and any per-window measurement share). Windows are labelled by ``labels``
    (``last``, ``majority``, ``time_weighted``, ``visible``; default: the model's training rule);
    ``observability=motion`` calls motion-only faults only on joints that moved
    (:mod:`robohealth_mj.data.observability`), as the monitor does with the same setting."""
    ckpt = load_checkpoint(ckpt_path)
    graph = graph_from_checkpoint(ckpt)
    motion = observability == "motion"  # then the model must read the joints' velocity
    check_observability(
        observability, load_profile(graph.sensing).joint_channels if motion else None
    )
    files = expand_paths(data)
    rec = graph.relabel(load_checked(ckpt, files))
    rule = labels or str(ckpt["config"].get("labels", "last"))
    rec = label_windows(rec, int(ckpt["window"]), rule)
    dev = pick_device(device)
    tensors = WindowTensors(
        graph.transform(rec.x), rec, ckpt["norm_mean"].numpy(), ckpt["norm_std"].numpy(), dev
    )
    model = model_from_checkpoint(ckpt).to(dev)
    windows = make_windows(rec, int(ckpt["window"]), ckpt["config"].get("stride"))
    predictions = predict(model, tensors, windows)
    if observability == "motion":
        moved = joints_moved(rec, windows)
        kind = joint_score_kind(ckpt)
        predictions = _observable(predictions, moved, kind, ckpt["labels"]["classes"])
    return Scored(ckpt, graph, files, rec, windows, model, predictions)


def _observable(
    predictions: Predictions, moved: np.ndarray, kind: str, classes: list[str]
) -> Predictions:
    """``predictions`` with their class logits replaced by the log of
    :func:`hide_unobservable`'s probabilities (``moved [K, J]``; ``kind``: how the joint logits
    were trained, :func:`joint_score_kind`)."""
    probs = softmax(predictions.class_logits.astype(np.float64))
    scores = joint_scores_from_logits(predictions.joint_logits.astype(np.float64), kind)
    kept = hide_unobservable(probs, scores, moved, classes)
    return replace(predictions, class_logits=np.log(np.maximum(kept, 1e-30)).astype(np.float32))


def evaluate_checkpoint(
    ckpt_path: Path | str,
    data: list[str] | str,
    device: str = "auto",
    labels: str | None = None,
    observability: str = "all",
) -> dict[str, Any]:
    """Rebuild the exact model from its checkpoint and score it on every window of ``data``
    (labelled by ``labels``; default: the rule it was trained with; ``observability``: as in
    :func:`score_checkpoint`)."""
    scored = score_checkpoint(ckpt_path, data, device, labels, observability)
    ckpt, graph, rec, model = scored.ckpt, scored.graph, scored.rec, scored.model
    files = scored.files
    metrics = metrics_of(scored.predictions, target_joint_moved(rec, scored.windows))
    return {
        "checkpoint": str(ckpt_path),
        "variant": ckpt["variant"],
        "graph": graph.name,
        "window": int(ckpt["window"]),
        "data": [str(f) for f in files],
        "data_fingerprint": rec.fingerprint(),
        "labels": labels or str(ckpt["config"].get("labels", "last")),
        "observability": observability,
        "best_epoch": ckpt["best_epoch"],
        "gamma": gamma_of(model),
        **coupling_report(model, graph),
        "metrics": metrics,
    }


def write_evaluation(result: dict[str, Any], prefix: Path | str) -> tuple[Path, Path]:
    """``<prefix>.json`` (everything) and ``<prefix>.csv`` (scalar metrics), atomically."""
    prefix = Path(prefix)
    json_path, csv_path = prefix.with_suffix(".json"), prefix.with_suffix(".csv")
    buffer = io.StringIO()
    w = csv.writer(buffer)
    w.writerow(["metric", "value"])
    w.writerows(flat_rows(result["metrics"]))
    atomic_write_text(csv_path, buffer.getvalue())
    atomic_write_json(json_path, result)  # last: its presence marks the evaluation as done
    return json_path, csv_path


def validation_windows(ckpt: dict[str, Any], rec: Recording) -> Windows:
    """The windows of ``rec`` in the checkpoint's validation runs: the split its training
    selected on, and the only one a design choice may be made on."""
    windows = make_windows(rec, int(ckpt["window"]))
    runs = list((ckpt.get("split_runs") or {}).get("val", []))
    return windows.subset(np.isin(np.asarray(rec.run_ids)[rec.run[windows.end]], runs))


def score_under_placement(
    ckpt: dict[str, Any],
    data: Recording,
    coupling: np.ndarray | None = None,
    *,
    healthy: Recording | None = None,
    tell_model: bool = False,
    validation_only: bool = False,
    model: Any = None,
) -> dict[str, Any]:
    """The metrics of a checkpoint's model (or ``model``) on ``data`` as an arm whose sensor
    packages are mixed by ``coupling`` (default: the checkpoint's own) reads it.

    ``healthy``: the sensors z-scored on that healthy running instead of the training
    statistics (what commissioning can measure on the arm); ``tell_model``: the model's coupling
    set to ``coupling`` (a pool model told the placement); ``validation_only``: the checkpoint's
    validation runs of ``data`` only."""
    graph = graph_from_checkpoint(ckpt)
    if coupling is not None:
        graph = replace(graph, coupling=coupling)
    rec = graph.relabel(data)
    mean, std = ckpt["norm_mean"].numpy().copy(), ckpt["norm_std"].numpy().copy()
    if healthy is not None:
        j, s = graph.num_joints, schema.SENSOR_CHANNELS
        mean[j:, s], std[j:, s] = healthy_sensor_statistics(graph, healthy.x)
    model = model_from_checkpoint(ckpt) if model is None else model
    if tell_model:
        model.anomaly.set_coupling(coupling)
    tensors = WindowTensors(graph.transform(rec.x), rec, mean, std, torch.device("cpu"))
    windows = (
        validation_windows(ckpt, rec) if validation_only else make_windows(rec, int(ckpt["window"]))
    )
    return metrics_of(predict(model, tensors, windows))
