"""ROS 2 bags: round trip, ROS 2 message definitions, clear errors for bad bags, the monitor's
diagnoses out, and one-line errors (exit status 2) for every kind of bad file."""

from __future__ import annotations

import contextlib
import io
import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from robohealth_mj import schema
from robohealth_mj.bag import main as bag_main
from robohealth_mj.bags.messages import MessageFactory, stamp_ns, typestore
from robohealth_mj.bags.reader import BagError, bag_manifest, read_bag_samples
from robohealth_mj.bags.topics import BagTopics
from robohealth_mj.bags.writer import BagWriter, write_bag
from robohealth_mj.common.config import compose_config
from robohealth_mj.data.arrays import load_recordings
from robohealth_mj.data.read import read_samples
from robohealth_mj.dataset import main as dataset_main
from robohealth_mj.learn.checkpoint import checkpoint_digest
from robohealth_mj.monitor import main as monitor_main
from robohealth_mj.runtime.runtime import HealthDiagnosis, ModelRuntime


@pytest.fixture(scope="module")
def bag(deployed, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("bags") / "heldout_bag"
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        assert bag_main(["write", str(deployed["heldout"].parent), "--out", str(out)]) == 0
    (out.parent / "printed.txt").write_text(printed.getvalue())
    return out


def test_jsonl_to_bag_to_samples_is_the_identity(deployed, bag):
    a, b = list(read_samples(deployed["heldout"])), list(read_samples(bag))
    assert len(a) == len(b) > 100
    printed = (bag.parent / "printed.txt").read_text()
    assert printed.startswith(f"wrote {len(a)} samples from ")
    # the session manifest rides along in the bag's metadata, as sorted JSON (same bytes)
    manifest = json.loads((deployed["heldout"].parent / "manifest.json").read_text())
    assert bag_manifest(bag) == manifest
    info = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert info["storage_identifier"] == "mcap" and info["version"] == 8  # what Humble reads
    custom = info["custom_data"]
    assert custom["robohealth_mj.manifest"] == json.dumps(manifest, sort_keys=True)
    assert custom["robohealth_mj.schema_version"] == schema.SCHEMA_VERSION == "3.0"
    assert not bag.with_name(bag.name + ".partial").exists()
    for x, y in zip(a, b, strict=True):
        np.testing.assert_allclose(y.x, x.x, rtol=0, atol=1e-6)
        assert (x.recording_run_id, x.sample_index, x.fault, x.segment) == (
            y.recording_run_id, y.sample_index, y.fault, y.segment,
        )  # fmt: skip
        assert y.t == pytest.approx(x.t, abs=1e-9)
    ra, rb = load_recordings([deployed["heldout"]]), load_recordings([bag])
    np.testing.assert_array_equal(ra.x, rb.x)
    np.testing.assert_array_equal(ra.fault_class, rb.fault_class)


def test_the_bag_is_standard_rosbag2_with_ros2_message_definitions(deployed, bag):
    import yaml
    from rosbags.rosbag2 import Reader

    info = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert info["storage_identifier"] == "mcap" and info["version"] >= 8
    manifest = json.loads(info["custom_data"]["robohealth_mj.manifest"])
    assert manifest["recording_run_id"] == next(read_samples(deployed["heldout"])).recording_run_id
    store = typestore()  # ROS 2 Humble's definitions
    expected = BagTopics.load().sample_topics()
    with Reader(bag) as reader:
        assert {c.topic: c.msgtype for c in reader.connections} == expected
        for conn in reader.connections:  # definitions embedded for readers without ROS
            assert conn.msgdef.data.strip() and conn.msgtype.split("/")[0] in (
                "sensor_msgs", "std_msgs", "diagnostic_msgs",
            )  # fmt: skip
        count = 0
        for conn, stamp, raw in reader.messages():
            msg = store.deserialize_cdr(raw, conn.msgtype)
            assert bytes(store.serialize_cdr(msg, conn.msgtype)) == bytes(raw)  # exact CDR
            header = getattr(msg, "header", None)
            if header is not None:
                assert header.stamp.sec * 10**9 + header.stamp.nanosec == stamp
            count += 1
    assert count == len(expected) * len(list(read_samples(bag)))


def test_a_bag_is_written_to_the_topics_it_is_given(deployed, tmp_path):
    from rosbags.rosbag2 import Reader

    samples = list(read_samples(deployed["heldout"]))[:5]
    topics = BagTopics.load(joint_states="/arm7/joint_states", imu="/arm7/{joint}/imu")
    assert write_bag(samples, tmp_path / "ns", topics=topics) == 5
    with Reader(tmp_path / "ns") as reader:
        got = {c.topic: c.msgtype for c in reader.connections}
        assert got == topics.sample_topics() and "/arm7/elbow/imu" in got
    assert bag_manifest(tmp_path / "ns") is None  # no manifest given, none written
    assert write_bag(samples, tmp_path / "m", manifest={"seed": 3, "run": "x"}) == 5
    info = yaml.safe_load((tmp_path / "m" / "metadata.yaml").read_text())
    stored = info["rosbag2_bagfile_information"]["custom_data"]["robohealth_mj.manifest"]
    assert stored == '{"run": "x", "seed": 3}'  # sorted keys: the same manifest, the same bytes
    assert len(list(read_bag_samples(tmp_path / "ns", topics))) == 5


def test_a_bag_is_whole_or_absent(deployed, tmp_path):
    """Written into ``<out>.partial`` and renamed on a clean close; a failure leaves nothing,
    and a partial left by an earlier crash is cleared before writing."""
    samples = list(read_samples(deployed["heldout"]))[:3]
    out, partial = tmp_path / "b", tmp_path / "b.partial"
    partial.mkdir()
    (partial / "junk.mcap").write_bytes(b"from a crashed run")
    with pytest.raises(RuntimeError, match="stop"), BagWriter(out) as writer:
        writer.write_sample(samples[0])
        assert partial.is_dir() and not (partial / "junk.mcap").exists() and not out.exists()
        raise RuntimeError("stop")
    assert not out.exists() and not partial.exists()
    assert write_bag(samples, out) == 3 and out.is_dir() and not partial.exists()
    with pytest.raises(FileExistsError, match=f"{out} exists; choose another bag directory"):
        BagWriter(out)


def _write_edited(samples, out: Path, edit) -> None:
    """A bag of ``samples`` where ``edit(topic, k, raw)`` returns the bytes to write (None to
    drop the message) and may move its stamp by returning ``(raw, stamp)``."""
    from rosbags.rosbag2 import StoragePlugin, Writer

    store = typestore()
    factory = MessageFactory(store)
    topics = BagTopics.load()
    with Writer(out, version=8, storage_plugin=StoragePlugin.MCAP) as writer:
        conns = {}
        for k, s in enumerate(samples):
            for topic, msg in factory.sample_messages(s, topics):
                raw = store.serialize_cdr(msg, msg.__msgtype__)
                got = edit(topic, k, raw)
                if got is None:
                    continue
                raw, stamp = got if isinstance(got, tuple) else (got, stamp_ns(s.t))
                if topic not in conns:
                    conns[topic] = writer.add_connection(topic, msg.__msgtype__, typestore=store)
                writer.write(conns[topic], stamp, raw)


ELBOW_VIB = "/sensors/elbow/vibration"


@pytest.mark.parametrize(
    "edit, message",
    [
        (lambda topic, k, raw: None if topic == "/sensors/elbow/imu" else raw,
         "topic '/sensors/elbow/imu' (sensor_msgs/msg/Imu) is missing"),
        (lambda topic, k, raw: None if (topic, k) == ("/sensors/wrist_1/vibration", 7) else raw,
         "topic '/sensors/wrist_1/vibration' at stamp 0.400000 s: message missing"),
        (lambda topic, k, raw: raw[:12] if (topic, k) == ("/joint_states", 5) else raw,
         "topic '/joint_states' at stamp 0.300000 s: malformed message"),
        (lambda topic, k, raw: (raw, stamp_ns(0.325)) if (topic, k) == (ELBOW_VIB, 5) else raw,
         "no '/joint_states' message at that stamp (late, early or stray)"),
    ],
    ids=["missing topic", "gap", "malformed", "late"],
)  # fmt: skip
def test_a_bad_bag_names_its_topic_and_stamp(deployed, tmp_path, edit, message):
    samples = list(read_samples(deployed["heldout"]))[:20]
    out = tmp_path / "bad"
    _write_edited(samples, out, edit)
    with pytest.raises(BagError, match=message.replace("(", r"\(").replace(")", r"\)")):
        list(read_bag_samples(out))
    assert dataset_main(["summarize", str(out)]) == 2


def _diagnoses(path: Path) -> list[tuple]:
    """``(stamp, level, message, fault_class, joint, alarm, confidence)`` per /health_diagnosis."""
    from rosbags.rosbag2 import Reader

    store = typestore()
    with Reader(path) as reader:
        conns = [c for c in reader.connections if c.topic == "/health_diagnosis"]
        out = []
        for _, stamp, raw in reader.messages(connections=conns):
            status = store.deserialize_cdr(raw, conns[0].msgtype).status[0]
            values = {kv.key: kv.value for kv in status.values}
            out.append((stamp, int(status.level), status.message, values["fault_class"],
                        values["joint"], values["alarm"], values["confidence"]))  # fmt: skip
        return out


OK, WARN, ERROR = 0, 1, 2  # diagnostic_msgs/DiagnosticStatus levels


def test_diagnosis_levels_follow_the_alarm(tmp_path):
    """ERROR while an alarm is up; WARN for a fault decided without one or an invalid sample;
    OK for healthy or undecided ticks (the README's table)."""

    def diag(**kw) -> HealthDiagnosis:
        return HealthDiagnosis(**{"stamp": 0.05 * (len(cases) + 1), "stream_id": "arm",
                                  "sample_index": len(cases), "valid": True, **kw})  # fmt: skip

    cases: list[tuple[HealthDiagnosis, int, str]] = []
    for kw, level, message in [
        ({"fault_class": "none", "confidence": 0.9}, OK, "healthy"),
        ({"fault_class": None, "reason": "warming up"}, OK, "no decision: warming up"),
        ({"fault_class": "jam", "fault_present": True, "localised_joint": "elbow"}, WARN,
         "jam @ elbow (no alarm)"),
        ({"valid": False, "reason": "NaN"}, WARN, "invalid sample: NaN"),
        ({"fault_class": "jam", "fault_present": True, "alarm": "raised", "alarm_class": "jam",
          "alarm_joint": "elbow"}, ERROR, "ALARM jam @ elbow (raised)"),
        ({"fault_class": "none", "alarm": "held", "alarm_class": "jam", "alarm_joint": "elbow"},
         ERROR, "ALARM jam @ elbow (held)"),
    ]:  # fmt: skip
        cases.append((diag(**kw), level, message))
    with BagWriter(tmp_path / "levels") as writer:
        for d, _, _ in cases:
            writer.write_diagnosis(d, list(schema.FAULT_CLASSES), list(schema.JOINT_NAMES))
    got = _diagnoses(tmp_path / "levels")
    assert [(g[1], g[2]) for g in got] == [(level, message) for _, level, message in cases]


def test_a_diagnosis_message_carries_every_field_as_key_values(tmp_path):
    from rosbags.rosbag2 import Reader

    classes, joints = list(schema.FAULT_CLASSES), list(schema.JOINT_NAMES)
    probs = dict(zip(classes, [0.01, 0.02, 0.03, 0.9, 0.02, 0.01, 0.01], strict=True))
    scores = dict(zip(joints, [0.1, 0.2, 0.8, 0.3, 0.2, 0.1], strict=True))
    alarmed = HealthDiagnosis(
        stamp=12.5, stream_id="arm7", sample_index=250, valid=True, fault_present=True,
        fault_class="jam", class_probabilities=probs, joint_scores=scores,
        localised_joint="elbow", confidence=0.9, model_id="m-1", alarm="held",
        alarm_class="jam", alarm_joint="elbow",
    )  # fmt: skip
    invalid = HealthDiagnosis(stamp=12.55, stream_id="arm7", sample_index=None, valid=False,
                              model_id="m-1", reason="x: NaN")  # fmt: skip
    pushed = HealthDiagnosis(stamp=12.6, stream_id="arm7", sample_index=252, valid=True,
                             model_id="m-1", contact=True, contact_joint="wrist_2")  # fmt: skip
    with BagWriter(tmp_path / "kv") as writer:
        writer.write_diagnosis(alarmed, classes, joints)
        writer.write_diagnosis(invalid, classes, joints)
        writer.write_diagnosis(pushed, classes, joints)
    store = typestore()
    with Reader(tmp_path / "kv") as reader:
        messages = [(stamp, store.deserialize_cdr(raw, conn.msgtype))
                    for conn, stamp, raw in reader.messages()]  # fmt: skip
    assert [stamp for stamp, _ in messages] == [stamp_ns(12.5), stamp_ns(12.55), stamp_ns(12.6)]
    first, second, third = (m.status[0] for _, m in messages)
    assert (first.name, first.hardware_id) == ("health_diagnosis", "m-1")
    assert {kv.key: kv.value for kv in first.values} == {
        "fault_class": "jam", "joint": "elbow", "confidence": "0.9000", "alarm": "held",
        "alarm_class": "jam", "alarm_joint": "elbow", "contact_joint": "", "valid": "true",
        "sample_index": "250",
        "p.none": "0.0100", "p.backlash": "0.0200", "p.friction": "0.0300", "p.jam": "0.9000",
        "p.struct_weaken": "0.0200", "p.sensor_drift": "0.0100", "p.sensor_noise": "0.0100",
        "score.shoulder_pan": "0.1000", "score.shoulder_lift": "0.2000", "score.elbow": "0.8000",
        "score.wrist_1": "0.3000", "score.wrist_2": "0.2000", "score.wrist_3": "0.1000",
    }  # fmt: skip
    values = {kv.key: kv.value for kv in second.values}
    assert values["valid"] == "false" and values["sample_index"] == ""
    assert values["fault_class"] == values["joint"] == ""
    assert values["alarm_class"] == values["alarm_joint"] == "" and values["alarm"] == "none"
    assert values["p.jam"] == "0.0000" and values["score.elbow"] == "0.0000"
    assert (third.level, third.message) == (2, "CONTACT @ wrist_2")  # a push is an error
    assert {kv.key: kv.value for kv in third.values}["contact_joint"] == "wrist_2"


@pytest.fixture(scope="module")
def diagnosed(deployed, deciding_alarm_args, bag, tmp_path_factory) -> dict[str, Path]:
    """The monitor's replays of the held-out JSONL and of its bag, each written to a bag."""
    root = tmp_path_factory.mktemp("diagnosed")
    out = {"jsonl": root / "from_jsonl", "bag": root / "from_bag"}
    for source, target in ((deployed["heldout"], out["jsonl"]), (bag, out["bag"])):
        monitor_main([f"model={deployed['structural_onnx']}", "source=replay", f"file={source}",
                      "quiet=true", f"bag_out={target}", *deciding_alarm_args])  # fmt: skip
    return out


def test_monitor_replays_a_bag_and_writes_its_diagnoses_beside_the_topics(
    deployed, deciding_alarm, bag, diagnosed
):
    from rosbags.rosbag2 import Reader

    from_jsonl, from_bag = _diagnoses(diagnosed["jsonl"]), _diagnoses(diagnosed["bag"])
    assert len(from_bag) == len(list(read_samples(bag))) and from_jsonl == from_bag
    # the levels are the runtime's alarms: ERROR exactly while one is up (the runtime run as
    # the monitor runs it, the model every decide_every-th tick)
    every = compose_config("monitor", []).decide_every
    runtime = ModelRuntime(deployed["structural_onnx"], alarm=deciding_alarm, decide_every=every)
    expected = []
    for sample in read_samples(deployed["heldout"]):
        d = runtime.process("arm1", sample)
        expected.append(ERROR if d.alarm_class else WARN if d.fault_present else OK)
    levels = [d[1] for d in from_bag]
    assert levels == expected
    assert levels.count(ERROR) > 100 and levels.count(WARN) > 10 and levels.count(OK) > 100
    with Reader(diagnosed["bag"]) as reader:
        assert {c.topic for c in reader.connections} >= set(BagTopics.load().sample_topics())


def test_bag_info_lists_topics_types_counts_and_the_manifest(bag, diagnosed, capsys):
    n = len(list(read_samples(bag)))
    assert bag_main(["info", str(bag)]) == 0
    lines = capsys.readouterr().out.splitlines()
    topics = BagTopics.load().sample_topics()
    assert lines[0].startswith(f"{bag}: {n * len(topics)} messages")
    rows = {line.split()[0]: line.split()[1:] for line in lines[1:-1]}
    assert rows == {topic: [kind, str(n)] for topic, kind in topics.items()}
    assert lines[-1].startswith("  manifest: run ur5e-s99-") and lines[-1].endswith("seed 99")
    assert bag_main(["info", str(diagnosed["bag"])]) == 0
    out = capsys.readouterr().out
    assert "/health_diagnosis" in out and f"diagnostic_msgs/msg/DiagnosticArray {n}" in " ".join(
        out.split()
    )
    assert bag_main(["info", str(bag.parent)]) == 2  # not a bag: one line, status 2
    assert "not a rosbag2 directory" in capsys.readouterr().err


def test_bag_plot_draws_truth_and_alarms_on_one_timeline(diagnosed, tmp_path):
    from PIL import Image

    png = tmp_path / "timeline.png"
    assert bag_main(["plot", str(diagnosed["bag"]), "--out", str(png)]) == 0
    image = np.asarray(Image.open(png).convert("RGB")).astype(int)
    assert image.shape == (572, 1210, 3)

    def share(rows: slice, rgb: tuple[float, float, float]) -> float:
        """Share of the pixels in ``rows`` painted in a class's band colour (alpha 0.8)."""
        target = np.round((0.8 * np.array(rgb) + 0.2) * 255)
        return float((np.abs(image[rows] - target).max(axis=-1) <= 3).mean())

    truth_row, alarm_row = slice(60, 180), slice(210, 320)
    backlash, jam = (1.0, 0.498, 0.055), (0.839, 0.153, 0.157)  # tab10 colours 1 and 3
    for colour in (backlash, jam):
        assert share(truth_row, colour) > 0.02 and share(alarm_row, colour) > 0.02
    # a bag whose diagnoses are missing cannot be plotted: one line, status 2
    assert bag_main(["plot", str(tmp_path / "nothing"), "--out", str(png)]) == 2


def test_training_on_bags_equals_training_on_their_jsonl(deployed, bag, tmp_path):
    from robohealth_mj.common.config import compose_config
    from robohealth_mj.learn.run import train_and_evaluate as run

    names = ("train_1", "train_2", "train_3")
    bags = [tmp_path / f"{name}_bag" for name in names]
    for name, out in zip(names, bags, strict=True):
        assert bag_main(["write", str(deployed["root"] / name), "--out", str(out)]) == 0
    jsonl = [deployed["root"] / name for name in names]
    results = []
    for train, heldout in ((bags, bag), (jsonl, deployed["heldout"])):
        cfg = compose_config(
            "train",
            [f"data.train=[{','.join(map(str, train))}]", f"data.evaluate.heldout={heldout}",
             "data.evaluate.probe=null", "trainer.epochs=1", "trainer.progress=false",
             "model.hidden=8", "window=8", "variant=mlp"],
        )  # fmt: skip
        results.append(run(cfg, tmp_path / f"run{len(results)}")["heldout"]["metrics"])
    assert results[0]["accuracy"] == results[1]["accuracy"]
    assert results[0]["localisation_accuracy"] == results[1]["localisation_accuracy"]


def _python(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", *args], capture_output=True, text=True, timeout=300
    )


def _one_line_error(proc: subprocess.CompletedProcess, *needles: str) -> None:
    lines = [line for line in proc.stderr.splitlines() if line.strip() and "Warning" not in line]
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr, proc.stderr
    assert len(lines) == 1, proc.stderr
    for needle in needles:
        assert needle in lines[0], lines[0]


@pytest.fixture(scope="module")
def bad_files(deployed, tmp_path_factory) -> dict[str, Path]:
    import onnx
    import torch

    root = tmp_path_factory.mktemp("bad")
    good = deployed["structural_ckpt"].read_bytes()
    files = {
        "empty_ckpt": root / "empty.ckpt",
        "truncated_ckpt": root / "truncated.ckpt",
        "tampered_ckpt": root / "tampered.ckpt",
        "unchecked_ckpt": root / "unchecked.ckpt",
        "schema_ckpt": root / "schema.ckpt",
        "topology_ckpt": root / "topology.ckpt",
        "not_onnx": root / "not.onnx",
        "shape_onnx": root / "shape.onnx",
        "empty_recording": root / "empty" / "graphs.jsonl",
        "no_recording": root / "nothing",
        "other_arm": root / "ur3e" / "graphs.jsonl",
    }
    files["empty_ckpt"].write_bytes(b"")
    files["truncated_ckpt"].write_bytes(good[: len(good) // 2])
    tampered = bytearray(good)
    middle = len(tampered) // 2
    tampered[middle : middle + 64] = b"\x00" * 64
    files["tampered_ckpt"].write_bytes(bytes(tampered))
    ckpt = torch.load(deployed["structural_ckpt"], weights_only=True)
    del ckpt["sha256"]  # the checksum removed, the rest intact
    torch.save(ckpt, files["unchecked_ckpt"])
    ckpt = torch.load(deployed["structural_ckpt"], weights_only=True)
    ckpt["schema"] = {**ckpt["schema"], "version": "1.0"}
    ckpt["sha256"] = checkpoint_digest(ckpt)  # a sound file, written for another schema
    torch.save(ckpt, files["schema_ckpt"])
    ckpt = torch.load(deployed["structural_ckpt"], weights_only=True)
    ckpt["schema"] = {**ckpt["schema"], "edges": ckpt["schema"]["edges"][:-1]}
    ckpt["sha256"] = checkpoint_digest(ckpt)
    torch.save(ckpt, files["topology_ckpt"])
    files["not_onnx"].write_bytes(b"this is not a model")
    proto = onnx.load(str(deployed["structural_onnx"]))
    proto.graph.input[0].type.tensor_type.shape.dim[2].dim_value = 10
    onnx.save(proto, str(files["shape_onnx"]))
    files["empty_recording"].parent.mkdir()
    files["empty_recording"].write_text("")
    files["no_recording"].mkdir()
    # the held-out session as its manifest would say were it a UR3e's
    files["other_arm"].parent.mkdir()
    shutil.copy(deployed["heldout"], files["other_arm"])
    manifest = json.loads((deployed["heldout"].parent / "manifest.json").read_text())
    manifest["arm_ratings"]["arm"] = "ur3e"
    (files["other_arm"].parent / "manifest.json").write_text(json.dumps(manifest))
    return files


@pytest.mark.parametrize(
    "key, command, needles",
    [
        ("empty_ckpt", "evaluate ckpt={f} data={heldout}", ["empty.ckpt", "empty file"]),
        ("truncated_ckpt", "evaluate ckpt={f} data={heldout}", ["truncated.ckpt", "unreadable"]),
        ("tampered_ckpt", "export ckpt={f}", ["tampered.ckpt", "altered"]),
        ("unchecked_ckpt", "evaluate ckpt={f} data={heldout}", ["unchecked.ckpt", "'sha256'"]),
        ("schema_ckpt", "evaluate ckpt={f} data={heldout}", ["schema.ckpt", "(2.0, 3.0)", "1.0"]),
        ("topology_ckpt", "export ckpt={f}", ["topology.ckpt", "topology"]),
        ("not_onnx", "monitor model={f} source=replay file={heldout}", ["not.onnx", "not an ONNX"]),
        ("shape_onnx", "monitor model={f} source=replay file={heldout}", ["shape.onnx", "'x'"]),
        ("empty_recording", "evaluate ckpt={ckpt} data={f}", ["graphs.jsonl", "no samples"]),
        ("no_recording", "evaluate ckpt={ckpt} data={f}", ["nothing", "no recording"]),
        ("no_recording", "dataset summarize {f}", ["nothing", "no recording"]),
        ("empty_recording", "bag write {f}", ["graphs.jsonl", "no samples"]),
        ("other_arm", "monitor model={onnx} source=replay file={f}", ["ur3e", "reads a ur5e"]),
        ("other_arm", "evaluate ckpt={ckpt} data={f}", ["ur3e", "trained on ur5e"]),
    ],
)  # fmt: skip
def test_every_bad_file_gets_one_line_and_exit_status_2(deployed, bad_files, key, command, needles):
    args = command.format(
        f=bad_files[key],
        heldout=deployed["heldout"],
        ckpt=deployed["structural_ckpt"],
        onnx=deployed["structural_onnx"],
    ).split()
    _one_line_error(_python(f"robohealth_mj.{args[0]}", *args[1:]), *needles)


def test_a_robots_own_bag_without_truth_or_sensors_is_numbered_by_stamp(deployed, tmp_path):
    """A bag of only the joint state and tracking error (a stock arm's, no /fault_state): samples
    numbered by stamp (a lost stamp is a gap), read as healthy, sensor channels zero, and the
    bag's profile is stock, which a full model refuses in one line."""
    from robohealth_mj.data.read import recording_sensing
    from robohealth_mj.learn.evaluation import evaluate_checkpoint

    samples = list(read_samples(deployed["heldout"]))[:30]
    topics = BagTopics.load()
    keep = {topics.joint_states, topics.joint_errors}
    out = tmp_path / "robot_bag"
    _write_edited(samples, out, lambda topic, k, raw: raw if topic in keep and k != 12 else None)
    got = list(read_samples(out))
    assert [s.sample_index for s in got] == [k for k in range(30) if k != 12]
    assert {s.recording_run_id for s in got} == {"robot_bag"}
    assert all(s.fault == schema.FaultLabel() for s in got)
    for s, source in zip(got, [s for k, s in enumerate(samples) if k != 12], strict=True):
        np.testing.assert_allclose(
            s.x[:, schema.STATE_CHANNELS], source.x[:, schema.STATE_CHANNELS], atol=1e-6
        )
        assert not s.x[:, schema.SENSOR_CHANNELS].any()
    assert recording_sensing(out) == "stock" and recording_sensing(deployed["heldout"]) == "full"
    with pytest.raises(ValueError, match="robot_bag: the data has the stock profile's channels"):
        evaluate_checkpoint(deployed["structural_ckpt"], [str(out)])
