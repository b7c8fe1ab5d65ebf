"""How a real UR controller runs point-to-point moves: per move of a log, its duration, each
joint's peak speed, the leading joint, how long the leading joint holds its speed, how long it
takes to reach it, and the pause before the move. The curriculum's ``cruise`` family takes its
speed, ramp and pause from this table (``robohealth_mj/sim/curriculum.py``).

    python studies/real_arms/moves.py \\
        [--log outputs/real_arms/logs/validation_data/ur-20_01_17-ptp_10_points.csv] \\
        > studies/real_arms/results/moves.md

Runs after ``studies/real_arms/fetch.sh``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from robohealth_mj.schema import JOINT_NAMES
from robohealth_mj.twin.joint_log import read_joint_log

LOG = Path("outputs/real_arms/logs/validation_data/ur-20_01_17-ptp_10_points.csv")
MOVING_RAD_S = 0.02  # the arm moves: some joint faster than this
AT_SPEED = 0.95  # the leading joint cruises above this share of its peak speed
STARTED = 0.05  # ... and has started above this share


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--log", type=Path, default=LOG)
    args = parser.parse_args()
    log = read_joint_log(args.log)
    t = log.t
    dt = np.gradient(t)  # per row: the log drops a row now and then
    moving = np.abs(log.qd).max(axis=1) > MOVING_RAD_S
    edges = np.flatnonzero(np.diff(moving.astype(int))) + 1  # first row of each change
    if moving[0]:
        edges = np.r_[0, edges]
    if moving[-1]:
        edges = np.r_[edges, len(moving)]
    print(f"## Moves of {args.log.name} ({t[-1] - t[0]:.1f} s, {len(t)} rows)\n")
    names = " | ".join(JOINT_NAMES)
    print(f"| move | pause before (s) | duration (s) | peak speed (rad/s): {names} | leading joint "
          "| at speed (s) | to speed (s) | acceleration (rad/s²) |")  # fmt: skip
    print("|---|---|---|" + "---|" * len(JOINT_NAMES) + "---|---|---|---|")
    last_stop = None
    for k, (start, stop) in enumerate(zip(edges[::2], edges[1::2], strict=True)):
        speed = np.abs(log.qd[start:stop])
        peak = speed.max(axis=0)
        lead = int(np.argmax(peak))
        lead_speed = speed[:, lead]
        cruise_s = float(dt[start:stop][lead_speed > AT_SPEED * peak[lead]].sum())
        ramp_s = float(t[start + np.argmax(lead_speed > AT_SPEED * peak[lead])]
                       - t[start + np.argmax(lead_speed > STARTED * peak[lead])])  # fmt: skip
        pause = "" if last_stop is None else f"{t[start] - t[last_stop - 1]:.2f}"
        peaks = " | ".join(f"{p:.2f}" for p in peak)
        accel = peak[lead] / ramp_s if ramp_s > 0 else float("nan")
        print(f"| {k + 1} | {pause} | {t[stop - 1] - t[start]:.2f} | {peaks} | {JOINT_NAMES[lead]} "
              f"| {cruise_s:.2f} | {ramp_s:.2f} | {accel:.2f} |")  # fmt: skip
        last_stop = stop
    print('\nCommand: `bash studies/real_arms/run.sh` (the block after "Cruising moves").')


if __name__ == "__main__":
    main()
