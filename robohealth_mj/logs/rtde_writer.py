"""Write joint channels as a UR RTDE CSV (``conf/logmap/ur_rtde.yaml``'s layout): the shipped
sample log and the tests' logs are made from recordings this way, so that what a user's
controller log goes through is exercised on data whose truth is known."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from robohealth_mj import schema
from robohealth_mj.common.atomic import atomic_write_text

# N*m per A of the six drives, base to tool, for the current columns. UR publishes none; the
# reader fits them back from target_moment / target_current, so any positive numbers round-trip.
TORQUE_CONSTANT = (11.0, 11.5, 9.0, 4.2, 4.0, 3.8)


def write_rtde_csv(
    x: np.ndarray,
    t: np.ndarray,
    path: Path | str,
    torque_constant: np.ndarray | tuple[float, ...] = TORQUE_CONSTANT,
) -> Path:
    """``x``: ``[T, N, F]`` snapshots (the joints are the first nodes, channels in the schema's
    order), ``t``: ``[T]`` seconds. Writes ``timestamp`` and per joint ``actual_q``,
    ``target_q``, ``actual_qd``, ``actual_current``, ``target_current`` and ``target_moment``
    (the controller's model torque) with a comma, atomically."""
    k_t = np.asarray(torque_constant, dtype=np.float64)
    joints = len(k_t)
    x = np.asarray(x, dtype=np.float64)[:, :joints]
    pos, vel, effort, err, residual = (
        x[..., schema.feature_index(name)] for name in schema.STATE_FEATURES
    )
    cols = {"timestamp": np.asarray(t, dtype=np.float64)}
    for j in range(joints):
        cols[f"actual_q_{j}"], cols[f"target_q_{j}"] = pos[:, j], pos[:, j] - err[:, j]
        cols[f"actual_qd_{j}"] = vel[:, j]
        cols[f"actual_current_{j}"] = effort[:, j] / k_t[j]
        cols[f"target_current_{j}"] = (effort[:, j] - residual[:, j]) / k_t[j]
        cols[f"target_moment_{j}"] = effort[:, j] - residual[:, j]
    names = list(cols)
    rows = np.column_stack([cols[n] for n in names])
    lines = [",".join(names), *(",".join(f"{v:.7g}" for v in row) for row in rows)]
    path = Path(path)
    atomic_write_text(path, "\n".join(lines) + "\n")
    return path
