"""Ablation: leave-one-arm-out with the channels in raw units (N m, rad/s) instead of relative to
each joint's ratings: what the relative channels buy a model that reads an arm it never saw.

    python studies/arms/raw_channels.py [--arms ur3e,ur16e] [--variants gbdt,stgnn_fixed]
        [--seed 42] [--epochs 10]

Trains as ``studies/arms/campaign.py`` does (W = 32, ``transfer=true`` on the three other
arms) with every arm's channel scale set to one, scores on the unseen arm's held-out session
(also read raw), and writes ``outputs/campaign_arms/raw/<arm>/<variant>/seed<s>/``; then prints
the rows beside the relative-channel runs of the campaign.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from robohealth_mj import schema
from robohealth_mj.common.config import compose_config
from robohealth_mj.data import relative
from robohealth_mj.learn.run import train_and_evaluate

CORPUS = Path("outputs/corpus/arms")
OUT = Path("outputs/campaign_arms")
ARMS = ("ur3e", "ur5e", "ur10e", "ur16e")


def raw_scale(arm: str) -> np.ndarray:
    """Every arm read in its own units: the ablated channel scale."""
    return np.ones((schema.N_NODES, schema.N_FEATURES), np.float32)


def metrics(path: Path) -> dict | None:
    return json.loads(path.read_text())["metrics"] if path.is_file() else None


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--arms", default="ur3e,ur16e")
    parser.add_argument("--variants", default="gbdt,stgnn_fixed")
    parser.add_argument("--seed", type=int, default=42)
    parser.add_argument("--epochs", type=int, default=10)
    args = parser.parse_args()
    relative.channel_scale = raw_scale  # load_recordings reads it through the module
    rows = []
    for arm in args.arms.split(","):
        others = ",".join(f"{CORPUS}/{a}/train_*" for a in ARMS if a != arm)
        for variant in args.variants.split(","):
            out = OUT / "raw" / arm / variant / f"seed{args.seed}"
            heldout = CORPUS / arm / "heldout_seed900"
            cfg = compose_config("train", [
                f"variant={variant}", f"seed={args.seed}", "window=32", "transfer=true",
                f"data.train=[{others}]", f"data.evaluate.heldout={heldout}",
                "data.evaluate.probe=null", f"trainer.epochs={args.epochs}",
                "trainer.progress=false",
            ])  # fmt: skip
            train_and_evaluate(cfg, out)
            pattern = f"**/{variant}/w32/seed{args.seed}/eval_heldout.json"
            rel = next((OUT / "full" / "loao" / arm).glob(pattern), None)
            raw, scaled = metrics(out / "eval_heldout.json"), metrics(rel) if rel else None
            cells = [raw["accuracy"], raw["localisation_accuracy"]]
            if scaled:
                cells += [scaled["accuracy"], scaled["localisation_accuracy"]]
            rows.append(f"| {arm} | {variant} | " + " | ".join(f"{c:.3f}" for c in cells) + " |")
    print(f"# Relative channels, ablated (seed {args.seed}, W = 32, leave-one-arm-out, before "
          "commissioning)\n\n`python studies/arms/raw_channels.py` (every arm read in its own "
          "units: N m, rad/s) beside the\nrelative-channel runs of "
          "`studies/arms/campaign.py`.\n")  # fmt: skip
    print("| unseen arm | variant | raw acc. | raw loc. | relative acc. | relative loc. |")
    print("|---|---|---|---|---|---|")
    print("\n".join(rows))


if __name__ == "__main__":
    main()
