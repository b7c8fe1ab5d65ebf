"""The cross-arm experiment (issue 36): per-arm models, then leave-one-arm-out before and after
commissioning, and false alarms on the unseen arm's healthy hour.

    python studies/arms/campaign.py [--variants gbdt,stgnn_fixed] [--seeds 42,43,44]
        [--epochs 10] [--sensing full] [--arms ur3e,ur5e,ur10e,ur16e] [--family ARMS]
        [--stages own,loao]
        [--steps train,rescore,commission,export,alarms,validate] [--healthy-rate 0.99]
        [--normalisation sensors|shift|moments] [--commissioning-minutes 10|20|30]
        [--unseen-sessions N]

Reads the per-arm corpora ``outputs/corpus/arms/<arm>`` (``python -m robohealth_mj.corpus
corpus=arms ...``, see ``studies/arms/run.sh``; ``--corpus`` names another root, e.g. one
with more training sessions per arm) and writes under ``outputs/campaign_arms``:

- ``own/<arm>/...``: each arm's own models (trained on its sessions, scored on its held-out one);
- ``loao/<arm>/...``: models trained with ``transfer=true`` on the family's other arms, scored on
  ``<arm>``'s held-out session; ``commissioned/`` beside each: the model commissioned on ten
  minutes of ``<arm>``'s healthy running and scored again; networks are also replayed through the
  fleet runtime and the monitor's alarms over ``<arm>``'s healthy hour
  (``alarms_healthy_hour_seed*.json``); the ``export`` step exports the networks as trained too
  (validation may pick one over its commissioned form), so that ``alarms`` counts theirs. With
  ``--healthy-rate R`` the commissioning asks for at least R of the arm's healthy windows called
  healthy (``commission healthy_rate=R``, a quieter operating point) and writes
  ``commissioned_hr<R>/`` instead. With ``--normalisation M`` the commissioning also refits the
  z-scoring to the arm's healthy running (``commission normalisation=M``) into
  ``commissioned_<M>/``. With ``--commissioning-minutes N`` it reads N healthy minutes
  (``healthy_commissioning_seed940``, ``941``, ...; the corpus records them with
  ``'corpus.healthy_commissioning.seeds=[940,941,942]'``) into ``commissioned<N>...``. The
  ``validate`` step scores each leave-one-arm-out model, before and after commissioning, on the
  unseen arm's validation sessions (``validation_seed500``, ``501``; ``eval_validation.json``):
  labelled running of that arm, in training's distribution, on programmes no model here trained
  on, where a recipe is chosen before the held-out session is read. (The arm's own training
  sessions will not do: a seed gives every arm of one joint count the same program and fault
  schedule, which the other arms' sessions of that seed trained on.) With ``--unseen-sessions N``
  the first N of the unseen arm's training sessions join the family's (what a few of the arm's own
  simulated sessions buy over leave-one-arm-out; give it its own ``--out``).

Every step skips what is done, so an interrupted campaign resumes. Training runs through the
package's own entry points (Hydra multirun, two jobs of one thread).
"""

from __future__ import annotations

import argparse
import json
import shutil
from functools import cache
from pathlib import Path

from robohealth_mj.common.atomic import atomic_write_json
from robohealth_mj.common.config import compose_config
from robohealth_mj.common.steps import run_step
from robohealth_mj.data.arrays import expand_paths, load_recordings
from robohealth_mj.deploy.alarm_sweep import evaluate_policy, replay_many
from robohealth_mj.deploy.renormalise import MATCHES
from robohealth_mj.runtime.alarms import AlarmPolicy
from robohealth_mj.runtime.evidence import EvidencePolicy

CORPUS = Path("outputs/corpus/arms")
OUT = Path("outputs/campaign_arms")
ARMS = ("ur3e", "ur5e", "ur10e", "ur16e")
HEALTHY_HOUR = ("healthy_hour_seed950", "healthy_hour_seed951", "healthy_hour_seed952")
COMMISSIONING_SEED = 940  # the first ten healthy minutes; 941, 942, ... the next tens


