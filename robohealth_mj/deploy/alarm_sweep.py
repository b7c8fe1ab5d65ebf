"""Choosing alarm settings on a selection recording (never the held-out one).

The model's per-tick decisions do not depend on the alarm policy, so they are computed once
(:func:`replay_decisions`, the fleet runtime on the recording's arrays) and every policy of a grid
is replayed over them (:func:`evaluate_policy`, the same alarm bank and on-line evaluator the
monitor uses). :func:`choose` picks, among the policies that meet the targets, the one with the
lowest median latency to the right class.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from robohealth_mj import schema
from robohealth_mj.arms.description import DEFAULT_ARM
from robohealth_mj.common.errors import InputError
from robohealth_mj.data.arrays import Recording, load_recordings
from robohealth_mj.data.relative import to_raw
from robohealth_mj.runtime.alarms import AlarmBank, AlarmPolicy
from robohealth_mj.runtime.evidence import EvidenceBank, EvidencePolicy
from robohealth_mj.runtime.fleet import DECIDED, FleetRuntime
from robohealth_mj.runtime.online_eval import OnlineEvaluator, joint_activity
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
    speed: np.ndarray | None = None  # [T, J] |joint velocity|, for the physically hidden strata
    torque: np.ndarray | None = None  # [T, J] joint torque (effort)
    joints: tuple[str, ...] = schema.JOINT_NAMES  # the arm's, the joint scores' order
    arm: str = DEFAULT_ARM  # whose ratings the torques are read against


def replay_decisions(model: str | Path, recording: str | Path, decide_every: int = 1) -> Decisions:
    """Run the fleet runtime (one stream) over a recording's samples in order; the model every
    ``decide_every``-th tick, as the monitor runs it with that setting."""
    return replay_many(model, [recording], decide_every)[0]


def replay_many(
    model: str | Path, recordings: Sequence[str | Path], decide_every: int = 1
) -> list[Decisions]:
    """:func:`replay_decisions` for several recordings at once: one stream each in one fleet, so
    the network runs once a tick for all of them. Streams are independent: each recording gets
    the decisions it gets alone, its probabilities to float32 rounding (a batch runs other
    kernels than one stream). A shorter recording's stream stops at its end."""
    fleet = FleetRuntime(model, decide_every=decide_every)
    if fleet.engine is None:
        raise InputError(fleet.problem)
    recs = [load_recordings([Path(r)]) for r in recordings]
    for recording, rec in zip(recordings, recs, strict=True):
        if rec.arms and rec.arms[0] != fleet.arm:
            raise InputError(
                f"{recording}: a recording of a {rec.arms[0]}; {model} reads a {fleet.arm} "
                f"(export one for the {rec.arms[0]}: python -m robohealth_mj.export "
                f"data=<that recording>)"
            )
    raws = [to_raw(rec.x, fleet.arm) for rec in recs]  # the runtime takes readings as they come
    slots = fleet.register([f"{k}:{r}" for k, r in enumerate(recordings)])
    lengths = np.array([len(rec) for rec in recs])
    decided = [np.zeros(n, bool) for n in lengths]
    probs = [np.zeros((n, len(fleet.classes)), np.float32) for n in lengths]
    scores = [np.zeros((n, len(fleet.joints)), np.float32) for n in lengths]
    for k in range(int(lengths.max(initial=0))):
        live = np.flatnonzero(lengths > k)
        index = np.array([recs[i].sample_index[k] for i in live])
        r = fleet.step(slots[live], index, index * 0.05 + 0.05,
                       np.stack([raws[i][k] for i in live]))  # fmt: skip
        for row, i in enumerate(live.tolist()):
            decided[i][k] = r.status[row] == DECIDED
            probs[i][k], scores[i][k] = r.probs[row], r.joint_scores[row]
    out = []
    for i, rec in enumerate(recs):
        speed, torque = joint_activity(raws[i])
        out.append(Decisions(decided[i], probs[i], scores[i], _truth(rec), fleet.window, speed,
                             torque, joints=rec.graph.joints, arm=fleet.arm))  # fmt: skip
    return out


