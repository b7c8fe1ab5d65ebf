"""The graph every sample lives on: node order, feature names and channels, fault classes,
edges and the schema's version."""

from __future__ import annotations

import numpy as np

SCHEMA_VERSION = "2.0"  # 2.0: tracking error, torque residual, piezo bands, kurtosis

JOINT_NAMES: tuple[str, ...] = (
    "shoulder_pan",
    "shoulder_lift",
    "elbow",
    "wrist_1",
    "wrist_2",
    "wrist_3",
)
SENSOR_NAMES: tuple[str, ...] = tuple(f"{name}_sensor" for name in JOINT_NAMES)
NODE_NAMES: tuple[str, ...] = JOINT_NAMES + SENSOR_NAMES
# Joint state (on joint nodes and, for its own joint, on each sensor node): what a UR controller
# reports over RTDE. ``pos_error`` is the measured link angle minus the controller's target;
# ``effort_residual`` the drive torque minus the controller's model torque (target vs actual
# current, the signal behind a UR's collision and friction monitoring).
STATE_FEATURES: tuple[str, ...] = ("pos", "vel", "effort", "pos_error", "effort_residual")
# The sensor package (sensor nodes only): piezo vibration level, MEMS acceleration, the piezo's
# energy in three sub-bands and the kurtosis of its signal over the tick (see sim/sensors.py).
SENSOR_FEATURES: tuple[str, ...] = (
    "vib",
    "acc_x",
    "acc_y",
    "acc_z",
    "vib_20_80",
    "vib_80_200",
    "vib_200_450",
    "vib_kurtosis",
)
FEATURE_NAMES: tuple[str, ...] = ("is_joint", "is_sensor", *STATE_FEATURES, *SENSOR_FEATURES)
N_JOINTS = len(JOINT_NAMES)
N_NODES = len(NODE_NAMES)
N_FEATURES = len(FEATURE_NAMES)
# The per-channel statistics a model pools each window into (models/statistics.py computes them in
# torch, runtime/incremental.py from running sums; both read the names here).
WINDOW_STATISTICS: tuple[str, ...] = (
    "mean",
    "std",
    "min",
    "max",
    "last_minus_first",
    "mean_abs_step",
    "max_abs_step",
)
STATE_CHANNELS = slice(2, 2 + len(STATE_FEATURES))
SENSOR_CHANNELS = slice(STATE_CHANNELS.stop, N_FEATURES)


def feature_index(name: str) -> int:
    """Column of a named feature in ``x``."""
    return FEATURE_NAMES.index(name)


FAULT_CLASSES: tuple[str, ...] = (
    "none",
    "backlash",
    "friction",
    "jam",
    "struct_weaken",
    "sensor_drift",
    "sensor_noise",
)


def _structural_edges() -> tuple[tuple[int, int], ...]:
    """Kinematic backbone between adjacent joints, then joint <-> own sensor, both directions."""
    edges: list[tuple[int, int]] = []
    for i in range(N_JOINTS - 1):
        edges += [(i, i + 1), (i + 1, i)]
    for i in range(N_JOINTS):
        edges += [(i, N_JOINTS + i), (N_JOINTS + i, i)]
    return tuple(edges)


EDGES: tuple[tuple[int, int], ...] = _structural_edges()


def edge_index() -> np.ndarray:
    """Edges as a PyG-style ``[2, E]`` int64 array."""
    return np.array(EDGES, dtype=np.int64).T.copy()


def adjacency() -> np.ndarray:
    """Dense ``[N, N]`` 0/1 adjacency of the structural graph (no self-loops)."""
    a = np.zeros((N_NODES, N_NODES), dtype=np.float32)
    for i, j in EDGES:
        a[i, j] = 1.0
    return a


def hop_distance() -> np.ndarray:
    """Hop distance between joints along the kinematic chain, ``[J, J]``."""
    idx = np.arange(N_JOINTS)
    return np.abs(idx[:, None] - idx[None, :])