def commissioning_sessions(minutes: int) -> list[str]:
    """The arm's healthy sessions (ten minutes each) a commissioning on ``minutes`` reads."""
    return [f"healthy_commissioning_seed{COMMISSIONING_SEED + k}" for k in range(minutes // 10)]


def train(sweep: Path, train: list[str], heldout: Path, args: argparse.Namespace, *extra: str):
    run_step(
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
        "threads=1",
        "trainer.progress=false",
        "hydra/launcher=local",
        f"hydra.sweep.dir={sweep}",
        *args.override,
        *extra,
    )


def runs(sweep: Path, variants: list[str]) -> list[Path]:
    """The sweep's runs of these variants (``.../<variant>/w<W>/seed<s>``)."""
    found = (
        p.parent for p in sweep.rglob("best.ckpt") if not p.parent.name.startswith("commissioned")
    )
    return sorted(run for run in found if run.parts[-3] in variants)


def rescore(run_dir: Path, arm_dir: Path) -> None:
    """Score ``run_dir`` again on this machine's recording of the held-out session in ``arm_dir``
    (one arm's corpus) when it was scored on another (a run trained on a lent GPU, whose corpus
    was recorded there from the same seeds: another numpy can move the physics in its last bits),
    so that every column of the table reads one recording; the trainer's own score is kept as
    ``eval_heldout_trained``."""
    scored = json.loads((run_dir / "eval_heldout.json").read_text())["data_fingerprint"]
    if scored == heldout_fingerprint(arm_dir / "heldout_seed900"):
        return
    for ext in ("json", "csv"):
        kept = run_dir / f"eval_heldout_trained.{ext}"
        if not kept.is_file():
            shutil.copy2(run_dir / f"eval_heldout.{ext}", kept)
    score(run_dir, arm_dir)


@cache
def heldout_fingerprint(session: Path) -> str:
    return load_recordings(expand_paths([str(session)])).fingerprint()


def commissioned_dir(
    run_dir: Path, healthy_rate: float | None = None, normalisation: str = "none", minutes: int = 10
) -> Path:
    """Where ``run_dir``'s model commissioned on ``minutes`` of healthy running at validation's
    healthy rate (``None``) or at ``healthy_rate``, with the z-scoring refitted by
    ``normalisation`` (``none``: kept), lives."""
    name = "commissioned" if minutes == 10 else f"commissioned{minutes}"
    name = name if healthy_rate is None else f"{name}_hr{healthy_rate:g}"
    return run_dir / (name if normalisation == "none" else f"{name}_{normalisation}")


def commission_and_score(
    run_dir: Path,
    arm_dir: Path,
    healthy_rate: float | None = None,
    normalisation: str = "none",
    minutes: int = 10,
) -> None:
    """Commission ``run_dir``'s model on ``minutes`` of healthy running of ``arm_dir`` (one arm's
    corpus) and score it on its held-out session."""
    done = commissioned_dir(run_dir, healthy_rate, normalisation, minutes)
    rate = [] if healthy_rate is None else [f"healthy_rate={healthy_rate:g}"]
    if not (done / "best.ckpt").is_file():
        sessions = [str(arm_dir / s) for s in commissioning_sessions(minutes)]
        missing = [s for s in sessions if not Path(s).is_dir()]
        if missing:
            raise SystemExit(
                f"{missing[0]}: not recorded (python -m robohealth_mj.corpus corpus=arms ... "
                f"'corpus.healthy_commissioning.seeds=[940,941,...]', "
                "studies/arms/run_false_alarms.sh)"
            )
        healthy = sessions[0] if len(sessions) == 1 else f"[{','.join(sessions)}]"
        run_step("robohealth_mj.commission", f"model={run_dir / 'best.ckpt'}",
                 f"healthy={healthy}", f"out={done}",
                 f"normalisation={normalisation}", *rate)  # fmt: skip
    if not (done / "eval_heldout.json").is_file():
        score(done, arm_dir)


def score(run_dir: Path, arm_dir: Path, split: str = "heldout") -> None:
    """``run_dir``'s checkpoint on the held-out session of ``arm_dir`` as ``eval_heldout.json``,
    or (``split="validation"``) on its validation sessions as ``eval_validation.json``."""
    data = arm_dir / "heldout_seed900" if split == "heldout" else f"{arm_dir}/validation_seed*"
    run_step("robohealth_mj.evaluate", f"ckpt={run_dir / 'best.ckpt'}",
             f"data={data}", f"out={run_dir / f'eval_{split}'}")  # fmt: skip


def export_as_trained(run_dir: Path, arm_dir: Path) -> None:
    """``run_dir``'s network as trained to ONNX (``model.onnx`` beside ``best.ckpt``; the
    commissioning exports its own form), its parity with the checkpoint checked on ``arm``'s
    held-out session: the arm it will read, not the training arms'."""
    if not (run_dir / "model.onnx").is_file():
        run_step("robohealth_mj.export", f"ckpt={run_dir / 'best.ckpt'}",
                 f"data={arm_dir / 'heldout_seed900'}")  # fmt: skip


def healthy_alarms(done: Path, arm_dir: Path) -> None:
    """The commissioned network's alarms over ``arm``'s healthy hour under the monitor's default
    alarm and evidence policies (``conf/monitor.yaml``): the fleet runtime's decisions over the
    three sessions at once, then the monitor's alarm bank and on-line evaluator
    (``deploy.alarm_sweep``). They count what ``monitor source=replay evaluate=true`` counts
    (checked on one session: the same ticks, decisions and alarms), several times faster."""
    todo = [s for s in HEALTHY_HOUR if not (done / f"alarms_{s}.json").is_file()]
    if not todo:
        return
    cfg = compose_config("monitor")
    policy, evidence = AlarmPolicy(**cfg.alarm), EvidencePolicy(**cfg.evidence)
    files = [arm_dir / session / "graphs.jsonl" for session in todo]
    print(f"+ alarms of {done} over {arm_dir.name}'s {', '.join(todo)}", flush=True)
    for session, file, decisions in zip(
        todo, files, replay_many(done / "model.onnx", files), strict=True
    ):
        result = evaluate_policy(decisions, policy, evidence)
        atomic_write_json(done / f"alarms_{session}.json", {"file": str(file), **result})


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--variants", default="gbdt,stgnn_fixed")
    parser.add_argument("--seeds", default="42")
    parser.add_argument("--epochs", type=int, default=10)
    parser.add_argument("--sensing", default="full")
    parser.add_argument("--arms", default=",".join(ARMS))
    parser.add_argument(
        "--family",
        help="the arms leave-one-arm-out trains on, less the one left out (default: --arms); "
        "arms of one joint count named apart are read by place along the chain",
    )
    parser.add_argument("--stages", default="own,loao", help="own, loao or both")
    parser.add_argument(
        "--steps",
        default="train,rescore,commission,alarms",
        help="any of train, rescore, commission, export (networks as trained: give --variants "
        "networks only), alarms, validate: train alone on a machine that lacks the healthy "
        "sessions (a lent GPU), then the rest where they are",
    )
    parser.add_argument(
        "--override",
        action="append",
        default=[],
        help="a train override for every run, e.g. model.severity=false for gbdt (the severity "
        "booster is fitted apart from the class and joint boosters and changes neither)",
    )
    parser.add_argument(
        "--out", type=Path, default=OUT, help="campaign root (a variant recipe's own)"
    )
    parser.add_argument(
        "--corpus",
        type=Path,
        default=CORPUS,
        help="root of the per-arm corpora (<root>/<arm>/train_*, heldout_seed900, ...)",
    )
    parser.add_argument(
        "--healthy-rate",
        type=float,
        help="commission at this healthy rate (e.g. 0.99) into commissioned_hr<R>/ "
        "(default: validation's rate, into commissioned/)",
    )
    parser.add_argument(
        "--normalisation",
        default="none",
        choices=MATCHES,
        help="commission with the z-scoring refitted to the arm's healthy running: sensors, "
        "shift or moments (commission normalisation=...), into commissioned_<M>/",
    )
    parser.add_argument(
        "--commissioning-minutes",
        type=int,
        default=10,
        choices=(10, 20, 30),
        help="commission on this many healthy minutes (healthy_commissioning_seed940, 941, ...), "
        "into commissioned<N>/ where N is not 10",
    )
    parser.add_argument(
        "--unseen-sessions",
        type=int,
        default=0,
        help="the first N of the unseen arm's training sessions join the family's (default 0: "
        "leave-one-arm-out proper); give the campaign its own --out",
    )
    args = parser.parse_args()
    arms = args.arms.split(",")
    family = (args.family or args.arms).split(",")
    root: Path = args.corpus
    missing = [a for a in dict.fromkeys(arms + family) if not (root / a / "corpus.json").is_file()]
    if missing:
        raise SystemExit(
            f"no corpus for {', '.join(missing)}: python -m robohealth_mj.corpus corpus=arms "
            f"out_dir={root}/<arm> 'record_overrides=[\"arm=<arm>\"]' (studies/arms/run.sh)"
        )
    stages, steps = args.stages.split(","), args.steps.split(",")
    variants = args.variants.split(",")
    unvalidated = [a for a in arms if not any((root / a).glob("validation_seed*/graphs.jsonl"))]
    if "validate" in steps and unvalidated:
        raise SystemExit(
            f"no validation sessions for {', '.join(unvalidated)}: record them with the arm's "
            "corpus command again (conf/corpus/arms.yaml, role validation)"
        )
    for arm in arms:
        heldout = root / arm / "heldout_seed900"
        own = args.out / args.sensing / "own" / arm
        if "own" in stages and "train" in steps:
            train(own, [f"{root}/{arm}/train_*"], heldout, args)
        if "own" in stages and "rescore" in steps:
            for run_dir in runs(own, variants):
                rescore(run_dir, root / arm)
        if "loao" in stages:
            sessions = sorted(str(p) for p in (root / arm).glob("train_*"))
            others = [f"{root}/{a}/train_*" for a in family if a != arm]
            others += sessions[: args.unseen_sessions]
            sweep = args.out / args.sensing / "loao" / arm
            if "train" in steps:
                train(sweep, others, heldout, args, "transfer=true")
            for run_dir in runs(sweep, variants):
                if "rescore" in steps:
                    rescore(run_dir, root / arm)
                minutes = args.commissioning_minutes
                done = commissioned_dir(run_dir, args.healthy_rate, args.normalisation, minutes)
                if "commission" in steps:
                    commission_and_score(
                        run_dir, root / arm, args.healthy_rate, args.normalisation, minutes
                    )
                if "validate" in steps:
                    for scored in (run_dir, done):  # the commissioned model where it is
                        if (scored / "best.ckpt").is_file() and not (
                            scored / "eval_validation.json"
                        ).is_file():
                            score(scored, root / arm, "validation")
                if "export" in steps:
                    export_as_trained(run_dir, root / arm)
                if "alarms" in steps:  # networks: a streaming runtime; the model as trained
                    for scored in (run_dir, done):  # too where it was exported
                        if (scored / "model.onnx").is_file():
                            healthy_alarms(scored, root / arm)


if __name__ == "__main__":
    main()
