"""What a quiet operating point costs: the real-arm campaign's models, as trained and as
commissioned, on the twin's held-out session (simulated faults), per fault class.

    python studies/real_arms/sensitivity.py --runs standard,cruise --seed 42 \\
        --suffix _ownmotion_rate0.99 > studies/real_arms/results/sensitivity.md

A run that calls fewer of the real arm's healthy ticks faulty may do so by calling fewer faults
too; this prints, for each run's ``gbdt`` and ``stgnn_fixed`` at ``--seed``, the share of the
held-out session's faulted windows called a fault and each class's recall, before and after
commissioning (``commissioned<suffix>``), with ``observability=motion`` as monitored. Every run
reads the same session (the standard corpus's, recorded on the twin), so the rows compare. Runs
after ``campaign.py`` (its models and corpora under ``outputs/``).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from robohealth_mj import schema
from robohealth_mj.learn.evaluation import evaluate_checkpoint
from robohealth_mj.learn.metrics import detection_rates

ROOT = Path("outputs/real_arms")
HELDOUT = "outputs/corpus/real_ur10e_standard/heldout_seed900"
FAULTS = schema.FAULT_CLASSES[1:]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", default="standard,cruise", help="comma-separated run names")
    parser.add_argument("--seed", default="42")
    parser.add_argument("--suffix", default="_ownmotion_rate0.99", help="commissioned<suffix>")
    parser.add_argument("--variants", default="gbdt,stgnn_fixed")
    args = parser.parse_args()
    print(f"## Simulated faults on the twin's held-out session ({HELDOUT}), seed {args.seed}\n")
    print("Recall per class; `observability=motion`; commissioned: `commissioned"
          f"{args.suffix}`.\n")  # fmt: skip
    head = " | ".join(FAULTS)
    print(f"| run | model | checkpoint | accuracy | healthy called a fault "
          f"| faulted called a fault | {head} |")  # fmt: skip
    print("|---|---|---|---|---|---|" + "---|" * len(FAULTS))
    for run in args.runs.split(","):
        for variant in args.variants.split(","):
            base = ROOT / run / "models"
            for trained in sorted(base.rglob(f"{variant}/w32/seed{args.seed}/best.ckpt")):
                commissioned = trained.parent / f"commissioned{args.suffix}" / "best.ckpt"
                for where, ckpt in (("trained", trained), ("commissioned", commissioned)):
                    if not ckpt.is_file():
                        continue
                    m = evaluate_checkpoint(ckpt, HELDOUT, "cpu", "last", "motion")["metrics"]
                    healthy, faulted = detection_rates(m)
                    recall = " | ".join(
                        f"{m['per_class'].get(c, {}).get('recall', float('nan')):.3f}"
                        for c in FAULTS
                    )
                    name = f"**{variant}**" if variant == "gbdt" else variant
                    print(f"| {run} | {name} | {where} | {m['accuracy']:.3f} | {healthy:.3f} "
                          f"| {faulted:.3f} | {recall} |")  # fmt: skip
    print('\nCommand: `bash studies/real_arms/run.sh` (the block after "Cruising moves").')


if __name__ == "__main__":
    main()
