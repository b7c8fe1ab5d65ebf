"""Q1: the pose kernel and the learned residual as paired effects over seeds."""

from __future__ import annotations

from typing import Any

import numpy as np

from robohealth_mj.reporting.markdown import heading
from robohealth_mj.reporting.runs import REFERENCE, value_at
from robohealth_mj.reporting.statistics import paired_cells

# The thesis's 2 x 2 (Q1): (pose kernel, learned residual) -> variant
DECOMPOSITION = {
    (False, False): "stgnn_fixed",
    (True, False): "stgnn_fixed_pose",
    (False, True): "stgnn_learnable",
    (True, True): "stgnn_pose_cond",
}


def decomposition_markdown(runs: list[dict[str, Any]]) -> str:
    """Q1 as paired effects: per seed, the pose kernel's effect (with the pose kernel minus
    without, averaged over the residual's two levels) and the learned residual's, on held-out
    accuracy and localisation, mean ± std over the seeds every cell of the 2 x 2 has. Paired,
    because the four variants of one seed see the same data in the same order: the seed's own
    luck cancels, which a comparison of means over seeds leaves in."""
    ref = [r for r in runs if r["setting"] == REFERENCE and r["label"] in DECOMPOSITION.values()]
    out = []
    for window in sorted({r["window"] for r in ref}):
        cell = {(r["label"], r["seed"]): r for r in ref if r["window"] == window}
        seeds = sorted(
            seed
            for seed in {s for _, s in cell}
            if all((v, seed) in cell for v in DECOMPOSITION.values())
        )
        if not seeds:
            continue
        if not out:
            out = heading(
                "Q1: the pose kernel and the learned residual, paired over seeds (held-out)",
                ["W", "seeds", "effect", "accuracy", "localisation", "macro-F1"],
            )
        for factor, name in ((0, "pose kernel"), (1, "learned residual")):
            on = [v for k, v in DECOMPOSITION.items() if k[factor]]
            off = [v for k, v in DECOMPOSITION.items() if not k[factor]]

            def effect(seed: int, metric: str, cell=cell, on=on, off=off) -> float:
                return float(
                    np.mean([value_at(cell[v, seed], "heldout", metric) for v in on])
                    - np.mean([value_at(cell[v, seed], "heldout", metric) for v in off])
                )

            cells = [str(window), str(len(seeds)), name]
            cells += paired_cells(effect, seeds, ("accuracy", "localisation_accuracy", "macro_f1"))
            out.append("| " + " | ".join(cells) + " |")
    return "\n".join([*out, ""]) if out else ""
