"""The faint-faults issue's on-line tables from the monitor's evaluation JSONs in this folder.

    .venv/bin/python studies/faint_faults/tabulate.py > studies/faint_faults/results/online.md

One row per configuration (model x alarm x memory): the held-out replay (seed 900) and two hours
of healthy running (seed 903), neither used for selection. The "before" row is the committed
fleet evaluation (studies/fleet/results), made before the runtime's joint scores were fixed.
"""

from __future__ import annotations

import json
from pathlib import Path

RESULTS = Path(__file__).resolve().parent / "results"  # its tables live there
ROWS = [
    ("before: headline, window alarms (runtime before this issue)",
     "../fleet/online_eval_heldout900", "../fleet/online_eval_healthy903"),
    ("headline, window alarms (joint scores fixed)",
     "online_eval_headline_window_heldout_seed900", "online_eval_headline_window_healthy903"),
    ("retrained (healthy segment starts), window alarms: chosen",
     "online_eval_deconf_window_heldout_seed900", "online_eval_deconf_window_healthy903"),
    ("retrained, with memory (best memory setting on selection)",
     "online_eval_deconf_memory_heldout_seed900", "online_eval_deconf_memory_healthy903"),
]  # fmt: skip


def _load(name: str) -> dict | None:
    path = RESULTS / f"{name}.json"
    return json.loads(path.read_text()) if path.is_file() else None


def _f(v, d: int = 2) -> str:
    return "–" if v is None else f"{v:.{d}f}"


def headline() -> list[str]:
    out = [
        "| configuration | detected | observable detected | class and joint right at rise | "
        "to class s (median / p90) | false alarms / h (2 h healthy) | alarmed healthy ticks | "
        "on-line localisation |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for label, held, healthy in ROWS:
        r, h = _load(held), _load(healthy)
        if r is None or h is None:
            continue
        a = r["alarms"]
        vis = r.get("alarms_by_visibility", {}).get("observable")
        observable = f"{vis['detected']} / {vis['episodes']}" if vis else "–"
        at_rise = (
            f"{a['right_at_rise']} / {a['detected']}"
            if "right_at_rise" in a
            else f"≤ {a['joint_detected']} / {a['detected']} (joint eventually)"
        )
        out.append(
            f"| {label} | {a['detected']} / {a['episodes']} | {observable} | {at_rise} | "
            f"{_f(a['class_latency_s_median'])} / {_f(a['class_latency_s_p90'])} | "
            f"{h['false_alarms']} in {h['settled_healthy_ticks'] * 0.05 / 3600:.2f} h "
            f"({_f(h['false_alarms_per_hour'])}) | {_f(h['false_alarm_rate'], 4)} | "
            f"{_f(r['localisation_accuracy'], 3)} |"
        )
    return out


def per_class(name: str) -> list[str]:
    r = _load(name)
    if r is None:
        return []
    out = [
        "| episodes of | n | detected | right at rise | to class s (median / p90) |",
        "|---|---|---|---|---|",
    ]
    groups = [*r["alarms_by_class"].items(), *r["alarms_by_severity"].items()]
    groups += list(r.get("alarms_by_visibility", {}).items())
    groups += list(r["alarms_by_class_and_severity"].items())
    for k, a in groups:
        out.append(
            f"| {k} | {a['episodes']} | {a['detected']} | {a.get('right_at_rise', '–')} | "
            f"{_f(a['class_latency_s_median'])} / {_f(a['class_latency_s_p90'])} |"
        )
    return out


def main() -> None:
    lines = ["## On-line figures, held-out replay (seed 900) and 2 h healthy (seed 903)", ""]
    lines += headline()
    for label, held, _ in ROWS[1:]:
        table = per_class(held)
        if table:
            lines += ["", f"### {label}: per class, severity and visibility", "", *table]
    print("\n".join(lines))


if __name__ == "__main__":
    main()
