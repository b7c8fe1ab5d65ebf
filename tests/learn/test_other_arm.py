"""A six-joint model read on a seven-joint arm (learn/other_arm.py): every per-node part is its
joint's UR counterpart's, the rest is the model's own, and it decides on the arm's windows."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from robohealth_mj.arms.description import load_arm
from robohealth_mj.common.errors import InputError
from robohealth_mj.learn.checkpoint import (
    checkpoint_digest,
    graph_from_checkpoint,
    load_checkpoint,
    model_from_checkpoint,
)
from robohealth_mj.learn.other_arm import read_as
from robohealth_mj.schema import JOINT_NAMES


def test_a_ur_model_reads_an_fr3_joint_by_joint_as_its_counterparts(deployed):
    ckpt = load_checkpoint(deployed["structural_ckpt"])
    fr3 = read_as(ckpt, "fr3")
    assert fr3["sha256"] == checkpoint_digest(fr3)
    graph = graph_from_checkpoint(fr3)
    assert graph.num_joints == 7 and graph.node_names[0] == "fr3_joint1"
    counterpart = [JOINT_NAMES.index(c) for c in load_arm("fr3").ur_counterparts()]
    rows = counterpart + [6 + c for c in counterpart]
    node = "backbone.encoder.node"
    np.testing.assert_array_equal(fr3["state_dict"][node], ckpt["state_dict"][node][rows])
    np.testing.assert_array_equal(fr3["norm_mean"], ckpt["norm_mean"][rows])
    shared = [k for k in ckpt["state_dict"] if k not in (node, "adjacency.structural")]
    assert shared and all(fr3["state_dict"][k] is ckpt["state_dict"][k] for k in shared)
    model = model_from_checkpoint(fr3)  # every other weight fits as it is
    out = model(torch.randn(3, int(fr3["window"]), 14, 15))
    assert out["class_logits"].shape == (3, 7) and out["joint_logits"].shape == (3, 7)


def test_a_ur_arm_reads_as_itself_and_a_harness_model_is_refused(deployed):
    ckpt = load_checkpoint(deployed["structural_ckpt"])
    same = read_as(ckpt, "ur10e")  # a UR arm's counterparts are its own joints
    for key, tensor in ckpt["state_dict"].items():
        np.testing.assert_array_equal(same["state_dict"][key], tensor)
    with pytest.raises(InputError, match="graph=harness: its placement is the UR arm's"):
        read_as(load_checkpoint(deployed["harness_ckpt"]), "fr3")
    with pytest.raises(InputError, match="a model of the UR's six joints only"):
        read_as(read_as(ckpt, "fr3"), "gen3")