def _truth(rec: Recording) -> list[FaultLabel]:
    return [
        FaultLabel(
            schema.FAULT_CLASSES[int(c)],
            rec.graph.joints[int(j)] if j >= 0 else None,
            float(s),
            bool(a),
        )
        for c, j, s, a in zip(
            rec.fault_class, rec.fault_joint, rec.severity, rec.active, strict=True
        )
    ]


def accumulate(d: Decisions, evidence: EvidencePolicy) -> np.ndarray:
    """The accumulated probabilities ``[T, C]`` the alarms read (zero where undecided)."""
    bank = EvidenceBank(evidence, d.probs.shape[1], 1)
    slot = np.zeros(1, np.int64)
    out = np.zeros_like(d.probs)
    for k in np.flatnonzero(d.decided).tolist():
        out[k] = bank.update(slot, d.probs[k : k + 1])[0]
    return out


def evaluate_policy(
    d: Decisions,
    policy: AlarmPolicy,
    evidence: EvidencePolicy | None = None,
    accumulated: np.ndarray | None = None,
) -> dict[str, Any]:
    """The on-line evaluation of ``policy`` (alarms reading the ``evidence`` accumulation of
    the decisions; pass ``accumulated`` to reuse :func:`accumulate`'s result) over precomputed
    decisions."""
    evidence = evidence or EvidencePolicy()
    if accumulated is None:
        accumulated = accumulate(d, evidence)
    bank = AlarmBank(policy, d.joint_scores.shape[1], 1)
    ev = OnlineEvaluator(
        arm=d.arm, settle_ticks=d.window + policy.clear_after + evidence.clearing_ticks
    )
    slot = np.zeros(1, np.int64)
    classes, joints = list(schema.FAULT_CLASSES), list(d.joints)
    for k, truth in enumerate(d.truth):
        diag = HealthDiagnosis(stamp=0.0, stream_id="s", sample_index=k, valid=True)
        if d.decided[k]:
            probs, scores = d.probs[k : k + 1], d.joint_scores[k : k + 1]
            state, alarm, joint = bank.update(slot, accumulated[k : k + 1], scores)
            decide(diag, probs[0], scores[0], int(state[0]), int(alarm[0]), int(joint[0]),
                   classes, joints, accumulated[k])  # fmt: skip
        activity = () if d.speed is None else (d.speed[k], d.torque[k])
        ev.update(truth, diag, *activity)
    return ev.result()


GRID = {
    "horizon_s": [0.0, 10.0, math.inf],  # none, leaky, CUSUM-like (no forgetting)
    "clip": [1.0, 2.0],
    "floor": [12.0],
    "raise_after": [3, 6, 10, 14],
    "min_confidence": [0.9, 0.97, 0.99],
    "clear_after": [10],
}

TARGETS = {
    "false_alarm_rate": 0.01,  # share of settled healthy ticks under an alarm
    "false_alarms_per_hour": 1.0,
    "detection_rate": 0.97,
    "right_at_rise_rate": 0.95,  # class and joint right when the alarm rises
}

_ALARM_KEYS = set(AlarmPolicy.__dataclass_fields__)
_EVIDENCE_KEYS = set(EvidencePolicy.__dataclass_fields__)


def policies(grid: dict[str, list]) -> list[tuple[EvidencePolicy, list[AlarmPolicy]]]:
    """The grid's evidence policies, each with every alarm policy of the grid (keys name fields
    of either; an unknown key is the user's to fix)."""
    unknown = set(grid) - _ALARM_KEYS - _EVIDENCE_KEYS
    if unknown:
        raise InputError(
            f"alarm grid: unknown key {sorted(unknown)[0]!r} (alarm: {sorted(_ALARM_KEYS)}; "
            f"evidence: {sorted(_EVIDENCE_KEYS)})"
        )

    def combos(keys: set[str]) -> list[dict]:
        names = [k for k in grid if k in keys]
        return [dict(zip(names, v, strict=True)) for v in itertools.product(*map(grid.get, names))]

    alarms = [AlarmPolicy(**c) for c in combos(_ALARM_KEYS)]
    evidence: list[EvidencePolicy] = []
    for c in combos(_EVIDENCE_KEYS):
        e = EvidencePolicy(**c)
        e = e if e.memory else EvidencePolicy(horizon_s=0.0)  # clip, floor: moot without memory
        if e not in evidence:
            evidence.append(e)
    return [(e, alarms) for e in evidence]


