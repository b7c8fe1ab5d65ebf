"""Where a commissioned model's false alarms fall on an unseen arm's healthy running (issue 65).

    python studies/arms/false_alarms.py RUN_DIR [RUN_DIR ...] [--arm iiwa14]
        [--corpus outputs/corpus/arms] [--commissioning-minutes 10]
        > studies/arms/results/<name>.md

Each ``RUN_DIR`` holds a commissioned ``model.onnx`` (``studies/arms/campaign.py``). Its
decisions over the arm's commissioning minutes (the first ten, or as many as
``--commissioning-minutes`` names) and its healthy hour are replayed through the
fleet runtime and the monitor's default alarm and evidence policies (``conf/monitor.yaml``),
as ``campaign.py`` counts them. For every alarm: when, which class and joint, and the curriculum
segment it rose in (family, waveform, moving joints, speed and payload scale). Then, per fault
class, the longest runs of consecutive confident votes (what the alarm's debounce reads) on the
commissioning minutes and on the hour, and the confident votes by kind of segment. A false alarm
the commissioning minutes hold no vote like cannot be commissioned away; one the debounce
nearly stops can be.
"""

from __future__ import annotations

import argparse
import json
from collections import Counter
from pathlib import Path

import numpy as np
from campaign import HEALTHY_HOUR, commissioning_sessions  # this folder's campaign: the sessions
from omegaconf import OmegaConf

from robohealth_mj import schema
from robohealth_mj.arms.description import load_arm
from robohealth_mj.common.config import compose_config
from robohealth_mj.deploy.alarm_sweep import Decisions, accumulate, replay_many
from robohealth_mj.recording.recorder import build_curriculum
from robohealth_mj.runtime.alarms import AlarmBank, AlarmPolicy
from robohealth_mj.runtime.evidence import EvidencePolicy
from robohealth_mj.sim.curriculum import Curriculum, Segment

TICK_S = 0.05


def session_curriculum(session: Path, arm: str) -> Curriculum:
    """The curriculum a recorded session ran (rebuilt from its manifest's config)."""
    manifest = json.loads((session / "manifest.json").read_text())
    return build_curriculum(OmegaConf.create(manifest["config"]), load_arm(arm))


def segment_at(curriculum: Curriculum, tick: int) -> tuple[Segment, float]:
    """The segment sample ``tick`` lies in, and how far into it (s)."""
    t = (tick + 1) * TICK_S
    visit = curriculum.visit_at(t)
    return curriculum.scheduled(visit).segment, t - visit * curriculum.segment_s


def describe(segment: Segment, joints: tuple[str, ...]) -> str:
    moving = ",".join(joints[j] for j in segment.joints)
    return (f"{segment.family}/{segment.waveform} [{moving}] speed {segment.speed_scale:g} "
            f"payload {segment.payload_scale:g}")  # fmt: skip


def alarms(d: Decisions, policy: AlarmPolicy, evidence: EvidencePolicy) -> list[tuple]:
    """``(tick, class, joint, probability)`` of every alarm raised over the decisions."""
    accumulated = accumulate(d, evidence)
    bank = AlarmBank(policy, d.joint_scores.shape[1], 1)
    slot, previous, out = np.zeros(1, np.int64), 0, []
    for k in np.flatnonzero(d.decided).tolist():
        _, alarm, joint = bank.update(slot, accumulated[k : k + 1], d.joint_scores[k : k + 1])
        if int(alarm[0]) not in (0, previous):
            out.append((k, int(alarm[0]), int(joint[0]), float(d.probs[k].max())))
        previous = int(alarm[0])
    return out


def vote_runs(d: Decisions, fault: int, min_confidence: float) -> list[int]:
    """Lengths of the runs of consecutive decided ticks voting for ``fault``, longest first."""
    top, conf = d.probs.argmax(1), d.probs.max(1)
    votes = ((top == fault) & (conf >= min_confidence))[d.decided]
    edges = np.flatnonzero(np.diff(np.concatenate([[0], votes.astype(int), [0]])))
    return sorted((edges[1::2] - edges[::2]).tolist(), reverse=True)


