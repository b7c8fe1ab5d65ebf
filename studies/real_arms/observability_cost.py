"""What ``observability=motion`` costs in simulation: the real-arm campaign's models on the twin's
held-out session, with and without the rule, scored on both label rules.

    python studies/real_arms/observability_cost.py [--run standard] [--seed 42]
        > studies/real_arms/results/observability_cost.md

Friction and backlash on a joint that stood still through a window show nothing, so the rule
hands them to ``none``; scored on ``labels=last`` that counts as a miss, on ``labels=visible``
(the same definition of *moved*) as a healthy window rightly called healthy. Runs after
``campaign.py`` (its models and corpus under ``outputs/``).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from robohealth_mj.learn.evaluation import evaluate_checkpoint
from robohealth_mj.learn.metrics import detection_rates

ROOT = Path("outputs/real_arms")
HELDOUT = "outputs/corpus/real_ur10e_standard/heldout_seed900"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--run", default="standard")
    parser.add_argument("--seed", default="42")
    args = parser.parse_args()
    models = ROOT / args.run / "models"
    print(f"## `observability` on the twin's held-out session ({HELDOUT}), run {args.run}\n")
    print("| model | checkpoint | labels | observability | windows | accuracy | localisation "
          "| healthy called a fault | faulted called a fault | friction recall |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|---|")
    for variant in ("gbdt", "stgnn_fixed"):
        for ckpt in sorted(models.rglob(f"{variant}/w32/seed{args.seed}/**/best.ckpt")):
            for labels in ("last", "visible"):
                for rule in ("all", "motion"):
                    r = evaluate_checkpoint(ckpt, HELDOUT, "cpu", labels, rule)
                    m = r["metrics"]
                    healthy, faulted = detection_rates(m)
                    friction = m["per_class"].get("friction", {}).get("recall", float("nan"))
                    name = f"**{variant}**" if variant == "gbdt" else variant
                    where = ckpt.parent.name if "commissioned" in ckpt.parent.name else "trained"
                    print(f"| {name} | {where} | {labels} | {rule} | {m['windows']} "
                          f"| {m['accuracy']:.3f} | {m['localisation_accuracy']:.3f} "
                          f"| {healthy:.3f} | {faulted:.3f} | {friction:.3f} |")  # fmt: skip
    print('\nCommand: `bash studies/real_arms/run.sh` (the block after "Observability").')


if __name__ == "__main__":
    main()
