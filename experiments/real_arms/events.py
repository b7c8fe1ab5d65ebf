"""What the commissioned monitor says, push by push, on the real logs where the arm is pushed
while it holds a pose. The logs carry no label of when or where it was pushed, so each push is
found from the log's own torque residual (measured minus the controller's model): ticks where a
joint's residual leaves its level of 1-3 s before by more than ``--share`` of its rated torque.
The joint nearest the push is the most distal joint the push loads that much (a force on a link
loads no joint beyond it).

    python experiments/real_arms/events.py [--run replay] [--suffix _rate0.99]
        [--observability all|motion] > results/real_arms/events.md

Per commissioned network (``outputs/real_arms/<run>/models/**/commissioned/model.onnx``), per
push: when and how long, the share of its ticks called faulty, whether an alarm rose during it
(or within a window after), the joint the monitor names most during it and the nearest joint.
"""

from __future__ import annotations

import argparse
from collections import Counter
from pathlib import Path

import numpy as np

from robohealth_mj import schema
from robohealth_mj.runtime.runtime import ModelRuntime
from robohealth_mj.runtime.sources import replay_stream
from robohealth_mj.sim.ratings import rated_torque_nm

LOGS = Path("outputs/real_arms/logs/collision")
RESIDUAL = schema.feature_index("effort_residual")
TICK_HZ = 20.0


def pushes(residual: np.ndarray, share: float) -> tuple[np.ndarray, list[tuple[int, int]]]:
    """Per tick how far each joint's residual is off its level 1-3 s before, relative to its
    rating ``[T, 6]``; the pushes as (first, last) ticks, gaps under 0.5 s merged."""
    off = np.zeros_like(residual)
    for t in range(25, len(residual)):  # the log's first second gives the first level
        off[t] = np.abs(residual[t] - np.median(residual[max(0, t - 60) : t - 20], axis=0))
    off /= rated_torque_nm("ur10e")
    ticks = np.flatnonzero(off.max(axis=1) > share)
    episodes: list[list[int]] = []
    for t in ticks:
        if episodes and t - episodes[-1][1] <= 10:
            episodes[-1][1] = t
        else:
            episodes.append([t, t])
    return off, [(a, b) for a, b in episodes if b - a >= 4]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--run", default="replay", help="a campaign run under outputs/real_arms/")
    parser.add_argument("--share", type=float, default=0.05, help="of the joint's rated torque")
    parser.add_argument("--suffix", default="", help="commissioned<SUFFIX>/ (campaign.py's)")
    parser.add_argument(
        "--observability", default="all", help="monitor observability= (all, motion)"
    )
    args = parser.parse_args()
    models = sorted(Path(f"outputs/real_arms/{args.run}/models").rglob(
        f"commissioned{args.suffix}/model.onnx"))  # fmt: skip
    print(f"## Pushed while holding a pose (run {args.run}{args.suffix}, "
          f"observability={args.observability})\n")  # fmt: skip
    print(f"A push: a joint's residual more than {args.share:.0%} of its rated torque off its "
          "level 1-3 s before.\n")  # fmt: skip
    print("| model | log | push at s | lasts s | called faulty | class called | alarm "
          "| joint named | nearest joint |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|")
    for model in models:
        variant = model.parts[-5]  # <variant>/w32/seed42/commissioned/model.onnx
        for log in sorted(LOGS.glob("*.csv")):
            runtime = ModelRuntime(str(model), observability=args.observability)
            samples = [s for _, s, _ in replay_stream(str(log))]
            said = [runtime.process("arm", s) for s in samples]
            off, found = pushes(np.stack([s.x[: schema.N_JOINTS, RESIDUAL] for s in samples]),
                                args.share)  # fmt: skip
            for first, last in found:
                during = said[first : last + 1]
                faulty = [d for d in during if d.fault_present]
                after = said[first : last + 1 + 32]  # an alarm within one window of the push
                alarm = any(d.alarm == "raised" for d in after)
                named = Counter(d.localised_joint for d in faulty).most_common(1)
                called = Counter(d.fault_class for d in faulty).most_common(1)
                loaded = np.flatnonzero(off[first : last + 1].max(axis=0) > args.share)
                print(f"| {variant} | {log.stem} | {first / TICK_HZ:.1f} | "
                      f"{(last - first + 1) / TICK_HZ:.1f} | {len(faulty) / len(during):.2f} | "
                      f"{called[0][0] if called else '-'} | {'yes' if alarm else 'no'} | "
                      f"{named[0][0] if named else '-'} | "
                      f"{schema.JOINT_NAMES[loaded.max()]} |")  # fmt: skip


if __name__ == "__main__":
    main()
