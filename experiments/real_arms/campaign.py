"""Sim-to-real on a real UR10e (issue 37): identify a twin from the arm's healthy logs, record a
corpus on the twin, train the stock_reduced profile's models on it, commission them on healthy
real logs and monitor the arm's other real logs.

    experiments/real_arms/fetch.sh                   # the logs -> outputs/real_arms/logs/
    python experiments/real_arms/campaign.py [--variants gbdt,stgnn_fixed] [--seed 42] [--epochs 10]

Writes under ``outputs/real_arms/``: ``twin/`` (twin.yaml, fidelity.md), the corpus
``outputs/corpus/real_ur10e``, the models ``models/``, per model and log the monitor's verdict
(``verdicts/``), and prints the tables ``results/real_arms/`` keeps. Every step skips what is
done. Logs: which fits, which commissions and which are monitored is fixed below (``LOGS``).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path("outputs/real_arms")
LOGS = ROOT / "logs"
CORPUS = Path("outputs/corpus/real_ur10e")
ID = LOGS / "identification_data"
LOGS_ROLES = {
    # identification: three excitation trajectories (12 harmonics), about 2.5 min
    "fit": [
        ID / f
        for f in (
            "ur-20_02_12-50sec_12harm.csv",
            "ur-20_02_12-40sec_12harm.csv",
            "ur-20_02_10-30sec_12harm.csv",
        )
    ],
    # fidelity: logs the fit never saw
    "validate": [
        ID / "ur-20_02_19_14harm50sec.csv",
        LOGS / "validation_data" / "ur-20_01_17-ptp_10_points.csv",
        ID / "ur-19_12_23_free.csv",
    ],
    # commissioning: one joint at a time, each through its range (6.8 min)
    "commission": sorted((LOGS / "jointwise_motion").glob("*.csv")),
}


def healthy_monitored() -> list[Path]:
    """Every healthy real log not used to commission, with no payload, that ingests."""
    unreadable = {"ur-19_09_27-11_28_22.csv", "ur-19_09_27-11_32_02.csv",  # another layout
                  "ur-20_02_19_15harm50secLoad.csv"}  # fmt: skip  # a corrupt file
    logs = sorted(ID.glob("*.csv")) + sorted((LOGS / "validation_data").glob("*.csv"))
    return [p for p in logs if p.name not in unreadable and "load" not in p.name.lower()]


def events() -> dict[str, list[Path]]:
    return {
        "push": sorted((LOGS / "collision").glob("*.csv")),
        "load": [p for p in sorted(ID.glob("*.csv")) if "load" in p.name.lower()
                 and "unload" not in p.name.lower() and "15harm50secLoad" not in p.name],
    }  # fmt: skip


def run(*args: str) -> None:
    print("+", " ".join(args), flush=True)
    subprocess.run([sys.executable, "-m", *args], check=True)


def as_list(paths: list[Path]) -> str:
    return "[" + ",".join(str(p) for p in paths) + "]"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--variants", default="gbdt,stgnn_fixed")
    parser.add_argument("--seed", default="42")
    parser.add_argument("--epochs", type=int, default=10)
    parser.add_argument("--corpus", default="quick")
    args = parser.parse_args()
    if not LOGS.is_dir():
        raise SystemExit(f"no logs in {LOGS}: run experiments/real_arms/fetch.sh")
    twin = ROOT / "twin" / "twin.yaml"
    if not twin.is_file():
        run("robohealth_mj.identify", "arm=ur10e", f"fit={as_list(LOGS_ROLES['fit'])}",
            f"validate={as_list(LOGS_ROLES['validate'])}", f"out={twin.parent}")  # fmt: skip
    if not (CORPUS / "corpus.json").is_file():
        run("robohealth_mj.corpus", f"corpus={args.corpus}", f"out_dir={CORPUS}",
            f'record_overrides=["arm=ur10e","sim.twin={twin}"]', "progress=false")  # fmt: skip
    sweep = ROOT / "models"
    if not any(sweep.rglob("best.ckpt")):
        run("robohealth_mj.train", "-m", f"variant={args.variants}", f"seed={args.seed}",
            "sensing=stock_reduced", "window=32", f"data.train=[{CORPUS}/train_*]",
            f"data.evaluate.heldout={CORPUS}/heldout_seed900", "data.evaluate.probe=null",
            f"trainer.epochs={args.epochs}", "trainer.threads=1", "trainer.progress=false",
            "hydra/launcher=local", f"hydra.sweep.dir={sweep}")  # fmt: skip
    verdicts = ROOT / "verdicts"
    for ckpt in sorted(p for p in sweep.rglob("best.ckpt") if p.parent.name != "commissioned"):
        variant = next(part for part in ckpt.parts if part in args.variants.split(","))
        done = ckpt.parent / "commissioned"
        if not (done / "best.ckpt").is_file():
            run("robohealth_mj.commission", f"model={ckpt}", "arm=ur10e",
                f"healthy={as_list(LOGS_ROLES['commission'])}", f"out={done}")  # fmt: skip
        targets = [("healthy", p) for p in healthy_monitored()]
        targets += [(kind, p) for kind, paths in events().items() for p in paths]
        for kind, log in targets:
            out = verdicts / variant / kind / f"{log.stem}.json"
            if out.is_file():
                continue
            out.parent.mkdir(parents=True, exist_ok=True)
            if (done / "model.onnx").is_file():
                run("robohealth_mj.monitor", "source=replay", f"model={done / 'model.onnx'}",
                    f"file={log}", "evaluate=true", "quiet=true", f"out={out}")  # fmt: skip
            else:  # a tree ensemble has no streaming form: its window decisions on the log
                run("robohealth_mj.evaluate", f"ckpt={done / 'best.ckpt'}", f"data={log}",
                    f"out={out.with_suffix('')}")  # fmt: skip
    print(json.dumps({"verdicts": str(verdicts)}))


if __name__ == "__main__":
    main()
