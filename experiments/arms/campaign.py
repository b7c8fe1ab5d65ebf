"""The cross-arm experiment (issue 36): per-arm models, then leave-one-arm-out before and after
commissioning, and false alarms on the unseen arm's healthy hour.

    python experiments/arms/campaign.py [--variants gbdt,stgnn_fixed] [--seeds 42,43,44]
        [--epochs 10] [--sensing full] [--arms ur3e,ur5e,ur10e,ur16e]

Reads the per-arm corpora ``outputs/corpus/arms/<arm>`` (``python -m robohealth_mj.corpus
corpus=arms ...``, see ``results/arms/command.sh``) and writes under ``outputs/campaign_arms``:

- ``own/<arm>/...``: each arm's own models (trained on its sessions, scored on its held-out one);
- ``loao/<arm>/...``: models trained with ``transfer=true`` on the three other arms, scored on
  ``<arm>``'s held-out session; ``commissioned/`` beside each: the model commissioned on ten
  minutes of ``<arm>``'s healthy running and scored again; networks are also replayed through the
  monitor over ``<arm>``'s healthy hour (``alarms_seed*.json``).

Every step skips what is done, so an interrupted campaign resumes. Training runs through the
package's own entry points (Hydra multirun, two jobs of one thread).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

CORPUS = Path("outputs/corpus/arms")
OUT = Path("outputs/campaign_arms")
ARMS = ("ur3e", "ur5e", "ur10e", "ur16e")
HEALTHY_HOUR = ("healthy_hour_seed950", "healthy_hour_seed951", "healthy_hour_seed952")


def run(*args: str) -> None:
    print("+", " ".join(args), flush=True)
    subprocess.run([sys.executable, "-m", *args], check=True)


def train(sweep: Path, train: list[str], heldout: str, args: argparse.Namespace, *extra: str):
    run(
        "robohealth_mj.train",
        "-m",
        f"variant={args.variants}",
        f"seed={args.seeds}",
        f"sensing={args.sensing}",
        "window=32",
        f"data.train=[{','.join(train)}]",
        f"data.evaluate.heldout={heldout}",
        "data.evaluate.probe=null",
        f"trainer.epochs={args.epochs}",
        "trainer.threads=1",
        "trainer.progress=false",
        "hydra/launcher=local",
        f"hydra.sweep.dir={sweep}",
        *extra,
    )


def runs(sweep: Path) -> list[Path]:
    return sorted(p.parent for p in sweep.rglob("best.ckpt") if p.parent.name != "commissioned")


def commission_and_score(run_dir: Path, arm: str) -> None:
    """Commission ``run_dir``'s model on ``arm``'s healthy ten minutes, score it on ``arm``'s
    held-out session and (networks) count its alarms over ``arm``'s healthy hour."""
    done = run_dir / "commissioned"
    if not (done / "best.ckpt").is_file():
        run("robohealth_mj.commission", f"model={run_dir / 'best.ckpt'}",
            f"healthy={CORPUS / arm / 'healthy_commissioning_seed940'}", f"out={done}")  # fmt: skip
    if not (done / "eval_heldout.json").is_file():
        run("robohealth_mj.evaluate", f"ckpt={done / 'best.ckpt'}",
            f"data={CORPUS / arm / 'heldout_seed900'}", f"out={done / 'eval_heldout'}")  # fmt: skip
    if not (done / "model.onnx").is_file():
        return  # a tree ensemble: no streaming runtime
    for session in HEALTHY_HOUR:
        out = done / f"alarms_{session}.json"
        if not out.is_file():
            run("robohealth_mj.monitor", "source=replay", f"model={done / 'model.onnx'}",
                f"file={CORPUS / arm / session / 'graphs.jsonl'}", "evaluate=true", "quiet=true",
                f"out={out}")  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--variants", default="gbdt,stgnn_fixed")
    parser.add_argument("--seeds", default="42")
    parser.add_argument("--epochs", type=int, default=10)
    parser.add_argument("--sensing", default="full")
    parser.add_argument("--arms", default=",".join(ARMS))
    parser.add_argument("--stages", default="own,loao", help="own, loao or both")
    parser.add_argument(
        "--out", type=Path, default=OUT, help="campaign root (a variant recipe's own)"
    )
    args = parser.parse_args()
    arms = args.arms.split(",")
    missing = [a for a in arms if not (CORPUS / a / "corpus.json").is_file()]
    if missing:
        raise SystemExit(
            f"no corpus for {', '.join(missing)}: python -m robohealth_mj.corpus corpus=arms "
            f"out_dir={CORPUS}/<arm> 'record_overrides=[\"arm=<arm>\"]' (results/arms/command.sh)"
        )
    stages = args.stages.split(",")
    for arm in arms:
        heldout = str(CORPUS / arm / "heldout_seed900")
        if "own" in stages:
            train(args.out / args.sensing / "own" / arm, [f"{CORPUS}/{arm}/train_*"], heldout, args)
        if "loao" in stages:
            others = [f"{CORPUS}/{a}/train_*" for a in ARMS if a != arm]
            sweep = args.out / args.sensing / "loao" / arm
            train(sweep, others, heldout, args, "transfer=true")
            for run_dir in runs(sweep):
                commission_and_score(run_dir, arm)


if __name__ == "__main__":
    main()
