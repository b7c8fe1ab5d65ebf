"""The graphs a model can be trained on: the structural schema graph, or the unknown-placement
harness (thesis §2.6.4) where four off-joint sensors mix the six per-joint sensor packages through
a ground-truth coupling ``C0 [6, 4]`` that no model is shown (on an arm of J joints, ``[J, M]``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from robohealth_mj import schema
from robohealth_mj.common.errors import InputError
from robohealth_mj.common.seeds import stream
from robohealth_mj.data.baseline import shift

# Every joint reaches at least one sensor, and every joint's row is distinct, so the six joints
# stay distinguishable from four sensors.
DEFAULT_C0 = np.array(
    [
        [1.0, 0.0, 0.0, 0.3],
        [0.7, 0.5, 0.0, 0.0],
        [0.0, 1.0, 0.3, 0.0],
        [0.0, 0.4, 1.0, 0.0],
        [0.0, 0.0, 0.6, 0.7],
        [0.3, 0.0, 0.0, 1.0],
    ],
    dtype=np.float32,
)


@dataclass(frozen=True)
class GraphSpec:
    name: str
    node_names: tuple[str, ...]
    adjacency: np.ndarray  # [N, N]
    num_joints: int
    coupling: np.ndarray | None = None  # C0 [J, M] for the harness
    sensing: str = "full"  # the sensing profile (data/sensing.py) whose channels the graph keeps
    channel_mask: np.ndarray | None = None  # [2J, F] 1 kept / 0 zeroed, on the arm's nodes
    schema_nodes: int = schema.N_NODES  # the leading arm nodes read (J: the joints only)
    classes: tuple[str, ...] = schema.FAULT_CLASSES  # the label set (the profile's)
    baseline_shift: np.ndarray | None = None  # [J, 2, B] commissioning (data/baseline.py)
    arm: schema.ArmGraph = schema.UR_GRAPH  # the arm graph the recordings carry
    coupling_seed: int | None = None  # the harness's drawn placement: redrawn for another arm

    def for_arm(self, arm: schema.ArmGraph) -> GraphSpec:
        """This graph on ``arm``'s joints (the recordings' graph; before :meth:`with_sensing`):
        the structural graph is the arm's own; the harness keeps its sensors, its placement
        redrawn from its seed for the arm's joints, or refused where a given one does not fit."""
        if arm == self.arm:
            return self
        if self.coupling is None:
            return replace(
                self, node_names=arm.nodes, adjacency=arm.adjacency(), num_joints=arm.n_joints,
                schema_nodes=arm.n_nodes, arm=arm,
            )  # fmt: skip
        m = self.coupling.shape[1]
        if self.coupling_seed is not None:
            c = random_coupling(self.coupling_seed, m, arm.n_joints)
        elif self.coupling.shape[0] == arm.n_joints:
            c = self.coupling
        else:
            raise InputError(
                f"graph=harness: the placement is [{self.coupling.shape[0]}, {m}], for "
                f"{self.coupling.shape[0]} joints; the recordings' arm has {arm.n_joints}: set "
                "graph.coupling_seed (a placement drawn for its joints) or graph.coupling_file"
            )
        spec = harness_graph(c, arm=arm)
        return replace(spec, coupling_seed=self.coupling_seed)

    def named_for(self, arm: schema.ArmGraph) -> GraphSpec:
        """A positional graph (a model of several arms of one joint count) with ``arm``'s node
        names: commissioned on that arm, the model is that arm's, and its diagnoses name its
        joints. Any other graph is returned as it is."""
        if not self.arm.positional or arm == self.arm or arm.n_joints != self.num_joints:
            return self
        names = dict(zip(self.arm.nodes, arm.nodes, strict=True))
        return replace(self, node_names=tuple(names.get(n, n) for n in self.node_names), arm=arm)

    def with_sensing(self, profile) -> GraphSpec:
        """This graph reading only the channels ``profile`` (a SensingProfile) names; without
        sensor channels, without the sensor nodes."""
        spec = replace(
            self,
            sensing=profile.name,
            channel_mask=profile.mask(self.arm.n_joints),
            classes=profile.label_set,
        )
        if profile.sensor_nodes:
            return spec
        if self.coupling is not None:
            raise InputError(
                f"sensing={profile.name} has no sensors, so there is no placement to learn: "
                "use graph=structural"
            )
        j = self.num_joints
        return replace(
            spec, node_names=self.node_names[:j], adjacency=self.adjacency[:j, :j], schema_nodes=j
        )

    def relabel(self, rec):
        """``rec`` (a Recording) with every class outside the label set read as healthy: a
        sensor fault on an arm without that sensor leaves the arm healthy."""
        if self.classes == schema.FAULT_CLASSES:
            return rec
        outside = ~np.isin(rec.fault_class, [schema.FAULT_CLASSES.index(c) for c in self.classes])
        if not outside.any():
            return rec
        return replace(
            rec,
            fault_class=np.where(outside, 0, rec.fault_class),
            fault_joint=np.where(outside, -1, rec.fault_joint),
            severity=np.where(outside, 0.0, rec.severity).astype(np.float32),
            active=rec.active & ~outside,
        )

    def transform(self, x: np.ndarray) -> np.ndarray:
        """Arm snapshots ``[..., 2J, F]`` -> this graph's node features ``[..., N, F]``."""
        if self.baseline_shift is not None:  # this arm's residuals onto the training arms'
            x = shift(x, self.baseline_shift).astype(np.float32)
        if self.channel_mask is not None:
            x = (x * self.channel_mask).astype(np.float32)
        if self.schema_nodes < x.shape[-2]:
            x = np.ascontiguousarray(x[..., : self.schema_nodes, :])
        if self.coupling is None:
            return x
        j = self.num_joints
        mixed = np.einsum("jm,...jc->...mc", self.coupling, x[..., j:, schema.SENSOR_CHANNELS])
        sensors = np.zeros((*x.shape[:-2], self.coupling.shape[1], schema.N_FEATURES), np.float32)
        sensors[..., 1] = 1.0  # is_sensor; joint-state channels stay zero
        sensors[..., schema.SENSOR_CHANNELS] = mixed
        return np.concatenate([x[..., :j, :], sensors], axis=-2).astype(np.float32)

    def as_dict(self) -> dict:
        return {
            "name": self.name,
            "node_names": list(self.node_names),
            "adjacency": self.adjacency.tolist(),
            "num_joints": self.num_joints,
            "coupling": None if self.coupling is None else self.coupling.tolist(),
            "sensing": self.sensing,
            "channel_mask": None if self.channel_mask is None else self.channel_mask.tolist(),
            "schema_nodes": self.schema_nodes,
            "classes": list(self.classes),
            "baseline_shift": None if self.baseline_shift is None else self.baseline_shift.tolist(),
            "joints": list(self.arm.joints),
            "coupling_seed": self.coupling_seed,
        }


