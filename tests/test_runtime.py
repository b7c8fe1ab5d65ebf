"""Export and the streaming runtime: parity, metadata, decisions equal batch evaluation, invalid
input, the no-model fallback, interleaved streams and on-line detection latency."""

from __future__ import annotations

import json

import numpy as np
import pytest
import torch

from robohealth_mj import schema
from robohealth_mj.data.arrays import load_recordings
from robohealth_mj.data.windows import make_windows
from robohealth_mj.learn.checkpoint import load_checkpoint, model_from_checkpoint
from robohealth_mj.monitor import main as monitor_main
from robohealth_mj.runtime.export import RawInput, export_checkpoint, read_metadata
from robohealth_mj.runtime.online_eval import OnlineEvaluator
from robohealth_mj.runtime.runtime import HealthDiagnosis, ModelRuntime
from robohealth_mj.schema import FaultLabel

F = schema.N_FEATURES


@pytest.mark.parametrize("graph", ["structural", "harness"])
def test_export_matches_pytorch_on_raw_windows_and_carries_metadata(deployed, graph):
    ckpt = load_checkpoint(deployed[f"{graph}_ckpt"])
    meta = read_metadata(deployed[f"{graph}_onnx"])
    assert meta["node_names"] == list(schema.NODE_NAMES)
    assert meta["feature_names"] == list(schema.FEATURE_NAMES)
    assert meta["window"] == 8 and meta["schema_version"] == schema.SCHEMA_VERSION
    assert meta["classes"] == list(schema.FAULT_CLASSES)
    assert meta["joints"] == list(schema.JOINT_NAMES)
    assert meta["data_fingerprint"] == ckpt["data_fingerprint"]
    assert len(meta["checkpoint_fingerprint"]) == 16 and meta["graph"] == graph
    assert float(meta["parity_error"]) <= 1e-4
    import onnxruntime as ort

    session = ort.InferenceSession(str(deployed[f"{graph}_onnx"]))
    assert session.get_inputs()[0].shape[1:] == [8, 12, F]  # raw schema windows, dynamic batch
    rec = load_recordings([deployed["heldout"]])
    x = torch.from_numpy(rec.x[np.arange(100, 108)][None].repeat(3, 0))
    model = model_from_checkpoint(ckpt)
    graph_spec = ckpt["graph"]
    pre = RawInput(
        ckpt["norm_mean"],
        ckpt["norm_std"],
        None if graph_spec["coupling"] is None else np.array(graph_spec["coupling"]),
    )
    with torch.no_grad():
        expected = model(pre(x))["class_logits"].numpy()
    got = session.run(None, {"x": x.numpy()})[0]
    np.testing.assert_allclose(got, expected, atol=1e-4)


def test_export_fails_loudly_without_held_out_data(deployed, tmp_path):
    with pytest.raises(FileNotFoundError):
        export_checkpoint(
            deployed["structural_ckpt"], tmp_path / "m.onnx", data=str(tmp_path / "missing")
        )


def test_runtime_on_a_replay_decides_as_batch_evaluation_does(deployed):
    runtime = ModelRuntime(deployed["structural_onnx"])
    lines = deployed["heldout"].read_text().splitlines()
    diagnoses = [runtime.process("arm", line) for line in lines]
    assert all(d.valid for d in diagnoses)
    assert all(d.fault_class is None for d in diagnoses[:7])  # warming up
    ckpt = load_checkpoint(deployed["structural_ckpt"])
    model = model_from_checkpoint(ckpt)
    rec = load_recordings([deployed["heldout"]])
    windows = make_windows(rec, 8)
    x = (rec.x - ckpt["norm_mean"].numpy()) / ckpt["norm_std"].numpy()
    idx = windows.start[:, None] + np.arange(8)
    with torch.no_grad():
        out = model(torch.from_numpy(x[idx]).float())
    for k, end in enumerate(windows.end):
        d = diagnoses[end]
        probs = torch.softmax(out["class_logits"][k], 0).numpy()
        assert d.fault_class == schema.FAULT_CLASSES[int(probs.argmax())]
        np.testing.assert_allclose(list(d.class_probabilities.values()), probs, atol=1e-5)
        if d.fault_present:
            assert d.localised_joint == schema.JOINT_NAMES[int(out["joint_logits"][k].argmax())]


def _line(deployed, k: int = 0) -> dict:
    return json.loads(deployed["heldout"].read_text().splitlines()[k])


@pytest.mark.parametrize(
    "corrupt, reason",
    [
        (lambda s: s.update(schema_version="0.1"), "schema_version"),
        (lambda s: s.update(nodes=s["nodes"][::-1]), "nodes"),
        (lambda s: s["x"][7].__setitem__(3, float("nan")), "NaN or Inf"),
        (lambda s: s.update(t=0.0), "time went backwards"),
        (lambda s: s.update(sample_index=s["sample_index"] + 5), "gap in sample_index"),
        (lambda s: s.pop("x"), "missing"),
    ],
)
def test_each_invalid_sample_yields_a_flagged_diagnosis(deployed, corrupt, reason):
    runtime = ModelRuntime(deployed["structural_onnx"])
    for k in range(10):
        assert runtime.process("arm", _line(deployed, k)).valid
    bad = _line(deployed, 10)
    corrupt(bad)
    d = runtime.process("arm", bad)
    assert not d.valid and reason in d.reason
    assert runtime.process("arm", "{not json").valid is False


