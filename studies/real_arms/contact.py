"""Choosing the contact watch's settings on the real UR10e, and what they give on logs not used
to choose them.

    python studies/real_arms/contact.py [--run cruise] [--verdicts verdicts_ownmotion_rate0.99_motion]
        > studies/real_arms/results/contact.md

The watch (:mod:`robohealth_mj.runtime.contact`) is commissioned on the run's commissioning logs
(the healthy logs its ``stgnn_fixed`` model at seed 42 was commissioned on) and replayed over
every log the campaign monitored for that run (``<verdicts>/stgnn_fixed/<kind>/``): for each
setting, the ticks called a contact on healthy running and, per pushed log, how much of each push
(found in hindsight, :mod:`robohealth_mj.twin.pushes`) is called and whether the joint named most
is the nearest joint. The real logs say neither when nor where a push was, so the twin is pushed
too (``session.pushes``, :mod:`robohealth_mj.sim.pushes`): it moves to a pose and holds it, and
one push of 1 s loads each link's own joint (60 N on the shoulder, upper arm and forearm, 30 N on
the wrists, across the joint's axis); the watch is commissioned on the same hold unpushed.

Selection reads the simulated pushes, the program logs (healthy, judged by no run) and the first
pushed log; the monitored healthy logs and the second pushed log are the test. The rule, in
order: no call after a simulated push has ended (an echo: the truth is known there); none on the
program logs; the most pushes called, simulated and on the first log together; the most joints
named right, likewise; the most confirming ticks (a contact call is an alarm, and 5.6 min cannot
show one an hour); the largest share of the first log's push ticks called. Last, the selected
setting on the runs with an added load.
"""  # noqa: E501

from __future__ import annotations

import argparse
import itertools
import json
from collections import Counter
from pathlib import Path

import numpy as np

from robohealth_mj import schema
from robohealth_mj.arms.ratings import rated_torque_nm
from robohealth_mj.common.config import compose_config
from robohealth_mj.logs import log_samples
from robohealth_mj.recording.recorder import build_simulator, chunk_features
from robohealth_mj.runtime.contact import ContactBank, ContactPolicy, commission_thresholds
from robohealth_mj.sim import pushes as sim_pushes
from robohealth_mj.twin.pushes import most_distal_loaded, pushes

ROOT = Path("outputs/real_arms")
ARM = "ur10e"
SHARE = 0.05  # a push: a joint more than this share of its rating off (events.py's default)
TICK_HZ = 20.0
RESIDUAL = schema.feature_index("effort_residual")
GRID = {
    "margin": (1.5, 2.0, 3.0),
    "confirm": (1, 2, 4),
    "command_share": (0.005, np.inf),  # inf: no guard on the controller's model torque
    "still_rad_s": (0.05, 0.3),
    "exclude_contact": (True, False),
}
TWIN = ["arm=ur10e", f"sim.twin={ROOT}/twin/twin.yaml", "sim.mount_height_m=0.8", "seed=3",
        "session.progress=false", "faults=none", "curriculum.families=[hold]"]  # fmt: skip
PUSH_AT_S, PUSH_S, HOLD_S = 6.0, 1.0, 12.0
SIM_PUSHES = {  # link: (force across its joint's axis, N, link frame; where, m)
    "shoulder_link": ([0, 60, 0], [0.1, 0, 0]),
    "upper_arm_link": ([0, 60, 0], [-0.3, 0, 0.158]),
    "forearm_link": ([0, 60, 0], [-0.3, 0, 0.068]),
    "wrist_1_link": ([0, 30, 0], [0.1, 0, 0]),
    "wrist_2_link": ([0, 30, 0], [0.1, 0, 0]),
    "wrist_3_link": ([0, 30, 0], [0.1, 0, 0]),
}


def raw(path: Path) -> np.ndarray:
    """A log's raw snapshots ``[T, 12, F]``."""
    return np.stack([s.x for s in log_samples(path)])


