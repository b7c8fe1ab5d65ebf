"""Q2: the coupling head minus each model under the harness, paired over seeds."""

from __future__ import annotations

from typing import Any

from robohealth_mj.reporting.markdown import heading
from robohealth_mj.reporting.runs import value_at, variant_rank
from robohealth_mj.reporting.statistics import paired_cells

# Q2's model: the learned joint-sensor coupling with sign-pinned sensor scores
COUPLING_HEAD = "anomaly_residual+energy"


def coupling_markdown(runs: list[dict[str, Any]]) -> str:
    """Q2 as paired differences: under each harness setting (sensing profile, placement) and
    window, the coupling head minus every other model run there, per seed, on held-out
    localisation, accuracy and macro-F1; mean ± std over the seeds both have. Paired for Q1's
    reason: a seed's luck is shared by the models of that seed."""
    harness = [r for r in runs if r["graph"] == "harness"]
    out: list[str] = []
    for setting, window in dict.fromkeys((r["setting"], r["window"]) for r in harness):
        cell = {
            (r["label"], r["seed"]): r
            for r in harness
            if (r["setting"], r["window"]) == (setting, window)
        }
        head_seeds = {seed for label, seed in cell if label == COUPLING_HEAD}
        others = sorted(
            {label for label, _ in cell if label != COUPLING_HEAD},
            key=lambda label: (variant_rank(label), label),
        )
        for other in others:
            seeds = sorted(head_seeds & {seed for label, seed in cell if label == other})
            if not seeds:
                continue
            if not out:
                out = heading(
                    f"Q2: the coupling head ({COUPLING_HEAD}) minus each model under the "
                    "harness, paired over seeds (held-out)",
                    ["setting", "W", "seeds", "minus", "localisation", "accuracy", "macro-F1"],
                )

            def difference(seed: int, metric: str, cell=cell, other=other) -> float:
                return value_at(cell[COUPLING_HEAD, seed], "heldout", metric) - value_at(
                    cell[other, seed], "heldout", metric
                )

            cells = [setting, str(window), str(len(seeds)), other]
            cells += paired_cells(
                difference, seeds, ("localisation_accuracy", "accuracy", "macro_f1")
            )
            out.append("| " + " | ".join(cells) + " |")
    return "\n".join([*out, ""]) if out else ""
