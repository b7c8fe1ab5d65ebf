"""One GraphSample as standard ROS 2 messages, and back.

Per sample (stamped with its simulation time):

- ``JointState`` on ``joint_states``: position, velocity, effort of the six joints;
- ``JointState`` on ``joint_errors``: position = tracking error (``pos_error``), effort = torque
  residual (``effort_residual``), velocity empty;
- per sensor package, ``Imu`` (``linear_acceleration`` = the MEMS axes; orientation and angular
  velocity marked unknown with covariance[0] = -1) and ``Float64MultiArray`` (the piezo levels:
  ``vib``, three bands and kurtosis, labelled in ``layout.dim[0].label``; the type has no header,
  so its stamp is the bag's log time, which the writer sets to the sample's time);
- ``DiagnosticArray`` on ``fault_state``: the ground truth (level ERROR while a fault is active)
  and the sample's bookkeeping (run id, sample index, curriculum segment) as key values.

A sensor node's joint-state channels are its joint's, so the joint topics carry them once.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from typing import Any

import numpy as np

from robohealth_mj.bags.joints import joint_order
from robohealth_mj.bags.topics import VIBRATION_FIELDS, BagTopics
from robohealth_mj.data.jsonl import node_features
from robohealth_mj.schema import (
    FEATURE_NAMES,
    JOINT_NAMES,
    N_FEATURES,
    N_JOINTS,
    N_NODES,
    NODE_NAMES,
    SENSOR_CHANNELS,
    STATE_CHANNELS,
    UNLABELLED_SEGMENT,
    FaultLabel,
    GraphSample,
)

_STATE = {name: FEATURE_NAMES.index(name) for name in FEATURE_NAMES}
_ACC = [_STATE[a] for a in ("acc_x", "acc_y", "acc_z")]
_VIB = [_STATE[v] for v in VIBRATION_FIELDS]
UNKNOWN = np.array([-1.0] + [0.0] * 8)
STAMP_LABEL = "stamp_ns="  # REP 145: covariance[0] = -1 marks "not provided"


def typestore():
    from rosbags.typesys import Stores, get_typestore

    return get_typestore(Stores.ROS2_HUMBLE)


def stamp_ns(t: float) -> int:
    return round(t * 1e9)


def health_fields(d: Any, classes: list[str], joints: list[str]) -> tuple[int, str, dict]:
    """A ``HealthDiagnosis`` as a ``DiagnosticStatus``'s level, message and key values: level
    from the alarm (OK: none, WARN: a fault decided without an alarm, or an invalid sample,
    ERROR: an alarm up); class, joint, confidence, alarm state and per-class and per-joint
    scores as text."""
    if d.alarm_class is not None:
        level, message = 2, f"ALARM {d.alarm_class} @ {d.alarm_joint} ({d.alarm})"
    elif d.contact:
        level, message = 2, f"CONTACT @ {d.contact_joint}"
    elif not d.valid:
        level, message = 1, f"invalid sample: {d.reason}"
    elif d.fault_present:
        level, message = 1, f"{d.fault_class} @ {d.localised_joint} (no alarm)"
    elif d.fault_class is None:
        level, message = 0, f"no decision: {d.reason}"
    else:
        level, message = 0, "healthy"
    values = {
        "fault_class": d.fault_class or "",
        "joint": d.localised_joint or "",
        "confidence": f"{d.confidence:.4f}",
        "alarm": str(d.alarm),
        "alarm_class": d.alarm_class or "",
        "alarm_joint": d.alarm_joint or "",
        "contact_joint": d.contact_joint or "",
        "valid": str(d.valid).lower(),
        "sample_index": "" if d.sample_index is None else str(d.sample_index),
        **{f"p.{c}": f"{d.class_probabilities.get(c, 0.0):.4f}" for c in classes},
        **{f"score.{j}": f"{d.joint_scores.get(j, 0.0):.4f}" for j in joints},
    }
    return level, message, values


class MessageFactory:
    """Builds this project's messages with the ROS 2 (Humble) type definitions."""

    def __init__(self, store: Any) -> None:
        self.store = store
        types = store.types
        self.Header = types["std_msgs/msg/Header"]
        self.Time = types["builtin_interfaces/msg/Time"]
        self.JointState = types["sensor_msgs/msg/JointState"]
        self.Imu = types["sensor_msgs/msg/Imu"]
        self.Quaternion = types["geometry_msgs/msg/Quaternion"]
        self.Vector3 = types["geometry_msgs/msg/Vector3"]
        self.Array = types["std_msgs/msg/Float64MultiArray"]
        self.Layout = types["std_msgs/msg/MultiArrayLayout"]
        self.Dim = types["std_msgs/msg/MultiArrayDimension"]
        self.DiagnosticArray = types["diagnostic_msgs/msg/DiagnosticArray"]
        self.Status = types["diagnostic_msgs/msg/DiagnosticStatus"]
        self.KeyValue = types["diagnostic_msgs/msg/KeyValue"]

    def header(self, t: float, frame: str = "", ns: int | None = None) -> Any:
        """A header stamped ``ns`` when the exact stamp is known, else ``t`` seconds."""
        ns = stamp_ns(t) if ns is None else ns
        return self.Header(stamp=self.Time(sec=ns // 10**9, nanosec=ns % 10**9), frame_id=frame)

    def diagnostics(
        self, t: float, level: int, name: str, message: str, hardware_id: str, values: dict
    ) -> Any:
        status = self.Status(
            level=np.uint8(level),
            name=name,
            message=message,
            hardware_id=hardware_id,
            values=[self.KeyValue(key=k, value=str(v)) for k, v in values.items()],
        )
        return self.DiagnosticArray(header=self.header(t), status=[status])

    def health_status(
        self, d: Any, classes: list[str], joints: list[str], name: str, hardware_id: str
    ) -> Any:
        """A ``HealthDiagnosis`` as one ``DiagnosticStatus`` (see :func:`health_fields`)."""
        level, message, values = health_fields(d, classes, joints)
        return self.Status(
            level=np.uint8(level),
            name=name,
            message=message,
            hardware_id=hardware_id,
            values=[self.KeyValue(key=k, value=v) for k, v in values.items()],
        )

    def health_diagnosis(
        self, d: Any, classes: list[str], joints: list[str], ns: int | None = None
    ) -> Any:
        """The full diagnosis topic's message (one status, stamped with the sample's time: its
        exact header stamp ``ns`` where the sample came from a live bus)."""
        status = self.health_status(d, classes, joints, "health_diagnosis", d.model_id)
        return self.DiagnosticArray(header=self.header(d.stamp, ns=ns), status=[status])

    def sample_messages(self, s: GraphSample, topics: BagTopics) -> list[tuple[str, Any]]:
        """``(topic, message)`` for every topic of one sample."""
        x = s.x.astype(np.float64)
        joints = x[:N_JOINTS, STATE_CHANNELS]  # [6, 5]
        names = list(JOINT_NAMES)
        out = [
            (
                topics.joint_states,
                self.JointState(
                    header=self.header(s.t),
                    name=names,
                    position=joints[:, 0].copy(),
                    velocity=joints[:, 1].copy(),
                    effort=joints[:, 2].copy(),
                ),
            ),
            (
                topics.joint_errors,
                self.JointState(
                    header=self.header(s.t),
                    name=names,
                    position=joints[:, 3].copy(),
                    velocity=np.zeros(0),
                    effort=joints[:, 4].copy(),
                ),
            ),
        ]
        # Float64MultiArray has no header: a second, empty dimension carries the sample's stamp
        # (``stamp_ns=…``) so that a live reader pairs it with the other topics of its tick.
        dim = [
            self.Dim(label=",".join(VIBRATION_FIELDS), size=len(VIBRATION_FIELDS), stride=1),
            self.Dim(label=f"{STAMP_LABEL}{stamp_ns(s.t)}", size=0, stride=0),
        ]
        for j, joint in enumerate(JOINT_NAMES):
            row = x[N_JOINTS + j]
            acc = row[_ACC]
            frame = f"{joint}_sensor"
            imu = self.Imu(
                header=self.header(s.t, frame),
                orientation=self.Quaternion(x=0.0, y=0.0, z=0.0, w=1.0),
                orientation_covariance=UNKNOWN.copy(),
                angular_velocity=self.Vector3(x=0.0, y=0.0, z=0.0),
                angular_velocity_covariance=UNKNOWN.copy(),
                linear_acceleration=self.Vector3(x=acc[0], y=acc[1], z=acc[2]),
                linear_acceleration_covariance=np.zeros(9),
            )
            out.append((topics.imu.format(joint=joint), imu))
            vib = self.Array(layout=self.Layout(dim=dim, data_offset=0), data=row[_VIB].copy())
            out.append((topics.vibration.format(joint=joint), vib))
        out.append((topics.fault_state, self.fault_state(s)))
        return out

    def aggregated(self, s: GraphSample) -> Any:
        """The whole snapshot as one ``Float64MultiArray`` (the aggregated live layout): dims
        nodes x features (labelled with their names) and the stamp dimension."""
        layout = self.Layout(
            dim=[
                self.Dim(label=",".join(NODE_NAMES), size=N_NODES, stride=N_NODES * N_FEATURES),
                self.Dim(label=",".join(FEATURE_NAMES), size=N_FEATURES, stride=N_FEATURES),
                self.Dim(label=f"{STAMP_LABEL}{stamp_ns(s.t)}", size=0, stride=0),
            ],
            data_offset=0,
        )
        return self.Array(layout=layout, data=s.x.astype(np.float64).ravel())

    def fault_state(self, s: GraphSample) -> Any:
        f = s.fault
        message = (
            f"{f.fault_class} @ {f.joint} (severity {f.severity:g})" if f.active else "healthy"
        )
        values = {
            "class": f.fault_class,
            "joint": f.joint or "",
            "severity": f"{f.severity:.6g}",
            "active": str(f.active).lower(),
            "sample_index": s.sample_index,
            "segment": json.dumps(s.segment, separators=(",", ":"), sort_keys=True),
        }
        level = self.Status.ERROR if f.active else self.Status.OK
        return self.diagnostics(s.t, level, "fault_state", message, s.recording_run_id, values)


def array_stamp_ns(msg: Any) -> int | None:
    """The stamp a vibration array carries in its layout (see ``sample_messages``), if any."""
    for dim in getattr(getattr(msg, "layout", None), "dim", ()):
        if dim.label.startswith(STAMP_LABEL):
            return label_stamp_ns(dim.label)
    return None


def label_stamp_ns(label: str) -> int | None:
    """The stamp of a ``stamp_ns=…`` dimension label (``None``: its digits are not a number)."""
    try:
        return int(label[len(STAMP_LABEL) :])
    except ValueError:
        return None


def truth_from_status(fault: Any, where) -> tuple[FaultLabel, int, dict, str]:
    """``fault_state``'s label, sample index, segment and run id."""
    if len(fault.status) != 1:
        raise where("fault_state", f"field 'status': {len(fault.status)} entries, not 1")
    status = fault.status[0]
    values = {kv.key: kv.value for kv in status.values}
    try:
        label = FaultLabel(
            values["class"],
            values["joint"] or None,
            float(values["severity"]),
            values["active"] == "true",
        )
        index = int(values["sample_index"])
        segment = json.loads(values["segment"])
    except (KeyError, ValueError) as exc:
        raise where("fault_state", f"field 'values': {type(exc).__name__}: {exc}") from None
    return label, index, segment, status.hardware_id


def sample_from_aggregated(t: float, array: Any, fault: Any, where) -> GraphSample:
    """One GraphSample from the aggregated layout's array and its ``fault_state``."""
    if len(array.data) != N_NODES * N_FEATURES:
        raise where(
            "aggregated", f"field 'data': {len(array.data)} values, not {N_NODES * N_FEATURES}"
        )
    x = np.asarray(array.data, np.float64).reshape(N_NODES, N_FEATURES).astype(np.float32)
    label, index, segment, run_id = truth_from_status(fault, where)
    return GraphSample(run_id, index, t, x, label, segment)


# where an IMU's acceleration and a vibration array's values go among the sensor channels
_SENSOR_COLUMNS = [
    FEATURE_NAMES.index(name) - SENSOR_CHANNELS.start
    for name in ("acc_x", "acc_y", "acc_z", *VIBRATION_FIELDS)
]


def sample_from_messages(
    t: float,
    state: Any,
    errors: Any,
    imus: list[Any] | None,
    vibs: list[Any] | None,
    fault: Any | None,
    where,
    joints: Sequence[str] = JOINT_NAMES,
) -> GraphSample:
    """Assemble one GraphSample; ``where(topic_key, message)`` makes the error for a bad field.
    ``joints``: the names the joint messages give the six joints, base to tool (found by name,
    in any order). Without the sensor messages the sensor channels stay zero; without ``fault``
    the sample is healthy, numbered 0 (the reader numbers such samples by stamp)."""
    columns = []
    for key, msg, fields in (
        ("joint_states", state, ("position", "velocity", "effort")),
        ("joint_errors", errors, ("position", "effort")),
    ):
        try:
            order = joint_order(msg.name, joints)
        except ValueError as exc:
            raise where(key, str(exc)) from None
        for name in fields:
            values = getattr(msg, name)
            if len(values) != len(msg.name):
                raise where(key, f"field '{name}': {len(values)} values, not {len(msg.name)}")
            columns.append(values if order is None else np.asarray(values)[order])
    joint_state = np.stack(columns, axis=-1)
    sensor = np.zeros((N_JOINTS, SENSOR_CHANNELS.stop - SENSOR_CHANNELS.start))
    rows = []
    for j, (imu, vib) in enumerate(zip(imus or (), vibs or (), strict=True)):
        a = imu.linear_acceleration
        if len(vib.data) != len(VIBRATION_FIELDS):
            raise where(("vibration", j), f"field 'data': {len(vib.data)} values, not 5")
        rows.append((a.x, a.y, a.z, *vib.data))
    if rows:  # every joint's acceleration and vibration channels, in one assignment
        sensor[:, _SENSOR_COLUMNS] = rows
    return labelled_sample(t, node_features(joint_state, sensor).astype(np.float32), fault, where)


def labelled_sample(t: float, x: np.ndarray, fault: Any | None, where) -> GraphSample:
    """A GraphSample of features ``x [N_NODES, N_FEATURES]`` and ``fault_state``'s truth
    (``None``: healthy, numbered 0)."""
    if fault is None:
        return GraphSample("", 0, t, x, FaultLabel(), dict(UNLABELLED_SEGMENT))
    label, index, segment, run_id = truth_from_status(fault, where)
    return GraphSample(run_id, index, t, x, label, segment)


def message_values_layout() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where the per-sensor messages' numbers go in a sample's features, as
    ``x = base.copy(); x.flat[dest] = values[src]``: ``values`` is each joint's position,
    velocity, effort (joint states), position error and effort residual (tracking error), 6 x 5
    joint by joint, then each joint's IMU acceleration x, y, z and five vibration values, 6 x 8
    (absent without the sensor messages). Read off :func:`node_features`, so the two agree."""
    n_state = N_JOINTS * (STATE_CHANNELS.stop - STATE_CHANNELS.start)
    state = 2.0 + np.arange(n_state, dtype=np.float64).reshape(N_JOINTS, -1)
    sensor = np.zeros((N_JOINTS, SENSOR_CHANNELS.stop - SENSOR_CHANNELS.start))
    n_sensor = N_JOINTS * len(_SENSOR_COLUMNS)
    sensor[:, _SENSOR_COLUMNS] = 2.0 + n_state + np.arange(n_sensor).reshape(N_JOINTS, -1)
    base = node_features(np.zeros_like(state), np.zeros_like(sensor))
    coded = node_features(state, sensor)
    dest = np.flatnonzero(coded != base)
    src = (coded.ravel()[dest] - 2.0).astype(np.intp)
    return base.astype(np.float32), dest, src
