"""Knowledge distillation: a small student trained on a trained teacher's soft labels as well as
the true ones (Hinton et al., 2015), so that a network cheap enough for a large fleet keeps what
the headline learned about near-ties between classes and joints.

The teacher must have been trained on the student's data, window, graph and split: its soft
labels on a window it was validated on would carry validation labels into the student's training
(``trainer.distill.teacher`` is refused in one line otherwise).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch
import torch.nn.functional as F

from robohealth_mj.common.errors import InputError

KEY = "trainer.distill.teacher"


@dataclass
class Teacher:
    """A frozen network and how much its soft labels weigh against the hard ones."""

    model: torch.nn.Module
    weight: float  # share of the soft-label loss: (1 - weight) hard + weight soft
    temperature: float

    @torch.no_grad()
    def outputs(self, x: torch.Tensor) -> dict[str, torch.Tensor]:
        return self.model(x)


def soft_label_loss(
    student: dict[str, torch.Tensor],
    teacher: dict[str, torch.Tensor],
    active: torch.Tensor,
    temperature: float,
    joint_weight: float,
) -> torch.Tensor:
    """KL(teacher || student) of the class distributions on every window, and of the joint
    distributions on the windows the truth marks faulted (the joints compete only there), both at
    ``temperature`` and scaled by its square so the gradients keep the hard loss's size."""
    t = temperature

    def kl(s_logits: torch.Tensor, t_logits: torch.Tensor) -> torch.Tensor:
        return F.kl_div(
            F.log_softmax(s_logits / t, dim=-1), F.log_softmax(t_logits / t, dim=-1),
            reduction="batchmean", log_target=True,
        ) * (t * t)  # fmt: skip

    loss = kl(student["class_logits"], teacher["class_logits"])
    faulted = active.nonzero(as_tuple=True)[0]
    if len(faulted):
        loss = loss + joint_weight * kl(
            student["joint_logits"][faulted], teacher["joint_logits"][faulted]
        )
    return loss


def load_teacher(
    distill: Any, window: int, graph: str, mean: np.ndarray, std: np.ndarray,
    split_runs: dict[str, list[str]], device: torch.device,
) -> Teacher | None:  # fmt: skip
    """The teacher ``trainer.distill`` names (None when it names none), checked against the
    student's run: a network, the same window and graph, the same normalisation (the same
    training data), and no run of the student's validation or test split in its training."""
    from robohealth_mj.learn.checkpoint import load_checkpoint, model_from_checkpoint

    if distill is None or not distill.get("teacher"):
        return None
    weight, temperature = float(distill.get("weight", 0.5)), float(distill.get("temperature", 2))
    if not 0.0 < weight <= 1.0:
        raise InputError(f"trainer.distill.weight: {weight} is not in (0, 1]")
    if not temperature > 0.0:
        raise InputError(f"trainer.distill.temperature: {temperature} is not positive")
    path = Path(str(distill.teacher))
    if not path.is_file():
        raise InputError(f"{KEY}: {path}: no checkpoint file")
    ckpt = load_checkpoint(path)
    if int(ckpt["window"]) != window:
        raise InputError(f"{KEY}: {path} reads windows of {ckpt['window']}, the student {window}")
    if ckpt["graph"].get("name") != graph:
        raise InputError(
            f"{KEY}: {path} was trained on graph {ckpt['graph'].get('name')!r}, the student on "
            f"{graph!r}"
        )
    same_norm = np.allclose(ckpt["norm_mean"].numpy(), mean, rtol=1e-5, atol=1e-6) and np.allclose(
        ckpt["norm_std"].numpy(), std, rtol=1e-5, atol=1e-6
    )
    if not same_norm:
        raise InputError(
            f"{KEY}: {path} was trained on other data or another split (its normalisation "
            "differs): train the teacher on the student's data and seed"
        )
    seen = set((ckpt.get("split_runs") or {}).get("train", []))
    held = sorted(seen & (set(split_runs.get("val", [])) | set(split_runs.get("test", []))))
    if held:
        raise InputError(
            f"{KEY}: {path} trained on run {held[0]}, which the student validates or tests on; "
            "use the teacher of the student's seed"
        )
    model = model_from_checkpoint(ckpt)
    if callable(getattr(model, "fit", None)):
        raise InputError(f"{KEY}: {path} is a tree ensemble; a teacher must be a network")
    model.to(device).eval()
    for parameter in model.parameters():
        parameter.requires_grad_(False)
    return Teacher(model, weight, temperature)
