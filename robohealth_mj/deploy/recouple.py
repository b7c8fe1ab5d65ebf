"""Placement self-calibration: a harness model's coupling ``C`` refitted on an arm's healthy
running, everything else frozen (a retrofit kit installed anywhere, no labels).

Two estimators of ``C`` (``placement_fit``):

- ``motion`` (default): on healthy running each sensor is the mixture, through ``C``, of what the
  joints' drives emit, and what a drive emits follows its joint's motion. Predictors of each
  joint's sensor package from the joint state are fitted on the model's training recordings
  (where the packages were recorded), on 1 s block means; each of the arm's sensors is then a
  non-negative least-squares mixture of the predicted packages, pruned of the joints that barely
  help it. Mean correlation with the true placement 0.99 on five unseen placements, 0.92
  unpruned (``studies/stock_arm/results/self_calibration.md``).
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
from scipy.optimize import nnls

from robohealth_mj import schema
from robohealth_mj.common.errors import InputError
from robohealth_mj.data.arrays import Recording
from robohealth_mj.data.graphs import GraphSpec, coupling_correlation
from robohealth_mj.data.windows import make_windows
from robohealth_mj.learn.data import WindowTensors
from robohealth_mj.learn.placements import healthy_sensor_statistics

STEPS = 500
LR = 0.05
BLOCK = 20  # ticks (1 s) averaged per row of the motion estimator: drive noise averages out
RIDGE = 0.1
PRUNE = 0.006  # chosen on five validation placements (studies/stock_arm/results/pool_design.md)
FITS = ("motion", "reconstruction")
SENSORS = schema.SENSOR_CHANNELS
POS, VEL = schema.feature_index("pos"), schema.feature_index("vel")


def motion_features(x: np.ndarray) -> np.ndarray:
    """What a drive's emission follows, from the joint state of snapshots ``[T, 2J, F]``:
    ``[T, D]`` (position, speed and acceleration terms of every joint, products of speeds)."""
    J = x.shape[1] // 2
    q, qd = x[:, :J, POS].astype(np.float64), x[:, :J, VEL].astype(np.float64)
    qdd = np.gradient(qd, axis=0) if len(qd) > 1 else np.zeros_like(qd)
    speed = np.abs(qd)
    parts = [q, qd, speed, qd**2, speed**3, qdd, np.abs(qdd), qdd**2, speed * np.abs(qdd),
             np.sin(q), np.cos(q), np.sin(2 * q), np.cos(2 * q), np.sign(qd),
             (speed > 0.02).astype(np.float64)]  # fmt: skip
    parts += [speed[:, [a]] * speed[:, [b]] for a in range(J) for b in range(a + 1, J)]
    return np.concatenate([*parts, np.ones((len(q), 1))], axis=1)


def _blocks(a: np.ndarray) -> np.ndarray:
    n = len(a) // BLOCK * BLOCK
    return a[:n].reshape(-1, BLOCK, *a.shape[1:]).mean(axis=1)


def sparse_mixture(
    joints: np.ndarray, offsets: np.ndarray, sensor: np.ndarray, prune: float
) -> np.ndarray:
    """Non-negative weights ``[J]`` of the predicted packages ``joints [R, J]`` (plus free
    per-channel offsets) that mix into ``sensor [R]``; then, one at a time, the joint whose
    removal costs least is dropped while the residual sum of squares grows by at most ``prune``
    (relative). The base joint's package rises with every joint's motion, so a plain fit gives
    it weight on every sensor; a kit sensor hears one to three joints."""

    def fit(keep: list[int]) -> tuple[np.ndarray, float]:
        w, r = nnls(np.concatenate([joints[:, keep], offsets, -offsets], axis=1), sensor)
        return w[: len(keep)], r * r

    keep = list(range(joints.shape[1]))
    weights, rss = fit(keep)
    while len(keep) > 1:
        trials = [([k for k in keep if k != d], fit([k for k in keep if k != d])) for d in keep]
        fewer, (w, r) = min(trials, key=lambda t: t[1][1])
        if r > rss * (1.0 + prune):
            break
        keep, weights, rss = fewer, w, r
    out = np.zeros(joints.shape[1])
    out[keep] = weights
    return out


def motion_estimate(
    reference: Recording, arm: Recording, world: GraphSpec, prune: float = PRUNE
) -> np.ndarray:
    """``C [J, M]`` from the arm's healthy sensors (``world``'s mixing of ``arm``) and package
    predictors fitted on ``reference``'s healthy ticks (per-joint packages recorded); a joint
    whose removal grows a sensor's residual sum of squares by less than ``prune`` (relative)
    is dropped from it (0: none)."""
    mask = 1.0 if world.channel_mask is None else world.channel_mask
    J = world.num_joints
    ref = reference.x[~reference.active] * mask
    packages = ref[:, J:, SENSORS].astype(np.float64)
    flat = packages.reshape(-1, packages.shape[-1])
    mu, sd = flat.mean(axis=0), flat.std(axis=0)
    sd[sd < 1e-9] = 1.0
    x, p = _blocks(motion_features(ref)), _blocks((packages - mu) / sd)  # [R, D], [R, J, C]
    gram = x.T @ x + RIDGE * np.eye(x.shape[1])
    weights = np.linalg.solve(gram, x.T @ p.reshape(len(p), -1)).reshape(-1, *p.shape[1:])
    predicted = np.einsum("rd,djc->rjc", _blocks(motion_features(arm.x)), weights)
    sensors = _blocks((world.transform(arm.x)[:, J:, SENSORS] - mu) / sd)  # [R, M, C]
    if len(sensors) < 10:
        raise InputError(f"placement fit: {len(arm)} healthy ticks are too few; record minutes")
    channels = sensors.shape[-1]
    offsets = np.tile(np.eye(channels), (len(sensors), 1))  # a free offset per channel
    joints = predicted.transpose(0, 2, 1).reshape(-1, J)  # rows (block, channel) as sensors[:, m]
    c = np.stack([sparse_mixture(joints, offsets, sensors[:, m].ravel(), prune)
                  for m in range(sensors.shape[1])], 1)  # fmt: skip
    if not np.all(c.max(axis=0) > 0):
        raise InputError("placement fit: a sensor follows no joint's motion; is it connected?")
    return (c / c.max()).astype(np.float32)


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