@pytest.mark.parametrize("model", [None, "missing.onnx", "broken"])
def test_without_a_usable_model_the_runtime_says_so_and_never_echoes_labels(
    deployed, model, tmp_path, caplog
):
    if model == "broken":
        (tmp_path / "broken.onnx").write_bytes(b"not an onnx model")
        model = tmp_path / "broken.onnx"
    runtime = ModelRuntime(model)
    assert "without a model" in caplog.text
    lines = deployed["heldout"].read_text().splitlines()
    faulted = [k for k, line in enumerate(lines) if json.loads(line)["fault"]["active"]]
    assert faulted
    for line in lines[: faulted[0] + 20]:
        d = runtime.process("arm", line)
        assert d.valid and not d.fault_present and d.confidence == 0.0
        assert d.fault_class is None and d.localised_joint is None
        assert d.model_id == "none"
    assert "no model" in d.reason or "unusable" in d.reason


def test_interleaved_streams_keep_their_own_windows(deployed):
    lines = deployed["heldout"].read_text().splitlines()
    alone = ModelRuntime(deployed["structural_onnx"])
    solo = [alone.process("a", line) for line in lines[:60]]
    together = ModelRuntime(deployed["structural_onnx"])
    other = [json.loads(line) for line in lines[300:360]]
    mixed = []
    for k in range(60):
        assert together.submit("a", lines[k]) is None
        assert together.submit("b", other[k]) is None
        ticked = {d.stream_id: d for d in together.tick()}  # one batch for both streams
        mixed.append(ticked["a"])
    for s, m in zip(solo, mixed, strict=True):
        assert s.fault_class == m.fault_class and s.sample_index == m.sample_index
        if s.fault_class is not None:
            np.testing.assert_allclose(
                list(s.class_probabilities.values()),
                list(m.class_probabilities.values()),
                atol=1e-5,
            )


def _diag(cls: str | None, joint: str | None = None) -> HealthDiagnosis:
    return HealthDiagnosis(
        stamp=0.0,
        stream_id="s",
        sample_index=0,
        valid=True,
        fault_class=cls,
        fault_present=cls not in (None, "none"),
        localised_joint=joint,
    )


def test_online_evaluation_measures_detection_latency_on_a_scripted_stream():
    healthy = FaultLabel()
    jam = FaultLabel("jam", "elbow", 0.6, True)
    drift = FaultLabel("sensor_drift", "wrist_1", 0.3, True)
    script = (
        [(healthy, _diag(None))] * 3  # warming up
        + [(healthy, _diag("none"))] * 4
        + [(healthy, _diag("jam", "elbow"))]  # one false alarm
        + [(jam, _diag("none"))] * 5  # 5 ticks to the right class
        + [(jam, _diag("jam", "wrist_1"))] * 2  # 2 more to the right joint
        + [(jam, _diag("jam", "elbow"))] * 3
        + [(healthy, _diag("none"))] * 2
        + [(drift, _diag("none"))] * 6  # never detected
    )
    ev = OnlineEvaluator(tick_s=0.05)
    for truth, d in script:
        ev.update(truth, d)
    r = ev.result()
    assert r["episodes"] == 2 and r["ticks"] == len(script)
    jam_lat = r["detection_latency_by_class"]["jam"]
    assert jam_lat["class_latency_ticks_mean"] == 5 and jam_lat["joint_latency_ticks_mean"] == 7
    assert jam_lat["class_latency_s_mean"] == pytest.approx(0.25)
    drift_lat = r["detection_latency_by_class_and_severity"]["sensor_drift@0.3"]
    assert drift_lat["class_detected"] == 0 and drift_lat["class_latency_ticks_mean"] is None
    assert r["false_positive_rate"] == pytest.approx(1 / 7)
    assert r["localisation_accuracy"] == pytest.approx(3 / 16)
    decided = len(script) - 3
    # right class: 4 healthy, 2 + 3 jam (joint aside), 2 healthy
    assert r["online_accuracy"] == pytest.approx((4 + 2 + 3 + 2) / decided)


def test_monitor_replays_and_evaluates_with_its_alarm_settings(deployed, tmp_path, capsys):
    out = tmp_path / "online.json"
    result = monitor_main(
        [
            f"model={deployed['structural_onnx']}",
            "source=replay",
            f"file={deployed['heldout']}",
            "evaluate=true",
            "alarm.raise_after=2",
            "alarm.min_confidence=0.3",
            f"out={out}",
        ]
    )
    assert json.loads(out.read_text())["episodes"] == result["episodes"] > 0
    assert result["alarm_policy"]["raise_after"] == 2
    assert result["alarms"]["episodes"] == result["episodes"]
    assert "| episodes of |" in out.with_suffix(".md").read_text()
    printed = capsys.readouterr().out
    assert "arm1:" in printed and "[truth:" in printed and "alarms: detected" in printed
