"""One arm's GraphSamples from its topics as messages arrive, in any order across topics.

Stamped topics (joint states, tracking error, each IMU, the ground truth) are keyed by their
header stamp, a vibration array by the stamp its layout carries (``stamp_ns=``); an array without
one (another publisher's) queues in arrival order and the oldest goes with the oldest stamp. A stamp
is emitted once every topic has its message, in stamp order.

What goes wrong on a live bus is returned for that arm, never raised. Problems (bad input): a
message that does not assemble (wrong array length, unknown joint order, NaN), a second,
different message at one stamp, a stamp older than every recent one (the clock went back), and a
tick whose messages stopped coming while newer ones completed. That last judgement is made only
at a poll boundary (:meth:`ArmAssembler.settle`, once every reader has been taken): a monitor
takes its topics one after another, so mid-poll the stamped topics of a long backlog are in while
the arrays of the same ticks are still in their readers. Not problems, counted apart: a repeated
identical message (``duplicates``: a re-delivery or re-publish) and a message for a tick already
reported missing (``late``).
"""

from __future__ import annotations

import json
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from robohealth_mj.bags.messages import (
    array_stamp_ns,
    labelled_sample,
    sample_from_aggregated,
    sample_from_messages,
)
from robohealth_mj.bags.topics import BagTopics
from robohealth_mj.ros2.cdr import MessageView, read, undecodable
from robohealth_mj.ros2.templates import SampleGather, Template, template_of
from robohealth_mj.schema import FEATURE_NAMES, JOINT_NAMES, NODE_NAMES, FaultLabel, GraphSample

UNKNOWN_TRUTH = FaultLabel("none", None, 0.0, False)


@dataclass
class Assembled:
    samples: list[GraphSample] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)
    duplicates: int = 0  # repeated identical messages, dropped
    late: int = 0  # messages for ticks already reported missing, dropped

    def extend(self, other: Assembled) -> None:
        self.samples += other.samples
        self.problems += other.problems
        self.duplicates += other.duplicates
        self.late += other.late


def header_stamp_ns(msg: Any) -> int | None:
    header = getattr(msg, "header", None)
    return None if header is None else int(header.stamp.sec) * 10**9 + int(header.stamp.nanosec)


class _Problem(Exception):
    pass


def keep_recent(store: dict[int, Any], stamp: int, value: Any, kept: int) -> None:
    """Remember ``value`` at ``stamp`` among the last ``kept`` (stamps come rising, so the
    first key is the oldest): how far back a re-delivery is still told from bad input."""
    store[stamp] = value
    if len(store) > kept:
        del store[next(iter(store))]


