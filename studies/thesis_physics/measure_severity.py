"""Where the severity head's error comes from: MAE on faulted held-out windows, split by what the
model called the window (the right fault, healthy, another fault), per class on the recognised
windows, beside a constant guess of 0.6. Markdown on stdout.

Usage: measure.py HELDOUT_DIR CKPT [CKPT ...]
"""

from __future__ import annotations

import sys

import numpy as np
import torch

from robohealth_mj.learn.evaluation import score_checkpoint
from robohealth_mj.schema import FAULT_CLASSES


def strata(heldout: str, ckpt_path: str) -> list[str]:
    p = score_checkpoint(ckpt_path, heldout, "cpu").predictions
    if p.severity is None:
        raise SystemExit(f"{ckpt_path}: the model has no severity head")
    faulted = p.active.astype(bool)
    error = np.abs(p.severity - p.true_severity)
    called = p.class_logits.argmax(1)
    right = called == p.true_class
    healthy = called == FAULT_CLASSES.index("none")
    rows = [
        f"`{ckpt_path}`",
        "",
        "| faulted windows | count | severity MAE |",
        "|---|---|---|",
    ]
    for name, mask in (
        ("class recognised", faulted & right),
        ("called healthy", faulted & healthy),
        ("another fault", faulted & ~right & ~healthy),
        ("all", faulted),
    ):
        rows.append(f"| {name} | {mask.sum()} | {error[mask].mean():.3f} |")
    guess = np.abs(0.6 - p.true_severity[faulted]).mean()
    rows.append(f"| all, constant guess 0.6 | {faulted.sum()} | {guess:.3f} |")
    rows += ["", "| class | recognised | MAE recognised | MAE all |", "|---|---|---|---|"]
    for c, name in enumerate(FAULT_CLASSES):
        mine = faulted & (p.true_class == c)
        if mine.any():
            mask = mine & right
            rows.append(
                f"| {name} | {mask.sum()} | {error[mask].mean():.3f} | {error[mine].mean():.3f} |"
            )
    return [*rows, ""]


if __name__ == "__main__":
    torch.set_num_threads(1)
    print("# Severity head: where the error comes from (held-out, faulted windows)\n")
    for path in sys.argv[2:]:
        print("\n".join(strata(sys.argv[1], path)))
