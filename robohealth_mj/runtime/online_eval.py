"""On-line evaluation: diagnoses and alarms logged against the true fault state (thesis §4.7).

An *episode* is a run of consecutive ticks with the same active fault (class, joint, severity).

Per-tick decisions give the on-line accuracy, localisation accuracy and the raw per-tick
false-positive rate. The operator sees alarms, so the headline figures are the alarms':

- an episode is *detected* when any alarm is up during it; its latency *to class* runs from the
  onset to the first tick whose alarm has the right class, *to joint* to the first tick whose
  alarm names the right joint;
- false alarms are counted on *settled* healthy ticks: healthy, and at least ``settle_ticks``
  ticks (the window plus the alarm's clearing run) after the last faulted tick, because until
  then the model's window still holds faulted samples and the alarm is still clearing. The rate
  is the share of settled healthy ticks with an alarm up; per hour counts alarms raised on settled
  healthy ticks per hour of settled healthy running.

Ticks without a decision (window warming up, invalid samples) count towards latency but not
towards the accuracies.

What the operator acts on is the alarm as it rises, so each detected episode also records whether
the alarm's class and joint were right *at the tick it rose* (not only eventually). Detection is
given per class x joint, and, given each tick's joint speeds and torques, per episode whether the
faulted joint ever moved and whether it carried load: friction on a joint that never moves and
structural weakening of a joint that carries no load change nothing any channel sees, so those
episodes are counted apart (``physically_hidden``) and the rest (``observable``) are the ceiling
a detector can reach.

The contact watch's calls (:mod:`robohealth_mj.runtime.contact`) are counted apart: its ticks
and its calls (a call: a run of contact ticks), over every tick. No fault label marks a push, so
on running without one every call is a false one.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from robohealth_mj import schema
from robohealth_mj.arms.description import DEFAULT_ARM
from robohealth_mj.arms.ratings import joint_keys, rated_torque_nm
from robohealth_mj.data.observability import MOVING_RAD_S
from robohealth_mj.runtime.runtime import HealthDiagnosis
from robohealth_mj.schema import FaultLabel


@dataclass
class _Episode:
    label: FaultLabel
    onset: int
    last: int
    class_tick: int | None = None  # first tick of a per-tick decision with the right class
    joint_tick: int | None = None
    alarm_tick: int | None = None  # first tick with any alarm up
    alarm_class_tick: int | None = None  # first tick with an alarm of the right class
    alarm_joint_tick: int | None = None  # first tick with an alarm naming the right joint
    rise_class: str | None = None  # the alarm's class and joint at its first tick in the episode
    rise_joint: str | None = None
    peak_speed: float | None = None  # max |velocity| of the faulted joint (rad/s), if known
    torque_sq: float = 0.0  # sum of its squared torque (N m^2) over the ticks with activity
    activity_ticks: int = 0

    def rms_torque(self) -> float | None:
        return (self.torque_sq / self.activity_ticks) ** 0.5 if self.activity_ticks else None


# What a fault needs to show at all (see physically_hidden): motion for friction, load for weakening
MOVED_SPEED = MOVING_RAD_S  # rad/s: 50 x the velocity noise floor (windows, observability too)
LOADED_SHARE = 0.05  # RMS torque as a share of the joint's rated torque


def joint_activity(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The joints' speeds ``|vel|`` and torques (effort) of snapshots ``x [..., 2J, F]``, each
    ``[..., J]``: what :meth:`OnlineEvaluator.update` takes for the physically hidden strata."""
    joints = x[..., : x.shape[-2] // 2, :]
    return np.abs(joints[..., schema.feature_index("vel")]), joints[
        ..., schema.feature_index("effort")
    ].copy()


def physically_hidden(
    ep: _Episode, rated_torque: np.ndarray, joints: tuple[str, ...] = schema.JOINT_NAMES
) -> bool | None:
    """Whether nothing about this episode's fault reaches any channel: friction on a joint that
    never moved, structural weakening of a joint that never carried load (None: not known);
    ``joints``: the arm's, in the order of ``rated_torque``."""
    if ep.peak_speed is None or ep.label.joint is None:
        return None
    j = joints.index(ep.label.joint)
    if ep.label.fault_class == "friction":
        return ep.peak_speed < MOVED_SPEED
    if ep.label.fault_class == "struct_weaken":
        return ep.rms_torque() < LOADED_SHARE * rated_torque[j]
    return False


@dataclass
class OnlineEvaluator:
    tick_s: float = 0.05
    arm: str = DEFAULT_ARM  # whose rated torques the fed torques are read against
    settle_ticks: int = 0
    decided: int = 0
    correct: int = 0
    faulted: int = 0
    localised: int = 0
    healthy: int = 0
    false_positives: int = 0
    settled: int = 0
    settled_alarm_ticks: int = 0
    false_alarms: int = 0
    contact_ticks: int = 0
    contact_calls: int = 0
    episodes: list[_Episode] = field(default_factory=list)
    _tick: int = 0
    _last_faulted: int | None = None
    _in_contact: bool = False

    def update(
        self,
        truth: FaultLabel,
        d: HealthDiagnosis,
        speed: np.ndarray | None = None,
        torque: np.ndarray | None = None,
    ) -> None:
        """One tick: its truth, its diagnosis, and (optional) the joints' measured speeds and
        torques ``[J]`` at this tick, for the physically-hidden strata."""
        tick = self._tick
        self._tick += 1
        current = self.episodes[-1] if self.episodes else None
        alarm_up = d.alarm_class is not None
        self.contact_ticks += d.contact
        self.contact_calls += d.contact and not self._in_contact
        self._in_contact = d.contact
        if truth.active:
            key = (truth.fault_class, truth.joint, truth.severity)
            if (
                current is None
                or current.last != tick - 1
                or (current.label.fault_class, current.label.joint, current.label.severity) != key
            ):
                current = _Episode(truth, tick, tick)
                self.episodes.append(current)
            current.last = tick
            self._last_faulted = tick
            if speed is not None and torque is not None and truth.joint is not None:
                j = joint_keys(self.arm).index(truth.joint)
                current.peak_speed = max(current.peak_speed or 0.0, abs(float(speed[j])))
                current.torque_sq += float(torque[j]) ** 2
                current.activity_ticks += 1
            if alarm_up:
                if current.alarm_tick is None:
                    current.alarm_tick = tick
                    current.rise_class, current.rise_joint = d.alarm_class, d.alarm_joint
                if current.alarm_class_tick is None and d.alarm_class == truth.fault_class:
                    current.alarm_class_tick = tick
                if current.alarm_joint_tick is None and d.alarm_joint == truth.joint:
                    current.alarm_joint_tick = tick
        elif self._last_faulted is None or tick - self._last_faulted > self.settle_ticks:
            self.settled += 1
            self.settled_alarm_ticks += alarm_up
            self.false_alarms += d.alarm == "raised"
        decided = d.valid and d.fault_class is not None
        if not decided:
            return
        self.decided += 1
        self.correct += d.fault_class == truth.fault_class
        if truth.active:
            self.faulted += 1
            self.localised += d.localised_joint == truth.joint
            if current.class_tick is None and d.fault_class == truth.fault_class:
                current.class_tick = tick
            if current.joint_tick is None and d.fault_present and d.localised_joint == truth.joint:
                current.joint_tick = tick
        else:
            self.healthy += 1
            self.false_positives += d.fault_present

    def result(self) -> dict[str, Any]:
        def rate(a: float, b: float) -> float | None:
            return a / b if b else None

        by_class: dict[str, list[_Episode]] = defaultdict(list)
        by_severity: dict[str, list[_Episode]] = defaultdict(list)
        by_both: dict[str, list[_Episode]] = defaultdict(list)
        by_joint: dict[str, list[_Episode]] = defaultdict(list)
        by_visibility: dict[str, list[_Episode]] = defaultdict(list)
        rated = rated_torque_nm(self.arm)
        for ep in self.episodes:
            by_class[ep.label.fault_class].append(ep)
            by_severity[f"{ep.label.severity:g}"].append(ep)
            by_both[f"{ep.label.fault_class}@{ep.label.severity:g}"].append(ep)
            by_joint[f"{ep.label.fault_class}@{ep.label.joint}"].append(ep)
            hidden = physically_hidden(ep, rated, joint_keys(self.arm))
            if hidden is not None:
                by_visibility["physically_hidden" if hidden else "observable"].append(ep)
        settled_hours = self.settled * self.tick_s / 3600.0
        return {
            "ticks": self._tick,
            "decided_ticks": self.decided,
            "online_accuracy": rate(self.correct, self.decided),
            "localisation_accuracy": rate(self.localised, self.faulted),
            "false_positive_rate": rate(self.false_positives, self.healthy),
            "settle_ticks": self.settle_ticks,
            "settled_healthy_ticks": self.settled,
            "false_alarm_rate": rate(self.settled_alarm_ticks, self.settled),
            "false_alarms": self.false_alarms,
            "false_alarms_per_hour": rate(self.false_alarms, settled_hours),
            "contact_ticks": self.contact_ticks,
            "contact_calls": self.contact_calls,
            "contact_calls_per_hour": rate(self.contact_calls, self._tick * self.tick_s / 3600),
            "episodes": len(self.episodes),
            "alarms": self._summary(self.episodes),
            "alarms_by_class": {k: self._summary(v) for k, v in sorted(by_class.items())},
            "alarms_by_severity": {k: self._summary(v) for k, v in sorted(by_severity.items())},
            "alarms_by_class_and_severity": {
                k: self._summary(v) for k, v in sorted(by_both.items())
            },
            "alarms_by_class_and_joint": {k: self._summary(v) for k, v in sorted(by_joint.items())},
            "alarms_by_visibility": {k: self._summary(v) for k, v in sorted(by_visibility.items())},
            "physically_hidden_episodes": [
                f"{e.label.fault_class}@{e.label.joint}@{e.label.severity:g}"
                for e in by_visibility.get("physically_hidden", [])
            ],
            "detection_latency": self._latency(self.episodes),
            "detection_latency_by_class": {
                k: self._latency(v) for k, v in sorted(by_class.items())
            },
            "detection_latency_by_class_and_severity": {
                k: self._latency(v) for k, v in sorted(by_both.items())
            },
        }

    def _summary(self, episodes: list[_Episode]) -> dict[str, Any]:
        """Alarm detection rate and debounced latency (median, p90; seconds) over episodes."""
        out: dict[str, Any] = {
            "episodes": len(episodes),
            "detected": sum(e.alarm_tick is not None for e in episodes),
        }
        out["detection_rate"] = out["detected"] / len(episodes) if episodes else None
        detected = [e for e in episodes if e.alarm_tick is not None]
        right = [e for e in detected if e.rise_class == e.label.fault_class]
        out["class_right_at_rise"] = len(right)
        out["right_at_rise"] = sum(e.rise_joint == e.label.joint for e in right)
        out["right_at_rise_rate"] = out["right_at_rise"] / len(detected) if detected else None
        for name, attr in (("class", "alarm_class_tick"), ("joint", "alarm_joint_tick")):
            ticks = [getattr(e, attr) - e.onset for e in episodes if getattr(e, attr) is not None]
            out[f"{name}_detected"] = len(ticks)
            for stat, q in (("median", 50), ("p90", 90)):
                out[f"{name}_latency_s_{stat}"] = (
                    float(np.percentile(ticks, q)) * self.tick_s if ticks else None
                )
        return out

    def _latency(self, episodes: list[_Episode]) -> dict[str, Any]:
        """Per-tick (undebounced) latency to the first right decision, as before alarms."""
        out: dict[str, Any] = {"episodes": len(episodes)}
        for name, attr in (("class", "class_tick"), ("joint", "joint_tick")):
            ticks = [getattr(e, attr) - e.onset for e in episodes if getattr(e, attr) is not None]
            out[f"{name}_detected"] = len(ticks)
            out[f"{name}_latency_ticks_mean"] = float(np.mean(ticks)) if ticks else None
            out[f"{name}_latency_ticks_median"] = float(np.median(ticks)) if ticks else None
            out[f"{name}_latency_s_mean"] = float(np.mean(ticks)) * self.tick_s if ticks else None
        return out
