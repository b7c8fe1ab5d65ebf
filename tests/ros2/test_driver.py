"""The UR ROS 2 driver's own topics: ``/joint_states`` at the controller's rate with the driver's
names in its order, and the trajectory controller's state (Humble and Jazzy layouts) for the
tracking error. Small synthetic arms made here; the bus tests run on loopback only."""

from __future__ import annotations

import dataclasses
import itertools
import os
import time

import numpy as np
import pytest

pytest.importorskip("cyclonedds", reason="the ROS 2 bridge needs cyclonedds: pip install '.[ros2]'")

from robohealth_mj.bags.joints import joint_names
from robohealth_mj.data.jsonl import node_features
from robohealth_mj.ros2.bus import Bus, BusConfig
from robohealth_mj.ros2.driver import DriverAssembler, DriverConfig, DriverMessages
from robohealth_mj.ros2.idl import (
    CONTROLLER_STATES,
    Header,
    JointState,
    JointTrajectoryPoint,
    Time,
)
from robohealth_mj.ros2.node import ArmPublisher, MonitorNode
from robohealth_mj.runtime.runtime import ModelRuntime
from robohealth_mj.schema import N_JOINTS, FaultLabel, GraphSample

# test_ros2.py takes domains 100-210: these stay below, so two modules never share one
_DOMAINS = itertools.count(20 + os.getpid() % 35 * 2)
UR = joint_names("ur_driver", "left_")  # the driver's names with a tf_prefix
PERIOD_NS = 50_000_000  # 20 Hz ticks

# The ROS message definitions (control_msgs 4.x on Humble; 5.3+ on Jazzy, Kilted, Rolling), to
# check our DDS types against the bytes rosbags writes for them.
_POINT = "trajectory_msgs/JointTrajectoryPoint"
_MULTI = "trajectory_msgs/MultiDOFJointTrajectoryPoint"
MSG = {
    "humble": [("std_msgs/Header", "header"), ("string[]", "joint_names"),
               *((_POINT, f) for f in ("reference", "feedback", "error", "output", "desired",
                                       "actual")),
               ("string[]", "multi_dof_joint_names"),
               *((_MULTI, f"multi_dof_{f}") for f in ("reference", "feedback", "error", "output",
                                                      "desired", "actual"))],
    "jazzy": [("std_msgs/Header", "header"), ("string[]", "joint_names"),
              *((_POINT, f) for f in ("reference", "feedback", "error", "output")),
              ("string[]", "multi_dof_joint_names"),
              *((_MULTI, f"multi_dof_{f}") for f in ("reference", "feedback", "error", "output")),
              ("float64", "speed_scaling_factor")],
}  # fmt: skip


def _samples(n: int, seed: int = 0, joints: int = N_JOINTS) -> list[GraphSample]:
    """``n`` ticks of a made-up arm at 20 Hz: smooth joint channels, no sensor package."""
    rng = np.random.default_rng(seed)
    state = np.cumsum(rng.normal(0, 0.01, (n, joints, 5)), axis=0)
    state[..., 4] = 0.0  # the driver has no torque residual
    x = node_features(state, np.zeros((n, joints, 8))).astype(np.float32)
    return [GraphSample("arm", k, 10.0 + k * 0.05, x[k], FaultLabel(), {}) for k in range(n)]


