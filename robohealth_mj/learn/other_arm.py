"""A model of the UR's six joints read on an arm of another joint count: each of the arm's joints
(and its sensor package) is read as its UR counterpart (``ArmDescription.ur_counterparts``, the
same rule that gives it its drive and its motion).

A graph network's convolutions, encoders and heads share their weights across nodes; what is
sized by the arm is its graph (the adjacency), the per-node parameters (node embeddings), the
per-node normalisation and, in a coupling head, the ``[J, M]`` coupling. Each of those is taken
node by node from the counterpart's, so a seven-joint FR3 reads with the UR's shoulder-lift
weights on its four big joints, the wrist-2 weights on the next two and the tool joint's on the
last. A parameter sized by the arm that is not one of those is refused, naming it: that model
reads only its own arm's graph.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import torch

from robohealth_mj import schema
from robohealth_mj.arms.description import load_arm
from robohealth_mj.common.errors import InputError
from robohealth_mj.learn.checkpoint import checkpoint_arm, checkpoint_digest

_NODE_ROWS = ("backbone.encoder.node",)  # [N, H]: one row per node
_NODE_SQUARE = ("adjacency.residual.logits",)  # [N, N]: a learned edge residual
_COUPLING = ("anomaly.coupling_logits",)  # [J, M]: joints x sensor packages (structural graph)


def read_as(ckpt: dict[str, Any], arm: str, source: str | None = None) -> dict[str, Any]:
    """``ckpt`` (a model of the UR's six joints, structural graph) as a model of ``arm``'s
    joints, each read as its UR counterpart; a new checkpoint dict (checksum recomputed).
    ``source``: the file ``ckpt`` was read from, which commissioning reads its training
    arms' data with."""
    trained = checkpoint_arm(ckpt)
    if trained != schema.UR_GRAPH:
        raise InputError(
            f"reading another joint count maps each joint to its UR counterpart: a model of the "
            f"UR's six joints only, not of {list(trained.joints)}"
        )
    graph = dict(ckpt["graph"])
    if graph.get("coupling") is not None:
        raise InputError("graph=harness: its placement is the UR arm's; read a structural model")
    description = load_arm(arm)
    target = schema.ArmGraph(description.joint_keys)
    joints = description.ur_counterpart_index()
    n_src = schema.UR_GRAPH.n_joints
    nodes = joints + [n_src + j for j in joints]
    kept = int(graph.get("schema_nodes", schema.N_NODES))  # 6: the joints only (stock)
    rows = nodes[: target.n_joints] if kept == n_src else nodes
    adjacency = target.adjacency()[: len(rows), : len(rows)]

    def take(value, *axes: int) -> np.ndarray:
        """``value`` with its node ``axes`` taken row by row from the counterparts."""
        array = np.asarray(value)
        for axis in axes:
            array = np.take(array, rows, axis=axis)
        return array

    state = {}
    for key, tensor in ckpt["state_dict"].items():
        if key == "adjacency.structural":
            state[key] = torch.from_numpy(adjacency.astype(np.float32))
        elif key in _NODE_ROWS:
            state[key] = torch.from_numpy(take(tensor.numpy(), 0))
        elif key in _NODE_SQUARE:
            state[key] = torch.from_numpy(take(tensor.numpy(), 0, 1))
        elif key in _COUPLING:
            state[key] = torch.from_numpy(np.ascontiguousarray(tensor.numpy()[joints][:, joints]))
        else:
            state[key] = tensor
    mask = graph.get("channel_mask")
    shift = graph.get("baseline_shift")
    graph.update({
        "node_names": list(target.nodes[: len(rows)]),
        "adjacency": adjacency.tolist(),
        "num_joints": target.n_joints,
        "schema_nodes": len(rows),
        "channel_mask": None if mask is None else take(mask, 0).tolist(),
        "baseline_shift": None if shift is None else np.asarray(shift)[joints].tolist(),
        "joints": list(target.joints),
    })  # fmt: skip
    out = {
        **ckpt,
        "state_dict": state,
        "graph": graph,
        "schema": {**ckpt["schema"], "version": schema.SCHEMA_VERSION,
                   "node_names": list(target.nodes), "edges": [list(e) for e in target.edges]},
        "labels": {**ckpt["labels"], "joints": list(target.joints)},
        "norm_mean": torch.from_numpy(take(ckpt["norm_mean"].numpy(), 0)),
        "norm_std": torch.from_numpy(take(ckpt["norm_std"].numpy(), 0)),
        "arms": [arm],  # the arm it now reads (its readings relative to that arm's ratings)
        "read_as": {"arm": arm, "trained_on": list(ckpt.get("arms") or []),
                    "counterparts": list(description.ur_counterparts()),
                    "checkpoint": None if source is None else str(source)},
    }  # fmt: skip
    out["sha256"] = checkpoint_digest(out)
    return out
