"""The monitor as a live ROS 2 participant, and simulated arms publishing as a robot would.

``MonitorNode`` subscribes to each arm's topics (the bag layout under ``/<arm>``), assembles
samples by stamp (:mod:`robohealth_mj.ros2.assembly`), diagnoses every arm in one batched runtime
step per poll, and publishes each diagnosis on ``/<arm>/health_diagnosis`` and, at a fixed
period, one ``DiagnosticStatus`` per arm on ``/diagnostics`` (level from the alarm; WARN with the
reason for a bad message; STALE when an arm stops publishing). A bad message marks its arm only.
"""

from __future__ import annotations

import time
import zlib
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

from robohealth_mj.bags.joints import joint_names as arm_joint_names
from robohealth_mj.bags.messages import MessageFactory, health_fields, stamp_ns
from robohealth_mj.bags.topics import BagTopics
from robohealth_mj.common.errors import InputError
from robohealth_mj.ros2 import layout_sensing
from robohealth_mj.ros2.assembly import ArmAssembler, Assembled
from robohealth_mj.ros2.bus import Bus, ReadySet
from robohealth_mj.ros2.cdr import encode_diagnostic_array, take_raw
from robohealth_mj.ros2.driver import DriverAssembler, DriverConfig, DriverMessages
from robohealth_mj.ros2.idl import CONTROLLER_STATES, TYPES, IdlStore
from robohealth_mj.schema import GraphSample

DIAGNOSTICS_TOPIC = "/diagnostics"
# What a requested-incompatible-QoS status's last policy id (DDS's QosPolicyId_t) means here.
INCOMPATIBLE = {
    2: "durability: the writer offers less than the reader asks",
    11: "reliability: a best-effort writer and a reliable reader (ros2.reliable_subscriptions)",
    24: "another message type, or another layout of it (a ROS distribution's: ros2.distro)",
    25: "data representation (XCDR2 writer, XCDR1 reader)",
}


def arm_topics(arm: str, topics: BagTopics | None = None, namespace: str = "/{arm}") -> BagTopics:
    """The bag layout's topic names under the arm's namespace (``/arm1/joint_states`` …;
    ``namespace=""``: at the root, as a single driver launched without one publishes)."""
    base = topics or BagTopics.load()
    fields = {k: in_namespace(arm, v, namespace) for k, v in vars(base).items()}
    return replace(base, **fields)


def in_namespace(arm: str, topic: str, namespace: str = "/{arm}") -> str:
    """``topic`` under the arm's namespace (``{arm}`` in ``namespace`` is its name)."""
    prefix = namespace.format(arm=arm).strip("/")
    return f"/{prefix}/{topic.lstrip('/')}" if prefix else f"/{topic.lstrip('/')}"


def in_partition(arm: str, partition: str | None) -> bool:
    """``partition="k/n"``: this process's share of a fleet split across ``n`` processes by a
    stable hash of the arm name (no coordinator: every process computes the same split)."""
    if not partition:
        return True
    k, n = (int(v) for v in partition.split("/"))
    if not 0 <= k < n:
        raise ValueError(f"partition {partition!r}: need k/n with 0 <= k < n")
    return zlib.crc32(arm.encode()) % n == k


def layout_topics(topics: BagTopics, layout: str) -> dict[str, str]:
    """The topics (-> message type) one sample travels on in ``layout``: ``per_sensor`` (the bag
    layout, 15 messages a tick), ``aggregated`` (the snapshot in one array, and the truth) or
    ``joints`` (a stock arm's own: joint state and tracking error, and the truth where there is
    one; no sensor package, so those channels stay zero). ``ur_driver``'s topics are the
    driver's (:func:`driver_topics`)."""
    layout_sensing(layout)  # a known layout, or one line
    if layout == "aggregated":
        return topics.aggregated_topics()
    every = topics.sample_topics()
    if layout == "joints":
        own = (topics.joint_states, topics.joint_errors, topics.fault_state)
        return {t: every[t] for t in own}
    return every


def driver_topics(topics: BagTopics, arm: str, driver: DriverConfig, namespace: str) -> dict:
    """The UR driver's topics of one arm -> their message classes: ``joint_states`` and the
    trajectory controller's state in the configured distribution's layout."""
    return {
        topics.joint_states: TYPES["sensor_msgs/msg/JointState"],
        in_namespace(arm, driver.controller_state, namespace): CONTROLLER_STATES[driver.layout],
    }