def find_log(stem: str) -> Path:
    found = sorted(ROOT.glob(f"logs/**/{stem}.csv")) + sorted(ROOT.glob(f"halves/{stem}.csv"))
    if not found:
        raise SystemExit(f"{stem}.csv: not under {ROOT}/logs or {ROOT}/halves (run fetch.sh)")
    return found[0]


def watch(x: np.ndarray, policy: ContactPolicy, threshold: np.ndarray) -> tuple:
    """The watch over one log: contact ``[T]`` and joint named ``[T]``."""
    bank = ContactBank(policy, threshold, ARM, 1)
    slot = np.zeros(1, np.int64)
    calls = [bank.update(slot, tick[None]) for tick in x]
    return np.array([c[0] for c, _ in calls]), np.array([j[0] for _, j in calls])


def held_pose(pushed: str | None) -> tuple[np.ndarray, str | None]:
    """The twin holding a pose (pushed on ``pushed`` or not): raw snapshots, the joint nearest."""
    extra = []
    if pushed:
        force, point = SIM_PUSHES[pushed]
        extra = [f"session.pushes=[{{at_s: {PUSH_AT_S}, for_s: {PUSH_S}, link: {pushed}, "
                 f"force_n: {force}, point_m: {point}}}]"]  # fmt: skip
    sim = build_simulator(compose_config("record", [*TWIN, *extra]))
    x = np.concatenate([chunk_features(c) for c in sim.run(round(HOLD_S / sim.tick_s))])
    return x, sim_pushes.joint_moving(sim.model, pushed) if pushed else None


def sim_cells(held: list, policy: ContactPolicy, threshold: np.ndarray) -> tuple[int, int, int]:
    """Simulated pushes called, joints named right, ticks called after the pushes ended."""
    first, last = round(PUSH_AT_S * TICK_HZ), round((PUSH_AT_S + PUSH_S) * TICK_HZ)
    called = right = echo = 0
    for x, truth in held:
        contact, joint = watch(x, policy, threshold)
        called += bool(contact[first:last].any())
        named = Counter(joint[first:last][contact[first:last]].tolist()).most_common(1)
        right += bool(named) and schema.JOINT_NAMES[named[0][0]] == truth
        echo += int(contact[last + 2 :].sum())  # the force has fallen by last + 2
    return called, right, echo


def episodes(contact: np.ndarray) -> int:
    return int(np.count_nonzero(np.diff(contact.astype(np.int8), prepend=0) == 1))


