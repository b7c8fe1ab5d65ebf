"""The gbdt severity booster under each LightGBM objective, on one trained checkpoint: its class and
joint boosters kept, the severity booster refit per objective on the same training windows (early
stopping on the validation split, as in training), each written as a checkpoint that `evaluate`
scores on the held-out session. Choose on the printed validation MAE; held-out only to report.

    python studies/wear/severity_objective.py outputs/severity_labels/gbdt_last/best.ckpt \
        --objectives regression,regression_l1,levels --out outputs/severity_objective

Prints one JSON line per objective: validation MAE on faulted windows, rounds, seconds, and
whether the refit ``regression`` booster equals the checkpoint's byte for byte (it should: a head's
trees depend on its own objective, data and seed alone).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import torch

from robohealth_mj.learn.checkpoint import load_checkpoint
from robohealth_mj.learn.metrics import metrics_of
from robohealth_mj.learn.predict import predict
from robohealth_mj.learn.trainer import prepare_from_checkpoint, save_prepared, tree_table


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("ckpt", type=Path, help="a gbdt checkpoint trained with model.severity=true")
    ap.add_argument("--objectives", default="regression,regression_l1,levels")
    ap.add_argument("--out", type=Path, default=Path("outputs/severity_objective"))
    args = ap.parse_args()
    ckpt = load_checkpoint(args.ckpt)
    p = prepare_from_checkpoint(ckpt)  # its data, split, normalisation and boosters
    cfg = p.cfg
    train, val = tree_table(p, p.splits["train"]), tree_table(p, p.splits["val"])
    for objective in args.objectives.split(","):
        started = time.perf_counter()
        p.model.severity_objective = objective
        p.cfg.model.severity_objective = objective
        record = p.model.fit(train, val, seed=int(cfg.seed), only=("severity",))
        seconds = time.perf_counter() - started
        val_m = metrics_of(predict(p.model, p.tensors, p.splits["val"]))
        save_prepared(p, args.out / objective, 1, None)
        same = torch.equal(p.model.severity_booster, ckpt["state_dict"]["severity_booster"])
        row = {
            "objective": objective,
            "val_severity_mae_faulted": val_m.get("severity_mae_faulted"),
            "val_accuracy": val_m.get("accuracy"),
            "rounds": record["severity"]["best_iteration"],
            "seconds": round(seconds, 1),
            "equals_checkpoint_booster": same,
            "ckpt": str(args.out / objective / "best.ckpt"),
        }
        print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
