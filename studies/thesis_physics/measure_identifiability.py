"""Why the learned coupling's shoulder_pan row misses C0: how well each joint's state explains each
sensor package on healthy ticks (R^2 of a least-squares fit of the package's 8 sensor channels, one
at a time, on the joint's pos, vel, effort, vel^2, |effort|), beside per-row correlations of learned
couplings with C0.

    .venv/bin/python studies/thesis_physics/measure_identifiability.py CORPUS_GLOB RUN_DIR...
"""

from __future__ import annotations

import glob
import json
import sys
from pathlib import Path

import numpy as np

from robohealth_mj.data.arrays import load_recordings
from robohealth_mj.schema import JOINT_NAMES


def explained(x: np.ndarray) -> np.ndarray:
    """R^2 [joint j, package k], mean over the package's sensor channels."""
    r2 = np.zeros((6, 6))
    for j in range(6):
        design = np.column_stack(
            [
                x[:, j, 2],
                x[:, j, 3],
                x[:, j, 4],
                x[:, j, 3] ** 2,
                np.abs(x[:, j, 4]),
                np.ones(len(x)),
            ]
        )
        for k in range(6):
            scores = []
            for ch in range(7, 15):
                y = x[:, 6 + k, ch]
                beta, *_ = np.linalg.lstsq(design, y, rcond=None)
                scores.append(1 - (y - design @ beta).var() / max(y.var(), 1e-12))
            r2[j, k] = np.mean(scores)
    return r2


def main() -> None:
    rec = load_recordings(sorted(glob.glob(sys.argv[1])))
    r2 = explained(rec.x[~rec.active])
    print("R^2 of package k's sensor channels from joint j's state, healthy ticks")
    print("| joint \\ package | " + " | ".join(JOINT_NAMES) + " |")
    print("|---|" + "---|" * 6)
    for j, name in enumerate(JOINT_NAMES):
        print(f"| {name} | " + " | ".join(f"{v:.2f}" for v in r2[j]) + " |")
    print()
    print("| run | corr(C, C0) | per joint row |")
    print("|---|---|---|")
    for run in sys.argv[2:]:
        summary = json.loads(Path(run, "train_summary.json").read_text())
        c, c0 = np.array(summary["coupling"]), np.array(summary["coupling_truth"])
        rows = [float(np.corrcoef(a, b)[0, 1]) for a, b in zip(c, c0, strict=True)]
        print(f"| {run} | {np.mean(rows):+.3f} | " + ", ".join(f"{v:+.2f}" for v in rows) + " |")


if __name__ == "__main__":
    main()
