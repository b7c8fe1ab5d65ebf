"""What the commissioned monitor says, tick by tick, on the real logs with a known event: the
arm pushed while it holds a pose. The push has no label in the log, so it is found from the log's
own residual (measured minus the controller's model torque): the ticks where a joint's residual
leaves its level at the log's start by more than ``--threshold`` N*m.

    python experiments/real_arms/events.py [--curriculum replay] > results/real_arms/events.md

Per commissioned network (``outputs/real_arms/<curriculum>/models/**/commissioned/model.onnx``)
and push log: how long the push lasts, the share of ticks called faulty during it and outside it,
alarms, the joint the monitor names most during it, and the joint whose residual moves most.
"""

from __future__ import annotations

import argparse
from collections import Counter
from pathlib import Path

import numpy as np

from robohealth_mj import schema
from robohealth_mj.runtime.runtime import ModelRuntime
from robohealth_mj.runtime.sources import replay_stream

LOGS = Path("outputs/real_arms/logs/collision")
RESIDUAL = schema.feature_index("effort_residual")


def ticks(model: Path, log: Path) -> list[tuple[np.ndarray, object]]:
    """Each tick's joint residuals ``[6]`` (N*m) and the monitor's diagnosis."""
    runtime = ModelRuntime(str(model))
    out = []
    for _, sample, _ in replay_stream(str(log)):
        d = runtime.process("arm", sample)
        out.append((np.asarray(sample.x[: schema.N_JOINTS, RESIDUAL], float), d))
    return out


def summarise(rows: list[tuple[np.ndarray, object]], threshold: float) -> dict:
    residual = np.stack([r for r, _ in rows])
    baseline = np.median(residual[:40], axis=0)  # the first 2 s, before any push
    moved = np.abs(residual - baseline)
    push = moved.max(axis=1) > threshold
    decided = np.array([d.valid and d.fault_class is not None for _, d in rows])
    faulty = np.array([bool(d.fault_present) for _, d in rows])
    named = Counter(d.localised_joint for (_, d), p in zip(rows, push, strict=True)
                    if p and d.fault_present)  # fmt: skip

    def share(mask: np.ndarray) -> float:
        n = int((mask & decided).sum())
        return float((faulty & mask & decided).sum()) / n if n else float("nan")

    return {
        "push_s": push.sum() / 20.0,
        "faulty_in": share(push),
        "faulty_out": share(~push),
        "alarms": sum(d.alarm == "raised" for _, d in rows),
        "alarms_in": sum(d.alarm == "raised" for (_, d), p in zip(rows, push, strict=True) if p),
        "named": named.most_common(1)[0][0] if named else "-",
        "loaded": schema.JOINT_NAMES[int(np.argmax(moved[push].mean(axis=0)))] if push.any()
        else "-",
    }  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--curriculum", default="replay")
    parser.add_argument("--threshold", type=float, default=3.0, help="N*m off the start level")
    args = parser.parse_args()
    models = sorted(Path(f"outputs/real_arms/{args.curriculum}/models").rglob(
        "commissioned/model.onnx"))  # fmt: skip
    print(f"## Pushed while holding a pose ({args.curriculum} curriculum)\n")
    print(f"Push: a joint's residual {args.threshold:g} N·m or more off its level in the first "
          "2 s.\n")  # fmt: skip
    print("| model | log | push s | faulty during push | faulty outside | alarms (during push) "
          "| joint named most | joint loaded most |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    for model in models:
        variant = next(p for p in model.parts if p.startswith(("stgnn", "gat", "anomaly", "mlp")))
        for log in sorted(LOGS.glob("*.csv")):
            s = summarise(ticks(model, log), args.threshold)
            print(f"| {variant} | {log.stem} | {s['push_s']:.1f} | {s['faulty_in']:.2f} | "
                  f"{s['faulty_out']:.2f} | {s['alarms']} ({s['alarms_in']}) | {s['named']} | "
                  f"{s['loaded']} |")  # fmt: skip


if __name__ == "__main__":
    main()
