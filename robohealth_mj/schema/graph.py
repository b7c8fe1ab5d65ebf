"""The graph every sample lives on: node order, feature names and channels, fault classes,
edges and the schema's version."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache, cached_property

import numpy as np

SCHEMA_VERSION = "3.0"  # 3.0: the graph is the arm's (any joint count); 2.0: the UR graph
# Versions a reader takes: 2.0 (tracking error, torque residual, piezo bands, kurtosis) is 3.0 on
# the six-joint UR graph.
READABLE_VERSIONS: tuple[str, ...] = ("2.0", "3.0")

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
CHAIN_PREFIX = "chain_"  # a positional graph's joints (ArmGraph.by_position): chain_1 … chain_J
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


@dataclass(frozen=True)
class ArmGraph:
    """The graph of one arm: its joints along the chain, base to tool, then one sensor package
    per joint (``<joint>_sensor``); edges between adjacent joints and between each joint and its
    package, both directions. The node set and edges come from the arm, so one definition serves
    a UR's six joints, a Franka's seven and a user's five (schema 3.0)."""

    joints: tuple[str, ...]

    def __post_init__(self) -> None:
        joints = tuple(str(j) for j in self.joints)
        object.__setattr__(self, "joints", joints)
        if len(joints) < 2 or len(set(joints)) != len(joints):
            raise ValueError(f"an arm graph needs two or more distinct joints, got {list(joints)}")

    @property
    def n_joints(self) -> int:
        return len(self.joints)

    @property
    def n_nodes(self) -> int:
        return 2 * len(self.joints)

    @property
    def sensors(self) -> tuple[str, ...]:
        return tuple(f"{name}_sensor" for name in self.joints)

    @property
    def nodes(self) -> tuple[str, ...]:
        return self.joints + self.sensors

    @cached_property
    def edges(self) -> tuple[tuple[int, int], ...]:
        """Kinematic backbone between adjacent joints, then joint <-> own sensor."""
        j = self.n_joints
        out: list[tuple[int, int]] = []
        for i in range(j - 1):
            out += [(i, i + 1), (i + 1, i)]
        for i in range(j):
            out += [(i, j + i), (j + i, i)]
        return tuple(out)

    def edge_index(self) -> np.ndarray:
        """Edges as a PyG-style ``[2, E]`` int64 array."""
        return np.array(self.edges, dtype=np.int64).T.copy()

    def adjacency(self) -> np.ndarray:
        """Dense ``[N, N]`` 0/1 adjacency of the structural graph (no self-loops)."""
        a = np.zeros((self.n_nodes, self.n_nodes), dtype=np.float32)
        for i, k in self.edges:
            a[i, k] = 1.0
        return a

    def hop_distance(self) -> np.ndarray:
        """Hop distance between joints along the kinematic chain, ``[J, J]``."""
        idx = np.arange(self.n_joints)
        return np.abs(idx[:, None] - idx[None, :])

    def type_flags(self) -> np.ndarray:
        """The ``is_joint``/``is_sensor`` columns every sample carries, ``[N, 2]`` (read-only:
        built once, as every sample's and every fleet tick's check reads it)."""
        return self._flags

    @cached_property
    def _flags(self) -> np.ndarray:
        flags = np.zeros((self.n_nodes, 2), np.float32)
        flags[: self.n_joints, 0] = 1.0
        flags[self.n_joints :, 1] = 1.0
        flags.setflags(write=False)
        return flags

    def as_dict(self) -> dict:
        """What a manifest, a checkpoint and an ONNX file carry of the graph."""
        return {
            "joints": list(self.joints),
            "nodes": list(self.nodes),
            "features": list(FEATURE_NAMES),
            "edges": [list(e) for e in self.edges],
        }

    @classmethod
    def by_position(cls, n_joints: int) -> ArmGraph:
        """The graph of a model trained on several arms of one joint count whose joints are
        named apart (a Franka's ``fr3_joint1``, a Kinova's ``joint_1``): its joints are named by
        their place along the chain, base to tool (``chain_1`` …), and it reads any arm of
        ``n_joints`` joints by that place, as its weights were fitted."""
        return cls(tuple(f"{CHAIN_PREFIX}{k + 1}" for k in range(n_joints)))

    @property
    def positional(self) -> bool:
        """Whether this is a :meth:`by_position` graph."""
        return self == ArmGraph.by_position(self.n_joints)

    def reads(self, data: ArmGraph) -> bool:
        """Whether a model trained on this graph reads data on ``data``: the same graph, or any
        arm of as many joints when this one is positional."""
        return self == data or (self.positional and data.n_joints == self.n_joints)

    def places_on(self, longer: ArmGraph) -> list[int]:
        """Where this arm's joints sit along a longer chain, read by place (:meth:`by_position`):
        the base two (the shoulder's pan and lift on every arm here) first, the rest with the
        tool joint last; the joints between, which this arm lacks, read as absent. A six-joint
        UR on seven places has no third joint: the upper-arm roll the seven-joint arms add
        between shoulder and elbow."""
        short, long = self.n_joints, longer.n_joints
        if short > long:
            raise ValueError(f"{short} joints do not sit on a chain of {long}")
        head = min(2, short)
        return list(range(head)) + list(range(long - (short - head), long))

    @classmethod
    def of_nodes(cls, nodes: Sequence[str]) -> ArmGraph:
        """The graph whose node list is ``nodes`` (J joints, then their J sensors), or
        ValueError saying why it is not one."""
        return _graph_of_nodes(tuple(nodes))


@cache
def _graph_of_nodes(nodes: tuple[str, ...]) -> ArmGraph:
    if len(nodes) % 2:
        raise ValueError(f"{len(nodes)} nodes: not J joints followed by their J sensors")
    graph = ArmGraph(nodes[: len(nodes) // 2])
    if graph.nodes != nodes:
        raise ValueError(f"node order {list(nodes)} is not J joints followed by their J sensors")
    return graph


# The UR e-Series graph: every 2.0 recording's, and the default where an arm is not named.
UR_GRAPH = ArmGraph(JOINT_NAMES)
EDGES: tuple[tuple[int, int], ...] = UR_GRAPH.edges


def edge_index() -> np.ndarray:
    """The UR graph's edges as a PyG-style ``[2, E]`` int64 array."""
    return UR_GRAPH.edge_index()


def adjacency() -> np.ndarray:
    """Dense ``[N, N]`` adjacency of the UR graph."""
    return UR_GRAPH.adjacency()


def hop_distance() -> np.ndarray:
    """Hop distance between the UR graph's joints, ``[J, J]``."""
    return UR_GRAPH.hop_distance()
