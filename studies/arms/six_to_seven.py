"""Issue 65's hard case: a model trained on a six-joint arm only (the UR5e's own models of
``studies/arms/run_seven.sh``), read on each seven-joint arm, each joint as its UR counterpart
(``learn/other_arm.py``), before and after commissioning on the arm's ten healthy minutes,
beside the arm's own model of the same recipe.

    python studies/arms/six_to_seven.py [--source ur5e] [--targets fr3,iiwa14,gen3,xarm7]
        [--variants mlp,anomaly_residual] [--seeds 42]

Reads the per-arm corpora ``outputs/corpus/arms/<arm>`` and the models of
``outputs/campaign_seven``; writes under ``outputs/campaign_seven/full/six``. ``gbdt`` has no
row: its input is the six joints' statistics in a fixed order, which a seventh joint has no place
in. Every step skips what is done.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from robohealth_mj.common.steps import run_step
from robohealth_mj.learn.checkpoint import load_checkpoint, write_checkpoint
from robohealth_mj.learn.other_arm import read_as

CORPUS = Path("outputs/corpus/arms")
OUT = Path("outputs/campaign_seven/full")


def own_run(arm: str, variant: str, seed: str) -> Path | None:
    """The arm's own run of ``variant`` at ``seed`` (``campaign.py``'s sweep layout)."""
    found = sorted((OUT / "own" / arm).glob(f"**/{variant}/w32/seed{seed}/best.ckpt"))
    return found[0].parent if found else None


def metrics(path: Path) -> dict | None:
    return json.loads(path.read_text())["metrics"] if path.is_file() else None


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--source", default="ur5e")
    parser.add_argument("--targets", default="fr3,iiwa14,gen3,xarm7")
    parser.add_argument("--variants", default="mlp,anomaly_residual")
    parser.add_argument("--seeds", default="42")
    args = parser.parse_args()
    targets = args.targets.split(",")
    print("| arm | variant | own acc. | own loc. | UR5e's model read on it: acc. | loc. | "
          "... commissioned: acc. | loc. |\n|---|---|---|---|---|---|---|---|")  # fmt: skip
    for variant in args.variants.split(","):
        for seed in args.seeds.split(","):
            source = own_run(args.source, variant, seed)
            if source is None:
                raise SystemExit(f"no {variant} seed {seed} of {args.source}: run run_seven.sh")
            for arm in targets:
                run = OUT / "six" / arm / variant / f"seed{seed}"
                if not (run / "best.ckpt").is_file():
                    run.mkdir(parents=True, exist_ok=True)
                    trained = source / "best.ckpt"
                    adapted = read_as(load_checkpoint(trained), arm, str(trained.resolve()))
                    write_checkpoint(run / "best.ckpt", adapted)
                if not (run / "eval_heldout.json").is_file():
                    run_step("robohealth_mj.evaluate", f"ckpt={run / 'best.ckpt'}",
                             f"data={CORPUS / arm / 'heldout_seed900'}",
                             f"out={run / 'eval_heldout'}", quiet=True)  # fmt: skip
                done = run / "commissioned"
                if not (done / "best.ckpt").is_file():
                    run_step("robohealth_mj.commission", f"model={run / 'best.ckpt'}",
                             f"healthy={CORPUS / arm / 'healthy_commissioning_seed940'}",
                             f"out={done}", quiet=True)  # fmt: skip
                if not (done / "eval_heldout.json").is_file():
                    run_step("robohealth_mj.evaluate", f"ckpt={done / 'best.ckpt'}",
                             f"data={CORPUS / arm / 'heldout_seed900'}",
                             f"out={done / 'eval_heldout'}", quiet=True)  # fmt: skip
                read = metrics(run / "eval_heldout.json")
                after = metrics(done / "eval_heldout.json")
                mine = own_run(arm, variant, seed)
                own = (metrics(mine / "eval_heldout.json") if mine else None) or {}
                cells = [own.get("accuracy"), own.get("localisation_accuracy"),
                         read["accuracy"], read["localisation_accuracy"],
                         after["accuracy"], after["localisation_accuracy"]]  # fmt: skip
                shown = " | ".join("–" if c is None else f"{c:.3f}" for c in cells)
                print(f"| {arm} | {variant} | {shown} |")


if __name__ == "__main__":
    main()
