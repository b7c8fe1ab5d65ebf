"""Running a model over many windows in batches, without gradients."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch
from torch import nn

from robohealth_mj.data.windows import Windows
from robohealth_mj.learn.data import WindowTensors


@dataclass
class Predictions:
    class_logits: np.ndarray
    joint_logits: np.ndarray
    severity: np.ndarray | None
    true_class: np.ndarray
    true_joint: np.ndarray
    true_severity: np.ndarray
    active: np.ndarray
    loss: float


@torch.no_grad()
def predict(
    model: nn.Module, tensors: WindowTensors, windows: Windows, batch_size: int = 512, loss_fn=None
) -> Predictions:
    model.eval()
    parts: dict[str, list] = {k: [] for k in ("cls", "joint", "sev", "tc", "tj", "ts", "act")}
    total, count = 0.0, 0
    for i in range(0, len(windows), batch_size):
        batch = tensors.batch(windows, np.arange(i, min(i + batch_size, len(windows))))
        out = model(batch.x)
        if loss_fn is not None:
            total += float(loss_fn(out, batch)[0]) * len(batch.x)
            count += len(batch.x)
        parts["cls"].append(out["class_logits"].cpu().numpy())
        parts["joint"].append(out["joint_logits"].cpu().numpy())
        if "severity" in out:
            parts["sev"].append(out["severity"].cpu().numpy())
        parts["tc"].append(batch.fault_class.cpu().numpy())
        parts["tj"].append(batch.fault_joint.cpu().numpy())
        parts["ts"].append(batch.severity.cpu().numpy())
        parts["act"].append(batch.active.cpu().numpy())
    cat = {k: np.concatenate(v) if v else None for k, v in parts.items()}
    return Predictions(
        cat["cls"],
        cat["joint"],
        cat["sev"],
        cat["tc"],
        cat["tj"],
        cat["ts"],
        cat["act"],
        total / max(count, 1),
    )