def sweep(
    d: Decisions, grid: dict[str, list] | None = None, healthy: Decisions | None = None
) -> list[dict[str, Any]]:
    """One row per policy of the grid (evidence x alarm settings): its settings and headline
    on-line figures. False alarms per hour count the settled healthy time of both ``d`` and,
    when given, a healthy-only session (a fault session's healthy gaps alone are a few minutes
    per hour). Each evidence policy's accumulation is computed once for all alarm policies."""
    rows = []
    for evidence, alarms in policies(grid or GRID):
        acc = accumulate(d, evidence)
        acc_h = accumulate(healthy, evidence) if healthy is not None else None
        for policy in alarms:
            r = evaluate_policy(d, policy, evidence, accumulated=acc)
            a = r["alarms"]
            alarms_up, ticks = r["false_alarms"], r["settled_healthy_ticks"]
            rate = r["false_alarm_rate"] or 0.0
            if healthy is not None:
                h = evaluate_policy(healthy, policy, evidence, accumulated=acc_h)
                alarms_up += h["false_alarms"]
                ticks += h["settled_healthy_ticks"]
                rate = max(rate, h["false_alarm_rate"] or 0.0)
            rows.append(
                {
                    **asdict(evidence),
                    **asdict(policy),
                    "detection_rate": a["detection_rate"],
                    "observable_detection_rate": r["alarms_by_visibility"]
                    .get("observable", {})
                    .get("detection_rate"),
                    "right_at_rise_rate": a["right_at_rise_rate"],
                    "false_alarm_rate": rate,
                    "false_alarms_per_hour": alarms_up / (ticks * 0.05 / 3600.0) if ticks else None,
                    "healthy_hours": ticks * 0.05 / 3600.0,
                    "class_latency_s_median": a["class_latency_s_median"],
                    "joint_latency_s_median": a["joint_latency_s_median"],
                }
            )
    return rows


def quiet(row: dict[str, Any]) -> bool:
    """Within both false-alarm targets: alarmed healthy ticks and alarms per healthy hour."""
    return (row["false_alarm_rate"] or 0.0) <= TARGETS["false_alarm_rate"] and (
        row["false_alarms_per_hour"] or 0.0
    ) <= TARGETS["false_alarms_per_hour"]


def detection(row: dict[str, Any]) -> float:
    """Detection of the episodes physics lets a channel reveal where that is known (see
    :func:`~robohealth_mj.runtime.online_eval.physically_hidden`), else of all episodes."""
    observable = row.get("observable_detection_rate")
    return observable if observable is not None else (row["detection_rate"] or 0.0)


def meets_targets(row: dict[str, Any]) -> bool:
    return (
        quiet(row)
        and detection(row) >= TARGETS["detection_rate"]
        and (row.get("right_at_rise_rate") or 0.0) >= TARGETS["right_at_rise_rate"]
    )


def choose(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """The policy meeting every target with the lowest median latency to class (then joint).
    If none meets them all, false alarms stay the hard limit: among the quiet policies, the one
    detecting most episodes (then right at rise most often, then fastest); if none is quiet, the
    one with the fewest false alarms per hour."""

    def latency(r: dict[str, Any]) -> tuple[float, float]:
        return (r["class_latency_s_median"] or 1e9, r["joint_latency_s_median"] or 1e9)

    good = [r for r in rows if meets_targets(r)]
    if good:
        return min(good, key=latency)
    calm = [r for r in rows if quiet(r)]
    if calm:
        return min(
            calm,
            key=lambda r: (
                -detection(r),
                -(r["detection_rate"] or 0.0),
                -(r.get("right_at_rise_rate") or 0.0),
                *latency(r),
            ),
        )
    return min(rows, key=lambda r: (r["false_alarms_per_hour"], -(r["detection_rate"] or 0)))
