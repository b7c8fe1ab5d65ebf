"""One arm's GraphSamples from the UR ROS 2 driver's own topics, with nothing added to the robot.

- ``joint_states`` (``sensor_msgs/JointState`` from the joint state broadcaster, every controller
  cycle: 500 Hz on an e-Series): position, velocity and effort of the joints, found by name in
  whatever order (the driver lists them alphabetically) and with whatever other joints. Ticks are
  taken at the model's rate (``tick_hz``): the first message at or after each tick instant.
- ``controller_state`` (``control_msgs/JointTrajectoryControllerState`` of the trajectory
  controller, Humble or Jazzy layout): the tracking error. The controller's ``error`` is
  reference minus feedback; this project's ``pos_error`` is measured minus target (as on UR's
  RTDE and in the simulator), so it is the negated error. A tick takes the controller state the
  controller last published at or before it (sample and hold, at most ``max_age_s`` old), once a
  state at or after the tick has come (nothing nearer can follow).

Only a model that reads ``pos_error`` waits for the controller (``tracking=True``). When the
trajectory controller is inactive (freedrive, another controller, a program on the pendant) its
state stops: after ``timeout_s`` of joint states without it, the waiting ticks are dropped and the
arm is marked once, naming the topic; they resume when the state returns. A model of the reduced
``joint_states`` profile diagnoses every tick either way. The driver reports no torque model, so
``effort_residual`` stays zero (no profile that runs here reads it), and its effort is the motor
current in A: ``effort_scale`` (N*m per A per joint) converts it where the model wants torque.

Every sample is unlabelled (a real arm has no ground truth) and numbered by its tick on the
``tick_hz`` grid, so a gap (a dropped tick) restarts the model's window instead of bridging it.
"""

from __future__ import annotations

import struct
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from robohealth_mj.bags.joints import joint_order
from robohealth_mj.common.errors import InputError
from robohealth_mj.data.jsonl import node_features
from robohealth_mj.ros2.assembly import Assembled, header_stamp_ns, keep_recent
from robohealth_mj.ros2.cdr import decode, stamp_ns_at, undecodable
from robohealth_mj.schema import (
    SENSOR_FEATURES,
    STATE_CHANNELS,
    STATE_FEATURES,
    UNLABELLED_SEGMENT,
    FaultLabel,
    GraphSample,
)

_POS, _VEL, _EFFORT, _POS_ERROR = (
    STATE_FEATURES.index(n) for n in ("pos", "vel", "effort", "pos_error")
)


# The ROS 2 distributions the UR driver supports -> the controller state's layout (idl.py).
DISTROS = {"humble": "humble", "jazzy": "jazzy", "kilted": "jazzy", "rolling": "jazzy"}


@dataclass(frozen=True)
class DriverConfig:
    """The driver's side of ``conf/ros2/default.yaml`` (``ros2.layout=ur_driver``)."""

    controller_state: str = "scaled_joint_trajectory_controller/controller_state"
    distro: str = "jazzy"  # the ROS 2 distribution: the controller state's layout
    tracking: bool = True  # the model reads pos_error: wait for the controller's state
    tick_hz: float = 20.0
    timeout_s: float = 0.5
    effort_scale: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        if self.distro not in DISTROS:
            raise InputError(f"ros2.distro must be one of {list(DISTROS)}, got {self.distro!r}")
        if self.tick_hz <= 0 or self.timeout_s <= 0:
            raise InputError(
                f"ros2.tick_hz and ros2.controller_timeout_s must be positive, got "
                f"{self.tick_hz} and {self.timeout_s}"
            )

    @property
    def layout(self) -> str:
        """The controller state's field layout: ``humble`` or ``jazzy``."""
        return DISTROS[self.distro]


class _Problem(Exception):
    pass


