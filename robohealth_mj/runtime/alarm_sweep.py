"""Choosing alarm settings on a selection recording (never the held-out one).

The model's per-tick decisions do not depend on the alarm policy, so they are computed once
(:func:`replay_decisions`, the fleet runtime on the recording's arrays) and every policy of a grid
is replayed over them (:func:`evaluate_policy`, the same alarm bank and on-line evaluator the
monitor uses). :func:`choose` picks, among the policies that meet the targets, the one with the
lowest median latency to the right class.
"""

from __future__ import annotations

import itertools
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from robohealth_mj import schema
from robohealth_mj.data.arrays import load_recordings
from robohealth_mj.errors import InputError
from robohealth_mj.runtime.alarms import AlarmBank, AlarmPolicy
from robohealth_mj.runtime.fleet import DECIDED, FleetRuntime
from robohealth_mj.runtime.online_eval import OnlineEvaluator
from robohealth_mj.runtime.runtime import HealthDiagnosis, decide
from robohealth_mj.schema import FaultLabel


@dataclass
class Decisions:
    """Per tick of one recording: the model's outputs and the truth."""

    decided: np.ndarray  # [T] bool
    probs: np.ndarray  # [T, C]
    joint_scores: np.ndarray  # [T, J]
    truth: list[FaultLabel]
    window: int


def replay_decisions(model: str | Path, recording: str | Path) -> Decisions:
    """Run the fleet runtime (one stream) over a recording's samples in order."""
    rec = load_recordings([Path(recording)])
    fleet = FleetRuntime(model)
    if fleet.engine is None:
        raise InputError(fleet.problem)
    slot = fleet.register([str(recording)])
    n = len(rec)
    decided = np.zeros(n, bool)
    probs = np.zeros((n, len(fleet.classes)), np.float32)
    scores = np.zeros((n, len(fleet.joints)), np.float32)
    for k in range(n):
        r = fleet.step(slot, rec.sample_index[k : k + 1], rec.sample_index[k : k + 1] * 0.05 + 0.05,
                       rec.x[k : k + 1])  # fmt: skip
        decided[k] = r.status[0] == DECIDED
        probs[k], scores[k] = r.probs[0], r.joint_scores[0]
    truth = [
        FaultLabel(
            schema.FAULT_CLASSES[int(c)],
            schema.JOINT_NAMES[int(j)] if j >= 0 else None,
            float(s),
            bool(a),
        )
        for c, j, s, a in zip(
            rec.fault_class, rec.fault_joint, rec.severity, rec.active, strict=True
        )
    ]
    return Decisions(decided, probs, scores, truth, fleet.window)


def evaluate_policy(d: Decisions, policy: AlarmPolicy) -> dict[str, Any]:
    """The on-line evaluation of ``policy`` over precomputed decisions."""
    bank = AlarmBank(policy, d.joint_scores.shape[1], 1)
    ev = OnlineEvaluator(settle_ticks=d.window + policy.clear_after)
    slot = np.zeros(1, np.int64)
    classes, joints = list(schema.FAULT_CLASSES), list(schema.JOINT_NAMES)
    for k, truth in enumerate(d.truth):
        diag = HealthDiagnosis(stamp=0.0, stream_id="s", sample_index=k, valid=True)
        if d.decided[k]:
            probs, scores = d.probs[k : k + 1], d.joint_scores[k : k + 1]
            state, alarm, joint = bank.update(slot, probs, scores)
            decide(diag, probs[0], scores[0], int(state[0]), int(alarm[0]), int(joint[0]),
                   classes, joints)  # fmt: skip
        ev.update(truth, diag)
    return ev.result()


GRID = {
    "raise_after": [6, 10, 14, 20],
    "min_confidence": [0.8, 0.9, 0.95, 0.97],
    "clear_after": [10],
}

TARGETS = {"false_alarm_rate": 0.01, "false_alarms_per_hour": 2.0, "detection_rate": 0.95}


def sweep(
    d: Decisions, grid: dict[str, list] | None = None, healthy: Decisions | None = None
) -> list[dict[str, Any]]:
    """One row per policy of the grid: its settings and headline on-line figures. False alarms
    per hour count the settled healthy time of both ``d`` and, when given, a healthy-only
    session (a fault session's healthy gaps alone are a few minutes per hour)."""
    grid = grid or GRID
    rows = []
    for values in itertools.product(*grid.values()):
        policy = AlarmPolicy(**dict(zip(grid, values, strict=True)))
        r = evaluate_policy(d, policy)
        a = r["alarms"]
        alarms, ticks = r["false_alarms"], r["settled_healthy_ticks"]
        if healthy is not None:
            h = evaluate_policy(healthy, policy)
            alarms, ticks = alarms + h["false_alarms"], ticks + h["settled_healthy_ticks"]
        rows.append(
            {
                **asdict(policy),
                "detection_rate": a["detection_rate"],
                "false_alarm_rate": r["false_alarm_rate"],
                "false_alarms_per_hour": alarms / (ticks * 0.05 / 3600.0) if ticks else None,
                "healthy_hours": ticks * 0.05 / 3600.0,
                "class_latency_s_median": a["class_latency_s_median"],
                "joint_latency_s_median": a["joint_latency_s_median"],
            }
        )
    return rows


def meets_targets(row: dict[str, Any]) -> bool:
    return (
        (row["false_alarm_rate"] or 0.0) <= TARGETS["false_alarm_rate"]
        and (row["false_alarms_per_hour"] or 0.0) <= TARGETS["false_alarms_per_hour"]
        and (row["detection_rate"] or 0.0) >= TARGETS["detection_rate"]
    )


def choose(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """The policy meeting every target with the lowest median latency to class (then joint);
    if none meets them, the one with the fewest false alarms per hour."""
    good = [r for r in rows if meets_targets(r)]
    if good:
        return min(
            good,
            key=lambda r: (r["class_latency_s_median"] or 1e9, r["joint_latency_s_median"] or 1e9),
        )
    return min(rows, key=lambda r: (r["false_alarms_per_hour"], -(r["detection_rate"] or 0)))