def _header(ns: int) -> Header:
    return Header(stamp=Time(sec=ns // 10**9, nanosec=ns % 10**9))


@pytest.mark.parametrize("distro", ["humble", "jazzy"])
def test_the_controller_state_s_bytes_equal_rosbags_for_each_distribution(distro):
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE if distro == "humble" else Stores.ROS2_JAZZY)
    name = "control_msgs/msg/JointTrajectoryControllerState"
    store.register(get_types_from_msg("\n".join(f"{t} {f}" for t, f in MSG[distro]), name))
    types = store.types
    duration = types["builtin_interfaces/msg/Duration"](sec=0, nanosec=0)

    def point(values):
        empty = np.zeros(0)
        return types["trajectory_msgs/msg/JointTrajectoryPoint"](
            positions=np.asarray(values, float), velocities=empty, accelerations=empty,
            effort=empty, time_from_start=duration)  # fmt: skip

    fields = {"header": types["std_msgs/msg/Header"](
        stamp=types["builtin_interfaces/msg/Time"](sec=3, nanosec=5), frame_id="")}  # fmt: skip
    for kind, field in MSG[distro][1:]:
        fields[field] = {
            "string[]": list(UR) if field == "joint_names" else [],
            _POINT: point([0.1, -0.2] if field == "error" else []),
            _MULTI: types["trajectory_msgs/msg/MultiDOFJointTrajectoryPoint"](
                transforms=[], velocities=[], accelerations=[], time_from_start=duration),
            "float64": 1.0,
        }[kind]  # fmt: skip
    reference = bytes(store.serialize_cdr(types[name](**fields), name))
    ours = CONTROLLER_STATES[distro](header=_header(3 * 10**9 + 5), joint_names=list(UR),
                                     error=JointTrajectoryPoint(positions=[0.1, -0.2]))  # fmt: skip
    assert ours.serialize() == reference
    assert CONTROLLER_STATES[distro].deserialize(reference).error.positions == [0.1, -0.2]


def _driver_stream(
    samples, rate_hz: int = 500, controller_hz: int = 100, gripper: bool = True, joints=UR
):
    """What the driver publishes over ``samples``' span: ``/joint_states`` at ``rate_hz`` with
    the names alphabetical (and a gripper joint), the controller state at ``controller_hz``,
    each holding the last sample's values (the controller's state changes between ticks)."""
    messages = DriverMessages(joints, DriverConfig())
    step = 10**9 // rate_hz
    start = round(samples[0].t * 1e9)
    out = []
    for k in range(len(samples) * rate_hz // 20):
        ns = start + k * step
        js, cs = messages.messages(samples[k * 20 // rate_hz])
        js.header = cs.header = _header(ns)
        if gripper:
            js.name = [*js.name, "left_gripper_joint"]
            for field in ("position", "velocity", "effort"):
                setattr(js, field, [*getattr(js, field), 0.5])
        out.append(("/js", js))
        if k % (rate_hz // controller_hz) == 0:
            out.append(("/cs", cs))
    return out


def _run(assembler, stream, settle_every: int = 10):
    samples, problems, duplicates = [], [], 0
    for n, (topic, msg) in enumerate(stream, 1):
        got = [assembler.add(topic, msg)]
        if n % settle_every == 0:
            got.append(assembler.settle())
        for g in got:
            samples += g.samples
            problems += g.problems
            duplicates += g.duplicates
    return samples, problems, duplicates


def test_driver_topics_at_500_hz_become_the_model_s_ticks_with_the_tracking_error():
    """Joints found by name (alphabetical, prefixed, a gripper besides), one tick per 50 ms of
    a 500 Hz stream, the tracking error the controller held at each tick (negated: measured minus
    target), the torque residual zero, numbered on the tick grid."""
    samples = _samples(12)
    assembler = DriverAssembler("left", "/js", "/cs", UR, DriverConfig(tracking=True))
    got, problems, _ = _run(assembler, _driver_stream(samples))
    assert problems == []
    assert [s.sample_index for s in got] == list(range(12))
    for a, b in zip(got, samples, strict=True):
        np.testing.assert_allclose(a.x, b.x, atol=1e-6)
        assert a.t == pytest.approx(b.t) and a.recording_run_id == "left"
    # a controller publishing at 4 Hz: a tick more than 0.1 s after its last state has no
    # tracking error it can trust and is dropped (the window restarts), the others keep theirs
    slow = DriverAssembler("left", "/js", "/cs", UR, DriverConfig(tracking=True))
    got, problems, _ = _run(slow, _driver_stream(samples, controller_hz=4))
    assert problems == [] and [s.sample_index for s in got] == [0, 1, 2, 5, 6, 7, 10]  # 11 waits


def test_the_bytes_path_at_500_hz_gives_the_same_ticks_decoding_one_message_of_each_per_tick(
    monkeypatch,
):
    """As the monitor reads the driver (``add_serialized``, bytes off the wire): the same
    samples as the decoded path, with only the joint state and the controller state each tick
    uses decoded (at 500 Hz, one of 25 of each); a malformed controller state that a tick takes
    marks the arm and drops that tick, one that no tick takes is never read."""
    import robohealth_mj.ros2.driver as driver
    from robohealth_mj.ros2.assembly import Assembled

    samples = _samples(12)
    stream = _driver_stream(samples, controller_hz=500)
    kinds = {"/js": JointState, "/cs": CONTROLLER_STATES["jazzy"]}
    decoded, decode = [], driver.decode
    monkeypatch.setattr(
        driver, "decode", lambda kind, buf: decoded.append(kind) or decode(kind, buf)
    )

    def run(buffers):
        assembler = DriverAssembler("left", "/js", "/cs", UR, DriverConfig(tracking=True))
        out = Assembled()
        for topic, data in buffers:
            assembler.add_serialized(topic, kinds[topic], [data], out)
        out.extend(assembler.settle())
        return out

    buffers = [(topic, msg.serialize()) for topic, msg in stream]
    out = run(buffers)
    reference, _, _ = _run(DriverAssembler("left", "/js", "/cs", UR, DriverConfig()), stream)
    assert out.problems == [] and len(out.samples) == len(reference) == 12
    for a, b in zip(out.samples, reference, strict=True):
        np.testing.assert_array_equal(a.x, b.x)
        assert a.sample_index == b.sample_index and a.stamp_ns == b.stamp_ns
    assert decoded.count(JointState) == 12  # of 300 joint states
    assert len(decoded) - 12 <= 12 + 1  # of 300 controller states: one a tick (and the last)
    # a garbled controller state: the one tick 3 takes (at its instant), and one between ticks
    tick3 = round(samples[3].t * 1e9)
    garbled = []
    for topic, data in buffers:
        stamp = int.from_bytes(data[4:8], "little") * 10**9 + int.from_bytes(data[8:12], "little")
        if topic == "/cs" and stamp in (tick3, tick3 + 10_000_000):
            data = data[:40]  # cut short: no decoder reads it
        garbled.append((topic, data))
    out = run(garbled)
    assert [s.sample_index for s in out.samples] == [k for k in range(12) if k != 3]
    assert len(out.problems) == 1 and "topic '/cs' at tick" in out.problems[0]
    assert "undecodable JazzyControllerState" in out.problems[0]


def test_a_seven_joint_ros2_control_arm_is_assembled_by_its_drivers_names():
    """franka_ros2's FR3 (any ros2_control driver): seven joints found by the preset's names,
    the samples on the arm's seven-joint graph; ``joint_names=auto`` takes the model's arm's
    driver names on the ur_driver layout."""
    from omegaconf import OmegaConf

    from robohealth_mj.bags.joints import joint_names
    from robohealth_mj.ros2.live import layout_options

    fr3 = joint_names("franka_ros2")
    assert fr3 == tuple(f"fr3_joint{k}" for k in range(1, 8))
    samples = _samples(6, joints=7)
    assembler = DriverAssembler("fr3", "/js", "/cs", fr3, DriverConfig(tracking=True))
    got, problems, _ = _run(assembler, _driver_stream(samples, joints=fr3))
    assert problems == [] and len(got) == 6 and got[0].x.shape == (14, 15)
    for a, b in zip(got, samples, strict=True):
        np.testing.assert_allclose(a.x, b.x, atol=1e-6)
    cfg = OmegaConf.create({"layout": "ur_driver", "joint_names": "auto"})
    assert layout_options(cfg, arm="fr3")["joint_names"] == list(fr3)
    assert layout_options(cfg, arm="ur10e")["joint_names"] == list(joint_names("ur_driver"))
    with pytest.raises(ValueError, match=r"ros2\.effort_scale: 7 numbers"):
        DriverAssembler("fr3", "/js", "/cs", fr3, DriverConfig(effort_scale=(1.0,) * 6))


def test_without_the_controller_a_tracking_model_is_told_once_and_a_reduced_one_goes_on():
    """The trajectory controller stops publishing (freedrive, another controller): a model that
    reads pos_error gets no tick and the arm one line naming the topic, until it returns; a
    model of the reduced joint_states profile gets every tick."""
    samples = _samples(30)
    stream = _driver_stream(samples)
    quiet = [m for m in stream if not (m[0] == "/cs" and 10.3 <= _t(m[1]) < 11.0)]
    tracking = DriverAssembler("left", "/js", "/cs", UR, DriverConfig(tracking=True))
    got, problems, _ = _run(tracking, quiet)
    assert len(problems) == 1
    assert problems[0].startswith("topic '/cs': no controller state for 0.5 s of joint states")
    indices = [s.sample_index for s in got]
    assert indices[:6] == list(range(6)) and indices[-9:] == list(range(21, 30))
    assert 8 <= 30 - len(got) <= 15  # the silent stretch (0.7 s) and the timeout's wait
    reduced = DriverAssembler("left", "/js", "/cs", UR, DriverConfig(tracking=False))
    assert reduced.topic_names() == ["/js"]
    got, problems, _ = _run(reduced, [m for m in quiet if m[0] == "/js"])
    assert problems == [] and [s.sample_index for s in got] == list(range(30))
    for a, b in zip(got, samples, strict=True):
        np.testing.assert_allclose(a.x[:, 2:5], b.x[:, 2:5], atol=1e-6)  # pos, vel, effort
        assert not a.x[:, 5].any()  # no tracking error without the controller


def _t(msg) -> float:
    return msg.header.stamp.sec + msg.header.stamp.nanosec / 1e9


def test_bad_driver_messages_are_one_line_naming_topic_and_field_and_repeats_are_duplicates():
    samples = _samples(4)
    messages = DriverMessages(UR, DriverConfig())
    assembler = DriverAssembler("left", "/js", "/cs", UR, DriverConfig(tracking=False))
    js, _ = messages.messages(samples[0])
    assert assembler.add("/js", js).samples
    assert assembler.add("/js", js).duplicates == 1  # the same message again
    missing, _ = messages.messages(samples[1])
    missing.name = [n for n in missing.name if n != "left_elbow_joint"]
    missing.position, missing.velocity, missing.effort = (
        v[:5] for v in (missing.position, missing.velocity, missing.effort)
    )
    nan, _ = messages.messages(samples[2])
    nan.effort = [float("nan"), *nan.effort[1:]]
    short, _ = messages.messages(samples[3])
    short.velocity = short.velocity[:4]
    lines = [assembler.add("/js", m).problems for m in (missing, nan, short)]
    assert lines[0] == [f"topic '/js' at stamp {samples[1].t:.6f} s: field 'name': joint "
                        "'left_elbow_joint' missing (1 of 6; the message names "
                        f"{missing.name})"]  # fmt: skip
    assert lines[1] == [f"topic '/js' at stamp {samples[2].t:.6f} s: field 'effort': NaN or Inf "
                        f"at joint '{nan.name[0]}'"]  # fmt: skip
    assert lines[2] == [f"topic '/js' at stamp {samples[3].t:.6f} s: field 'velocity': 4 values, "
                        "not 6"]  # fmt: skip
    back = assembler.add("/js", messages.messages(samples[1])[0])  # older than the newest
    assert back.problems[0].endswith("stamps went backwards")
    again = assembler.add("/js", js)  # the first message re-delivered after three newer ones
    assert again.duplicates == 1 and again.problems == []
    forgetful = DriverAssembler("left", "/js", "/cs", UR, DriverConfig(tracking=False), history=2)
    for m in (js, *(messages.messages(s)[0] for s in samples[1:])):
        forgetful.add("/js", m)
    assert forgetful.add("/js", js).problems[0].endswith("stamps went backwards")  # past depth


def _bus(**kw) -> BusConfig:
    return BusConfig(domain_id=next(_DOMAINS), interface="127.0.0.1", depth=64, **kw)


def _matched(writers, readers, timeout_s: float = 10.0) -> None:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline and not (
        all(w.get_matched_subscriptions() for w in writers)
        and all(r.get_matched_publications() for r in readers)
    ):
        time.sleep(0.05)


@pytest.mark.parametrize("distro", ["humble", "jazzy"])
def test_a_ur_driver_on_the_bus_is_assembled_for_two_arms_in_each_layout(distro):
    """Two arms in their namespaces, each with its tf_prefix, publishing as the driver does
    (``robot ros2.layout=ur_driver``); the monitor assembles every tick of both exactly."""
    config = _bus()
    robot, monitor_bus = Bus(config), Bus(config)
    driver = DriverConfig(distro=distro, tracking=True)
    options = {"layout": "ur_driver", "joint_names": "ur_driver", "tf_prefix": "{arm}_",
               "driver": driver}  # fmt: skip
    got: dict[str, list] = {"left": [], "right": []}
    node = MonitorNode(monitor_bus, ModelRuntime(None), list(got), require_truth=False,
                       on_diagnosis=lambda arm, s, d: got[arm].append(s), **options)  # fmt: skip
    arms = [ArmPublisher(robot, arm, **options) for arm in got]
    assert list(arms[0].writers) == [
        "/left/joint_states",
        "/left/scaled_joint_trajectory_controller/controller_state",
    ]
    readers = [r for state in node.arms.values() for _, _, r in state.readers]
    _matched([w for a in arms for w in a.writers.values()], readers)
    samples = _samples(20)
    for s in samples:
        for arm in arms:
            arm.publish(s)
    deadline = time.monotonic() + 10.0
    while time.monotonic() < deadline and min(map(len, got.values())) < len(samples):
        node.poll()
        time.sleep(0.005)
    for arm, received in got.items():
        assert [s.sample_index for s in received] == list(range(20)), arm
        for a, b in zip(received, samples, strict=True):
            np.testing.assert_allclose(a.x, b.x, atol=1e-6)
    assert all(s.problems == 0 for s in node.arms.values())
    for bus in (robot, monitor_bus):
        bus.close()


def test_a_writer_that_cannot_match_is_named_with_its_likely_cause_within_a_period():
    """A Humble driver read with ``ros2.distro=jazzy`` (one DDS type name, two layouts) on one
    arm, a best-effort joint_states writer to reliable subscriptions on the other: each arm says
    so on /diagnostics (and in the monitor's output) naming the topic and the cause, not
    silence."""
    from cyclonedds.core import Policy, Qos
    from cyclonedds.pub import DataWriter

    config = _bus(reliable_subscriptions=True)
    robot, monitor_bus = Bus(config), Bus(config)
    best_effort = Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(10))
    kept = [
        robot.writer("/left/scaled_joint_trajectory_controller/controller_state",
                     CONTROLLER_STATES["humble"]),
        DataWriter(robot.participant, robot._topic("/right/joint_states", JointState),
                   best_effort),
    ]  # fmt: skip
    node = MonitorNode(monitor_bus, ModelRuntime(None), ["left", "right"], require_truth=False,
                       layout="ur_driver", driver=DriverConfig(distro="jazzy"))  # fmt: skip
    deadline, reported = time.monotonic() + 5.0, {}
    while time.monotonic() < deadline and len(reported) < 2:
        node.poll()
        node.publish_diagnostics(0.0)
        reported.update(node.reported)
        time.sleep(0.1)
    assert reported == {
        "left": "topic '/left/scaled_joint_trajectory_controller/controller_state': a writer that "
        "cannot match a JazzyControllerState reader (another message type, or another layout of "
        "it (a ROS distribution's: ros2.distro); DDS policy id 24)",
        "right": "topic '/right/joint_states': a writer that cannot match a JointState reader "
        "(reliability: a best-effort writer and a reliable reader (ros2.reliable_subscriptions); "
        "DDS policy id 11)",
    }
    del kept
    for bus in (robot, monitor_bus):
        bus.close()


def test_effort_scale_turns_the_driver_s_current_into_torque():
    samples = _samples(3)
    scale = (10.0, 11.0, 12.0, 13.0, 14.0, 15.0)
    config = DriverConfig(tracking=False, effort_scale=scale)
    messages = DriverMessages(UR, config)  # publishes effort / scale: amperes
    assembler = DriverAssembler("left", "/js", "/cs", UR, config)
    got = [s for x in samples for s in assembler.add("/js", messages.messages(x)[0]).samples]
    for a, b in zip(got, samples, strict=True):
        np.testing.assert_allclose(a.x[:6, 4], b.x[:6, 4], rtol=1e-6)
    amperes = messages.messages(samples[0])[0].effort
    assert amperes[0] == pytest.approx(samples[0].x[2, 4] / 12.0)  # elbow_joint listed first
    assert DriverConfig(distro="kilted").layout == DriverConfig(distro="rolling").layout == "jazzy"
    with pytest.raises(ValueError, match=r"ros2\.distro must be one of \['humble', 'jazzy'"):
        DriverConfig(distro="iron")  # end of life, and not a UR driver's
    with pytest.raises(ValueError, match=r"ros2\.effort_scale: 6 numbers"):
        DriverAssembler("left", "/js", "/cs", UR, dataclasses.replace(config, effort_scale=(1.0,)))


def test_a_model_reading_more_than_the_driver_gives_is_refused_in_one_line(stock_deployed, capsys):
    """A stock model reads the torque residual, which the UR driver does not publish: the
    monitor says so before joining the bus, and which profile to train instead."""
    from robohealth_mj.monitor import main

    with pytest.raises(SystemExit) as exit_:
        main([f"model={stock_deployed['onnx']}", "source=ros2", "ros2.layout=ur_driver"])
    assert exit_.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        "monitor: error: ros2.layout=ur_driver: the data has the ur_driver profile's channels "
        "and the model reads the stock profile's: ['effort_residual'] missing; use a model "
        "trained with sensing=ur_driver"
    ]


def test_a_diagnosis_is_stamped_with_its_sample_s_header_stamp_exactly():
    """At epoch times a stamp in float seconds is up to 128 ns off: the driver's tick carries
    its header stamp whole, and the diagnosis's header equals it to the nanosecond."""
    from robohealth_mj.bags.messages import MessageFactory
    from robohealth_mj.ros2.node import IdlStore
    from robohealth_mj.runtime.runtime import HealthDiagnosis

    epoch = 1_764_300_000_123_456_789  # 2025-11-28, 789 ns past a microsecond
    samples = [dataclasses.replace(s, t=epoch / 1e9 + k * 0.05) for k, s in enumerate(_samples(6))]
    stream = _driver_stream(samples)
    for k, (_, msg) in enumerate(stream):  # exact stamps, not from the float seconds
        msg.header = _header(epoch + (k // 6) * 2_000_000)
    assembler = DriverAssembler("left", "/js", "/cs", UR, DriverConfig(tracking=False))
    got, problems, _ = _run(assembler, [m for m in stream if m[0] == "/js"])
    assert problems == [] and got
    first = got[0]
    assert first.stamp_ns == epoch and round(first.t * 1e9) != epoch  # the float loses it
    d = HealthDiagnosis(stamp=first.t, stream_id="left", sample_index=0, valid=True)
    factory = MessageFactory(IdlStore())
    header = factory.health_diagnosis(d, ["none"], ["j"], first.stamp_ns).header
    assert header.stamp.sec * 10**9 + header.stamp.nanosec == epoch
