"""Where a push was: the most distal joint loaded against a force fit on the arm's kinematics
(:mod:`robohealth_mj.arms.contact_place`) and the contact watch as deployed, which places its
contacts with that fit; where the truth is known and on the real pushes, where it is not.

    python studies/real_arms/contact_where.py [--run cruise]
        > studies/real_arms/results/contact_where.md

The watch before 2026-11-27, and the hindsight finder the real pushes were scored against
(``events.py``), both name the most distal joint a push loads. A hand pressing square on a
joint's round housing pushes through that joint's axis and loads it not at all, so that rule can
name a joint short of the push. Three parts, each with that rule beside the fit's:

1. The twin, simulated (selection): it holds a pose and is pushed for 1 s at points drawn on
   each link's collision surface (a geom by its area), with a force drawn uniformly inside the
   friction cone there (60-120 N on the shoulder, upper arm and forearm, 30-60 N on the wrists).
   The truth is the link pushed. The fit's acceptance is chosen here: the most pushes named
   right, then the smaller.
2. The real pushes (found in hindsight, :mod:`robohealth_mj.twin.pushes`): what the finder, the
   watch and the fit each name. No truth: the logs say neither where nor how.
3. Kinematics alone, at the real arm's two held poses: pushes drawn the same way, their joint
   torques ``J^T F`` with the real arm's thresholds and noise (the largest quiet deviation of its
   commissioning running per joint; a normal draw of half that is added): read after.

A push's torques: each joint's residual against its median 3 s to 1 s before the push, the
median over the push's ticks where it is at least half its largest, with the sign turned (the
drives hold against the push).
"""

from __future__ import annotations

import argparse
import json
from collections import Counter
from pathlib import Path

import mujoco
import numpy as np

from robohealth_mj import schema
from robohealth_mj.arms.contact_place import ACCEPT as PLACE_ACCEPT
from robohealth_mj.arms.contact_place import FRICTION, place, tangents
from robohealth_mj.arms.ratings import rated_torque_nm
from robohealth_mj.common.config import compose_config
from robohealth_mj.logs import log_samples
from robohealth_mj.recording.recorder import build_simulator, chunk_features
from robohealth_mj.runtime.contact import ContactBank, ContactPolicy, Placing, quiet_deviations
from robohealth_mj.sim.contact_surface import arm_surface, geom_area, geom_in_body, geom_surface
from robohealth_mj.sim.dynamics import nominal_model
from robohealth_mj.twin.pushes import most_distal_loaded, pushes

ROOT = Path("outputs/real_arms")
ARM = "ur10e"
SEED = 7
MARGIN = 2.0  # the watch's thresholds: this times each joint's largest quiet deviation
SHARE = 0.05  # the finder's push: a joint more than this share of its rating off its level
ACCEPT = (1.0, 2.0, 4.0, 8.0)
TICK_HZ = 20.0
POS, RESIDUAL = schema.feature_index("pos"), schema.feature_index("effort_residual")
TWIN = ["arm=ur10e", f"sim.twin={ROOT}/twin/twin.yaml", "sim.mount_height_m=0.8", "seed=3",
        "session.progress=false", "faults=none", "curriculum.families=[hold]"]  # fmt: skip
PUSH_AT_S, PUSH_S, HOLD_S = 6.0, 1.0, 12.0
FORCE_N = {True: (60.0, 120.0), False: (30.0, 60.0)}  # big links, wrists
TWIN_PER_LINK, KINEMATIC_PER_LINK = 8, 12
SURFACE = arm_surface(ARM)