def structural_graph(arm: schema.ArmGraph = schema.UR_GRAPH) -> GraphSpec:
    """The arm's own graph: its joints along the chain, a sensor package on each."""
    return GraphSpec(
        "structural", arm.nodes, arm.adjacency(), arm.n_joints, schema_nodes=arm.n_nodes, arm=arm
    )


def load_coupling(path: str | Path) -> np.ndarray:
    """A ``[J, M]`` non-negative coupling from ``.npy``, ``.json`` or ``.csv``."""
    path = Path(path)
    if path.suffix == ".npy":
        c = np.load(path)
    elif path.suffix == ".json":
        c = np.array(json.loads(path.read_text()), dtype=np.float32)
    else:
        c = np.loadtxt(path, delimiter=",", dtype=np.float32, ndmin=2)
    c = np.asarray(c, dtype=np.float32)
    if c.ndim != 2 or c.shape[0] < 2 or c.shape[1] < 1:
        raise InputError(f"{path}: coupling must be [J, M] (a row per joint), got {c.shape}")
    if not _reaches(c):
        raise InputError(f"{path}: {_UNREACHED}")
    return c


_UNREACHED = "coupling must be >= 0 and every joint must reach a sensor"


def _reaches(c: np.ndarray) -> bool:
    return bool(np.all(c >= 0) and np.all(c.sum(axis=1) > 0))


