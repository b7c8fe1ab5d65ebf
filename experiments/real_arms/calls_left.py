"""What a commissioned network still calls faulty on a healthy real log: each faulty tick's class
and joint, and how many joints moved (faster than the observability threshold) in its window.

    python experiments/real_arms/calls_left.py [--run standard] [--suffix _rate0.99]
        [--observability motion] [--log validation_data/ur-20_01_17-ptp_10_points.csv]

Runs after ``campaign.py`` (its commissioned ``stgnn_fixed`` under ``outputs/real_arms/<run>/``).
"""

from __future__ import annotations

import argparse
from collections import Counter
from pathlib import Path

import numpy as np

from robohealth_mj import schema
from robohealth_mj.data.observability import MOVING_RAD_S
from robohealth_mj.runtime.runtime import ModelRuntime
from robohealth_mj.runtime.sources import replay_stream

LOGS = Path("outputs/real_arms/logs")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--run", default="standard")
    parser.add_argument("--suffix", default="_rate0.99", help="commissioned<SUFFIX>/")
    parser.add_argument("--observability", default="motion")
    parser.add_argument("--log", default="validation_data/ur-20_01_17-ptp_10_points.csv")
    args = parser.parse_args()
    (model,) = Path(f"outputs/real_arms/{args.run}/models").rglob(
        f"stgnn_fixed/**/commissioned{args.suffix}/model.onnx"
    )
    runtime = ModelRuntime(str(model), observability=args.observability)
    samples = [s for _, s, _ in replay_stream(str(LOGS / args.log))]
    said = [runtime.process("arm", s) for s in samples]
    speed = np.abs(np.stack([s.x[: schema.N_JOINTS, schema.feature_index("vel")] for s in samples]))
    calls, moving = Counter(), Counter()
    for k, d in enumerate(said):
        if d.fault_present:
            calls[f"{d.fault_class} @ {d.localised_joint}"] += 1
            window = speed[max(0, k - runtime.window + 1) : k + 1]
            moving[int((window.max(axis=0) > MOVING_RAD_S).sum())] += 1
    decided = sum(d.fault_class is not None for d in said)
    print(f"## {args.log}, run {args.run}{args.suffix}, observability={args.observability}\n")
    print(f"{sum(calls.values())} of {decided} decided ticks called faulty\n")
    print("| class @ joint | ticks |\n|---|---|")
    for what, n in calls.most_common():
        print(f"| {what} | {n} |")
    print("\n| joints that moved in the window | faulty ticks |\n|---|---|")
    for joints, n in sorted(moving.items()):
        print(f"| {joints} | {n} |")


if __name__ == "__main__":
    main()
