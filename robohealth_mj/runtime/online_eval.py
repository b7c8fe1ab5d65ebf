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
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass, field
from typing import Any

import numpy as np

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


@dataclass
class OnlineEvaluator:
    tick_s: float = 0.05
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
    episodes: list[_Episode] = field(default_factory=list)
    _tick: int = 0
    _last_faulted: int | None = None

    def update(self, truth: FaultLabel, d: HealthDiagnosis) -> None:
        tick = self._tick
        self._tick += 1
        current = self.episodes[-1] if self.episodes else None
        alarm_up = d.alarm_class is not None
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
            if alarm_up:
                if current.alarm_tick is None:
                    current.alarm_tick = tick
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
        for ep in self.episodes:
            by_class[ep.label.fault_class].append(ep)
            by_severity[f"{ep.label.severity:g}"].append(ep)
            by_both[f"{ep.label.fault_class}@{ep.label.severity:g}"].append(ep)
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
            "episodes": len(self.episodes),
            "alarms": self._summary(self.episodes),
            "alarms_by_class": {k: self._summary(v) for k, v in sorted(by_class.items())},
            "alarms_by_severity": {k: self._summary(v) for k, v in sorted(by_severity.items())},
            "alarms_by_class_and_severity": {
                k: self._summary(v) for k, v in sorted(by_both.items())
            },
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
