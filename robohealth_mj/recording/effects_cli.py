"""Fault effect sizes on every channel: ``python -m robohealth_mj.effects``.

Effect = RMS(faulted - healthy) / the healthy channel's std, on the faulted joint's own nodes, for
each fault x joint x severity (same seed, trajectory and noise draws in both runs). ``1-hop`` is
the mean effect over the sensor channels of the neighbouring joints' sensors.

    python -m robohealth_mj.effects [--joints shoulder_pan elbow wrist_3]
        [--severities 0.3 0.6 0.9] [--seconds 30] [--models physics] [--json rows.json]
    python -m robohealth_mj.effects --arm fr3 --joints fr3_joint2 fr3_joint4 fr3_joint7
"""

from __future__ import annotations

import argparse

from robohealth_mj.common.errors import one_line_errors

DEFAULT_JOINTS = ("shoulder_pan", "elbow", "wrist_3")

with one_line_errors("effects"):  # a missing extra is one line, not a traceback
    from robohealth_mj.faults.catalogue import FAULT_MODELS, MODES
    from robohealth_mj.recording.effect_sizes import COLUMNS, sweep, table_row


def default_joints(arm: str | None) -> list[str]:
    """The base, a middle and the tool joint of ``arm`` (the UR's shoulder pan, elbow, wrist 3)."""
    if arm is None:
        return list(DEFAULT_JOINTS)
    from robohealth_mj.arms.description import load_arm

    keys = load_arm(arm).joint_keys
    return [keys[0], keys[len(keys) // 2], keys[-1]]


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(
        prog="python -m robohealth_mj.effects",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "--arm", default=None, help="the arm (ur5e, fr3 ..., your.urdf); default the UR5e"
    )
    parser.add_argument(
        "--joints", nargs="+", default=None,
        help=f"the arm's joints to fault (default: {' '.join(DEFAULT_JOINTS)} on a UR; the "
        "base, middle and tool joints on another arm)",
    )  # fmt: skip
    parser.add_argument("--severities", nargs="+", type=float, default=[0.3, 0.6, 0.9])
    parser.add_argument("--seconds", type=float, default=30.0)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--models", nargs="+", default=["physics"], choices=FAULT_MODELS)
    parser.add_argument("--classes", nargs="+", default=list(MODES), choices=MODES)
    parser.add_argument("--markdown", action="store_true", help="print a Markdown table")
    parser.add_argument("--json", help="also write the rows to this JSON file")
    args = parser.parse_args(argv)
    if any(not 0.0 <= s <= 1.0 for s in args.severities):
        parser.error("--severities must lie in [0, 1]")
    joints = args.joints or default_joints(args.arm)
    names = [*COLUMNS, "1-hop"]
    if args.markdown:
        print("| fault | joint | sev. | model | " + " | ".join(names) + " |")
        print("|---|---|---|---|" + "---:|" * len(names))
    else:
        print(
            f"{'fault':<14}{'joint':<14}{'sev':>5} {'model':<9}" + "".join(f"{n:>9}" for n in names)
        )
    rows = []
    for row in sweep(
        args.classes, joints, args.severities, args.models, args.seconds, args.seed, args.arm
    ):
        rows.append(row)
        values = table_row(row)
        head = (row["fault"], row["joint"], f"{row['severity']:g}", row["fault_model"])
        if args.markdown:
            print("| " + " | ".join(head) + " | " + " | ".join(f"{v:.2f}" for v in values) + " |")
        else:
            print(
                f"{head[0]:<14}{head[1]:<14}{head[2]:>5} {head[3]:<9}"
                + "".join(f"{v:>9.2f}" for v in values),
                flush=True,
            )
    if args.json:
        from robohealth_mj.common.atomic import atomic_write_json

        atomic_write_json(args.json, rows)