class DriverAssembler:
    """Assembles one arm's samples from ``joint_states`` and, with ``tracking``, the trajectory
    controller's ``controller_state`` (same interface as :class:`~robohealth_mj.ros2.assembly.
    ArmAssembler`: :meth:`add` per message, :meth:`settle` at each poll boundary)."""

    def __init__(
        self,
        arm: str,
        joint_states: str,
        controller_state: str,
        joints: Sequence[str],
        config: DriverConfig | None = None,
        max_age_s: float = 0.1,
        history: int = 10,
    ) -> None:
        """``joint_states`` and ``controller_state``: the arm's topic names; ``joints``: the
        names its driver gives its joints, base to tool (any ros2_control arm: a UR's six, an
        FR3's seven). ``history``: the bus's history depth, how many messages back a reliable
        writer can still re-deliver."""
        config = config or DriverConfig()
        self.arm, self.joint_states, self.controller_state = arm, joint_states, controller_state
        self.joints, self.tracking = tuple(joints), config.tracking
        self.period_ns = round(1e9 / config.tick_hz)
        self.timeout_ns, self.max_age_ns = round(config.timeout_s * 1e9), round(max_age_s * 1e9)
        scale = config.effort_scale
        self.scale = None if scale is None else np.asarray(scale, np.float64)
        if self.scale is not None and self.scale.shape != (len(self.joints),):
            raise InputError(
                f"ros2.effort_scale: {len(self.joints)} numbers (N*m per A), one per joint, got "
                f"{list(scale)}"
            )
        self.origin: int | None = None  # the tick grid's first instant
        self.next_tick: int | None = None
        self.last_state: tuple[int, Any] | None = None  # the newest joint_states (stamp, msg)
        self.pending: deque[tuple[int, np.ndarray]] = deque()  # ticks waiting for the controller
        self.errors: deque[tuple[int, np.ndarray]] = deque(maxlen=256)  # (stamp, pos_error [J])
        self.last_error: tuple[int, Any] | None = None
        # each topic's last ``history`` messages by stamp: a re-delivery of any is a duplicate
        self.recent: dict[str, dict[int, Any]] = {joint_states: {}, controller_state: {}}
        self.history = max(history, 1)
        self.silent = False  # the controller is reported silent until its state returns

    def topic_names(self) -> list[str]:
        return [self.joint_states, *([self.controller_state] if self.tracking else [])]

    def add(self, topic: str, msg: Any) -> Assembled:
        """Take one message; return the samples it completed and any problems."""
        out = Assembled()
        stamp = header_stamp_ns(msg)
        if stamp is None:
            out.problems.append(f"topic '{topic}': message without a header stamp")
            return out
        last = self.last_state if topic == self.joint_states else self.last_error
        if last is not None and stamp <= last[0]:
            self._not_after(topic, stamp, msg, last[0], out)
            return out
        keep_recent(self.recent[topic], stamp, msg, self.history)
        try:
            if topic == self.joint_states:
                self.last_state = (stamp, msg)
                self._joint_state(stamp, msg, out)
            else:
                self.last_error = (stamp, msg)
                self._tracking_error(stamp, msg)
        except _Problem as exc:
            out.problems.append(f"topic '{topic}' at stamp {stamp / 1e9:.6f} s: {exc}")
        self._drain(out, settle=False)
        return out

    def add_serialized(self, topic: str, kind: type, buffers: list[bytes], out: Assembled) -> None:
        """Take one topic's messages as they came off the wire, into ``out``, decoding only
        what a tick uses. At 500 Hz the driver sends 25 joint states and 25 controller states
        per 20 Hz tick and a tick reads one of each: a joint state between ticks is passed
        over from its stamp alone (8 bytes), and a controller state is kept as bytes until a
        tick takes it (:meth:`_held_error`). A malformed message a tick never uses is
        therefore not reported."""
        joint_states = topic == self.joint_states
        for buf in buffers:
            try:
                stamp = stamp_ns_at(buf)
            except struct.error:
                out.problems.append(f"topic '{topic}': {len(buf)} bytes, too short for a header")
                continue
            last = self.last_state if joint_states else self.last_error
            if last is not None and stamp <= last[0]:
                self._not_after(topic, stamp, buf, last[0], out)
                continue
            keep_recent(self.recent[topic], stamp, buf, self.history)
            if not joint_states:
                self.last_error = (stamp, buf)
                self.errors.append((stamp, (kind, buf)))  # decoded when a tick takes it
                self.silent = False
            else:
                self.last_state = (stamp, buf)
                if self._between_ticks(stamp):
                    continue
                try:
                    self._joint_state(stamp, decode(kind, buf), out)
                except _Problem as exc:
                    out.problems.append(f"topic '{topic}' at stamp {stamp / 1e9:.6f} s: {exc}")
                except Exception as exc:  # bytes no decoder reads: this arm's bad input
                    out.problems.append(f"topic '{topic}': {undecodable(kind, exc)}")
            self._drain(out, settle=False)

    def _not_after(self, topic: str, stamp: int, msg: Any, last: int, out: Assembled) -> None:
        """A message not newer than the topic's last: a re-delivery of one of its recent
        messages, or stamps going back."""
        if stamp in self.recent[topic] and self.recent[topic][stamp] == msg:
            out.duplicates += 1
        else:
            out.problems.append(
                f"topic '{topic}': stamp {stamp / 1e9:.6f} s is not after the last message "
                f"({last / 1e9:.6f} s): stamps went backwards"
            )

    def _between_ticks(self, stamp: int) -> bool:
        """Whether a joint state falls between two ticks: the driver publishes faster than the
        model reads."""
        return self.next_tick is not None and stamp < self.next_tick - self.period_ns // 100

    def add_all(self, topic: str, messages: list[Any], out: Assembled) -> None:
        """Take one topic's messages in order, into ``out``."""
        for msg in messages:
            out.extend(self.add(topic, msg))

    def settle(self) -> Assembled:
        """At a poll boundary: drop the ticks the silent controller cannot serve."""
        out = Assembled()
        self._drain(out, settle=True)
        return out

    def _columns(self, msg: Any, names: Sequence[str], point: Any, fields: Sequence[str]) -> list:
        try:
            order = joint_order(names, self.joints)
        except ValueError as exc:
            raise _Problem(str(exc)) from None
        columns = []
        for name in fields:
            values = np.asarray(getattr(point, name), np.float64)
            if len(values) != len(names):
                raise _Problem(f"field '{name}': {len(values)} values, not {len(names)}")
            values = values if order is None else values[order]
            bad = np.flatnonzero(~np.isfinite(values))
            if bad.size:
                raise _Problem(f"field '{name}': NaN or Inf at joint '{self.joints[bad[0]]}'")
            columns.append(values)
        return columns

    def _joint_state(self, stamp: int, msg: Any, out: Assembled) -> None:
        if self._between_ticks(stamp):
            return
        pos, vel, effort = self._columns(msg, msg.name, msg, ("position", "velocity", "effort"))
        if self.scale is not None:
            effort = effort * self.scale
        state = np.zeros((len(self.joints), len(STATE_FEATURES)))
        state[:, _POS], state[:, _VEL], state[:, _EFFORT] = pos, vel, effort
        if self.origin is None:
            self.origin = stamp
        behind = self.next_tick is not None and stamp < self.next_tick + self.period_ns
        self.next_tick = (self.next_tick if behind else stamp) + self.period_ns
        if self.tracking:
            self.pending.append((stamp, state))
        else:
            out.samples.append(self._sample(stamp, state))

    def _tracking_error(self, stamp: int, msg: Any) -> None:
        self.errors.append((stamp, self._error_of(msg)))
        self.silent = False

    def _error_of(self, msg: Any) -> np.ndarray:
        """A controller state's tracking error as this project reads it (measured - target)."""
        (error,) = self._columns(msg, msg.joint_names, msg.error, ("positions",))
        return -error

    def _held_error(self, tick: int) -> np.ndarray | None:
        """The controller's tracking error at ``tick``: its last state at or before it
        (decoded here where it came as bytes)."""
        for k in range(len(self.errors) - 1, -1, -1):
            stamp, error = self.errors[k]
            if stamp <= tick:
                if tick - stamp > self.max_age_ns:
                    return None
                if isinstance(error, tuple):  # (kind, bytes): the first tick to use it
                    kind, buf = error
                    try:
                        message = decode(kind, buf)
                    except Exception as exc:
                        raise _Problem(undecodable(kind, exc)) from None
                    error = self._error_of(message)
                    self.errors[k] = (stamp, error)
                return error
        return None

    def _drain(self, out: Assembled, settle: bool) -> None:
        newest = self.errors[-1][0] if self.errors else None
        while self.pending:
            tick, state = self.pending[0]
            if newest is not None and newest >= tick:  # nothing nearer can come
                self.pending.popleft()
                try:
                    error = self._held_error(tick)
                except _Problem as exc:  # the state this tick takes is malformed: dropped
                    out.problems.append(f"topic '{self.controller_state}' at tick "
                                        f"{tick / 1e9:.6f} s: {exc}")  # fmt: skip
                    continue
                if error is not None:  # else too old to trust: the tick is dropped
                    state[:, _POS_ERROR] = error
                    out.samples.append(self._sample(tick, state))
                continue
            heard = newest if newest is not None else self.origin
            if not settle or self.last_state[0] - heard <= self.timeout_ns:
                return
            self.pending.popleft()  # the controller is silent: this tick has no tracking error
            if not self.silent:
                self.silent = True
                out.problems.append(
                    f"topic '{self.controller_state}': no controller state for "
                    f"{(self.last_state[0] - heard) / 1e9:.1f} s of joint states (trajectory "
                    "controller inactive?); the model reads pos_error, so ticks are dropped "
                    "until it returns (a model of sensing=joint_states runs without it)"
                )

    def _sample(self, stamp: int, state: np.ndarray) -> GraphSample:
        no_sensors = np.zeros((len(self.joints), len(SENSOR_FEATURES)))
        x = node_features(state, no_sensors).astype(np.float32)
        index = round((stamp - self.origin) / self.period_ns)
        return GraphSample(self.arm, index, stamp / 1e9, x, FaultLabel(),
                           dict(UNLABELLED_SEGMENT), stamp)  # fmt: skip


