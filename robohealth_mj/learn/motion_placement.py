"""The placement a sensor kit sits in, from healthy running alone (the ``motion`` estimator).

On healthy running each sensor is the mixture, through ``C``, of what the joints' drives emit,
and what a drive emits follows its joint's motion. Predictors of each joint's sensor package
from the joint state are fitted on recordings where the packages were recorded (per joint);
each of the arm's sensors is then a non-negative least-squares mixture of the predicted
packages, pruned of the joints that barely help it. Every entry of ``C`` is such a mixture
weight, so it is non-negative and measures how much of a joint's predicted emission a sensor
carries: no loss can invert it. Used by commissioning (``deploy/recouple.py``) and by training
(``model.coupling_fit=motion``). Mean correlation with the true placement 0.99 on five unseen
placements, 0.92 unpruned (``studies/stock_arm/results/self_calibration.md``).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import nnls

from robohealth_mj import schema
from robohealth_mj.common.errors import InputError
from robohealth_mj.data.arrays import Recording
from robohealth_mj.data.graphs import GraphSpec
from robohealth_mj.data.windows import covered

BLOCK = 20  # ticks (1 s) averaged per row of the motion estimator: drive noise averages out
RIDGE = 0.1
MAX_BLOCKS = 20_000  # 400,000 ticks: the training fit's bound on memory
PRUNE = 0.006  # chosen on five validation placements (studies/stock_arm/results/pool_design.md)
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
    return motion_fit(reference.x[~reference.active], arm.x, world, prune)


def motion_fit(
    reference: np.ndarray, arm: np.ndarray, world: GraphSpec, prune: float = PRUNE
) -> np.ndarray:
    """:func:`motion_estimate` on snapshots ``[T, 2J, F]``: healthy ticks with the packages
    recorded, and the arm's healthy ticks (read through ``world``)."""
    mask = 1.0 if world.channel_mask is None else world.channel_mask
    J = world.num_joints
    ref = reference * mask
    packages = ref[:, J:, SENSORS].astype(np.float64)
    flat = packages.reshape(-1, packages.shape[-1])
    mu, sd = flat.mean(axis=0), flat.std(axis=0)
    sd[sd < 1e-9] = 1.0
    x, p = _blocks(motion_features(ref)), _blocks((packages - mu) / sd)  # [R, D], [R, J, C]
    gram = x.T @ x + RIDGE * np.eye(x.shape[1])
    weights = np.linalg.solve(gram, x.T @ p.reshape(len(p), -1)).reshape(-1, *p.shape[1:])
    predicted = np.einsum("rd,djc->rjc", _blocks(motion_features(arm)), weights)
    sensors = _blocks((world.transform(arm)[:, J:, SENSORS] - mu) / sd)  # [R, M, C]
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


def healthy_training_ticks(rec: Recording, windows, max_blocks: int = MAX_BLOCKS) -> np.ndarray:
    """The healthy snapshots ``[T, 2J, F]`` the training windows cover, as whole 1 s blocks of
    consecutive ticks, at most ``max_blocks`` of them spread evenly (memory stays bounded on a
    large corpus; the fit's 100-odd coefficients need far fewer)."""
    ticks = np.flatnonzero(covered(windows, len(rec)) & ~rec.active)
    n = len(ticks) // BLOCK
    blocks = ticks[: n * BLOCK].reshape(n, BLOCK)
    if n > max_blocks:
        blocks = blocks[np.linspace(0, n - 1, max_blocks).round().astype(int)]
    return rec.x[blocks.ravel()]


def training_placement(rec: Recording, windows, world: GraphSpec) -> np.ndarray:
    """``C [J, M]`` for ``model.coupling_fit=motion``: the motion estimate on the healthy
    running the training windows cover, with package predictors from the same ticks (the
    recordings carry each joint's package; the model is shown only ``world``'s mixture)."""
    ticks = healthy_training_ticks(rec, windows)
    return motion_fit(ticks, ticks, world)