def arm_kinds(
    names: BagTopics, arm: str, layout: str, driver: DriverConfig | None, namespace: str
) -> dict[str, type]:
    """One arm's topics in ``layout`` (``names``: under its namespace) -> their message classes:
    what a robot publishes and the monitor reads."""
    if layout == "ur_driver":
        return driver_topics(names, arm, driver or DriverConfig(), namespace)
    return {t: TYPES[k] for t, k in layout_topics(names, layout).items()}


def poll_paced(node: MonitorNode, period_s: float) -> int:
    """One poll of ``node``, then the rest of ``period_s``: what arrived meanwhile is taken in
    one go and diagnosed in one runtime step (fewer, larger takes and steps: polling as fast as
    messages trickle in would diagnose a few arms a step)."""
    started = time.perf_counter()
    done = node.poll()
    rest = period_s - (time.perf_counter() - started)
    if rest > 0:
        time.sleep(rest)
    return done


class ArmPublisher:
    """One simulated or replayed arm publishing its samples as a robot driver would."""

    def __init__(
        self,
        bus: Bus,
        arm: str,
        topics: BagTopics | None = None,
        layout: str = "per_sensor",
        namespace: str = "/{arm}",
        driver: DriverConfig | None = None,
        joint_names: str | Sequence[str] = "ur_driver",
        tf_prefix: str = "",
    ) -> None:
        """``layout="ur_driver"``: as the UR driver publishes, with ``joint_names`` (and the
        ``tf_prefix``) in its alphabetical order and the controller state of ``driver.distro``."""
        self.arm, self.layout = arm, layout
        self.topics = arm_topics(arm, topics, namespace)
        self.factory = MessageFactory(IdlStore())
        if layout == "ur_driver":
            self.driver = DriverMessages(arm_joint_names(joint_names, tf_prefix.format(arm=arm)),
                                         driver or DriverConfig())  # fmt: skip
        kinds = arm_kinds(self.topics, arm, layout, driver, namespace)
        self.writers = {name: bus.writer(name, cls) for name, cls in kinds.items()}

    def messages(self, sample: GraphSample, topics: BagTopics | None = None) -> list[tuple]:
        """``(topic, message)`` of one sample in this arm's layout (``topics``: other names)."""
        topics = topics or self.topics
        if self.layout == "ur_driver":
            return list(zip(self.writers, self.driver.messages(sample), strict=True))
        if self.layout == "aggregated":
            return [
                (topics.aggregated, self.factory.aggregated(sample)),
                (topics.fault_state, self.factory.fault_state(sample)),
            ]
        messages = self.factory.sample_messages(sample, topics)
        if self.layout == "joints":
            own = layout_topics(topics, "joints")
            messages = [(t, m) for t, m in messages if t in own]
        return messages

    def publish(self, sample: GraphSample) -> None:
        for topic, msg in self.messages(sample):
            self.writers[topic].write(msg)

    def serialized(self, messages: list[Any]) -> list[bytes]:
        """One tick's messages (in ``sample_topics`` order) as this arm's writers put them on
        the wire, for :meth:`publish_serialized`."""
        return [Bus.serialize(w, m) for w, m in zip(self.writers.values(), messages, strict=True)]

    def publish_serialized(self, data: list[bytes]) -> None:
        """Bytes from :meth:`serialized`, shared by arms that replay the same sample: the
        benchmark's publishers serialise once and write N times."""
        for writer, blob in zip(self.writers.values(), data, strict=True):
            Bus.write_serialized(writer, blob)


@dataclass
class ArmState:
    """What ``/diagnostics`` says of one arm."""

    assembler: ArmAssembler | DriverAssembler
    readers: list[tuple[str, type, Any]]  # (topic, message class, reader)
    last_sample_wall: float | None = None
    last_diagnosis: Any = None
    problem: str | None = None  # the latest, until /diagnostics has reported it
    last_problem: str | None = None
    problems: int = 0
    duplicates: int = 0  # repeated identical messages (re-deliveries), dropped
    late: int = 0  # messages for ticks already reported missing, dropped
    samples: int = 0
    diagnoses: list[Any] = field(default_factory=list)