class DriverMessages:
    """A GraphSample as the UR driver would publish it (a simulated or replayed arm standing in
    for one, ``python -m robohealth_mj.robot ros2.layout=ur_driver``): ``joint_states`` with
    ``joints`` listed alphabetically, and the controller state in ``config.distro``'s layout
    (reference = measured - ``pos_error``, so that its error is the negated ``pos_error``)."""

    def __init__(self, joints: Sequence[str], config: DriverConfig) -> None:
        from robohealth_mj.ros2.idl import CONTROLLER_STATES, JointState, JointTrajectoryPoint

        self.config, self.joints = config, tuple(joints)
        self.order = sorted(range(len(self.joints)), key=lambda k: self.joints[k])
        self.names = [self.joints[k] for k in self.order]
        self.State, self.Point = CONTROLLER_STATES[config.layout], JointTrajectoryPoint
        self.JointState = JointState

    def messages(self, sample: GraphSample) -> list[Any]:
        """``[joint_states, controller_state]`` of one sample, stamped with its time."""
        from robohealth_mj.ros2.idl import Header, Time

        state = sample.x[: len(self.joints), STATE_CHANNELS].astype(np.float64)[self.order]

        def column(k: int) -> list[float]:
            return state[:, k].tolist()

        ns = round(sample.t * 1e9)

        def header() -> Any:
            return Header(stamp=Time(sec=ns // 10**9, nanosec=ns % 10**9))

        scale = self.config.effort_scale
        effort = state[:, _EFFORT] / (1.0 if scale is None else np.asarray(scale)[self.order])
        joint_states = self.JointState(header=header(), name=list(self.names),
                                       position=column(_POS), velocity=column(_VEL),
                                       effort=effort.tolist())  # fmt: skip
        error = state[:, _POS_ERROR]
        controller = self.State(
            header=header(),
            joint_names=list(self.names),
            reference=self.Point(positions=(state[:, _POS] - error).tolist()),
            feedback=self.Point(positions=column(_POS), velocities=column(_VEL)),
            error=self.Point(positions=(-error).tolist()),
        )
        return [joint_states, controller]
