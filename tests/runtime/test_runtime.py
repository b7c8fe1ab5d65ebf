"""Export and the streaming runtime: parity, metadata, decisions equal batch evaluation, invalid
input, the no-model fallback, interleaved streams and on-line detection latency."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import torch

from robohealth_mj import schema
from robohealth_mj.data.arrays import load_recordings
from robohealth_mj.data.windows import make_windows
from robohealth_mj.deploy.alarm_sweep import evaluate_policy, replay_decisions, replay_many
from robohealth_mj.deploy.export import RawInput, export_checkpoint, read_metadata
from robohealth_mj.learn.checkpoint import load_checkpoint, model_from_checkpoint
from robohealth_mj.monitor import main as monitor_main
from robohealth_mj.prognostics.channels import CHANNELS
from robohealth_mj.prognostics.health import MECHANICAL_CLASSES
from robohealth_mj.prognostics.signature import Signatures
from robohealth_mj.runtime.alarms import CLEARED, HELD, RAISED
from robohealth_mj.runtime.fleet import DECIDED, FleetRuntime
from robohealth_mj.runtime.online_eval import OnlineEvaluator
from robohealth_mj.runtime.runtime import HealthDiagnosis, ModelRuntime, decide
from robohealth_mj.runtime.runtime import diagnoses as tick_diagnoses
from robohealth_mj.schema import FaultLabel, GraphSample

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


def test_export_refuses_an_onnx_file_that_fails_its_parity_check(deployed, tmp_path, monkeypatch):
    """The exported graph is checked against PyTorch on held-out windows; here the exporter is
    handed a network whose weights differ slightly, so the check must refuse it and leave
    nothing behind."""
    import copy

    from robohealth_mj.deploy import export as export_module

    real_export = export_module.export_onnx

    def export_a_drifted_copy(model, examples, path, pre=None):
        drifted = copy.deepcopy(model)
        with torch.no_grad():
            for p in drifted.parameters():
                p.add_(0.05 * torch.randn_like(p))
        return real_export(drifted, examples, path, pre=pre)

    monkeypatch.setattr(export_module, "export_onnx", export_a_drifted_copy)
    out = tmp_path / "model.onnx"
    with pytest.raises(RuntimeError, match="ONNX parity check failed"):
        export_checkpoint(deployed["structural_ckpt"], out)
    assert list(tmp_path.iterdir()) == []  # no model, no temporary file, no side data


def test_export_fails_loudly_without_held_out_data(deployed, tmp_path):
    with pytest.raises(FileNotFoundError):
        export_checkpoint(
            deployed["structural_ckpt"], tmp_path / "m.onnx", data=str(tmp_path / "missing")
        )


def test_runtime_on_a_replay_decides_as_batch_evaluation_does(deployed):
    runtime = ModelRuntime(deployed["structural_onnx"])
    assert runtime.describe()["mode"] == "incremental" and runtime.describe()["threads"] == 1
    lines = deployed["heldout"].read_text().splitlines()
    diagnoses = [runtime.process("arm", line) for line in lines]
    assert all(d.valid for d in diagnoses)
    assert all(d.fault_class is None for d in diagnoses[:7])  # warming up
    assert [d.sample_index for d in diagnoses] == [json.loads(x)["sample_index"] for x in lines]
    assert {d.model_id for d in diagnoses} == {runtime.model_id} != {"none"}
    assert {d.stream_id for d in diagnoses} == {"arm"}
    assert all(d.inference_latency_ms > 0 for d in diagnoses[7:])
    ckpt = load_checkpoint(deployed["structural_ckpt"])
    model = model_from_checkpoint(ckpt)
    rec = load_recordings([deployed["heldout"]])
    windows = make_windows(rec, 8)
    x = (rec.x - ckpt["norm_mean"].numpy()) / ckpt["norm_std"].numpy()
    idx = windows.start[:, None] + np.arange(8)
    with torch.no_grad():
        out = model(torch.from_numpy(x[idx]).float())
    faults = right = 0
    for k, end in enumerate(windows.end):
        d = diagnoses[end]
        probs = torch.softmax(out["class_logits"][k], 0).numpy()
        assert d.fault_class == schema.FAULT_CLASSES[int(probs.argmax())]
        assert d.confidence == pytest.approx(float(probs.max()), abs=1e-5)
        np.testing.assert_allclose(list(d.class_probabilities.values()), probs, atol=1e-5)
        if d.fault_present:
            faults += 1
            assert d.localised_joint == schema.JOINT_NAMES[int(out["joint_logits"][k].argmax())]
            right += d.localised_joint == schema.JOINT_NAMES[rec.fault_joint[end]]
        else:
            assert d.fault_class == "none" and d.localised_joint is None
    # the fault path ran: the model calls faults on a good share of the windows, mostly at the
    # faulted joint (three joints carry faults: chance is 1/3)
    assert faults > 300 and right / faults > 0.6


def _alarm_states(fleet: FleetRuntime, x: np.ndarray, streams: int) -> np.ndarray:
    """Stream ``k`` replays ``x`` from offset ``200 k``; ``[ticks, streams, 3]`` of (alarm
    state, alarmed class, alarmed joint) per decided tick (-9 where undecided)."""
    slots = fleet.register([f"s{k}" for k in range(streams)])
    ticks = len(x) - 200 * (streams - 1)
    out = np.full((ticks, streams, 3), -9, np.int64)
    for t in range(ticks):
        r = fleet.step(slots, np.full(streams, t), np.full(streams, 0.05 * (t + 1)),
                       x[200 * np.arange(streams) + t])  # fmt: skip
        decided = r.status == DECIDED
        out[t, decided] = np.stack([r.alarm, r.alarm_class, r.alarm_joint], 1)[decided]
    return out


def test_alarms_raise_hold_and_clear_through_the_fleet_runtime(deployed, deciding_alarm):
    rec = load_recordings([deployed["heldout"]])
    fleet = FleetRuntime(deployed["structural_onnx"], alarm=deciding_alarm)
    states = _alarm_states(fleet, rec.x, 1)[:, 0]
    decided = states[:, 0] >= 0
    state, cls, joint = states[decided].T
    raised = np.flatnonzero(state == RAISED)
    assert len(raised) >= 8 and (state == CLEARED).sum() >= 5
    # the state machine: an alarm is up (with a class and joint) from RAISED until CLEARED
    up = False
    for s, c, j in zip(state.tolist(), cls.tolist(), joint.tolist(), strict=True):
        assert s != HELD or up, "held without an alarm"
        assert s != CLEARED or up, "cleared without an alarm"
        up = (up or s == RAISED) and s != CLEARED
        assert (c > 0 and j >= 0) == up
    # the alarms are right: the class and joint raised are the truth at that tick
    ends = np.flatnonzero(decided)[raised]
    right_class = cls[raised] == rec.fault_class[ends]
    right_joint = joint[raised] == rec.fault_joint[ends]
    assert right_class.mean() >= 0.7 and (right_class & right_joint).mean() >= 0.6
    # each stream keeps its own alarm: interleaved streams alarm exactly as each alone
    together = _alarm_states(FleetRuntime(deployed["structural_onnx"], alarm=deciding_alarm),
                             rec.x, 3)  # fmt: skip
    for k in range(3):
        alone = _alarm_states(FleetRuntime(deployed["structural_onnx"], alarm=deciding_alarm),
                              rec.x[200 * k :], 1)  # fmt: skip
        np.testing.assert_array_equal(together[:, k], alone[: len(together), 0])


def test_a_row_of_an_unknown_slot_is_diagnosed_as_stream_question_mark(deployed):
    runtime = ModelRuntime(deployed["structural_onnx"], threads=2, incremental=False)
    assert runtime.describe()["mode"] == "windowed" and runtime.describe()["threads"] == 2
    fleet = runtime.fleet
    x = load_recordings([deployed["heldout"]]).x[:1]
    (d,) = tick_diagnoses(fleet, fleet.step(np.array([fleet.capacity]), [0], [0.05], x))
    assert (d.stream_id, d.valid, d.sample_index) == ("?", False, 0)
    assert "unknown stream" in d.reason and d.model_id == fleet.model_id


def test_a_decision_refuses_outputs_that_do_not_match_the_labels():
    """A model whose outputs and metadata disagree in length must fail loudly, not label
    probabilities with the wrong names."""
    classes, joints = list(schema.FAULT_CLASSES), list(schema.JOINT_NAMES)
    d = HealthDiagnosis(stamp=0.0, stream_id="s", sample_index=0, valid=True)
    with pytest.raises(ValueError):
        decide(d, np.full(6, 1 / 6), np.zeros(6), 0, 0, -1, classes, joints)
    with pytest.raises(ValueError):
        decide(d, np.full(7, 1 / 7), np.zeros(5), 0, 0, -1, classes, joints)


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


def test_a_sample_that_does_not_parse_is_flagged_at_once_naming_the_field(deployed):
    runtime = ModelRuntime(deployed["structural_onnx"])
    d = runtime.process("arm", "{not json")
    assert (d.valid, d.stream_id, d.stamp, d.sample_index) == (False, "arm", 0.0, None)
    assert d.model_id == runtime.model_id != "none"
    assert d.reason.startswith("<sample>: field '<json>': invalid JSON (")
    bad = GraphSample("r", 0, 0.05, np.zeros((3, 3), np.float32), FaultLabel(), {})
    assert runtime.process("arm", bad).reason == "<sample>: field 'x': shape (3, 3)"
    line = _line(deployed)
    del line["t"]
    assert runtime.process("arm", line).reason.startswith("stream: field 't': ")
    assert runtime.streams == ["arm"]  # flagged samples still name their stream


@pytest.mark.parametrize("model", [None, "missing.onnx", "broken"])
def test_without_a_usable_model_the_runtime_says_so_and_never_echoes_labels(
    deployed, model, tmp_path, caplog
):
    if model == "broken":
        (tmp_path / "broken.onnx").write_bytes(b"not an onnx model")
        model = tmp_path / "broken.onnx"
    runtime = ModelRuntime(model)
    assert (
        f"runtime running without a model ({runtime.problem}): every diagnosis will say 'no "
        "model', fault absent, confidence 0"
    ) in caplog.text
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


def test_monitor_replays_and_evaluates_with_its_alarm_settings(
    deployed, deciding_alarm, deciding_alarm_args, tmp_path, capsys
):
    out = tmp_path / "online.json"
    result = monitor_main(
        [
            f"model={deployed['structural_onnx']}",
            "source=replay",
            f"file={deployed['heldout']}",
            "evaluate=true",
            "decide_every=3",  # the model every third tick; the sweep below replays the same
            *deciding_alarm_args,
            f"out={out}",
        ]
    )
    assert json.loads(out.read_text())["episodes"] == result["episodes"] == 18
    assert result["alarm_policy"]["raise_after"] == deciding_alarm.raise_after
    alarms = result["alarms"]
    assert alarms["episodes"] == result["episodes"]
    assert alarms["detected"] >= 10 and alarms["class_detected"] >= 10
    assert "| episodes of |" in out.with_suffix(".md").read_text()
    printed = capsys.readouterr().out
    assert "arm1:" in printed and "[truth:" in printed and "alarms: detected" in printed
    raised = [line for line in printed.splitlines() if "ALARM RAISED" in line]
    assert len(raised) >= 8 and sum("CLEARED" in line for line in printed.splitlines()) >= 5
    # the alarm sweep replays the same policy over the same decisions to the same figures
    swept = evaluate_policy(replay_decisions(deployed["structural_onnx"], deployed["heldout"], 3),
                            deciding_alarm)  # fmt: skip
    for key in ("alarms", "false_alarms", "settled_healthy_ticks", "online_accuracy"):
        assert swept[key] == result[key], key


def test_recordings_replayed_together_get_the_decisions_each_gets_alone(deployed, tmp_path):
    """``replay_many`` runs one stream per recording in one fleet (how the cross-arm campaign
    counts alarms over three healthy sessions at once): each recording's decisions, classes and
    truth are those it gets replayed alone, a shorter one's included; the probabilities agree to
    float32 rounding (a batch of two runs other kernels than a batch of one)."""
    heldout = Path(deployed["heldout"])
    short = tmp_path / "short" / "graphs.jsonl"
    short.parent.mkdir()
    lines = heldout.read_text().splitlines(keepends=True)
    short.write_text("".join(lines[len(lines) // 3 : len(lines) // 2]))
    together = replay_many(deployed["structural_onnx"], [heldout, short])
    for recording, joint in zip([heldout, short], together, strict=True):
        alone = replay_decisions(deployed["structural_onnx"], recording)
        assert len(joint.truth) == len(alone.truth) and joint.truth == alone.truth
        assert joint.decided.any() and np.array_equal(joint.decided, alone.decided)
        np.testing.assert_allclose(joint.probs, alone.probs, atol=1e-5)
        np.testing.assert_allclose(joint.joint_scores, alone.joint_scores, atol=1e-5)
        decided = alone.decided
        assert np.array_equal(joint.probs[decided].argmax(1), alone.probs[decided].argmax(1))
    assert len(together[1].truth) < len(together[0].truth)


def test_monitor_diagnoses_the_simulator_live(deployed, deciding_alarm_args, tmp_path, capsys):
    """``source=sim``: the simulator's samples straight into the runtime, here with a backlash
    at the elbow held on from the start (a fault the deployed model was trained on)."""
    fault = '"faults=fixed","faults.schedule.fault_class=backlash","faults.schedule.joint=elbow"'
    result = monitor_main(
        [
            f"model={deployed['structural_onnx']}",
            "source=sim",
            "duration_s=6",
            f'sim_overrides=["seed=5",{fault},"faults.schedule.severity=0.9"]',
            "evaluate=true",
            *deciding_alarm_args,
            f"out={tmp_path / 'sim.json'}",
        ]
    )
    assert result["source"] == "sim" and result["ticks"] == 120 and result["episodes"] == 1
    assert result["alarms"]["class_detected"] == 1 and result["alarms"]["joint_detected"] == 1
    assert result["alarms"]["class_latency_s_median"] <= 2.0
    printed = capsys.readouterr().out
    assert "ALARM RAISED backlash @ elbow" in printed and "[truth: backlash @ elbow" in printed


def test_a_diagnosis_serialises_to_sorted_json_that_rebuilds_it():
    d = HealthDiagnosis(stamp=1.5, stream_id="arm", sample_index=30, valid=True,
                        fault_present=True, fault_class="jam", confidence=0.9,
                        class_probabilities={"none": 0.1, "jam": 0.9}, alarm="raised",
                        alarm_class="jam", alarm_joint="elbow")  # fmt: skip
    text = d.to_json()
    assert HealthDiagnosis(**json.loads(text)) == d
    keys = list(json.loads(text))
    assert keys == sorted(keys) and text.startswith(
        '{"accumulated_probabilities": {}, "alarm": "raised"'
    )


def test_monitor_adds_each_session_to_the_arm_health_history(deployed, tmp_path, capsys):
    """``health.state_dir``: each monitored session becomes the arm's per-joint health index,
    kept across runs of the monitor; a worn elbow reads higher than the healthy day before."""
    state = tmp_path / "health"
    fault = '"faults=fixed","faults.schedule.fault_class=backlash","faults.schedule.joint=elbow"'
    days = {0: '"faults=none"', 1: f'{fault},"faults.schedule.severity=0.9"'}
    for day, faults in days.items():
        monitor_main(
            [
                f"model={deployed['structural_onnx']}",
                "source=sim",
                "duration_s=6",
                f'sim_overrides=["seed=5",{faults}]',
                "quiet=true",
                f"health.state_dir={state}",
                f"health.day={day}",
            ]
        )
    sessions = json.loads((state / "arm1.health.json").read_text())["sessions"]
    assert [s["day"] for s in sessions] == [0, 1]
    elbow = schema.JOINT_NAMES.index("elbow")
    assert sessions[1]["index"][elbow] > sessions[0]["index"][elbow] + 0.2
    assert sessions[1]["index"][elbow] == max(sessions[1]["index"])
    printed = capsys.readouterr().out
    assert "health arm1 day 1 elbow:" in printed and "RUL" in printed


def test_monitor_reads_the_index_through_a_fitted_index_file(deployed, tmp_path):
    """``health.calibration``: a fitted index (studies/wear) with a map for the elbow alone; the
    session's elbow index is that map's reading, the other joints the pooled map's. An index that
    reads friction and backlash from the joints' own channels gets them from the session's
    samples: on a healthy arm they read near zero wherever the model names those modes, and so
    do the four modes' signatures."""

    def healthy_day(name: str, index: dict) -> list[float]:
        (tmp_path / f"{name}.json").write_text(json.dumps(index))
        monitor_main(
            [
                f"model={deployed['structural_onnx']}",
                "source=sim",
                "duration_s=4",
                'sim_overrides=["seed=5","faults=none"]',
                "quiet=true",
                f"health.state_dir={tmp_path / name}",
                "health.day=0",
                f"health.calibration={tmp_path / f'{name}.json'}",
            ]
        )
        state = json.loads((tmp_path / name / "arm1.health.json").read_text())
        return state["sessions"][0]["index"]

    elbow = schema.JOINT_NAMES.index("elbow")
    index = healthy_day("joint", {
        "index_model": {"raw": "moving", "calibration": "joint", "monotone": True},
        "x": [0.0, 1.0], "y": [0.0, 1.0],
        "cells": {f"j{elbow}": {"x": [0.0, 1.0], "y": [0.5, 0.5]}},
    })  # fmt: skip
    assert index[elbow] == 0.5 and max(np.delete(index, elbow)) < 0.5
    read = healthy_day("channel", {
        "index_model": {"raw": "channel", "calibration": "pooled", "monotone": False},
        "x": [0.0, 1.0], "y": [0.0, 1.0], "cells": {},
        "channel_scales": [[10.0] * 6, [0.01] * 6],
    })  # fmt: skip
    assert np.isfinite(read).all() and max(read) < 0.2
    c, m = len(CHANNELS), len(MECHANICAL_CLASSES)
    response = np.zeros((m, c, 6, 4))
    response[:, CHANNELS.index("friction"), :, 0] = 10.0  # every mode: 10 N m per unit severity
    signed = healthy_day("signature", {
        "index_model": {"raw": "signature", "calibration": "pooled", "monotone": False},
        "x": [0.0, 1.0], "y": [0.0, 1.0], "cells": {}, "channel_scales": [[10.0] * 6, [0.01] * 6],
        "signatures": Signatures(np.zeros((c, 6, 3)), np.full((c, 6), 0.5), response,
                                 np.ones((m, c), bool), detect=16.0).to_json(),
    })  # fmt: skip
    assert np.isfinite(signed).all() and max(signed) < 0.2


@pytest.mark.parametrize(
    ("extra", "named"),
    [
        ([], "health.day"),
        (["health.day=0", "health.min_sessions=1"], "health.min_sessions"),
        (["health.day=0", "health.min_sessions=11"], "health.min_sessions"),
        (["health.day=0", "health.floor=0.9"], "health.floor"),
    ],
)
def test_monitor_health_settings_that_cannot_work_are_one_line(
    deployed, tmp_path, capsys, extra, named
):
    with pytest.raises(SystemExit) as exc:
        monitor_main(
            [
                f"model={deployed['structural_onnx']}",
                "source=sim",
                "duration_s=2",
                f"health.state_dir={tmp_path}",
                *extra,
            ]
        )
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and named in err[0], err
