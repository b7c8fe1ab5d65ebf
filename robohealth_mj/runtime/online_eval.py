"""On-line evaluation: diagnoses logged against the true fault state (thesis §4.7).

An *episode* is a run of consecutive ticks with the same active fault (class, joint, severity).
Detection latency is counted from its onset to the first tick whose diagnosis has the right class,
and to the first tick that localises the right joint. Ticks without a decision (window warming up,
invalid samples) count towards latency but not towards the accuracies.
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
    class_tick: int | None = None
    joint_tick: int | None = None


@dataclass
class OnlineEvaluator:
    tick_s: float = 0.05
    decided: int = 0
    correct: int = 0
    faulted: int = 0
    localised: int = 0
    healthy: int = 0
    false_alarms: int = 0
    episodes: list[_Episode] = field(default_factory=list)
    _tick: int = 0

    def update(self, truth: FaultLabel, d: HealthDiagnosis) -> None:
        tick = self._tick
        self._tick += 1
        current = self.episodes[-1] if self.episodes else None
        if truth.active:
            key = (truth.fault_class, truth.joint, truth.severity)
            if (
                current is None
                or current.onset + self._length(current) != tick
                or (current.label.fault_class, current.label.joint, current.label.severity) != key
            ):
                current = _Episode(truth, tick)
                self.episodes.append(current)
            current.last = tick  # type: ignore[attr-defined]
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
            self.false_alarms += d.fault_present

    @staticmethod
    def _length(ep: _Episode) -> int:
        return getattr(ep, "last", ep.onset) - ep.onset + 1

    def result(self) -> dict[str, Any]:
        def rate(a: int, b: int) -> float | None:
            return a / b if b else None

        groups: dict[str, list[_Episode]] = defaultdict(list)
        for ep in self.episodes:
            groups[f"{ep.label.fault_class}@{ep.label.severity:g}"].append(ep)
        per_group = {key: self._latency(eps) for key, eps in sorted(groups.items())}
        by_class: dict[str, list[_Episode]] = defaultdict(list)
        for ep in self.episodes:
            by_class[ep.label.fault_class].append(ep)
        return {
            "ticks": self._tick,
            "decided_ticks": self.decided,
            "online_accuracy": rate(self.correct, self.decided),
            "localisation_accuracy": rate(self.localised, self.faulted),
            "false_alarm_rate": rate(self.false_alarms, self.healthy),
            "episodes": len(self.episodes),
            "detection_latency": self._latency(self.episodes),
            "detection_latency_by_class": {
                k: self._latency(v) for k, v in sorted(by_class.items())
            },
            "detection_latency_by_class_and_severity": per_group,
        }

    def _latency(self, episodes: list[_Episode]) -> dict[str, Any]:
        out: dict[str, Any] = {"episodes": len(episodes)}
        for name, attr in (("class", "class_tick"), ("joint", "joint_tick")):
            ticks = [getattr(e, attr) - e.onset for e in episodes if getattr(e, attr) is not None]
            out[f"{name}_detected"] = len(ticks)
            out[f"{name}_latency_ticks_mean"] = float(np.mean(ticks)) if ticks else None
            out[f"{name}_latency_ticks_median"] = float(np.median(ticks)) if ticks else None
            out[f"{name}_latency_s_mean"] = float(np.mean(ticks)) * self.tick_s if ticks else None
        return out
