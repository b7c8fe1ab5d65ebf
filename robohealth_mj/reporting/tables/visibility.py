"""What each model sees of each fault: recall per class, accuracy by severity and by motion."""

from __future__ import annotations

from typing import Any

from robohealth_mj.reporting.runs import FAULTS, grouped, recall_of, value_at
from robohealth_mj.reporting.statistics import fmt_stat, mean_std


def visibility_markdown(runs: list[dict[str, Any]]) -> str:
    """What each model sees of each fault on the held-out session: recall per class, accuracy of
    faulted windows per severity, and on faulted windows whose faulted joint moved or stood
    still (friction acts only on a moving joint)."""
    strata = [("by_severity", s) for s in ("0.3", "0.6", "0.9")] + [
        ("by_motion", m) for m in ("moving", "still")
    ]
    head = [*FAULTS, *(f"sev. {s}" for _, s in strata[:3]), "moving", "still"]
    out = [
        "### Held-out recall per class, and accuracy by severity and by motion",
        "",
        "| setting | variant | W | " + " | ".join(head) + " |",
        "|---|---|---|" + "---|" * len(head),
    ]
    for key, members in grouped(runs):
        cells = [fmt_stat(mean_std([recall_of(m, c) for m in members])) for c in FAULTS]
        cells += [
            fmt_stat(mean_std([value_at(m, "heldout", group, name, "accuracy") for m in members]))
            for group, name in strata
        ]
        out.append(f"| {key[0]} | {key[1]} | {key[2]} | " + " | ".join(cells) + " |")
    return "\n".join([*out, ""])