class MonitorNode:
    """Diagnoses a fleet of arms on the bus; ``poll`` once per loop iteration."""

    def __init__(
        self,
        bus: Bus,
        runtime: Any,
        arms: list[str],
        topics: BagTopics | None = None,
        require_truth: bool = True,
        stale_s: float = 1.0,
        keep_diagnoses: bool = False,
        on_diagnosis: Callable[[str, GraphSample, Any], None] | None = None,
        layout: str = "per_sensor",
        joint_names: str | Sequence[str] = "schema",
        tf_prefix: str = "",
        namespace: str = "/{arm}",
        driver: DriverConfig | None = None,
        health_diagnosis_hz: float = 20.0,
        diagnose_wait_s: float = 0.02,
        tick_hz: float = 20.0,
        member: str | None = None,
        late_ticks: int = 10,
    ) -> None:
        """``health_diagnosis_hz``: each arm's ``/health_diagnosis`` at most this often (every
        diagnosis at ``tick_hz``, the model's rate; less saves the monitor's publishing time at
        many arms). ``member``: this monitor's name in a monitor group (``/diagnostics`` then
        says which monitor watches each arm; :meth:`set_arms` moves arms in and out).
        ``joint_names`` (a preset of ``conf/joint_names.yaml`` or six names) and ``tf_prefix``
        (``{arm}`` is the arm's name) say what each arm's JointState messages call its joints;
        ``namespace`` where its topics live; ``driver`` the UR driver's side (``ur_driver``).
        ``diagnose_wait_s``: how long a completed sample may wait for the other arms' before
        the runtime step (one step for the whole fleet's tick instead of a step per arm).
        ``late_ticks``: a tick still missing a message once this many newer ticks are complete
        is reported missing (the message, should it come, counts late)."""
        self.bus, self.runtime, self.stale_s = bus, runtime, stale_s
        if not late_ticks >= 1:
            raise InputError(f"ros2.late_ticks must be >= 1, got {late_ticks}")
        if not health_diagnosis_hz > 0:
            raise InputError(f"ros2.health_diagnosis_hz must be > 0, got {health_diagnosis_hz}")
        self.health_every = max(1, round(tick_hz / health_diagnosis_hz))  # every k-th diagnosis
        if not diagnose_wait_s >= 0:
            raise InputError(f"ros2.diagnose_wait_s must be >= 0, got {diagnose_wait_s}")
        self.diagnose_wait_s = diagnose_wait_s
        self._waiting: dict[str, list[GraphSample]] = {}  # completed, not yet diagnosed
        self._waiting_since: float | None = None
        self.keep_diagnoses, self.on_diagnosis = keep_diagnoses, on_diagnosis
        # where the monitor's time goes (the benchmark reports it): take (the DDS take),
        # assemble (with the decoding of what a sample needs), diagnose (runtime), publish (the
        # diagnoses' writes)
        self.seconds: dict[str, float] = dict.fromkeys(
            ("take", "assemble", "diagnose", "publish"), 0.0
        )
        self._publishing = 0.0
        self.factory = MessageFactory(IdlStore())
        self.arms: dict[str, ArmState] = {}
        self.released: dict[str, ArmState] = {}  # arms another monitor took (their counts)
        self.reported: list[tuple[str, str]] = []  # (arm, problem) of the last /diagnostics
        self.diagnosis_writers: dict[str, Any] = {}
        self.member = member
        self._arm_options = {"topics": topics, "namespace": namespace, "layout": layout,
                             "joint_names": joint_names, "tf_prefix": tf_prefix,
                             "driver": driver, "require_truth": require_truth,
                             "late_ticks": late_ticks}  # fmt: skip
        self.diagnostics = bus.writer(
            DIAGNOSTICS_TOPIC, TYPES["diagnostic_msgs/msg/DiagnosticArray"]
        )
        self.ready: ReadySet | None = None
        self.set_arms(arms)

    def _add_arm(self, arm: str) -> None:
        """The arm's readers, assembler and diagnosis writer (its counts carried over from an
        earlier watch)."""
        o = self._arm_options
        names = arm_topics(arm, o["topics"], o["namespace"])
        joints = arm_joint_names(o["joint_names"], o["tf_prefix"].format(arm=arm))
        kinds = arm_kinds(names, arm, o["layout"], o["driver"], o["namespace"])
        if o["layout"] == "ur_driver":
            assembler = DriverAssembler(arm, *kinds, joints, o["driver"] or DriverConfig(),
                                        history=self.bus.config.depth)  # fmt: skip
        else:
            aggregated = names.aggregated if o["layout"] == "aggregated" else None
            assembler = ArmAssembler(arm, names, require_truth=o["require_truth"],
                                     late_ticks=o["late_ticks"], aggregated=aggregated,
                                     sensors=o["layout"] != "joints", joints=joints,
                                     history=self.bus.config.depth)  # fmt: skip
        # every assembler reads the bytes: the bag layouts' by byte templates, the driver's
        # decoding only the messages a tick uses
        readers = [(t, kinds[t], self.bus.reader(t, kinds[t])) for t in assembler.topic_names()]
        state = ArmState(assembler, readers)
        if (before := self.released.pop(arm, None)) is not None:
            for key in ("problems", "duplicates", "late", "samples"):
                setattr(state, key, getattr(before, key))
            state.last_problem = before.last_problem
        self.arms[arm] = state
        self.diagnosis_writers[arm] = self.bus.writer(names.health_diagnosis, TYPES[
            "diagnostic_msgs/msg/DiagnosticArray"])  # fmt: skip

    def _drop_arm(self, arm: str) -> None:
        """Stop watching the arm: its readers and writer go, and its window and alarm state in
        the runtime (another monitor starts them afresh; so does this one if it comes back)."""
        state = self.arms.pop(arm)
        for _, _, reader in state.readers:
            Bus.delete(reader)
        Bus.delete(self.diagnosis_writers.pop(arm))
        state.readers = []
        self.released[arm] = state
        self._waiting.pop(arm, None)
        self.runtime.forget(arm)

    def set_arms(self, arms: Sequence[str]) -> None:
        """Watch exactly these arms from the next poll: new ones get readers, dropped ones lose
        theirs (a monitor group moves arms between monitors this way)."""
        wanted = list(dict.fromkeys(arms))
        if self.ready is not None and wanted == list(self.arms):
            return
        if self.ready is not None:
            self.ready.close()
        for arm in [a for a in self.arms if a not in wanted]:
            self._drop_arm(arm)
        for arm in wanted:
            if arm not in self.arms:
                self._add_arm(arm)
        self._taps = [(arm, topic, kind, reader) for arm in wanted
                      for topic, kind, reader in self.arms[arm].readers]  # fmt: skip
        self.arms = {arm: self.arms[arm] for arm in wanted}
        self.ready = ReadySet(self.bus, [tap[3] for tap in self._taps])

    def poll(self, max_per_reader: int = 256) -> int:
        """Take what has arrived; diagnose the completed samples once every arm has one, or
        once the oldest has waited ``diagnose_wait_s``. Returns how many were diagnosed."""
        clock = time.perf_counter
        ready = self.ready.wait()  # the readers holding data, arm by arm
        now = time.monotonic()
        submitted: list[tuple[str, GraphSample]] = []
        taken_by_arm: dict[str, Assembled] = {}
        for index in ready:
            arm, topic, kind, reader = self._taps[index]
            state = self.arms[arm]
            out = taken_by_arm.get(arm)
            if out is None:
                out = taken_by_arm[arm] = Assembled()
            t0 = clock()
            raw = take_raw(reader, max_per_reader)
            t1 = clock()
            self.seconds["take"] += t1 - t0
            # decoding is part of assembly (only what a sample needs is decoded)
            state.assembler.add_serialized(topic, kind, raw, out)
            self.seconds["assemble"] += clock() - t1
        t1 = clock()
        for arm, out in taken_by_arm.items():
            # every ready reader of the arm taken: now a missing message is missing (only an arm
            # that received something can have a tick newly complete or newly overdue)
            state = self.arms[arm]
            out.extend(state.assembler.settle())
            self._collect(arm, state, out, now, submitted)
        self.seconds["assemble"] += clock() - t1
        t2 = clock()
        for arm, sample in submitted:
            self._waiting.setdefault(arm, []).append(sample)
        if self._waiting and self._waiting_since is None:
            self._waiting_since = now
        if not self._waiting or (
            len(self._waiting) < len(self.arms) and now - self._waiting_since < self.diagnose_wait_s
        ):
            return 0  # a runtime step costs about a millisecond whatever its size: fill it
        by_arm, self._waiting, self._waiting_since = self._waiting, {}, None
        # One sample per arm per runtime step: every sample gets its own decision (a step given
        # several samples of one stream decides only the last), and the arms share each step.
        for round_ in range(max((len(v) for v in by_arm.values()), default=0)):
            queued = {}
            for arm, samples in by_arm.items():
                if round_ < len(samples):
                    invalid = self.runtime.submit(arm, samples[round_])
                    if invalid is not None:
                        self._record(arm, invalid, samples[round_])
                    else:
                        queued[arm] = samples[round_]
            for d in self.runtime.tick():
                self._record(d.stream_id, d, queued[d.stream_id])
        self.seconds["diagnose"] += clock() - t2 - self._publishing
        self.seconds["publish"] += self._publishing
        self._publishing = 0.0
        return sum(len(v) for v in by_arm.values())

    @staticmethod
    def _collect(arm: str, state: ArmState, got: Any, now: float, submitted: list) -> None:
        for problem in got.problems:
            state.problem = state.last_problem = problem
            state.problems += 1
        state.duplicates += got.duplicates
        state.late += got.late
        for sample in got.samples:
            submitted.append((arm, sample))
            state.last_sample_wall = now

    def _record(self, arm: str, d: Any, sample: GraphSample) -> None:
        state = self.arms[arm]
        state.last_diagnosis, state.samples = d, state.samples + 1
        if self.keep_diagnoses:
            state.diagnoses.append(d)
        if self.on_diagnosis is not None:
            self.on_diagnosis(arm, sample, d)
        if (state.samples - 1) % self.health_every:
            return
        fleet = self.runtime.fleet
        t0 = time.perf_counter()
        writer = self.diagnosis_writers[arm]
        stamp = sample.stamp_ns if sample.stamp_ns is not None else stamp_ns(d.stamp)
        if writer._use_version_2:  # the byte encoder writes XCDR1, as ROS 2 types are
            writer.write(self.factory.health_diagnosis(d, fleet.classes, fleet.joints, stamp))
        else:
            level, message, values = health_fields(d, fleet.classes, fleet.joints)
            data = encode_diagnostic_array(
                stamp, "", [(level, "health_diagnosis", message, d.model_id, values)]
            )
            Bus.write_serialized(writer, data)
        self._publishing += time.perf_counter() - t0

    def arm_status(self, arm: str, now: float) -> Any:
        """One arm's ``DiagnosticStatus``: STALE without recent samples, WARN with the last
        problem, else the last diagnosis's level."""
        state, status = self.arms[arm], self.factory.Status
        fleet = self.runtime.fleet
        d = state.last_diagnosis
        if d is not None:
            msg = self.factory.health_status(
                d, fleet.classes, fleet.joints, f"robohealth/{arm}", arm
            )
        else:
            msg = status(level=status.STALE, name=f"robohealth/{arm}", message="no sample yet",
                         hardware_id=arm, values=[])  # fmt: skip
        if state.last_sample_wall is not None and now - state.last_sample_wall > self.stale_s:
            msg.level = status.STALE
            msg.message = f"no sample for {now - state.last_sample_wall:.1f} s"
        elif state.problem is not None:  # bad input, diagnosed or not yet: WARN, never STALE
            msg.level = status.WARN if d is None else max(int(msg.level), status.WARN)
            msg.message = f"bad input: {state.problem}"
        for key in ("problems", "late", "duplicates"):
            msg.values.append(self.factory.KeyValue(key=key, value=str(getattr(state, key))))
        if self.member is not None:
            msg.values.append(self.factory.KeyValue(key="monitor", value=self.member))
        return msg

    def check_writers(self) -> None:
        """A writer on an arm's topic that cannot match (another message type, or a QoS the
        reader cannot take) marks that arm: DDS reports it as a requested-incompatible QoS
        (type consistency for a wrong type). The secured binding (Cyclone 0.10) has no such
        status in Python: there a mismatched writer shows only as the arm going STALE."""
        for state in self.arms.values():
            for topic, kind, reader in state.readers:
                incompatible = getattr(reader, "get_requested_incompatible_qos_status", None)
                if incompatible is None:
                    return
                status = incompatible()
                if status.total_count_change:
                    cause = INCOMPATIBLE.get(status.last_policy_id, "QoS")
                    state.problem = state.last_problem = (
                        f"topic '{topic}': a writer that cannot match a {kind.__name__} reader "
                        f"({cause}; DDS policy id {status.last_policy_id})"
                    )
                    state.problems += 1

    def publish_diagnostics(self, stamp: float) -> Any:
        self.check_writers()
        now = time.monotonic()
        array = self.factory.DiagnosticArray(
            header=self.factory.header(stamp),
            status=[self.arm_status(arm, now) for arm in self.arms],
        )
        self.diagnostics.write(array)
        # what this period reported, for the monitor's own log (one line an arm at most)
        self.reported = [(arm, s.problem) for arm, s in self.arms.items() if s.problem]
        for state in self.arms.values():
            state.problem = None  # a problem is reported once, then the arm recovers
        return array
