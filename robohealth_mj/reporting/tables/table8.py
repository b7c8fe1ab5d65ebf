"""Table 8: the unknown-placement harness by sensing profile and placement."""

from __future__ import annotations

from typing import Any

from robohealth_mj.reporting.markdown import heading
from robohealth_mj.reporting.runs import FAULTS
from robohealth_mj.reporting.statistics import fmt_stat


def table8(rows: list[dict[str, Any]]) -> str:
    """Table 8's layout: the harness under each sensing profile and placement, with the
    coupling's correlation to the truth and localisation per fault class."""
    sub = [r for r in rows if r["graph"] != "structural"]
    if not sub:
        return ""
    head = [
        "profile",
        "placement",
        "variant",
        "W",
        "seeds",
        "accuracy",
        "macro-F1",
        "localisation",
        "corr(C, C0)",
        *(f"loc. {f}" for f in FAULTS),
    ]
    out = heading("Table 8: unknown placement (harness graph) by sensing profile, placement", head)
    for r in sub:
        cells = [
            r["sensing"],
            r["placement"],
            r["variant"],
            str(r["window"]),
            str(len(r["seeds"])),
            fmt_stat(r["heldout.accuracy"]),
            fmt_stat(r["heldout.macro_f1"]),
            fmt_stat(r["heldout.localisation_accuracy"]),
            fmt_stat(r["coupling_correlation"]),
            *(fmt_stat(r[f"loc.{f}"], 2) for f in FAULTS),
        ]
        out.append("| " + " | ".join(cells) + " |")
    return "\n".join([*out, ""])
