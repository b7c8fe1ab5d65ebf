"""What the commissioned monitor says, push by push, on the real logs where the arm is pushed
while it holds a pose. The logs carry no label of when or where it was pushed, so each push is
found from the log's own torque residual (measured minus the controller's model): ticks where a
joint's residual leaves its level of 1-3 s before by more than ``--share`` of its rated torque.
The joint nearest the push is the most distal joint the push loads that much (a force on a link
loads no joint beyond it).

    python studies/real_arms/events.py [--run replay] [--suffix _rate0.99]
        [--observability all|motion] > studies/real_arms/results/events.md

Per commissioned network (``outputs/real_arms/<run>/models/**/commissioned/model.onnx``), per
push: when and how long, the share of its ticks called faulty, whether an alarm rose during it
(or within a window after), the joint the monitor names most during it and the nearest joint;
and what the contact watch says (:mod:`robohealth_mj.runtime.contact`, where the model carries
its thresholds): the share of the push's ticks it calls a contact, how soon after the push's
first tick, and the joint it names most.
"""

from __future__ import annotations

import argparse
from collections import Counter
from pathlib import Path

import numpy as np

from robohealth_mj import schema
from robohealth_mj.arms.ratings import rated_torque_nm
from robohealth_mj.runtime.runtime import HealthDiagnosis, ModelRuntime
from robohealth_mj.runtime.sources import replay_stream
from robohealth_mj.twin.pushes import most_distal_loaded, pushes

LOGS = Path("outputs/real_arms/logs/collision")
RESIDUAL = schema.feature_index("effort_residual")
EFFORT = schema.feature_index("effort")
TICK_HZ = 20.0


def contact_cells(during: list[HealthDiagnosis]) -> str:
    """The contact watch over a push's ticks: share called, first call (s after the push's
    first tick), the joint named most."""
    called = [k for k, d in enumerate(during) if d.contact]
    if not called:
        return "0.00 | - | -"
    named = Counter(during[k].contact_joint for k in called).most_common(1)[0][0]
    return f"{len(called) / len(during):.2f} | {called[0] / TICK_HZ:.2f} | {named}"


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
          "| joint named | contact called | contact from s | contact joint "
          "| nearest joint |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    moved: dict[str, np.ndarray] = {}
    for model in models:
        variant = model.parts[-5]  # <variant>/w32/seed42/commissioned/model.onnx
        for log in sorted(LOGS.glob("*.csv")):
            runtime = ModelRuntime(str(model), observability=args.observability)
            samples = [s for _, s, _ in replay_stream(str(log))]
            said = [runtime.process("arm", s) for s in samples]
            residual = np.stack([s.x[: schema.N_JOINTS, RESIDUAL] for s in samples])
            expected = np.stack([s.x[: schema.N_JOINTS, EFFORT] for s in samples]) - residual
            moved[log.stem] = np.ptp(expected, axis=0) / rated_torque_nm("ur10e")
            off, found = pushes(residual, rated_torque_nm("ur10e"), args.share)
            for first, last in found:
                during = said[first : last + 1]
                faulty = [d for d in during if d.fault_present]
                after = said[first : last + 1 + 32]  # an alarm within one window of the push
                alarm = any(d.alarm == "raised" for d in after)
                named = Counter(d.localised_joint for d in faulty).most_common(1)
                called = Counter(d.fault_class for d in faulty).most_common(1)
                nearest = most_distal_loaded(off[first : last + 1], args.share)
                print(f"| {variant} | {log.stem} | {first / TICK_HZ:.1f} | "
                      f"{(last - first + 1) / TICK_HZ:.1f} | {len(faulty) / len(during):.2f} | "
                      f"{called[0][0] if called else '-'} | {'yes' if alarm else 'no'} | "
                      f"{named[0][0] if named else '-'} | {contact_cells(during)} | "
                      f"{schema.JOINT_NAMES[nearest]} |")  # fmt: skip
    for stem, share in moved.items():  # the contact watch's guard: nothing commanded
        print(f"\n{stem}: the controller's model torque moved at most {share.max():.2%} of a "
              "joint's rating over the log (the contact watch reads a push only while it stays "
              "put).")  # fmt: skip


if __name__ == "__main__":
    main()