def drawn_push(model: mujoco.MjModel, joint: int, rng: np.random.Generator) -> tuple:
    """A push on the link ``joint`` moves: ``(point, force)`` in the link's body frame, at a
    point of its collision surface (each geom by its area), pushing in a direction drawn
    uniformly inside the friction cone there."""
    body = int(model.joint(f"{schema.JOINT_NAMES[joint]}_joint").bodyid[0])
    geoms = np.flatnonzero(model.geom_bodyid == body)
    areas = np.array([geom_area(model, g) for g in geoms])
    geom = int(rng.choice(geoms, p=areas / areas.sum()))
    points, normals = geom_surface(model, geom)
    k = int(rng.integers(len(points)))
    pos, turn = geom_in_body(model, geom)
    normal = turn @ normals[k]
    t1, t2 = (t[0] for t in tangents(normal[None]))
    slide, angle = FRICTION * np.sqrt(rng.random()), rng.uniform(0, 2 * np.pi)
    force = -normal + slide * (np.cos(angle) * t1 + np.sin(angle) * t2)
    force *= rng.uniform(*FORCE_N[joint < 3]) / np.linalg.norm(force)
    return pos + turn @ points[k], force


def push_torque(x: np.ndarray, first: int, last: int) -> tuple[np.ndarray, np.ndarray]:
    """The pose ``[6]`` and the push's external torque on the joints ``[6]`` (N·m) over ticks
    first..last: minus the residual's change, as the drives hold against it."""
    residual = x[:, : schema.N_JOINTS, RESIDUAL].astype(np.float64)
    level = np.median(residual[max(0, first - 60) : first - 20], axis=0)
    off = residual[first : last + 1] - level
    size = np.abs(off).max(axis=1)
    pose = x[(first + last) // 2, : schema.N_JOINTS, POS]
    return pose, -np.median(off[size >= 0.5 * size.max()], axis=0)


def watch_named(
    x: np.ndarray, threshold: np.ndarray, first: int, last: int, placing: Placing | None = None
) -> int | None:
    """The joint the watch names most over ticks first..last (None: no contact called), by the
    most distal joint over its threshold or, given ``placing``, as deployed since 2026-11-27."""
    bank = ContactBank(ContactPolicy(), threshold, ARM, 1, placing)
    slot = np.zeros(1, np.int64)
    named = [int(bank.update(slot, tick[None])[1][0]) for tick in x]
    called = Counter(j for j in named[first : last + 1] if j >= 0).most_common(1)
    return called[0][0] if called else None


def fit_named(q: np.ndarray, torque: np.ndarray, noise: np.ndarray) -> tuple[dict, object]:
    """Per acceptance, the joint the fit names (None: no single push explains the torques), and
    the placement (chi-square and force per link)."""
    placed = place(SURFACE, q, torque, noise, accept=np.inf)
    names = {}
    for a in ACCEPT:
        fits = np.flatnonzero(placed.chi2 <= a)
        names[a] = int(fits[0]) if len(fits) else None
    return names, placed


def short(joint: int | None) -> str:
    return "-" if joint is None else schema.JOINT_NAMES[joint]


def held(push: tuple | None, link: str = "") -> np.ndarray:
    """The twin holding a pose, pushed at ``push`` (body-frame point, force) on ``link`` or not."""
    extra = []
    if push is not None:
        point, force = (np.round(v, 4).tolist() for v in push)
        extra = [f"session.pushes=[{{at_s: {PUSH_AT_S}, for_s: {PUSH_S}, link: {link}, "
                 f"force_n: {force}, point_m: {point}}}]"]  # fmt: skip
    sim = build_simulator(compose_config("record", [*TWIN, *extra]))
    return np.concatenate([chunk_features(c) for c in sim.run(round(HOLD_S / sim.tick_s))])


def tally(rows: list[tuple]) -> str:
    """'right of called' for the most-distal rule, the watch as deployed where the rows have it,
    and the fit at each acceptance. A row: (truth, rule's joint, fit's joints[, watch's])."""
    called = [r for r in rows if r[1] is not None]
    cells = [f"{sum(r[1] == r[0] for r in called)} / {len(called)}"]
    if called and len(called[0]) > 3:
        cells.append(f"{sum(r[3] == r[0] for r in called)} / {len(called)}")
    cells += [f"{sum(r[2][a] == r[0] for r in called)} / {len(called)}" for a in ACCEPT]
    return " | ".join(cells)


def twin_part(rng: np.random.Generator) -> float:
    """Part 1; returns the acceptance it selects."""
    model, _ = nominal_model(ARM)
    unpushed = held(None)
    noise = quiet_deviations([unpushed], ARM)
    threshold = MARGIN * noise
    first, last = round(PUSH_AT_S * TICK_HZ), round((PUSH_AT_S + PUSH_S) * TICK_HZ)
    rows, lines = [], []
    for joint in range(schema.N_JOINTS):
        link = model.body(int(model.joint(f"{schema.JOINT_NAMES[joint]}_joint").bodyid[0])).name
        for _ in range(TWIN_PER_LINK):
            push = drawn_push(model, joint, rng)
            x = held(push, link)
            q, torque = push_torque(x, first, last)
            watch = watch_named(x, threshold, first, last)
            deployed = watch_named(x, threshold, first, last, Placing(SURFACE, noise))
            named, fits = fit_named(q, torque, noise)
            rows.append((joint, watch, named, deployed))
            chi2 = " / ".join(f"{c:.1f}" for c in fits.chi2)
            lines.append((f"{link} ({schema.JOINT_NAMES[joint]})", np.linalg.norm(push[1]),
                          watch, deployed, named, chi2))  # fmt: skip
    called = [r for r in rows if r[1] is not None]
    accept = max(ACCEPT, key=lambda a: (sum(r[2][a] == r[0] for r in called), -a))
    print("## 1. The twin pushed (truth known; selection)\n")
    print(f"Thresholds from its unpushed hold (N·m): {np.round(threshold, 2).tolist()}.\n")
    print("| | most distal joint loaded | watch as deployed | "
          + " | ".join(f"fit, accept {a:g}" for a in ACCEPT) + " |")  # fmt: skip
    print("|---|---|---|" + "---|" * len(ACCEPT))
    print(f"| named right, of the pushes the watch called | {tally(rows)} |\n")
    # determined by the torques: the pushed link explains them within the quiet wander and no
    # link before it does (what the fit at PLACE_ACCEPT names right, by its definition)
    determined = [r for r in called if r[2][PLACE_ACCEPT] == r[0]]
    print(f"Determined by the torques (the pushed link explains them within the quiet wander, "
          f"chi-square <= {PLACE_ACCEPT:g}, and no link before it does): {len(determined)} of the "
          f"{len(called)} called. Of those, the watch as deployed names "
          f"{sum(r[3] == r[0] for r in determined)} right, the most distal joint loaded "
          f"{sum(r[1] == r[0] for r in determined)}.\n")  # fmt: skip
    print(f"Selected: accept {accept:g} (the watch places at {PLACE_ACCEPT:g}). Push by push:\n")
    print("| link pushed (its joint) | force N | most distal joint loaded | watch as deployed "
          f"| fit (accept {accept:g}) | chi-square per link, base to flange |")  # fmt: skip
    print("|---|---|---|---|---|---|")
    for pushed, newtons, watch, deployed, named, chi2 in lines:
        print(f"| {pushed} | {newtons:.0f} | {short(watch)} | {short(deployed)} | "
              f"{short(named[accept])} | {chi2} |")  # fmt: skip
    print()
    return accept


def kinematic_part(rng: np.random.Generator, poses: dict, noise: np.ndarray) -> None:
    model, index = nominal_model(ARM)
    data = mujoco.MjData(model)
    jac = np.zeros((3, model.nv))
    threshold = MARGIN * noise
    print("## 3. Kinematics alone, at the real arm's held poses (read after)\n")
    print(
        f"{KINEMATIC_PER_LINK} pushes per link and pose; the real arm's thresholds (N·m): "
        f"{np.round(threshold, 2).tolist()}; pushes no threshold calls are left out.\n"
    )
    print("| pose | link's joint | called | most distal joint loaded: right | "
          + " | ".join(f"fit right, accept {a:g}" for a in ACCEPT) + " |")  # fmt: skip
    print("|---|---|---|---|" + "---|" * len(ACCEPT))
    every = []
    for pose, q in poses.items():
        index.set_link_pose(data, q)
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        for joint in range(schema.N_JOINTS):
            body = int(model.joint(f"{schema.JOINT_NAMES[joint]}_joint").bodyid[0])
            rows = []
            for _ in range(KINEMATIC_PER_LINK):
                point, force = drawn_push(model, joint, rng)
                turn = data.xmat[body].reshape(3, 3)
                where = data.xpos[body] + turn @ point
                mujoco.mj_jac(model, data, jac, None, where, body)
                torque = jac[:, index.motor_dof].T @ (turn @ force)
                torque = torque + rng.normal(0.0, 0.5, schema.N_JOINTS) * noise
                over = np.flatnonzero(np.abs(torque) > threshold)
                watch = int(over.max()) if len(over) else None
                rows.append((joint, watch, fit_named(q, torque, noise)[0] if len(over) else {}))
            every += rows
            called = sum(r[1] is not None for r in rows)
            print(
                f"| {pose} | {schema.JOINT_NAMES[joint]} | {called} | {tally(rows)} |", flush=True
            )
    print(f"| both | all | {sum(r[1] is not None for r in every)} | {tally(every)} |\n")


def real_part(logs: list[Path], noise: np.ndarray, accept: float) -> dict:
    print("## 2. The real pushes (no truth)\n")
    print(f"The fit at accept {accept:g}, chosen on part 1.\n")
    print("| log | push at s | finder (most distal joint > 5 % of its rating) "
          "| most distal joint over its threshold | watch as deployed "
          "| fit | chi-square per link, base to flange | force N |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    rated = rated_torque_nm(ARM)
    placing = Placing(SURFACE, noise)
    poses = {}
    for log in logs:
        x = np.stack([s.x for s in log_samples(log)])
        poses[log.stem[-6:]] = x[0, : schema.N_JOINTS, POS].astype(np.float64)
        off, found = pushes(x[:, : schema.N_JOINTS, RESIDUAL], rated, SHARE)
        for first, last in found:
            q, torque = push_torque(x, first, last)
            named, fits = fit_named(q, torque, noise)
            joint = named[accept]
            force = "-" if joint is None else f"{np.linalg.norm(fits.force_n[joint]):.0f}"
            print(f"| {log.stem} | {first / TICK_HZ:.1f} | "
                  f"{schema.JOINT_NAMES[most_distal_loaded(off[first : last + 1], SHARE)]} | "
                  f"{short(watch_named(x, MARGIN * noise, first, last))} | "
                  f"{short(watch_named(x, MARGIN * noise, first, last, placing))} | "
                  f"{short(named[accept])} | " + " / ".join(f"{c:.1f}" for c in fits.chi2)
                  + f" | {force} |", flush=True)  # fmt: skip
    return poses


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--run", default="cruise", help="the campaign run whose commissioning "
                        "logs give the real arm's thresholds")  # fmt: skip
    args = parser.parse_args()
    record = next((ROOT / args.run / "models").rglob(
        "stgnn_fixed/w32/seed42/commissioned_ownmotion_rate0.99/commissioning.json"))  # fmt: skip
    commissioning = [np.stack([s.x for s in log_samples(Path(p))])
                     for p in json.loads(record.read_text())["healthy"]]  # fmt: skip
    noise = quiet_deviations(commissioning, ARM)
    rng = np.random.default_rng(SEED)
    print("# Where a push was: the contact watch's joint against a force fit\n")
    print("Command: `python studies/real_arms/contact_where.py` (after `run.sh` has made "
          f"run `{args.run}`). Noise per joint: the largest quiet deviation of the healthy "
          "running (the watch's threshold over its margin); chi-square: the torques' misfit "
          "in those units, summed over the joints.\n")  # fmt: skip
    accept = twin_part(rng)
    poses = real_part(sorted((ROOT / "logs/collision").glob("*.csv")), noise, accept)
    print()
    kinematic_part(rng, poses, noise)


if __name__ == "__main__":
    main()
