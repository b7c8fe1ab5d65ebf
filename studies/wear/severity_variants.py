"""How the severity head's formulation was chosen: each candidate's MAE on the faulted windows of
the validation split of a trained gbdt checkpoint (its class and joint boosters kept), the split
the boosters stop early on. Selection only: the held-out figures come from `evaluate` on the
checkpoints `severity_objective.py` writes.

    python studies/wear/severity_variants.py outputs/severity_labels/gbdt_last/best.ckpt

Candidates: squared and absolute error regressions; one level classifier over all faults, read
as the expectation and as the median of its distribution; level classifiers per fault class,
mixed by the class posterior; per (class, joint), mixed by the class and joint posteriors (the
``levels`` objective), with fewer leaves and a lower learning rate beside it. One JSON line each.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from robohealth_mj.learn.checkpoint import load_checkpoint
from robohealth_mj.learn.trainer import prepare_from_checkpoint, tree_table
from robohealth_mj.models.boosting import train_early_stopped
from robohealth_mj.models.severity_levels import (
    SeverityLevels,
    level_classifier,
    median_level,
    nearest_level,
    severity_levels,
)

ROUNDS, PATIENCE = 300, 50


def _classifier(x, y, x_val, y_val, params, n):
    return train_early_stopped(
        level_classifier(params, n), (x, y), (x_val, y_val), ROUNDS, PATIENCE
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("ckpt", type=Path)
    args = ap.parse_args()
    ckpt = load_checkpoint(args.ckpt)
    p = prepare_from_checkpoint(ckpt)  # its data, split, normalisation and boosters
    cfg = p.cfg
    tables = [tree_table(p, p.splits[s]) for s in ("train", "val")]
    (x, c, j, s), (xv, cv, jv, sv) = [tuple(a[t[2] >= 0] for a in t) for t in tables]
    params = {**p.model.params, "seed": int(cfg.seed)}
    classes = p.model._booster("class").predict(xv)
    joints = p.model._booster("joint").predict(xv)
    levels = severity_levels(s, 10)
    y, y_val = nearest_level(s, levels), nearest_level(sv, levels)

    def report(name: str, predicted: np.ndarray, started: float) -> None:
        mae = float(np.abs(np.clip(predicted, 0, 1) - sv).mean())
        row = {"candidate": name, "val_severity_mae_faulted": round(mae, 4)}
        print(json.dumps({**row, "seconds": round(time.perf_counter() - started, 1)}), flush=True)

    def median(dist: np.ndarray) -> np.ndarray:
        return median_level(dist, levels)

    for objective in ("regression", "regression_l1"):
        started = time.perf_counter()
        booster = train_early_stopped(
            {**params, "objective": objective, "metric": "l1"}, (x, s), (xv, sv), ROUNDS, PATIENCE
        )
        report(objective, booster.predict(xv), started)
    started = time.perf_counter()
    dist = _classifier(x, y, xv, y_val, params, len(levels)).predict(xv)
    report("one level classifier, expectation", dist @ levels, started)
    report("one level classifier, median", median(dist), started)
    started = time.perf_counter()
    mix = np.zeros_like(dist)
    faults = np.unique(c)
    posterior = classes[:, faults] / classes[:, faults].sum(1, keepdims=True)  # P(c | faulted)
    for k, fault in enumerate(faults):
        model = _classifier(x[c == fault], y[c == fault], xv[cv == fault], y_val[cv == fault],
                            params, len(levels))  # fmt: skip
        mix += posterior[:, [k]] * model.predict(xv)
    report("per fault class, class-posterior mixture, median", median(mix), started)
    for name, extra in (("", {}), (", 15 leaves", {"num_leaves": 15}),
                        (", learning rate 0.05", {"learning_rate": 0.05})):  # fmt: skip
        started = time.perf_counter()
        head, _ = SeverityLevels.fit(
            (x, c, j, s), (xv, cv, jv, sv), {**params, **extra}, ROUNDS, PATIENCE
        )
        report(f"per (class, joint), levels objective{name}", head.predict(xv, classes, joints),
               started)  # fmt: skip


if __name__ == "__main__":
    main()