def push_cells(x: np.ndarray, contact: np.ndarray, joint: np.ndarray) -> tuple[int, int, list]:
    """Pushes called (any tick), the nearest joint named most, each push's share called."""
    off, found = pushes(x[:, : schema.N_JOINTS, RESIDUAL], rated_torque_nm(ARM), SHARE)
    called = agree = 0
    shares = []
    for a, b in found:
        during = contact[a : b + 1]
        shares.append(float(during.mean()))
        called += bool(during.any())
        named = Counter(joint[a : b + 1][during].tolist()).most_common(1)
        agree += bool(named) and named[0][0] == most_distal_loaded(off[a : b + 1], SHARE)
    return called, agree, shares


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--run", default="cruise")
    parser.add_argument("--verdicts", default="verdicts_ownmotion_rate0.99_motion")
    args = parser.parse_args()
    verdicts = ROOT / args.run / args.verdicts / "stgnn_fixed"
    record = next((ROOT / args.run / "models").rglob("stgnn_fixed/w32/seed42/commissioned"
                  + args.verdicts.removeprefix("verdicts").removesuffix("_motion")
                  + "/commissioning.json"))  # fmt: skip
    commissioning = [raw(Path(p)) for p in json.loads(record.read_text())["healthy"]]
    logs = {kind: [raw(find_log(p.stem)) for p in sorted((verdicts / kind).glob("*.json"))]
            for kind in ("program", "healthy", "push", "load")}  # fmt: skip
    hours = {k: sum(len(x) for x in v) / TICK_HZ / 3600 for k, v in logs.items()}
    unpushed, _ = held_pose(None)
    held = [held_pose(link) for link in SIM_PUSHES]
    print(f"## The contact watch on the real UR10e (commissioned as `{record.parent.name}` of run "
          f"`{args.run}`)\n")  # fmt: skip
    print(f"Commissioning: {len(commissioning)} healthy logs "
          f"({sum(len(x) for x in commissioning) / TICK_HZ / 60:.1f} min). Selection: "
          f"{len(logs['program'])} program logs ({hours['program'] * 60:.1f} min) and the first "
          f"pushed log. Test: {len(logs['healthy'])} monitored healthy logs "
          f"({hours['healthy'] * 60:.1f} min) and the second pushed log. A push: a joint more "
          f"than {SHARE:.0%} of its rating off its level 1-3 s before (found in hindsight); "
          "'joint' counts the pushes whose joint named most is the most distal joint so "
          "loaded. Thresholds as shares of the rated torque, joints in order.\n")  # fmt: skip
    print("| margin | confirm | model-torque guard | still below rad/s "
          "| pushes left out of the level "
          "| thresholds (share of rating) | twin pushed: called, joint, ticks after "
          "| program: contact ticks (episodes) | push log 1: called, joint, mean share "
          "| monitored: contact ticks (episodes) "
          "| push log 2: called, joint, mean share |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    rated = rated_torque_nm(ARM)
    rows = []
    for margin, confirm, command, still, exclude in itertools.product(*GRID.values()):
        policy = ContactPolicy(confirm=confirm, command_share=command, still_rad_s=still,
                               exclude_contact=exclude)  # fmt: skip
        threshold, _ = commission_thresholds(commissioning, ARM, margin, policy)
        twin_threshold, _ = commission_thresholds([unpushed], ARM, margin, policy)
        sim = sim_cells(held, policy, twin_threshold)
        healthy = {}
        for kind in ("program", "healthy"):
            calls = [watch(x, policy, threshold)[0] for x in logs[kind]]
            healthy[kind] = (sum(int(c.sum()) for c in calls), sum(episodes(c) for c in calls))
        pushed = [push_cells(x, *watch(x, policy, threshold)) for x in logs["push"]]
        (called, agree, shares) = pushed[0]
        rule = (sim[2] == 0, healthy["program"][0] == 0, sim[0] + called, sim[1] + agree,
                confirm, float(np.mean(shares)))  # fmt: skip
        cells = [f"{margin:g}", str(confirm), "yes" if np.isfinite(command) else "no",
                 f"{still:g}", "yes" if exclude else "no",
                 " / ".join(f"{v:.3f}" for v in threshold / rated),
                 f"{sim[0]}/{len(held)}, {sim[1]}/{len(held)}, {sim[2]}",
                 "{} ({})".format(*healthy["program"]), push_text(pushed[0]),
                 "{} ({})".format(*healthy["healthy"]), push_text(pushed[1])]  # fmt: skip
        rows.append((rule, cells, policy, threshold))
        print("| " + " | ".join(cells) + " |", flush=True)
    _, best, policy, threshold = max(rows, key=lambda row: row[0])
    print(
        f"\nSelected by the rule: margin {best[0]}, confirm {best[1]}, model-torque guard "
        f"{best[2]}, still below {best[3]} rad/s, pushes left out of the level {best[4]}."
    )
    calls = [watch(x, policy, threshold)[0] for x in logs["load"]]
    print(f"\nThe selected setting on the {len(calls)} runs with an added load (healthy, a "
          f"payload the controller was not told of; {hours['load'] * 60:.1f} min, used by no "
          f"choice): {sum(int(c.sum()) for c in calls)} contact ticks in "
          f"{sum(episodes(c) for c in calls)} calls.")  # fmt: skip


def push_text(cells: tuple[int, int, list]) -> str:
    called, agree, shares = cells
    return f"{called}/{len(shares)}, {agree}/{len(shares)}, {np.mean(shares):.2f}"


if __name__ == "__main__":
    main()
