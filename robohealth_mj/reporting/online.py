"""The on-line evaluation as markdown: alarms per class and per severity."""

from __future__ import annotations

from typing import Any


def _f(value: float | None, digits: int = 2) -> str:
    return "–" if value is None else f"{value:.{digits}f}"


def _row(name: str, a: dict[str, Any]) -> str:
    return (
        f"| {name} | {a['episodes']} | {_f(a['detection_rate'])} | "
        f"{_f(a['class_latency_s_median'])} / {_f(a['class_latency_s_p90'])} | "
        f"{_f(a['joint_latency_s_median'])} / {_f(a['joint_latency_s_p90'])} |"
    )


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
        f"- latency to the right class: median {_f(a['class_latency_s_median'])} s, p90 "
        f"{_f(a['class_latency_s_p90'])} s; to the right joint: median "
        f"{_f(a['joint_latency_s_median'])} s, p90 {_f(a['joint_latency_s_p90'])} s",
        f"- per-tick on-line accuracy {_f(result['online_accuracy'], 3)}",
        "",
        "| episodes of | n | detected | to class s (median / p90) | to joint s (median / p90) |",
        "|---|---|---|---|---|",
    ]
    lines += [_row(k, v) for k, v in result["alarms_by_class"].items()]
    lines += [_row(f"severity {k}", v) for k, v in result["alarms_by_severity"].items()]
    lines.append(_row("**all**", a))
    return "\n".join(lines) + "\n"
