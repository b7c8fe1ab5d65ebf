"""Placement self-calibration: a harness model's coupling ``C`` refitted on an arm's healthy
running, everything else frozen (a retrofit kit installed anywhere, no labels).

Two estimators of ``C`` (``placement_fit``):

- ``motion`` (default, :mod:`robohealth_mj.learn.motion_placement`): each sensor a
  non-negative mixture of the joints' emissions predicted from their motion, with package
  predictors fitted on the model's training recordings (where the packages were recorded).
- ``reconstruction``: ``C`` refitted by gradient to minimise the model's own prediction error of
  each sensor from its coupled joints (``AnomalyResidualHead.reconstruction_error``); 0.32 with
  the earlier dense-edge pool model, -0.08 with the chosen one.

Either only helps a model that has learned to use *any* placement (``trainer.placements``); a
model trained on one placement has that placement in its sensor embeddings as well
(``studies/stock_arm/results/recouple_trial.txt``).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import torch

from robohealth_mj.common.errors import InputError
from robohealth_mj.data.arrays import Recording
from robohealth_mj.data.graphs import GraphSpec, coupling_correlation
from robohealth_mj.data.windows import make_windows
from robohealth_mj.learn.data import WindowTensors
from robohealth_mj.learn.motion_placement import PRUNE, SENSORS, motion_estimate
from robohealth_mj.learn.placements import healthy_sensor_statistics

STEPS = 500
LR = 0.05
FITS = ("motion", "reconstruction")


def reconstruction_estimate(
    head, nodes: torch.Tensor, seed: int = 0, steps: int = STEPS
) -> tuple[float, float]:
    """Refit ``head``'s ``C`` (from a near-uniform start, as in training) to minimise the
    reconstruction error of the sensors in ``nodes [B, N, H]``; the error before and after."""
    with torch.no_grad():
        torch.manual_seed(seed)
        head.coupling_logits.normal_(0.0, head.init_noise)
        before = float(head.reconstruction_error(nodes).mean())
    logits = head.coupling_logits
    logits.requires_grad_(True)
    optimiser = torch.optim.Adam([logits], lr=LR)
    for _ in range(steps):
        loss = head.reconstruction_error(nodes).mean()
        optimiser.zero_grad()
        loss.backward()
        optimiser.step()
    logits.requires_grad_(False)
    with torch.no_grad():
        after = float(head.reconstruction_error(nodes).mean())
    return before, after


def recouple(
    model: torch.nn.Module,
    world: GraphSpec,
    arm: Recording,
    reference: Recording,
    mean: np.ndarray,
    std: np.ndarray,
    window: int,
    fit: str = "motion",
    refit_sensor_statistics: bool = True,
    seed: int = 0,
    prune: float | None = None,
) -> tuple[np.ndarray, np.ndarray, dict[str, Any]]:
    """Refit ``model``'s ``C`` in place on ``arm`` (healthy, read through ``world``: the
    profile, commissioning shift and the placement the sensors really sit in). With
    ``refit_sensor_statistics`` the sensors are z-scored on this arm's healthy running, as the
    model was trained (``trainer.placements``). Returns the normalisation and a record: the
    refitted ``C``, the reconstruction fit's error before and after and, where the placement is
    known (simulation), ``C``'s correlation with it. ``prune``: the motion fit's (None:
    :data:`PRUNE`)."""
    if fit not in FITS:
        raise InputError(f"placement_fit must be one of {FITS}, got {fit!r}")
    prune = PRUNE if prune is None else float(prune)
    if not 0.0 <= prune < 1.0:
        raise InputError(f"placement_prune must be in [0, 1), got {prune}")
    mean, std = mean.copy(), std.copy()
    j = world.num_joints
    if refit_sensor_statistics:
        mu, sd = healthy_sensor_statistics(world, arm.x)
        mean[j:, SENSORS], std[j:, SENSORS] = mu, sd
    head = model.anomaly
    record: dict[str, Any] = {"fit": fit}
    if fit == "reconstruction":
        model.eval()
        tensors = WindowTensors(world.transform(arm.x), arm, mean, std, torch.device("cpu"))
        windows = make_windows(arm, window)
        n = len(windows)
        with torch.no_grad():  # the backbone is frozen: the embeddings the head reads, once
            nodes = torch.cat([
                model._features(tensors.batch(windows, np.arange(i, min(i + 512, n))).x)[1][1]
                for i in range(0, n, 512)
            ])  # fmt: skip
        before, after = reconstruction_estimate(head, nodes, seed)
        record.update(reconstruction_before=before, reconstruction_after=after)
    else:
        head.set_coupling(motion_estimate(reference, arm, world, prune))
        record["prune"] = prune
    coupling = head.coupling().detach().numpy()
    record["coupling"] = coupling.round(5).tolist()
    record["sensor_statistics"] = "refitted" if refit_sensor_statistics else "kept"
    if world.coupling is not None:
        record["coupling_correlation"] = coupling_correlation(coupling, world.coupling)
    return mean, std, record
