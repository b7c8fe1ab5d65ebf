"""The healthy baseline of the residual channels, and moving it from one arm to another.

A controller's model never matches its arm: a heavier link leaves a pose-dependent torque
residual, more friction a residual that follows the direction of motion, more damping one that
follows speed, and a softer drive a larger tracking error under load. A model trained on one arm
reads another arm's healthy residuals as evidence. Commissioning fits, per joint, a linear
baseline of each residual channel (tracking error, torque residual) on the joint state, from
healthy running of the new arm, and moves the new arm's residuals onto the training arms'
baseline: ``r' = r - basis(state) @ (W_arm - W_reference)``. The constant term of the basis is
the normalisation's offset; the others carry what an offset cannot.

Works on NumPy arrays and on torch tensors alike (the exported model's input stage runs it).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from robohealth_mj import schema

RESIDUALS = ("pos_error", "effort_residual")
COULOMB_SCALE = 0.05  # rad/s: the controller's own smoothing of the friction sign
N_BASIS = 11


def basis(x: Any, joints: int = schema.N_JOINTS) -> Any:
    """Snapshots ``[..., 2J (or J), F]`` of an arm of ``joints`` joints -> per-joint regressors
    ``[..., J, N_BASIS]``: a constant, the smoothed direction of motion, the speed, and the
    gravity terms of a UR's pitch chain (cos and sin of the summed shoulder-lift, elbow, wrist-1
    angles; wrist 2); on another arm (five joints or more) the same terms of its joints 2-5, a
    rougher basis that the fit weighs per joint."""
    xp = _xp(x)
    q = x[..., :joints, schema.feature_index("pos")]
    qd = x[..., :joints, schema.feature_index("vel")]
    a1, a2, a3 = q[..., 1], q[..., 1] + q[..., 2], q[..., 1] + q[..., 2] + q[..., 3]
    shared = [xp.cos(a1), xp.sin(a1), xp.cos(a2), xp.sin(a2), xp.cos(a3), xp.sin(a3),
              xp.cos(q[..., 4]), xp.sin(q[..., 4])]  # fmt: skip
    shared = xp.stack(shared, -1)[..., None, :] * xp.ones_like(q)[..., None]
    own = xp.stack([xp.ones_like(q), xp.tanh(qd / COULOMB_SCALE), qd], -1)
    return xp.concatenate([own, shared], -1) if xp is np else xp.cat([own, shared], -1)


def fit(x: np.ndarray) -> np.ndarray:
    """Least-squares baseline ``W [J, 2, N_BASIS]`` of the residual channels on healthy
    snapshots ``x [T, 2J, F]`` (a small ridge keeps a joint that never moved well posed)."""
    joints = x.shape[-2] // 2
    b = basis(x.astype(np.float64), joints)  # [T, J, B]
    out = np.zeros((joints, len(RESIDUALS), N_BASIS))
    ridge = 1e-6 * len(x) * np.eye(N_BASIS)
    for j in range(joints):
        gram = b[:, j].T @ b[:, j] + ridge
        for c, name in enumerate(RESIDUALS):
            target = x[:, j, schema.feature_index(name)].astype(np.float64)
            out[j, c] = np.linalg.solve(gram, b[:, j].T @ target)
    return out


def shift(x: Any, delta: Any) -> Any:
    """``x [..., 2J (or J), F]`` with each joint's residual channels moved by ``-basis @ delta``
    (``delta [J, 2, N_BASIS]`` = the arm's baseline minus the reference's), on the joint nodes and
    on the copies the schema puts on the sensor nodes."""
    xp = _xp(x)
    j = delta.shape[0]
    moved = (basis(x, j)[..., None, :] * delta).sum(-1)  # [..., J, 2]
    cols = [schema.feature_index(n) for n in RESIDUALS]
    out = x.copy() if xp is np else x.clone()
    for c, col in enumerate(cols):
        out[..., :j, col] = x[..., :j, col] - moved[..., c]
        if x.shape[-2] > j:
            out[..., j : 2 * j, col] = x[..., j : 2 * j, col] - moved[..., c]
    return out


def _xp(x: Any):
    if isinstance(x, np.ndarray):
        return np
    import torch

    return torch
