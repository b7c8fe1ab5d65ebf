"""Table 7: the window ablation, held-out accuracy / localisation per window."""

from __future__ import annotations

from collections import defaultdict
from typing import Any

from robohealth_mj.reporting.runs import REFERENCE, variant_rank
from robohealth_mj.reporting.statistics import fmt_stat


def table7(rows: list[dict[str, Any]]) -> str:
    """Table 7's layout: held-out accuracy / localisation per window, for each model run at
    more than one window in the reference setting."""
    ref = [r for r in rows if r["setting"] == REFERENCE]
    by_model: dict[str, dict[int, dict]] = defaultdict(dict)
    for r in ref:
        by_model[r["variant"]][r["window"]] = r
    models = {m: ws for m, ws in by_model.items() if len(ws) > 1}
    if not models:
        return ""
    windows = sorted({w for ws in models.values() for w in ws})
    out = [
        "### Table 7: window ablation (held-out accuracy / localisation, mean ± std over seeds)",
        "",
        "| variant | " + " | ".join(f"W = {w}" for w in windows) + " |",
        "|---|" + "---|" * len(windows),
    ]
    for model in sorted(models, key=variant_rank):
        cells = []
        for w in windows:
            r = models[model].get(w)
            cells.append(
                "—"
                if r is None
                else " / ".join(
                    fmt_stat(r[k], 2) for k in ("heldout.accuracy", "heldout.localisation_accuracy")
                )
            )
        out.append(f"| {model} | " + " | ".join(cells) + " |")
    return "\n".join([*out, ""])
