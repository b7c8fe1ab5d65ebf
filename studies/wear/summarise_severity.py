"""The severity objective's table: per objective and seed, the validation MAE (what chose it),
the held-out session's MAE on faulted windows, per fault class, and the refit's wall time, from the
outputs of ``severity_objective.py`` and ``evaluate`` (``studies/wear/run.sh``).

    python studies/wear/summarise_severity.py outputs/severity_objective --seeds 42,43,44
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from robohealth_mj.reporting.markdown import heading
from robohealth_mj.reporting.statistics import mean_pm_std

CLASSES = ("backlash", "friction", "jam", "struct_weaken", "sensor_drift", "sensor_noise")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("root", type=Path)
    ap.add_argument("--seeds", default="42,43,44")
    args = ap.parse_args()
    seeds = args.seeds.split(",")
    rows: dict[str, list[dict]] = {}
    for seed in seeds:
        for line in (args.root / f"s{seed}.jsonl").read_text().splitlines():
            fit = json.loads(line)
            objective = fit["objective"]
            evaluated = json.loads(
                (args.root / f"s{seed}" / objective / "eval_heldout.json").read_text()
            )
            metrics = evaluated.get("metrics", evaluated)
            rows.setdefault(objective, []).append({"seed": seed, "fit": fit, "heldout": metrics})
    head = ["objective", "seeds", "val MAE", "held-out MAE", *CLASSES, "refit s"]
    print("\n".join(heading("Severity MAE on faulted windows, by objective", head)))

    for objective, runs in rows.items():
        val = [r["fit"]["val_severity_mae_faulted"] for r in runs]
        held = [r["heldout"]["severity_mae_faulted"] for r in runs]
        per_class = [
            f"{np.mean([r['heldout']['per_class'][c]['severity_mae'] for r in runs]):.3f}"
            for c in CLASSES
        ]
        seconds = np.mean([r["fit"]["seconds"] for r in runs])
        print(f"| {objective} | {len(runs)} | {mean_pm_std(val, 4)} | **{mean_pm_std(held, 4)}** | "
              + " | ".join(per_class) + f" | {seconds:.0f} |")  # fmt: skip
    print()
    for objective, runs in rows.items():
        each = ", ".join(f"{r['seed']}: {r['heldout']['severity_mae_faulted']:.4f}" for r in runs)
        print(f"- {objective}, held-out per seed: {each}")


if __name__ == "__main__":
    main()
