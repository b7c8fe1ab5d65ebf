"""The on-line evaluation as markdown: alarms per class and per severity."""

from __future__ import annotations

from typing import Any

from robohealth_mj.schema import JOINT_NAMES


def _f(value: float | None, digits: int = 2) -> str:
    return "–" if value is None else f"{value:.{digits}f}"


def _row(name: str, a: dict[str, Any]) -> str:
    return (
        f"| {name} | {a['episodes']} | {_f(a['detection_rate'])} | "
        f"{_f(a.get('right_at_rise_rate'))} | "
        f"{_f(a['class_latency_s_median'])} / {_f(a['class_latency_s_p90'])} | "
        f"{_f(a['joint_latency_s_median'])} / {_f(a['joint_latency_s_p90'])} |"
    )


HEADER = [
    "| episodes of | n | detected | class and joint right at rise | to class s (median / p90) "
    "| to joint s (median / p90) |",
    "|---|---|---|---|---|---|",
]


def _detection_grid(by_joint: dict[str, dict[str, Any]]) -> list[str]:
    """Detected / episodes per class (rows) x joint (columns)."""
    classes = sorted({k.split("@")[0] for k in by_joint})
    named = list(dict.fromkeys(k.split("@", 1)[1] for k in by_joint))  # as they came
    joints = list(JOINT_NAMES) if set(named) <= set(JOINT_NAMES) else named
    lines = ["| detected | " + " | ".join(joints) + " |", "|---" * (len(joints) + 1) + "|"]
    for c in classes:
        cells = [by_joint.get(f"{c}@{j}") for j in joints]
        lines.append(
            f"| {c} | "
            + " | ".join("–" if a is None else f"{a['detected']}/{a['episodes']}" for a in cells)
            + " |"
        )
    return lines


def online_markdown(result: dict[str, Any]) -> str:
    """Headline alarm figures, then detection and debounced latency per class and severity."""
    a = result["alarms"]
    lines = [
        f"Alarm policy: {result.get('alarm_policy')}",
        "",
        f"- fault episodes detected: {a['detected']} / {a['episodes']} "
        f"({_f(a['detection_rate'], 3)})",
        f"- false alarms: {_f(result['false_alarm_rate'], 4)} of "
        f"{result['settled_healthy_ticks']} settled healthy ticks, "
        f"{result['false_alarms']} raised ({_f(result['false_alarms_per_hour'])} per healthy "
        f"hour); per-tick decisions alone: {_f(result['false_positive_rate'], 4)} of healthy ticks",
        f"- contact watch: {result.get('contact_calls', 0)} calls "
        f"({result.get('contact_ticks', 0)} ticks, "
        f"{_f(result.get('contact_calls_per_hour'))} per hour)",
        f"- latency to the right class: median {_f(a['class_latency_s_median'])} s, p90 "
        f"{_f(a['class_latency_s_p90'])} s; to the right joint: median "
        f"{_f(a['joint_latency_s_median'])} s, p90 {_f(a['joint_latency_s_p90'])} s",
        f"- class and joint right when the alarm rose: {a.get('right_at_rise')} of "
        f"{a['detected']} detected episodes ({_f(a.get('right_at_rise_rate'), 3)})",
        f"- per-tick on-line accuracy {_f(result['online_accuracy'], 3)}",
        "",
        *HEADER,
    ]
    lines += [_row(k, v) for k, v in result["alarms_by_class"].items()]
    lines += [_row(f"severity {k}", v) for k, v in result["alarms_by_severity"].items()]
    lines += [_row(k, v) for k, v in result.get("alarms_by_visibility", {}).items()]
    lines.append(_row("**all**", a))
    if result.get("alarms_by_class_and_severity"):
        lines += ["", "Per class and severity:", "", *HEADER]
        lines += [_row(k, v) for k, v in result["alarms_by_class_and_severity"].items()]
    if result.get("alarms_by_class_and_joint"):
        lines += ["", "Episodes detected per class and joint:", ""]
        lines += _detection_grid(result["alarms_by_class_and_joint"])
    hidden = result.get("physically_hidden_episodes")
    if hidden:
        lines += [
            "",
            f"Physically hidden (friction on a joint that never moved, weakening of a joint that "
            f"never carried load): {', '.join(hidden)}",
        ]
    return "\n".join(lines) + "\n"
