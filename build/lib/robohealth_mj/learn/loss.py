"""``CE(graph) + w_j L_joint + 0.1 L_recon`` (+ severity MSE when that head is on).

``L_joint`` is, by default, a softmax cross-entropy over the joints on faulted windows (exactly
one joint is at fault, so the joints compete); ``joint_softmax=False`` gives the thesis's
per-joint BCE with all-zero targets on healthy windows.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

import torch
import torch.nn.functional as F

from robohealth_mj.learn.data import WindowBatch


def training_loss(
    out: dict[str, torch.Tensor],
    batch: WindowBatch,
    joint_weight: float,
    recon_weight: float,
    severity_weight: float,
    joint_softmax: bool = True,
) -> tuple[torch.Tensor, dict]:
    ce = F.cross_entropy(out["class_logits"], batch.fault_class)
    faulted = batch.active.nonzero(as_tuple=True)[0]
    if joint_softmax:
        joint = (
            F.cross_entropy(out["joint_logits"][faulted], batch.fault_joint[faulted])
            if len(faulted)
            else out["joint_logits"].sum() * 0.0
        )
    else:
        target = torch.zeros_like(out["joint_logits"])
        target[faulted, batch.fault_joint[faulted]] = 1.0  # healthy windows: no joint at fault
        joint = F.binary_cross_entropy_with_logits(out["joint_logits"], target)
    loss = ce + joint_weight * joint
    parts = {"ce": ce.detach(), "joint": joint.detach()}
    if "recon_energy" in out:
        healthy = ~batch.active
        recon = (
            out["recon_energy"][healthy].sum(-1).mean()
            if healthy.any()
            else out["recon_energy"].sum() * 0.0
        )
        loss = loss + recon_weight * recon
        parts["recon"] = recon.detach()
    if "severity" in out:
        sev = F.mse_loss(out["severity"], batch.severity)
        loss = loss + severity_weight * sev
        parts["severity"] = sev.detach()
    return loss, parts


def loss_from_config(trainer_cfg) -> Callable[[dict[str, torch.Tensor], WindowBatch], tuple]:
    """``training_loss`` with the weights and options of a ``trainer`` config."""
    t = trainer_cfg
    return functools.partial(
        training_loss,
        joint_weight=float(t.joint_loss_weight),
        recon_weight=float(t.recon_loss_weight),
        severity_weight=float(t.severity_loss_weight),
        joint_softmax=bool(t.joint_softmax),
    )