def random_coupling(
    seed: int, sensors: int = 4, joints: int = schema.UR_GRAPH.n_joints
) -> np.ndarray:
    """A placement nobody measured, drawn from ``seed``: ``[joints, sensors]``, non-negative.

    Each joint reaches a primary sensor (weight in [0.6, 1]) and, with probability one half, a
    second one (weight in [0.2, 0.5]); every sensor is reached by some joint; no two joints'
    rows are alike (normalised rows at least 0.1 apart), so the joints stay distinguishable
    through the sensors. Redrawn from the same generator until those hold, so one seed gives
    one matrix.
    """
    if not 2 <= sensors <= 2 * joints:
        raise InputError(
            f"a random placement needs 2 to {2 * joints} sensors (each joint reaches one or two), "
            f"got {sensors}"
        )
    rng = stream("graphs.placement", seed)
    while True:
        c = np.zeros((joints, sensors), np.float32)
        primary = rng.permutation(np.resize(rng.permutation(sensors), joints))
        for j, m in enumerate(primary):
            c[j, m] = rng.uniform(0.6, 1.0)
            if rng.random() < 0.5:
                other = rng.choice([k for k in range(sensors) if k != m])
                c[j, other] = rng.uniform(0.2, 0.5)
        if placement_problem(c) is None:
            return c


def placement_problem(c: np.ndarray) -> str | None:
    """Why a coupling cannot serve as a placement (None: it can)."""
    if not _reaches(c):
        return _UNREACHED
    if np.any(c.sum(axis=0) == 0):
        return "every sensor must be reached by some joint"
    rows = c / np.linalg.norm(c, axis=1, keepdims=True)
    gaps = np.linalg.norm(rows[:, None] - rows[None], axis=-1) + np.eye(len(c)) * 9.0
    if gaps.min() < 0.1:
        return "two joints reach the sensors alike (normalised rows closer than 0.1)"
    return None


def harness_graph(
    coupling: np.ndarray | list | None = None,
    coupling_file: str | None = None,
    coupling_seed: int | None = None,
    coupling_sensors: int = 4,
    arm: schema.ArmGraph = schema.UR_GRAPH,
) -> GraphSpec:
    """Joints keep their backbone; every joint links to every harness sensor (dense bipartite),
    so message passing is not told the coupling either. C0: the default, a matrix, a file, or
    a random placement of ``coupling_sensors`` sensors drawn from ``coupling_seed`` (for the
    UR's six joints; :meth:`GraphSpec.for_arm` takes it to another arm's)."""
    given = [k for k, v in (("coupling", coupling), ("coupling_file", coupling_file),
                            ("coupling_seed", coupling_seed)) if v is not None]  # fmt: skip
    if len(given) > 1:
        raise InputError(f"graph: set one of coupling, coupling_file, coupling_seed (got {given})")
    if coupling_file:
        c = load_coupling(coupling_file)
    elif coupling_seed is not None:
        c = random_coupling(int(coupling_seed), int(coupling_sensors))
    else:
        c = DEFAULT_C0 if coupling is None else np.asarray(coupling, dtype=np.float32)
    j, m = c.shape
    if j != arm.n_joints:
        raise InputError(
            f"graph: the coupling has {j} rows, one per joint; the arm has {arm.n_joints}"
        )
    n = j + m
    adj = np.zeros((n, n), np.float32)
    for i in range(j - 1):
        adj[i, i + 1] = adj[i + 1, i] = 1.0
    adj[:j, j:] = adj[j:, :j] = 1.0
    names = arm.joints + tuple(f"harness_sensor_{k}" for k in range(m))
    seed = None if coupling_seed is None else int(coupling_seed)
    return GraphSpec(
        "harness", names, adj, j, c, schema_nodes=arm.n_nodes, arm=arm, coupling_seed=seed
    )


def coupling_correlation(learned: np.ndarray, truth: np.ndarray) -> float:
    """Mean over joints of the Pearson correlation between a joint's learned and true rows."""
    corr = []
    for a, b in zip(learned, truth, strict=True):
        if np.std(a) < 1e-12 or np.std(b) < 1e-12:
            corr.append(0.0)
        else:
            corr.append(float(np.corrcoef(a, b)[0, 1]))
    return float(np.mean(corr))
