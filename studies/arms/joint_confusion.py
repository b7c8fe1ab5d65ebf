"""Where on the chain does a leave-one-arm-out model put the faulted joint? (issue 65)

    python studies/arms/joint_confusion.py [--out DIR] [--corpus DIR] [--arms fr3,gen3]
        [--variants anomaly_residual,gbdt] [--seed 42]

For each unseen arm and model, commissioned (``studies/arms/campaign.py``), the faulted windows
of the arm's held-out session: the share of the windows of each true joint (rows) named as
each joint (columns), and how often each joint is named at all. A model whose localisation is
near chance while its class is right names one or two places for every fault: what it learnt to
point at on its training arms, not the unseen arm's joints.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from robohealth_mj.learn.evaluation import score_checkpoint


def confusion(run: Path, heldout: Path) -> np.ndarray:
    """``[J, J]``: faulted windows of true joint (row) named as joint (column), row-normalised."""
    p = score_checkpoint(run / "commissioned" / "best.ckpt", str(heldout), device="cpu").predictions
    active = p.active.astype(bool)
    true, named = p.true_joint[active], p.joint_logits.argmax(1)[active]
    j = p.joint_logits.shape[1]
    counts = np.zeros((j, j))
    np.add.at(counts, (true, named), 1)
    return counts / np.maximum(counts.sum(1, keepdims=True), 1)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("outputs/campaign_family"))
    parser.add_argument("--corpus", type=Path, default=Path("outputs/corpus/arms"))
    parser.add_argument("--arms", default="fr3,iiwa14,gen3,xarm7")
    parser.add_argument("--variants", default="anomaly_residual,gbdt")
    parser.add_argument("--seed", default="42")
    args = parser.parse_args()
    for arm in args.arms.split(","):
        for variant in args.variants.split(","):
            run = args.out / "full" / "loao" / arm / "structural" / "full" / "C0" / variant
            run = run / "w32" / f"seed{args.seed}"
            if not (run / "commissioned" / "best.ckpt").is_file():
                continue
            c = confusion(run, args.corpus / arm / "heldout_seed900")
            diagonal = " ".join(f"{v:.2f}" for v in np.diag(c))
            named = " ".join(f"{v:.2f}" for v in c.mean(0))
            print(f"{args.out.name} {arm} {variant}: right per joint [{diagonal}]; "
                  f"named (share of windows per joint) [{named}]")  # fmt: skip


if __name__ == "__main__":
    main()
