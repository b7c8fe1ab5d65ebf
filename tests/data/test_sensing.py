"""Sensing profiles: the channels an arm really has, from training through the deployed model."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hydra.utils import instantiate

from robohealth_mj import schema
from robohealth_mj.common.config import compose_config
from robohealth_mj.data.jsonl import node_features
from robohealth_mj.data.sensing import SensingProfile

J = schema.N_JOINTS


def _profile(name: str) -> SensingProfile:
    return instantiate(compose_config("train", [f"sensing={name}"]).sensing)


def test_retrofit_zeroes_exactly_the_joint_channels_it_drops_and_no_sensor_channel():
    """The dropped joint channels go on the joints and on the copies the schema puts on each
    sensor node (else a sensor node would hand the model the motor current back); every sensor
    channel and the kept joint channels pass untouched."""
    assert _profile("full").mask() is None
    mask = _profile("retrofit").mask()
    dropped = [schema.feature_index(n) for n in ("effort", "pos_error", "effort_residual")]
    expected = np.ones((schema.N_NODES, schema.N_FEATURES), np.float32)
    expected[:, dropped] = 0.0
    np.testing.assert_array_equal(mask, expected)
    rng = np.random.default_rng(0)
    state = rng.normal(size=(5, J, len(schema.STATE_FEATURES)))
    sensor = rng.normal(size=(5, J, len(schema.SENSOR_FEATURES)))
    x = node_features(state, sensor)  # the recorder's layout: state on joints and sensors
    kept = x * mask
    np.testing.assert_array_equal(kept[..., schema.SENSOR_CHANNELS], x[..., schema.SENSOR_CHANNELS])
    for name in ("pos", "vel"):
        k = schema.feature_index(name)
        np.testing.assert_array_equal(kept[..., k], x[..., k])
    assert not kept[..., dropped].any()


def test_an_unknown_channel_is_refused_by_name():
    with pytest.raises(ValueError, match=r"sensing odd: joint_channels \['torque'\] unknown"):
        SensingProfile("odd", joint_channels=("pos", "torque"))
    with pytest.raises(ValueError, match=r"sensor_channels \['pos'\] unknown"):
        SensingProfile("odd", sensor_channels=("pos",))


@pytest.mark.slow
def test_a_retrofit_model_never_reads_the_channels_its_arm_lacks(tiny_corpus, tmp_path):
    """Trained with sensing=retrofit, the checkpoint, the evaluation and the exported model all
    keep the profile: the deployed model's outputs do not move when effort, tracking error and
    torque residual do."""
    import onnxruntime as ort

    from robohealth_mj.data.arrays import load_recordings
    from robohealth_mj.deploy.export import export_checkpoint, read_metadata
    from robohealth_mj.learn.checkpoint import graph_from_checkpoint, load_checkpoint
    from robohealth_mj.learn.run import train_and_evaluate as run

    cfg = compose_config(
        "train",
        [
            f"data.train=[{tiny_corpus}/train_*]",
            f"data.evaluate.heldout={tiny_corpus}/heldout",
            "data.evaluate.probe=null",
            "trainer.progress=false",
            "trainer.epochs=1",
            "window=8",
            "graph=harness",
            "sensing=retrofit",
            "variant=anomaly_residual",
            "model.hidden=8",
        ],
    )
    run(cfg, tmp_path / "run")
    ckpt = tmp_path / "run" / "best.ckpt"
    graph = graph_from_checkpoint(load_checkpoint(ckpt))
    assert graph.sensing == "retrofit"
    np.testing.assert_array_equal(graph.channel_mask, _profile("retrofit").mask())
    onnx = export_checkpoint(ckpt, tmp_path / "model.onnx")["path"]
    assert read_metadata(onnx)["sensing"] == "retrofit"
    rec = load_recordings([tiny_corpus / "heldout" / "graphs.jsonl"])
    dropped = [schema.feature_index(n) for n in ("effort", "pos_error", "effort_residual")]
    assert rec.x[:, :J, dropped].any()  # the recording has them; what is learnt from does not
    assert not graph.transform(rec.x)[:, :J][..., dropped].any()
    x = np.ascontiguousarray(np.stack([rec.x[k : k + 8] for k in range(0, 400, 40)]))
    noisy = x.copy()
    for name in ("effort", "pos_error", "effort_residual"):
        noisy[:, :, :J, schema.feature_index(name)] += 50.0
    moved = x.copy()
    moved[:, :, :J, schema.feature_index("vel")] += 0.5
    session = ort.InferenceSession(onnx, providers=["CPUExecutionProvider"])
    out, same, other = (session.run(None, {"x": v})[0] for v in (x, noisy, moved))
    np.testing.assert_allclose(out, same, atol=1e-5)
    assert not np.allclose(out, other, atol=1e-3)  # the channels it keeps still count


def test_stock_reads_the_joints_alone_and_labels_sensor_faults_healthy(stock_deployed):
    """The stock profile: a graph of the six joints, a label set without sensor faults (those
    sessions are healthy on an arm without the sensor), trained, evaluated, exported and run in
    the fleet runtime with outputs that no sensor channel can move."""
    from robohealth_mj.data.arrays import load_recordings
    from robohealth_mj.learn.checkpoint import graph_from_checkpoint, load_checkpoint
    from robohealth_mj.learn.evaluation import evaluate_checkpoint
    from robohealth_mj.runtime.fleet import DECIDED, FleetRuntime
    from robohealth_mj.runtime.metadata import read_metadata

    ckpt = stock_deployed["ckpt"]
    graph = graph_from_checkpoint(load_checkpoint(ckpt))
    assert graph.node_names == schema.JOINT_NAMES and graph.adjacency.shape == (J, J)
    assert graph.classes == ("none", "backlash", "friction", "jam", "struct_weaken")
    heldout = stock_deployed["heldout"]
    rec = load_recordings([heldout])
    sensor_faults = np.isin(rec.fault_class, [5, 6])
    assert sensor_faults.any()  # the session has them; the stock label set does not
    relabelled = graph.relabel(rec)
    assert not np.isin(relabelled.fault_class, [5, 6]).any()
    assert not relabelled.active[sensor_faults].any()
    np.testing.assert_array_equal(
        relabelled.fault_class[~sensor_faults], rec.fault_class[~sensor_faults]
    )
    per_class = evaluate_checkpoint(ckpt, [str(heldout)])["metrics"]["per_class"]
    assert per_class["sensor_drift"]["support"] == per_class["sensor_noise"]["support"] == 0

    onnx = str(stock_deployed["onnx"])
    meta = read_metadata(onnx)
    assert meta["sensing"] == "stock" and json.loads(meta["label_set"]) == list(graph.classes)
    x = rec.x[:64].copy()
    loud = x.copy()
    loud[:, J:, schema.SENSOR_CHANNELS] += 50.0  # a sensor package the stock arm does not have
    probs = []
    for data in (x, loud):
        fleet = FleetRuntime(onnx)
        slot = fleet.register(["arm"])
        for t in range(len(data)):
            r = fleet.step(slot, np.array([t]), np.array([0.05 * (t + 1)]), data[t : t + 1])
        assert r.status[0] == DECIDED
        probs.append(r.probs[0])
    np.testing.assert_allclose(probs[0], probs[1], atol=1e-5)


def test_stock_on_the_harness_is_refused_in_one_line():
    cfg = compose_config("train", ["sensing=stock", "graph=harness"])
    with pytest.raises(ValueError, match="sensing=stock has no sensors"):
        instantiate(cfg.graph).with_sensing(instantiate(cfg.sensing))
