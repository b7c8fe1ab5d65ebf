"""What a commissioned network still calls faulty on a healthy real log: each faulty tick's class
and joint, how many joints moved (faster than the observability threshold) in its window, and
whether a joint cruised in it (held a constant speed, as a trapezoidal move does), beside how
often the training corpus's windows hold a cruise.

    python studies/real_arms/calls_left.py [--run standard] [--suffix _rate0.99]
        [--observability motion] [--log validation_data/ur-20_01_17-ptp_10_points.csv]
        [--corpus outputs/corpus/real_ur10e_standard]

Runs after ``campaign.py`` (its commissioned ``stgnn_fixed`` under ``outputs/real_arms/<run>/``).
"""

from __future__ import annotations

import argparse
from collections import Counter
from pathlib import Path

import numpy as np

from robohealth_mj import schema
from robohealth_mj.data.arrays import load_recordings
from robohealth_mj.data.observability import MOVING_RAD_S
from robohealth_mj.runtime.runtime import ModelRuntime
from robohealth_mj.runtime.sources import replay_stream

LOGS = Path("outputs/real_arms/logs")
CRUISE_RAD_S = 0.2  # a joint cruises in a window: faster than this on average,
CRUISE_SPREAD = 0.1  # with a speed that varies by less than this share of it (std / |mean|)


def cruising(vel: np.ndarray) -> np.ndarray:
    """``vel`` [..., W, J] -> [..., J]: which joints held a constant speed through the window."""
    mean, spread = vel.mean(axis=-2), vel.std(axis=-2)
    return (np.abs(mean) > CRUISE_RAD_S) & (spread < CRUISE_SPREAD * np.abs(mean))


def corpus_cruise_share(corpus: Path, window: int) -> float:
    """The share of the corpus's training windows (every fourth) in which some joint cruises."""
    rec = load_recordings(sorted(corpus.glob("train_*/graphs.jsonl")))
    vel = rec.x[:, : schema.N_JOINTS, schema.feature_index("vel")]
    ends = np.arange(window - 1, len(vel), 4)
    ends = ends[rec.run[ends] == rec.run[ends - window + 1]]  # windows within one session
    windows = np.stack([vel[k - window + 1 : k + 1] for k in ends])
    return float(cruising(windows).any(axis=1).mean())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--run", default="standard")
    parser.add_argument("--suffix", default="_rate0.99", help="commissioned<SUFFIX>/")
    parser.add_argument("--observability", default="motion")
    parser.add_argument("--log", default="validation_data/ur-20_01_17-ptp_10_points.csv")
    parser.add_argument("--corpus", type=Path, default=Path("outputs/corpus/real_ur10e_standard"))
    args = parser.parse_args()
    (model,) = Path(f"outputs/real_arms/{args.run}/models").rglob(
        f"stgnn_fixed/**/commissioned{args.suffix}/model.onnx"
    )
    runtime = ModelRuntime(str(model), observability=args.observability)
    samples = [s for _, s, _ in replay_stream(str(LOGS / args.log))]
    said = [runtime.process("arm", s) for s in samples]
    vel = np.stack([s.x[: schema.N_JOINTS, schema.feature_index("vel")] for s in samples])
    speed = np.abs(vel)
    calls, moving = Counter(), Counter()
    cruise = {True: [0, 0], False: [0, 0]}  # a joint cruised in the window: [decided, faulty]
    for k, d in enumerate(said):
        window = slice(max(0, k - runtime.window + 1), k + 1)
        if d.fault_class is not None:
            cruised = bool(cruising(vel[window]).any())
            cruise[cruised][0] += 1
            cruise[cruised][1] += bool(d.fault_present)
        if d.fault_present:
            calls[f"{d.fault_class} @ {d.localised_joint}"] += 1
            moving[int((speed[window].max(axis=0) > MOVING_RAD_S).sum())] += 1
    decided = sum(d.fault_class is not None for d in said)
    print(f"## {args.log}, run {args.run}{args.suffix}, observability={args.observability}\n")
    print(f"{sum(calls.values())} of {decided} decided ticks called faulty\n")
    print("| class @ joint | ticks |\n|---|---|")
    for what, n in calls.most_common():
        print(f"| {what} | {n} |")
    print("\n| joints that moved in the window | faulty ticks |\n|---|---|")
    for joints, n in sorted(moving.items()):
        print(f"| {joints} | {n} |")
    print("\n| a joint cruised in the window | decided ticks | called faulty |\n|---|---|---|")
    for cruised in (True, False):
        n, faulty = cruise[cruised]
        print(f"| {'yes' if cruised else 'no'} | {n} | {faulty / max(n, 1):.3f} |")
    share = corpus_cruise_share(args.corpus, runtime.window)
    print(f"\nTraining windows of {args.corpus.name} in which a joint cruised: {share:.3f}")


if __name__ == "__main__":
    main()
