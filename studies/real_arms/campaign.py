"""Sim-to-real on a real UR10e (issue 37): identify a twin from the arm's healthy logs, record a
corpus on the twin, train the stock_reduced profile's models on it, commission them on healthy
real logs and monitor the arm's other real logs.

    studies/real_arms/fetch.sh                   # the logs -> outputs/real_arms/logs/
    python studies/real_arms/campaign.py [--curriculum standard|replay|mixed|programs|holds|
        cruise|cruise_heavy|mixed_own_motion]
        [--commission jointwise|jointwise+program|jointwise+own_motion] [--healthy-rate R]
        [--twin FILE] [--name RUN]
        [--variants gbdt,stgnn_fixed] [--seed 42] [--epochs 10] [--labels last|visible]
        [--observability all|motion]

``--curriculum standard`` trains on our sweeps and payloads (the quick corpus on the twin);
``replay`` on the arm's own program: the ``program`` logs replayed on the twin with no payload
(``conf/corpus/replay.yaml``, ``curriculum=replay``); ``mixed`` on both corpora; ``programs`` on
the standard sweeps and pendant-taught point-to-point programs (``pick_place`` family);
``holds`` on the standard sweeps and holds (``hold`` family: a move to a new pose, then held);
``cruise`` on the standard sweeps and cruising moves (``cruise`` family: long synchronised joint
moves at a constant speed, as a UR controller runs point-to-point programs); ``cruise_heavy``
the same with three times the cruising segments;
``mixed_own_motion`` on the standard sweeps and the first half of the point-to-point log replayed.
``--commission`` names the healthy real running the models are commissioned on
(``jointwise+own_motion``: also the first half of the point-to-point log, whose second half is
then monitored in its place; verdicts in ``verdicts_ownmotion...``); ``--labels`` how
training windows are labelled (``train labels=``; ``visible``: friction and backlash on a joint
that stood still through the window, which nothing shows, as healthy); ``--stiction`` records the
corpora with the twin's dry friction made to stick (``STICTION``); ``--observability motion``
monitors (and, for gbdt, evaluates) with friction and backlash called only on joints that moved
in the window (``monitor observability=motion``; verdicts in ``verdicts<suffix>_motion``, the
same commissioned models). Writes under
``outputs/real_arms/``: ``twin/`` (twin.yaml, fidelity.md), the corpora
``outputs/corpus/real_ur10e_<curriculum>``, and per run (``--name``, default the curriculum) the
models ``<run>/models/`` and per model and log the monitor's verdict (``<run>/verdicts/``). Every
step skips what is done; a recording made on another twin than the one named stops the run.
``--swap VARIANT`` prints where the real arm's healthy running looks faulty to a commissioned
network, and why: each monitored log's motion is replayed on the healthy twin (tick for tick the
same motion), and the network reads the real ticks, the simulated ticks, and the real ticks with
one channel (or one joint's torque residual) taken from the simulation.
A swap that brings the real share of ticks called faulty to the simulated one names where twin and
arm differ; a simulated share as high as the real one says the model calls this motion faulty in
simulation too (a gap between training program and motion, not between simulation and arm).
Which log fits, is replayed, commissions or is monitored is fixed below (``LOGS_ROLES``): the
monitored healthy logs are none of the others.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from robohealth_mj import schema
from robohealth_mj.common.atomic import atomic_write_text
from robohealth_mj.common.errors import one_line_errors
from robohealth_mj.common.steps import run_step
from robohealth_mj.runtime.runtime import ModelRuntime
from robohealth_mj.runtime.sources import replay_stream
from robohealth_mj.sim.twin_file import mark_recorded, recorded_on

ROOT = Path("outputs/real_arms")
LOGS = ROOT / "logs"
ID = LOGS / "identification_data"
VAL = LOGS / "validation_data"
# The twin stands on a 0.8 m pedestal: these logs take the arm's links down to 0.6 m below its
# base plane (forward kinematics of every log, bounding spheres), where our floor would stop them.
MOUNT_M = 0.8
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
    # the arm's program for curriculum=replay: the other excitation runs without payload (5.6 min)
    "program": [
        ID / f
        for f in (
            "ur-19_09_27-15_11_06.csv",
            "ur-19_10_01-13_51_41.csv",
            "ur-19_10_01-14_04_13.csv",
            "ur-19_10_01-14_04_41.csv",
            "ur-20_02_05-20sec_12harm.csv",
            "ur-20_02_05-20sec_8harm.csv",
            "ur-20_02_06-20sec_10harm.csv",
            "ur-20_02_06-20sec_5harm.csv",
            "ur-20_02_10-20sec_7harm.csv",
            "ur-20_02_10-30sec_12harm.csv",
            "ur-20_02_12-40sec_12harm.csv",
            "ur-20_02_12-50sec_12harm.csv",
        )
    ],
}


# the corpora each curriculum trains on (the last one's held-out session is the one evaluated)
CURRICULA = {"standard": ["standard"], "replay": ["replay"], "mixed": ["standard", "replay"],
             "programs": ["programs"], "holds": ["holds"], "cruise": ["cruise"],
             "cruise_heavy": ["cruise_heavy"],
             "mixed_own_motion": ["standard", "replay_own_motion"]}  # fmt: skip
# the healthy real running each model is commissioned on
COMMISSION = {"jointwise": ["commission"], "jointwise+program": ["commission", "program"],
              "jointwise+own_motion": ["commission"]}  # fmt: skip
# the verdicts' suffix per commissioning set
COMMISSION_SUFFIX = {"jointwise": "", "jointwise+program": "_program",
                     "jointwise+own_motion": "_ownmotion"}  # fmt: skip


def healthy_monitored() -> list[Path]:
    """The healthy real logs without payload that neither commission nor are replayed: unseen
    excitation runs, a free motion, a run after unloading, point-to-point moves and ten holds."""
    # the short layout (no target current: joint_states, not the stock_reduced models' profile)
    # and a corrupt file
    unreadable = {"ur-19_09_27-11_28_22.csv", "ur-19_09_27-11_32_02.csv",
                  "ur-20_02_19_15harm50secLoad.csv"}  # fmt: skip
    used = {p.name for role in LOGS_ROLES.values() for p in role} - {
        p.name
        for p in LOGS_ROLES["validate"]  # fidelity logs: not fitted, so unseen here too
    }
    logs = sorted(ID.glob("*.csv")) + sorted(VAL.glob("*.csv"))
    payload = [p.name for p in logs if "load" in p.name.lower() and "unload" not in p.name]
    return [p for p in logs if p.name not in unreadable | used | set(payload)]


def events() -> dict[str, list[Path]]:
    return {
        "push": sorted((LOGS / "collision").glob("*.csv")),
        "load": [p for p in sorted(ID.glob("*.csv")) if "load" in p.name.lower()
                 and "unload" not in p.name.lower() and "15harm50secLoad" not in p.name],
    }  # fmt: skip


def as_list(paths: list[Path]) -> str:
    return "[" + ",".join(str(p) for p in paths) + "]"


# The arm's own point-to-point program, the one motion our sweeps lack. A user commissions on
# their arm's own running; this dataset has one such log, so --commission jointwise+own_motion
# cuts it in two: commissioning reads its first half and the monitor its second
# (--curriculum mixed_own_motion also replays the first half on the twin in training).
OWN_MOTION = VAL / "ur-20_01_17-ptp_10_points.csv"


def half_paths(log: Path) -> tuple[Path, Path]:
    """Where :func:`halves` writes ``log``'s first and second half."""
    out = ROOT / "halves"
    return out / f"{log.stem}_first_half.csv", out / f"{log.stem}_second_half.csv"


