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


def test_a_ur_model_read_on_an_fr3_is_commissioned_on_the_fr3s_healthy_running(
    deployed, record_cfg, tmp_path
):
    """Commissioning a six-joint model read on a seven-joint arm: the arm's residual baseline
    against each joint's UR counterpart's, the operating point matched to the UR validation
    session as the source model reads it; the commissioned model is the FR3's and exports."""
    from robohealth_mj.deploy.commission import commission
    from robohealth_mj.learn.checkpoint import write_checkpoint
    from robohealth_mj.recording.recorder import record_session
    from robohealth_mj.runtime.metadata import read_metadata

    healthy = tmp_path / "fr3_healthy"
    record_session(record_cfg("arm=fr3", "faults=none", "session.duration_s=40"), healthy)
    source = str(deployed["structural_ckpt"])
    write_checkpoint(tmp_path / "read.ckpt", read_as(load_checkpoint(source), "fr3", source))
    record = commission(tmp_path / "read.ckpt", str(healthy), tmp_path / "done")
    done = load_checkpoint(tmp_path / "done" / "best.ckpt")
    assert done["read_as"]["checkpoint"] == source and done["arms"] == ["fr3"]
    shift = np.asarray(done["graph"]["baseline_shift"])
    assert shift.shape[0] == 7 and np.abs(shift).sum() > 0  # the FR3's own baseline
    assert record["operating_point"]["validation_windows"] > 0
    assert len(done["class_offset"]) == 7  # the seven fault classes' offsets
    meta = read_metadata(tmp_path / "done" / "model.onnx")
    assert meta["arm"] == "fr3" and meta["arm_graph"].n_joints == 7
