"""The stock profile beside the full one (W = 32, structural graph, held-out session): every
model's accuracy, localisation and per-class recall, and the figures both profiles share (the
mechanical faults' recall and localisation), from the campaign's runs.

    .venv/bin/python studies/stock_arm/compare.py [RUNS]
    # -> studies/stock_arm/results/stock_vs_full.md
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from robohealth_mj.common.atomic import atomic_write_text
from robohealth_mj.reporting.statistics import mean_pm_std

RESULTS = Path(__file__).resolve().parent / "results"  # its tables live there

RUNS = Path(sys.argv[1] if len(sys.argv) > 1 else "outputs/thesis_physics/structural")
MECHANICAL = ("backlash", "friction", "jam", "struct_weaken")
VARIANTS = ("gbdt", "mlp", "stgnn_fixed", "anomaly_residual")


def mechanical_localisation(per_class: dict) -> float:
    """Localisation on the mechanical faults' windows: the same windows in either label set."""
    n = np.array([per_class[c]["support"] for c in MECHANICAL], float)
    loc = np.array([per_class[c].get("localisation", np.nan) for c in MECHANICAL])
    return float((n * loc).sum() / n.sum())


def row(profile: str, variant: str) -> str | None:
    evals = sorted((RUNS / profile / "C0" / variant / "w32").glob("seed*/eval_heldout.json"))
    if not evals:
        return None
    ms = [json.loads(p.read_text())["metrics"] for p in evals]

    cell = mean_pm_std
    cells = [
        cell([m["accuracy"] for m in ms]),
        cell([m["macro_f1"] for m in ms]),
        cell([m["localisation_accuracy"] for m in ms]),
        cell([mechanical_localisation(m["per_class"]) for m in ms]),
        *(f"{np.mean([m['per_class'][c]['recall'] for m in ms]):.3f}" for c in MECHANICAL),
    ]
    return f"| {profile} | {variant} | {len(ms)} | " + " | ".join(cells) + " |"


def main() -> None:
    lines = [
        "# The stock arm beside the full sensor package (W = 32, held-out session)",
        "",
        "Made by `.venv/bin/python studies/stock_arm/compare.py` over the campaign's runs",
        "(`bash studies/thesis_physics/run.sh stock matrix_w32`). Accuracy, macro-F1 and",
        "localisation are each profile's own (stock: five classes, sensor-fault windows healthy;",
        "full: seven); the mechanical faults' localisation and recall are the same windows in",
        "both. Mean ± std over seeds.",
        "",
        "| profile | variant | seeds | accuracy | macro-F1 | localisation | mech. localisation | "
        + " | ".join(f"recall {c}" for c in MECHANICAL)
        + " |",
        "|---|---|---|---|---|---|---|" + "---|" * len(MECHANICAL),
    ]
    for profile in ("stock", "full"):
        lines += [r for v in VARIANTS if (r := row(profile, v))]
    atomic_write_text(RESULTS / "stock_vs_full.md", "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