def halves(log: Path) -> tuple[Path, Path]:
    """``log`` cut at its middle row into two logs of the same layout (written once)."""
    first, second = half_paths(log)
    if not (first.is_file() and second.is_file()):
        rows = log.read_text().splitlines(keepends=True)
        first.parent.mkdir(parents=True, exist_ok=True)
        atomic_write_text(first, "".join(rows[: len(rows) // 2]))
        atomic_write_text(second, "".join(rows[len(rows) // 2 :]))
    return first, second


OWN_MOTION_FIRST, _ = half_paths(OWN_MOTION)

# each corpus: its config and what its sessions add to the twin's record overrides
CORPORA = {
    "standard": ("quick", []),
    "replay": (
        "replay",
        ["curriculum=replay", f"curriculum.files={as_list(LOGS_ROLES['program'])}"],
    ),
    # the standard sweeps and the pendant-taught point-to-point programs (pick and place,
    # palletising: moves between poses with dwells)
    "programs": ("quick", ["curriculum.families=[single_joint,joint_pair,whole_arm,pick_place]"]),
    # the standard sweeps and holds: one move from rest to a new pose, then the pose held
    "holds": ("quick", ["curriculum.families=[single_joint,joint_pair,whole_arm,hold]"]),
    # the standard sweeps and cruising moves: long joint moves at a constant speed, as a UR
    # controller runs its point-to-point programs
    "cruise": ("quick", ["curriculum.families=[single_joint,joint_pair,whole_arm,cruise]"]),
    # the same, three times the cruising segments (81 of 207 instead of 27 of 153)
    "cruise_heavy": (
        "quick",
        [
            "curriculum.families=[single_joint,joint_pair,whole_arm,cruise]",
            "+curriculum.cruise_repeats=9",
        ],
    ),
    # the first half of the arm's own point-to-point program replayed (see OWN_MOTION)
    "replay_own_motion": (
        "replay",
        ["curriculum=replay", f"curriculum.files=[{OWN_MOTION_FIRST}]"],
    ),
}


# The twin's dry friction made to stick (``sim.friction_solref``): MuJoCo's default friction creeps,
# so a simulated rest keeps a residual offset of 0.25-0.89 N m on the big joints (median), where
# this arm's rests keep 0.94-2.01 (p90 4.1-7.4); with this setting the twin's keep 2.2-7.9
# (studies/real_arms/results/rest_offsets.md, whose script holds the same override).
STICTION = ["sim.friction_solref=[0.002,1]"]


def record_corpus(corpus_name: str, twin: Path, tag: str, stiction: bool = False) -> Path:
    """The quick-size corpus ``corpus_name`` (CORPORA) on ``twin`` (recorded once)."""
    tag += "_stiction" if stiction else ""
    corpus = Path(f"outputs/corpus/real_ur10e_{corpus_name}{tag}")
    config, extra = CORPORA[corpus_name]
    overrides = ["arm=ur10e", f"sim.twin={twin}", f"sim.mount_height_m={MOUNT_M}", *extra]
    overrides += STICTION if stiction else []
    if not recorded_on(corpus, corpus / "corpus.json", twin):
        run_step("robohealth_mj.corpus", f"corpus={config}", f"out_dir={corpus}",
                 f"record_overrides={json.dumps(overrides)}", "progress=false")  # fmt: skip
        mark_recorded(corpus, twin)
    return corpus


CHANNELS = ("pos", "vel", "effort", "effort_residual")
LEAD_S = 1.5  # the replay's first move (from rest to the log's first pose) before the log plays


def simulated(log: Path, twin: Path, out: Path) -> Path:
    """The log's motion replayed on the healthy twin (recorded once)."""
    graphs = out / "graphs.jsonl"
    if not recorded_on(out, graphs, twin):
        seconds = float(np.loadtxt(log, delimiter=",", usecols=0, ndmin=1)[[0, -1]] @ [-1, 1])
        run_step("robohealth_mj.record", "arm=ur10e", f"sim.twin={twin}",
                 f"sim.mount_height_m={MOUNT_M}", "curriculum=replay", f"curriculum.files=[{log}]",
                 "curriculum.passes=1", "curriculum.hold_s=0", "faults=none",
                 f"session.duration_s={seconds + LEAD_S + 0.5:.2f}", "seed=1",
                 f"session.out_dir={out}", "session.progress=false", quiet=True)  # fmt: skip
        mark_recorded(out, twin)
    return graphs


def share(
    model: Path, xs: list[np.ndarray], like: list[schema.GraphSample], observability: str = "all"
) -> float:
    """Share of decided ticks called faulty when the monitor reads ``xs`` in ``like``'s place."""
    runtime = ModelRuntime(str(model), observability=observability)
    decided = faulty = 0
    for x, s in zip(xs, like, strict=True):
        d = runtime.process("arm", schema.GraphSample(s.recording_run_id, s.sample_index, s.t, x,
                                                      s.fault, s.segment))  # fmt: skip
        if d.valid and d.fault_class is not None:
            decided += 1
            faulty += bool(d.fault_present)
    return faulty / max(decided, 1)


def swap_table(run_name: str, variant: str, suffix: str, observability: str = "all") -> None:
    """Prints the channel-swap table (see ``--swap``) for ``variant`` of run ``run_name``."""
    models = ROOT / run_name / "models"
    model = next(p for p in models.rglob(f"commissioned{suffix}/model.onnx") if variant in p.parts)
    twin = ROOT / "twin" / "twin.yaml"
    residual = schema.feature_index("effort_residual")
    short = ("pan", "lift", "elbow", "w1", "w2", "w3")
    print(f"## Channel swaps: {variant}, run {run_name}{suffix}, observability={observability} "
          "(share of ticks called faulty)\n")  # fmt: skip
    heads = [f"real, sim {c}" for c in CHANNELS] + [f"real, sim residual {j}" for j in short]
    print("| log | real | sim, same motion | " + " | ".join(heads) + " |")
    print("|---" * (3 + len(heads)) + "|")
    for log in healthy_monitored():
        real = [s for _, s, _ in replay_stream(str(log))]
        sim = [s for _, s, _ in replay_stream(str(simulated(log, twin, ROOT / "swap" / log.stem)))]
        t_sim = np.array([s.t for s in sim]) - LEAD_S  # the log's first row plays at LEAD_S
        t_real = np.array([s.t for s in real]) - real[0].t
        at = np.clip(np.searchsorted(t_sim, t_real - 1e-6), 0, len(sim) - 1)
        real_x = [s.x for s in real]
        sim_x = [sim[k].x for k in at]
        cells = [
            share(model, real_x, real, observability),
            share(model, sim_x, real, observability),
        ]
        for c in CHANNELS:
            f = schema.feature_index(c)
            cells.append(share(model, [_swap(r, s, slice(0, 6), f) for r, s in
                                       zip(real_x, sim_x, strict=True)], real,
                               observability))  # fmt: skip
        for j in range(schema.N_JOINTS):
            cells.append(share(model, [_swap(r, s, slice(j, j + 1), residual) for r, s in
                                       zip(real_x, sim_x, strict=True)], real,
                               observability))  # fmt: skip
        print(f"| {log.stem} | " + " | ".join(f"{v:.2f}" for v in cells)
              + " |")  # fmt: skip


def _swap(real: np.ndarray, sim: np.ndarray, joints: slice, feature: int) -> np.ndarray:
    """The real snapshot with ``feature`` of ``joints`` taken from the simulated one."""
    x = real.copy()
    x[joints, feature] = sim[joints, feature]
    return x


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--variants", default="gbdt,stgnn_fixed")
    parser.add_argument("--seed", default="42")
    parser.add_argument("--epochs", type=int, default=10)
    parser.add_argument("--labels", default="last", help="train labels= (last, visible, ...)")
    parser.add_argument(
        "--stiction",
        action="store_true",
        help="record the corpora on the twin with sticking dry friction (STICTION)",
    )
    parser.add_argument(
        "--observability",
        choices=("all", "motion"),
        default="all",
        help="monitor observability= (motion: friction and backlash only on joints that moved)",
    )
    parser.add_argument("--curriculum", choices=tuple(CURRICULA), default="replay")
    parser.add_argument("--commission", choices=tuple(COMMISSION), default="jointwise")
    parser.add_argument(
        "--second-half",
        action="store_true",
        help="monitor the point-to-point log's second half in place of the whole, the logs that "
        "--commission jointwise+own_motion monitors (verdicts<suffix>_half)",
    )
    parser.add_argument(
        "--twin",
        type=Path,
        default=None,
        help="a twin file of the UR10e (default: identified into twin/)",
    )
    parser.add_argument(
        "--name",
        default=None,
        help="this run's directory under outputs/real_arms/ (default: curriculum)",
    )
    parser.add_argument(
        "--healthy-rate",
        type=float,
        default=None,
        help="commission at this healthy rate (commission healthy_rate=)",
    )
    parser.add_argument(
        "--swap",
        default=None,
        metavar="VARIANT",
        help="print instead where the real arm's healthy running looks faulty "
        "to VARIANT of this run, and why (the channel-swap table)",
    )
    args = parser.parse_args()  # fmt: skip
    name = args.name or args.curriculum
    # beside the jointwise ones at validation's healthy rate
    suffix = COMMISSION_SUFFIX[args.commission] + (
        f"_rate{args.healthy_rate:g}" if args.healthy_rate else ""
    )
    if args.swap:
        swap_table(name, args.swap, suffix, args.observability)
        return
    if not LOGS.is_dir():
        raise SystemExit(f"no logs in {LOGS}: run studies/real_arms/fetch.sh")
    twin = args.twin or ROOT / "twin" / "twin.yaml"
    if not twin.is_file():
        run_step("robohealth_mj.identify", "arm=ur10e", f"fit={as_list(LOGS_ROLES['fit'])}",
                 f"validate={as_list(LOGS_ROLES['validate'])}", f"out={twin.parent}")  # fmt: skip
    tag = f"_{args.twin.stem}" if args.twin else ""
    first, second = halves(OWN_MOTION)  # the replay_own_motion corpus replays the first half
    corpora = [record_corpus(c, twin, tag, args.stiction) for c in CURRICULA[args.curriculum]]
    train = ",".join(f"{c}/train_*" for c in corpora)
    sweep = ROOT / name / "models"
    if not any(sweep.rglob("best.ckpt")):
        run_step("robohealth_mj.train", "-m", f"variant={args.variants}", f"seed={args.seed}",
                 "sensing=stock_reduced", "window=32", f"data.train=[{train}]",
                 f"data.evaluate.heldout={corpora[-1]}/heldout_seed900", "data.evaluate.probe=null",
                 f"trainer.epochs={args.epochs}", f"labels={args.labels}", "threads=1",
                 "trainer.progress=false",
                 "hydra/launcher=local", f"hydra.sweep.dir={sweep}")  # fmt: skip
    commissioning = [p for role in COMMISSION[args.commission] for p in LOGS_ROLES[role]]
    monitored = healthy_monitored()
    if args.commission == "jointwise+own_motion" or args.second_half:
        commissioning += [first] if args.commission == "jointwise+own_motion" else []
        monitored = [second if p == OWN_MOTION else p for p in monitored]
    gate = "_motion" if args.observability == "motion" else ""
    half = "_half" if args.second_half and args.commission != "jointwise+own_motion" else ""
    verdicts = ROOT / name / f"verdicts{suffix}{half}{gate}"
    wanted = args.variants.split(",")
    for ckpt in sorted(p for p in sweep.rglob("best.ckpt") if "commissioned" not in p.parent.name):
        variant = next((part for part in ckpt.parts if part in wanted), None)
        if variant is None:  # a model of this run that --variants leaves out
            continue
        done = ckpt.parent / f"commissioned{suffix}"
        if not (done / "best.ckpt").is_file():
            run_step("robohealth_mj.commission", f"model={ckpt}", "arm=ur10e",
                     f"healthy={as_list(commissioning)}", f"out={done}",
                     f"healthy_rate={args.healthy_rate or 'null'}")  # fmt: skip
        # the program logs: healthy real running no run is judged on, so runs are compared on
        # it (selection); in-sample for the curricula that replay it
        targets = [("program", p) for p in LOGS_ROLES["program"]]
        targets += [("healthy", p) for p in monitored]
        targets += [(kind, p) for kind, paths in events().items() for p in paths]
        for kind, log in targets:
            out = verdicts / variant / kind / f"{log.stem}.json"
            if out.is_file():
                continue
            out.parent.mkdir(parents=True, exist_ok=True)
            if (done / "model.onnx").is_file():
                run_step("robohealth_mj.monitor", "source=replay", f"model={done / 'model.onnx'}",
                         f"file={log}", "evaluate=true", "quiet=true", f"out={out}",
                         f"observability={args.observability}")  # fmt: skip
            else:  # a tree ensemble has no streaming form: its window decisions on the log
                run_step("robohealth_mj.evaluate", f"ckpt={done / 'best.ckpt'}", f"data={log}",
                         f"out={out.with_suffix('')}",
                         f"observability={args.observability}")  # fmt: skip
    print(json.dumps({"verdicts": str(verdicts)}))


if __name__ == "__main__":
    with one_line_errors("campaign"):
        main()