def longest_runs(decisions: list[Decisions], fault: int, min_confidence: float) -> list[int]:
    """:func:`vote_runs` over several recordings, longest first."""
    runs = [n for d in decisions for n in vote_runs(d, fault, min_confidence)]
    return sorted(runs, reverse=True)


def report(run: Path, arm: str, corpus: Path, minutes: int = 10) -> None:
    cfg = compose_config("monitor")
    policy, evidence = AlarmPolicy(**cfg.alarm), EvidencePolicy(**cfg.evidence)
    commissioning = tuple(commissioning_sessions(minutes))
    sessions = (*commissioning, *HEALTHY_HOUR)
    files = [corpus / arm / session / "graphs.jsonl" for session in sessions]
    decisions = replay_many(run / "model.onnx", files)
    classes = schema.FAULT_CLASSES
    print(f"## {run}\n\nAlarms (monitor defaults: raise after {policy.raise_after} votes at "
          f"confidence {policy.min_confidence:g}):\n")  # fmt: skip
    print("| session | at s | class | joint | probability | segment | s into it |")
    print("|---|---|---|---|---|---|---|")
    kinds: dict[str, Counter] = {s: Counter() for s in sessions}
    visits: dict[str, Counter] = {s: Counter() for s in sessions}
    for session, d in zip(sessions, decisions, strict=True):
        curriculum = session_curriculum(corpus / arm / session, arm)
        for tick, fault, joint, p in alarms(d, policy, evidence):
            segment, into = segment_at(curriculum, tick)
            print(f"| {session} | {(tick + 1) * TICK_S:.1f} | {classes[fault]} | {d.joints[joint]} "
                  f"| {p:.3f} | {describe(segment, d.joints)} | {into:.1f} |")  # fmt: skip
        top, conf = d.probs.argmax(1), d.probs.max(1)
        for tick in range(len(d.decided)):
            segment, _ = segment_at(curriculum, tick)
            kind = f"{segment.family}/{segment.waveform} speed {segment.speed_scale:g}"
            visits[session][kind] += 1
            if d.decided[tick] and top[tick] > 0 and conf[tick] >= policy.min_confidence:
                kinds[session][kind] += 1
    print("\nLongest runs of consecutive confident votes per class (the debounce raises at "
          f"{policy.raise_after}):\n")  # fmt: skip
    print("| class | commissioning minutes | healthy hour |")
    print("|---|---|---|")
    for fault in range(1, len(classes)):
        ten = longest_runs(decisions[: len(commissioning)], fault, policy.min_confidence)[:4]
        hour = longest_runs(decisions[len(commissioning) :], fault, policy.min_confidence)[:6]
        print(f"| {classes[fault]} | {ten or '–'} | {hour or '–'} |")
    print("\nConfident fault votes by kind of segment (share of its ticks):\n")
    print("| segment kind | commissioning minutes | healthy hour |")
    print("|---|---|---|")
    for kind in sorted(set().union(*visits.values())):
        ten = (sum(kinds[s][kind] for s in commissioning),
               sum(visits[s][kind] for s in commissioning))  # fmt: skip
        hour = sum(kinds[s][kind] for s in HEALTHY_HOUR), sum(visits[s][kind] for s in HEALTHY_HOUR)
        cells = [f"{v} of {n} ({100 * v / n:.2f} %)" if n else "–" for v, n in (ten, hour)]
        print(f"| {kind} | {cells[0]} | {cells[1]} |")
    print()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", type=Path, nargs="+")
    parser.add_argument("--arm", default="iiwa14")
    parser.add_argument("--corpus", type=Path, default=Path("outputs/corpus/arms"))
    parser.add_argument("--commissioning-minutes", type=int, default=10, choices=(10, 20, 30))
    args = parser.parse_args()
    print(f"# Where the false alarms fall on the {args.arm}'s healthy running\n")
    print("`python studies/arms/false_alarms.py` (see its docstring).\n")
    for run in args.runs:
        report(run, args.arm, args.corpus, args.commissioning_minutes)


if __name__ == "__main__":
    main()
