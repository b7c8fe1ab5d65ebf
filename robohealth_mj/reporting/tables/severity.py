"""The severity head's error on faulted windows, beside the same model without the head."""

from __future__ import annotations

from typing import Any

from robohealth_mj.reporting.markdown import heading
from robohealth_mj.reporting.runs import FAULTS, value_at
from robohealth_mj.reporting.statistics import fmt_stat, mean_std


def severity_markdown(runs: list[dict[str, Any]]) -> str:
    """The severity head (thesis §4.7): MAE on faulted windows overall, per class and per true
    severity, beside what the same model without the head reaches (its cost)."""
    with_head = [r for r in runs if r["label"].endswith("+severity")]
    if not with_head:
        return ""
    levels = sorted({k for r in with_head for k in (value_at(r, "heldout", "by_severity") or {})})
    head = [
        "setting",
        "variant",
        "W",
        "seeds",
        "MAE (faulted)",
        *(f"MAE {f}" for f in FAULTS),
        *(f"MAE sev. {s}" for s in levels),
        "accuracy",
        "localisation",
    ]
    out = heading("Severity head: mean absolute error on faulted windows (held-out)", head)
    keys = dict.fromkeys((r["setting"], r["label"], r["window"]) for r in with_head)
    for setting, label, window in keys:
        members = [
            r
            for r in with_head
            if (r["setting"], r["label"], r["window"]) == (setting, label, window)
        ]
        base = label.removesuffix("+severity")
        twins = [
            r for r in runs if (r["setting"], r["label"], r["window"]) == (setting, base, window)
        ]
        for name, group in ((label, members), (f"{base} (no head)", twins)):
            if not group:
                continue
            has_head = group is members

            def stat(*path, digits=3, needs_head=True, group=group, has_head=has_head) -> str:
                if needs_head and not has_head:
                    return "—"
                return fmt_stat(mean_std([value_at(m, "heldout", *path) for m in group]), digits)

            cells = [
                setting,
                name,
                str(window),
                str(len(group)),
                stat("severity_mae_faulted"),
                *(stat("per_class", f, "severity_mae", digits=2) for f in FAULTS),
                *(stat("by_severity", s, "severity_mae", digits=2) for s in levels),
                stat("accuracy", needs_head=False),
                stat("localisation_accuracy", needs_head=False),
            ]
            out.append("| " + " | ".join(cells) + " |")
    return "\n".join([*out, ""])
