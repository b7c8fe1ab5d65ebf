"""Do the graph and the trees mislocalise the same windows? (issue 36)

    python studies/arms/localisation_errors.py [--out DIR] [--corpus DIR] [--seeds 42]

For each unseen arm and seed, the leave-one-arm-out models after commissioning (``gbdt``,
``stgnn_fixed``, the headline ``anomaly_residual``; ``studies/arms/campaign.py``) predict
every window of the arm's held-out session. On its faulted windows (those localisation is
scored on) it counts, per model, the windows whose joint is wrong, and how many of a network's
wrong windows ``gbdt`` gets wrong too. Errors shared by models this different point at the
windows, not at a model: what the channels do not show. Also: localisation if one could pick,
per window, whichever model is right (the most that combining these models could give), and per
fault class the share of faulted windows that every model mislocalises.
"""

from __future__ import annotations

import argparse
from collections import defaultdict
from pathlib import Path

import numpy as np

from robohealth_mj.learn.evaluation import score_checkpoint
from robohealth_mj.reporting.markdown import heading
from robohealth_mj.schema import FAULT_CLASSES

ARMS = ("ur3e", "ur5e", "ur10e", "ur16e")
NETWORKS = ("stgnn_fixed", "anomaly_residual")


def joint_correct(run: Path, heldout: Path) -> tuple[np.ndarray, np.ndarray]:
    """``(correct [K], class [K])`` on the faulted windows of ``heldout``: whether the model
    commissioned in ``run`` names the faulted joint, and the window's true class."""
    p = score_checkpoint(run / "commissioned" / "best.ckpt", str(heldout), device="cpu").predictions
    active = p.active.astype(bool)
    return (p.joint_logits.argmax(1) == p.true_joint)[active], p.true_class[active]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("outputs/campaign_arms_grouped"))
    parser.add_argument("--corpus", type=Path, default=Path("outputs/corpus/arms"))
    parser.add_argument("--seeds", default="42,43,44")
    args = parser.parse_args()
    rows, pooled, by_class = [], defaultdict(list), defaultdict(list)
    for arm in ARMS:
        for seed in args.seeds.split(","):
            base = args.out / "full" / "loao" / arm / "structural" / "full" / "C0"
            runs = {v: base / v / "w32" / f"seed{seed}" for v in ("gbdt", *NETWORKS)}
            if not all((r / "commissioned" / "best.ckpt").is_file() for r in runs.values()):
                continue
            heldout = args.corpus / arm / "heldout_seed900"
            scored = {v: joint_correct(r, heldout) for v, r in runs.items()}
            correct = {v: c for v, (c, _) in scored.items()}
            classes = scored["gbdt"][1]
            all_wrong = ~np.logical_or.reduce(list(correct.values()))
            for c in np.unique(classes):
                by_class[FAULT_CLASSES[c]].append(float(np.mean(all_wrong[classes == c])))
            trees_wrong = ~correct["gbdt"]
            for v in NETWORKS:
                wrong = ~correct[v]
                shared = float(np.mean(trees_wrong[wrong])) if wrong.any() else float("nan")
                either = float(np.mean(correct[v] | correct["gbdt"]))
                row = (arm, seed, v, correct["gbdt"].mean(), correct[v].mean(), shared,
                       trees_wrong.mean(), either)  # fmt: skip
                rows.append(row)
                pooled[v].append(row[3:])
    lines = heading(
        f"Localisation errors shared by the graph and the trees ({args.out.name}, faulted "
        "windows of the unseen arm's held-out session, after commissioning)",
        ["unseen arm", "seed", "network", "gbdt loc.", "network loc.",
         "of the network's wrong windows, gbdt wrong too", "gbdt wrong on all windows",
         "either right"],
    )  # fmt: skip
    for arm, seed, v, g, n, shared, base_rate, either in rows:
        lines.append(
            f"| {arm} | {seed} | {v} | {g:.3f} | {n:.3f} | {shared:.3f} | {base_rate:.3f} | "
            f"{either:.3f} |"
        )
    for v, values in pooled.items():
        g, n, shared, base_rate, either = np.mean(values, axis=0)
        lines.append(
            f"| **mean** | {len(values)} runs | {v} | {g:.3f} | {n:.3f} | {shared:.3f} | "
            f"{base_rate:.3f} | {either:.3f} |"
        )
    lines.append("")
    lines += heading(
        "Faulted windows that every model mislocalises, by fault class (mean over runs)",
        ["class", "share of its faulted windows"],
    )
    lines += [f"| {c} | {np.mean(v):.3f} |" for c, v in sorted(by_class.items())]
    print("\n".join(lines))


if __name__ == "__main__":
    main()