class ArmAssembler:
    """Assembles one arm's samples; ``topics`` are that arm's (namespaced) topic names."""

    def __init__(
        self,
        arm: str,
        topics: BagTopics,
        require_truth: bool = True,
        late_ticks: int = 10,
        aggregated: str | None = None,
        sensors: bool = True,
        joints: Sequence[str] = JOINT_NAMES,
        history: int = 10,
    ) -> None:
        """``history``: the bus's history depth, how many ticks back a reliable writer can still
        re-deliver (Cyclone re-sends a late-matched reader's first samples after newer ones)."""
        self.arm, self.topics, self.aggregated = arm, topics, aggregated
        self.joints = tuple(joints)  # what this arm's JointState messages call its joints
        self.require_truth, self.late_ticks, self.sensors = require_truth, late_ticks, sensors
        if aggregated:  # one array per tick carries the whole snapshot
            self.vibration, self.imu, self.stamped = [], [], [aggregated]
        elif not sensors:  # a stock arm: its joint state and tracking error only
            self.vibration, self.imu = [], []
            self.stamped = [topics.joint_states, topics.joint_errors]
        else:
            self.vibration = [topics.vibration.format(joint=j) for j in JOINT_NAMES]
            self.imu = [topics.imu.format(joint=j) for j in JOINT_NAMES]
            self.stamped = [topics.joint_states, topics.joint_errors, *self.imu]
        if require_truth:
            self.stamped.append(topics.fault_state)
        self._stamped_set, self._every = frozenset(self.stamped), frozenset(self.topic_names())
        self._n_every = len(self._every)
        # what each topic's numbers are in a sample, for its byte template (per-sensor layouts)
        self.roles = {topics.joint_states: "joint_states", topics.joint_errors: "joint_errors"}
        self.roles |= {t: "imu" for t in self.imu} | {t: "vibration" for t in self.vibration}
        self.roles[topics.fault_state] = "truth"
        if aggregated:
            self.roles[aggregated] = "aggregated"
        self.templates: dict[str, Template | None] = {}
        self.gather = SampleGather("aggregated" if aggregated else "per_sensor" if sensors
                                   else "joints")  # fmt: skip
        self.pending: dict[int, dict[str, Any]] = {}
        self.queues: dict[str, deque] = {t: deque() for t in self.vibration}
        self.last_emitted: int | None = None
        # the messages of the last settled (emitted or missed) ticks, to tell a duplicate or a
        # late message from a stamp that went backwards: as far back as a writer re-delivers
        self.settled: dict[int, dict[str, Any]] = {}
        self.settled_kept = max(4 * late_ticks, 32, history)
        self.count = 0

    def topic_names(self) -> list[str]:
        return [*self.stamped, *self.vibration]

    def add(self, topic: str, msg: Any) -> Assembled:
        """Take one message; return the samples it completed and any problems."""
        out = Assembled()
        self._add(topic, msg, out)
        return out

    def add_all(self, topic: str, messages: list[Any], out: Assembled) -> None:
        """Take one topic's messages in order, into ``out`` (a reader's take at a time)."""
        for msg in messages:
            self._add(topic, msg, out)

    def add_serialized(self, topic: str, kind: type, buffers: list[bytes], out: Assembled) -> None:
        """Take one topic's messages as they came off the wire, into ``out``: a message of the
        topic's byte template is kept as its bytes and stamp; any other is read in full (the
        binding decides what that one is), and its layout becomes the topic's template."""
        template = self.templates.get(topic)
        for buf in buffers:
            msg = template.view(buf) if template is not None else None
            if msg is None:
                try:
                    msg = read(kind, buf)
                except Exception as exc:  # a buffer no decoder reads is this arm's bad input
                    out.problems.append(f"topic '{topic}': {undecodable(kind, exc)}")
                    continue
                if isinstance(msg, MessageView):
                    template = template_of(msg, self.roles.get(topic, ""), self.joints)
                    self.templates[topic] = msg.template = template
            self._add(topic, msg, out)

    def _stamp(self, topic: str, msg: Any) -> int | None:
        if isinstance(msg, MessageView):  # read from the bytes with the rest of the view
            return msg.stamp_ns
        headerless = topic in self.queues or topic == self.aggregated
        return array_stamp_ns(msg) if headerless else header_stamp_ns(msg)

    def _add(self, topic: str, msg: Any, out: Assembled) -> None:
        stamp = self._stamp(topic, msg)
        if stamp is None and topic in self.queues:  # an array without a stamp: by arrival
            self.queues[topic].append(msg)
            self._drain(out, drop_late=False)
            return
        if stamp is None:
            out.problems.append(f"topic '{topic}': message without a header stamp")
            return
        if self.last_emitted is not None and stamp <= self.last_emitted:
            self._settled_message(topic, stamp, msg, out)
            return
        slot = self.pending.get(stamp)
        if slot is None:
            slot = self.pending[stamp] = {}
        elif topic in slot:
            self._repeated(topic, stamp, slot[topic], msg, out)
            return
        slot[topic] = msg
        # Only a slot that is now complete (or arrays queued by arrival) can let a tick out:
        # adding to an incomplete tick changes nothing older.
        if len(slot) == self._n_every or self._queued():
            self._drain(out, drop_late=False)

    def _queued(self) -> bool:
        return any(self.queues.values()) if self.queues else False

    def settle(self) -> Assembled:
        """At a poll boundary: report the ticks that stay incomplete while ``late_ticks`` newer
        ones have every stamped topic, and emit what waited behind them."""
        out = Assembled()
        self._drain(out, drop_late=True)
        return out

    def _repeated(self, topic: str, stamp: int, first: Any, msg: Any, out: Assembled) -> None:
        if msg == first:
            out.duplicates += 1
        else:
            out.problems.append(
                f"topic '{topic}': a second, different message at stamp {stamp / 1e9:.6f} s"
            )

    def _settled_message(self, topic: str, stamp: int, msg: Any, out: Assembled) -> None:
        """A message at or before the last emitted stamp: a duplicate of one already used, a
        late one for a tick reported missing, or a stamp from before the recent ticks."""
        slot = self.settled.get(stamp)
        if slot is None:
            out.problems.append(
                f"topic '{topic}': stamp {stamp / 1e9:.6f} s is not after the last sample "
                f"({self.last_emitted / 1e9:.6f} s): stamps went backwards"
            )
        elif topic in slot:
            self._repeated(topic, stamp, slot[topic], msg, out)
        else:
            out.late += 1

    def _settle(self, stamp: int, slot: dict[str, Any]) -> None:
        del self.pending[stamp]
        self.last_emitted = stamp
        keep_recent(self.settled, stamp, slot, self.settled_kept)

    def _stamped_in(self, slot: dict[str, Any]) -> bool:
        return self._stamped_set <= slot.keys()

    def _complete(self, slot: dict[str, Any]) -> bool:
        if self._every <= slot.keys():  # every topic's message at this stamp (the usual case)
            return True
        return self._stamped_in(slot) and all(t in slot or self.queues[t] for t in self.vibration)

    def _drain(self, out: Assembled, drop_late: bool) -> None:
        while self.pending:
            oldest = min(self.pending)
            slot = self.pending[oldest]
            if self._complete(slot):
                vibs = [slot[t] if t in slot else self.queues[t].popleft() for t in self.vibration]
                self._settle(oldest, slot)
                try:
                    out.samples.append(self._sample(oldest, slot, vibs))
                except _Problem as exc:
                    out.problems.append(str(exc))
                continue
            if not drop_late:
                return
            newer_complete = sum(
                1 for s, sl in self.pending.items() if s > oldest and self._stamped_in(sl)
            )
            if newer_complete < self.late_ticks:
                return
            missing = [t for t in self.stamped if t not in slot] or [
                t for t in self.vibration if t not in slot and not self.queues[t]
            ]
            self._settle(oldest, slot)
            out.problems.append(
                f"topic '{missing[0]}' at stamp {oldest / 1e9:.6f} s: message missing "
                f"({len(missing)} topics)"
            )

    def _sample(self, stamp: int, slot: dict[str, Any], vibs: list[Any]) -> GraphSample:
        def where(key, message: str) -> _Problem:
            if key == "aggregated":
                topic = self.aggregated
            else:
                topic = (
                    getattr(self.topics, key) if isinstance(key, str) else self.vibration[key[1]]
                )
            return _Problem(f"topic '{topic}' {_at(stamp)}: {message}")

        truth = slot.get(self.topics.fault_state) if self.require_truth else None
        truth = truth if truth is not None else _NoTruth(self.arm, self.count)
        if self.aggregated:
            parts = [slot[self.aggregated]]
        else:
            parts = [slot[self.topics.joint_states], slot[self.topics.joint_errors]]
            if self.sensors:
                parts += [*(slot[t] for t in self.imu), *vibs]
        if all(isinstance(m, MessageView) and m.template is not None for m in parts):
            x = self.gather.features(parts)
            if np.isfinite(x).all():  # else the full reading below names the bad field
                if isinstance(truth, MessageView) and truth.template is not None:
                    label, segment, run_id = truth.template.truth
                    sample = GraphSample(run_id, truth.index, stamp / 1e9, x, label,
                                         json.loads(segment), stamp)  # fmt: skip
                else:
                    try:
                        sample = labelled_sample(stamp / 1e9, x, _in_full(truth), where)
                        sample = replace(sample, stamp_ns=stamp)
                    except (AttributeError, TypeError, ValueError) as exc:
                        raise _Problem(f"{_at(stamp)}: malformed message ({exc})") from None
                self.count += 1
                return sample
        # read what was kept as bytes, as the message path reads it
        slot = {t: _in_full(m) for t, m in slot.items()}
        vibs, truth = [_in_full(m) for m in vibs], _in_full(truth)
        try:
            if self.aggregated:
                sample = sample_from_aggregated(stamp / 1e9, slot[self.aggregated], truth, where)
            else:
                sample = sample_from_messages(
                    stamp / 1e9,
                    slot[self.topics.joint_states],
                    slot[self.topics.joint_errors],
                    [slot[t] for t in self.imu] if self.sensors else None,
                    vibs if self.sensors else None,
                    truth,
                    where,
                    self.joints,
                )
        except (AttributeError, TypeError, ValueError) as exc:
            raise _Problem(f"{_at(stamp)}: malformed message ({exc})") from None
        bad = np.argwhere(~np.isfinite(sample.x))
        if bad.size:
            node, feat = bad[0]
            topic = self._topic_of(int(node), FEATURE_NAMES[feat])
            raise _Problem(
                f"topic '{topic}' {_at(stamp)}: NaN or Inf in x[{NODE_NAMES[node]}]."
                f"{FEATURE_NAMES[feat]}"
            )
        self.count += 1
        return sample

    def _topic_of(self, node: int, feature: str) -> str:
        """The topic that carried ``feature`` of ``node``: joint state and tracking error are
        every node's own joint's, the package's channels its sensor's."""
        if self.aggregated:
            return self.aggregated
        joint = JOINT_NAMES[node % len(JOINT_NAMES)]
        if feature in ("pos", "vel", "effort"):
            return self.topics.joint_states
        if feature in ("pos_error", "effort_residual"):
            return self.topics.joint_errors
        kind = self.topics.imu if feature.startswith("acc_") else self.topics.vibration
        return kind.format(joint=joint)


def _at(stamp: int) -> str:
    """Where a problem is, in time (made only for a problem: not on every sample)."""
    return f"at stamp {stamp / 1e9:.6f} s"


def _in_full(msg: Any) -> Any:
    """A message kept as its bytes and stamp, read in full (other messages as they are)."""
    if isinstance(msg, MessageView) and msg.template is not None:
        return read(msg.kind, msg.raw)
    return msg


class _NoTruth:
    """Stands in for ``/fault_state`` on a robot that publishes no ground truth: the sample is
    numbered by arrival and labelled healthy-unknown."""

    def __init__(self, arm: str, index: int) -> None:
        from types import SimpleNamespace

        values = [
            SimpleNamespace(key=k, value=v)
            for k, v in (("class", "none"), ("joint", ""), ("severity", "0"), ("active", "false"),
                         ("sample_index", str(index)), ("segment", "{}"))
        ]  # fmt: skip
        self.status = [SimpleNamespace(hardware_id=arm, values=values)]
