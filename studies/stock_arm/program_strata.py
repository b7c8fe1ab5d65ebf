"""The unseen program against the held-out session, window by window kind.

A session's accuracy depends on its mix of windows as well as on the model: healthy windows are
easy, and a faulted joint that stands still through a window shows a friction fault to no
channel the stock arm has. This splits each session's windows into healthy and, per fault class,
faulted windows whose faulted joint moved or stood still; gives each stratum's share and
accuracy; and re-weights the program's per-stratum accuracies by the held-out session's shares
(the program's accuracy had it the held-out session's mix). Stock profile, W = 32, seeds 42-44,
the program scored after commissioning.

    .venv/bin/python studies/stock_arm/program_strata.py [CORPUS] \\
        > studies/stock_arm/results/program_strata.md

Needs the runs of ``studies/thesis_physics/run.sh stock`` and the commissioned checkpoints
``studies/stock_arm/unseen_program.py`` writes (``outputs/unseen_program``).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from robohealth_mj.data.windows import target_joint_moved
from robohealth_mj.learn.evaluation import score_checkpoint

CORPUS = Path(sys.argv[1] if len(sys.argv) > 1 else "outputs/corpus/standard")
RUNS = Path("outputs/thesis_physics/structural/stock/C0")
COMMISSIONED = Path("outputs/unseen_program")
CLASSES = ("none", "backlash", "friction", "jam", "struct_weaken")


def strata(ckpt: Path, data: list[str] | str) -> dict[str, tuple[int, float]]:
    """Stratum -> (windows, accuracy): ``none``, then ``<class> moving`` / ``<class> still``."""
    s = score_checkpoint(ckpt, data, device="cpu")
    p = s.predictions
    right = p.class_logits.argmax(1) == p.true_class
    moving = target_joint_moved(s.rec, s.windows)
    out = {}
    for k, name in enumerate(CLASSES):
        of_class = p.true_class == k
        parts = [("", of_class)] if k == 0 else [(" moving", of_class & moving),
                                                  (" still", of_class & ~moving)]  # fmt: skip
        for suffix, mask in parts:
            n = int(mask.sum())
            out[name + suffix] = (n, float(right[mask].mean()) if n else float("nan"))
    return out


def accuracy(table: dict[str, tuple[int, float]], weights: dict[str, float]) -> float:
    """Accuracy with each stratum weighted by ``weights`` (shares; empty strata dropped)."""
    keep = {k: w for k, w in weights.items() if table[k][0] and w > 0}
    total = sum(keep.values())
    return sum(w * table[k][1] for k, w in keep.items()) / total


def shares(table: dict[str, tuple[int, float]]) -> dict[str, float]:
    n = sum(v[0] for v in table.values())
    return {k: v[0] / n for k, v in table.items()}


def main() -> None:
    program = [str(p) for p in sorted(CORPUS.glob("probe_unseen_program_seed*"))]
    heldout = str(CORPUS / "heldout_seed900")
    print("# The unseen program, stratified (stock profile, W = 32, after commissioning)\n")
    print(f"Made by `.venv/bin/python studies/stock_arm/program_strata.py {CORPUS}`. Per stratum:")
    print("share of the session's windows, then accuracy (mean over seeds 42-44). `moving` /")
    print("`still`: faulted windows whose faulted joint moved / stood still through the window.\n")
    for variant in ("gbdt", "mlp", "stgnn_fixed"):
        rows = []
        for seed in (42, 43, 44):
            trained = RUNS / variant / "w32" / f"seed{seed}" / "best.ckpt"
            commissioned = COMMISSIONED / variant / f"seed{seed}" / "best.ckpt"
            rows.append((strata(trained, heldout), strata(commissioned, program)))
        names = list(rows[0][0])
        print(f"## {variant}\n")
        print("| stratum | held-out share | held-out acc. | program share | program acc. |")
        print("|---|---|---|---|---|")
        for k in names:
            cells = []
            for side in (0, 1):
                share = np.mean([shares(r[side])[k] for r in rows])
                acc = np.nanmean([r[side][k][1] for r in rows])
                cells += [f"{share:.3f}", f"{acc:.3f}"]
            print(f"| {k} | " + " | ".join(cells) + " |")
        held = [accuracy(r[0], shares(r[0])) for r in rows]
        prog = [accuracy(r[1], shares(r[1])) for r in rows]
        mixed = [accuracy(r[1], shares(r[0])) for r in rows]
        moving_only = [
            (accuracy(r[0], {k: v for k, v in shares(r[0]).items() if "still" not in k}),
             accuracy(r[1], {k: v for k, v in shares(r[1]).items() if "still" not in k}))
            for r in rows
        ]  # fmt: skip
        print()
        print(f"- accuracy: held-out {np.mean(held):.3f}, program {np.mean(prog):.3f} "
              f"(gap {np.mean(held) - np.mean(prog):+.3f})")  # fmt: skip
        print(f"- program at the held-out session's mix of strata: {np.mean(mixed):.3f} "
              f"(gap {np.mean(held) - np.mean(mixed):+.3f})")  # fmt: skip
        h, p = np.mean(moving_only, axis=0)
        print(f"- healthy and moving-fault windows only: held-out {h:.3f}, program {p:.3f} "
              f"(gap {h - p:+.3f})\n")  # fmt: skip


if __name__ == "__main__":
    main()
