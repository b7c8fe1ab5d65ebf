"""Support statistics of recordings and the corpus gate (thesis §2.6.1).

A file passes the gate only if every class is present, the faulted samples are spread over all
joints, and it is large enough; otherwise it should be re-recorded, never silently trained on.
"""

from __future__ import annotations

from collections import Counter, defaultdict
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from robohealth_mj.data.read import read_samples
from robohealth_mj.schema import FAULT_CLASSES, JOINT_NAMES


@dataclass
class FileSummary:
    path: str
    samples: int = 0
    classes: Counter = field(default_factory=Counter)
    joints: Counter = field(default_factory=Counter)  # faulted samples per target joint
    severities: dict[str, Counter] = field(default_factory=lambda: defaultdict(Counter))
    runs: dict[str, dict[str, Any]] = field(default_factory=dict)
    problems: list[str] = field(default_factory=list)
    arm_joints: tuple[str, ...] = JOINT_NAMES  # the recording's arm's, base to tool

    def as_dict(self) -> dict[str, Any]:
        return {
            "path": self.path,
            "samples": self.samples,
            "classes": {c: self.classes.get(c, 0) for c in FAULT_CLASSES},
            "faulted_per_joint": {j: self.joints.get(j, 0) for j in self.arm_joints},
            "severities": {
                c: {str(k): v for k, v in sorted(s.items())}
                for c, s in sorted(self.severities.items())
            },
            "runs": self.runs,
            "gate": "pass" if not self.problems else "fail",
            "problems": self.problems,
        }


def summarize_file(path: Path | str) -> FileSummary:
    """Read (and validate) every line of a recording and count its support."""
    summary = FileSummary(str(path))
    scenarios: dict[str, set] = defaultdict(set)
    for s in read_samples(path):
        summary.arm_joints = s.graph.joints
        summary.samples += 1
        summary.classes[s.fault.fault_class] += 1
        run = summary.runs.setdefault(
            s.recording_run_id, {"samples": 0, "faulted": 0, "classes": set()}
        )
        run["samples"] += 1
        run["classes"].add(s.fault.fault_class)
        if s.fault.active:
            run["faulted"] += 1
            summary.joints[s.fault.joint] += 1
            summary.severities[s.fault.fault_class][s.fault.severity] += 1
            scenarios[s.recording_run_id].add(
                (s.fault.fault_class, s.fault.joint, s.fault.severity)
            )
    for run_id, run in summary.runs.items():
        run["classes"] = sorted(run["classes"], key=FAULT_CLASSES.index)
        run["scenarios_covered"] = len(scenarios[run_id])
    return summary


def gate(summary: FileSummary, min_samples: int = 400, min_joint_share: float = 0.5) -> list[str]:
    """Reasons a file must not be used; empty when it passes.

    ``min_joint_share``: every joint must carry at least this fraction of a uniform share of the
    faulted samples (0.5 = half of 1/J).
    """
    problems = []
    if summary.samples < min_samples:
        problems.append(f"too small: {summary.samples} samples < {min_samples}")
    missing = [c for c in FAULT_CLASSES if summary.classes.get(c, 0) == 0]
    if missing:
        problems.append(f"classes missing: {', '.join(missing)}")
    faulted = sum(summary.joints.values())
    if faulted:
        floor = min_joint_share * faulted / len(summary.arm_joints)
        thin = [
            f"{j} ({summary.joints.get(j, 0)})"
            for j in summary.arm_joints
            if summary.joints.get(j, 0) < floor
        ]
        if thin:
            problems.append(
                f"degenerate joint-target distribution: {', '.join(thin)} below "
                f"{floor:.0f} of {faulted} faulted samples"
            )
    summary.problems = problems
    return problems


def format_summary(summary: FileSummary) -> str:
    d = summary.as_dict()
    lines = [
        f"== {d['path']}: {d['samples']} samples, {len(d['runs'])} run(s), gate {d['gate'].upper()}"
    ]
    total = max(d["samples"], 1)
    lines.append(
        "  class support:  "
        + "  ".join(f"{c} {n} ({n / total:.1%})" for c, n in d["classes"].items())
    )
    lines.append(
        "  faulted/joint:  " + "  ".join(f"{j} {n}" for j, n in d["faulted_per_joint"].items())
    )
    for c, sev in d["severities"].items():
        lines.append(f"  severity {c:<14}" + "  ".join(f"{k}: {v}" for k, v in sev.items()))
    for run_id, run in d["runs"].items():
        lines.append(
            f"  run {run_id}: {run['samples']} samples, {run['faulted']} faulted, "
            f"{run['scenarios_covered']} scenarios, classes {run['classes']}"
        )
    lines += [f"  REJECT: {p}" for p in d["problems"]]
    return "\n".join(lines)
