"""Measured fault effect sizes: how far a fault moves each sensor's readings, by hop distance.

The same session (seed, trajectory, noise draws) is simulated healthy and with one fault held on;
the effect on a channel is the RMS of the faulted-minus-healthy difference divided by the healthy
channel's standard deviation. Nothing here is authored: propagation is whatever the physics does.

    python -m robohealth_mj.faults.effects [--joint elbow] [--seconds 30] [--models physics hybrid]
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence

import numpy as np

from robohealth_mj.config import compose_config
from robohealth_mj.faults.catalogue import FAULT_MODELS, MODES
from robohealth_mj.recorder import build_simulator
from robohealth_mj.schema import JOINT_NAMES

CHANNELS = {"vib": (slice(None), [0]), "acc": (slice(None), [1, 2, 3])}


def _readings(overrides: Sequence[str], seconds: float) -> dict[str, np.ndarray]:
    cfg = compose_config("record", ["session.progress=false", *overrides])
    sim = build_simulator(cfg)
    chunks = list(sim.run(round(seconds / sim.tick_s)))
    vib = np.concatenate([c.vib for c in chunks])  # [T, 6]
    acc = np.concatenate([c.acc for c in chunks])  # [T, 6, 3]
    effort = np.concatenate([c.effort for c in chunks])
    return {"sensor": np.concatenate([vib[:, :, None], acc], axis=2), "effort": effort}


def effect_by_sensor(healthy: np.ndarray, faulted: np.ndarray) -> np.ndarray:
    """Standardised effect per sensor ``[6]``, mean over its channels (vib, acc x/y/z).

    Each sensor channel is scaled by its own healthy spread: the change a detector watching that
    sensor would see against its healthy baseline.
    """
    scale = healthy.std(axis=0) + 1e-9  # [6, 4]
    rms = np.sqrt(((faulted - healthy) ** 2).mean(axis=0))
    return (rms / scale).mean(axis=-1)


def by_hops(effect: np.ndarray, joint: int) -> dict[int, float]:
    hops = np.abs(np.arange(len(JOINT_NAMES)) - joint)
    return {int(h): float(effect[hops == h].mean()) for h in sorted(set(hops.tolist()))}


def measure(
    fault_class: str,
    joint: str,
    severity: float,
    fault_model: str,
    seconds: float,
    seed: int = 0,
    extra: Sequence[str] = (),
) -> dict:
    common = [f"seed={seed}", *extra]
    healthy = _readings([*common, "faults=none"], seconds)
    faulted = _readings(
        [
            *common,
            "faults=fixed",
            f"faults.fault_model={fault_model}",
            f"faults.schedule.fault_class={fault_class}",
            f"faults.schedule.joint={joint}",
            f"faults.schedule.severity={severity}",
        ],
        seconds,
    )
    effect = effect_by_sensor(healthy["sensor"], faulted["sensor"])
    j = JOINT_NAMES.index(joint)
    effort_shift = float(
        np.abs(faulted["effort"][:, j]).mean() - np.abs(healthy["effort"][:, j]).mean()
    )
    return {
        "fault": fault_class,
        "joint": joint,
        "severity": severity,
        "fault_model": fault_model,
        "effect_by_sensor": effect.round(4).tolist(),
        "effect_by_hops": by_hops(effect, j),
        "target_effort_shift_nm": round(effort_shift, 4),
    }


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(
        prog="python -m robohealth_mj.faults.effects",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--joint", default="elbow", choices=JOINT_NAMES)
    parser.add_argument("--severity", type=float, default=0.9)
    parser.add_argument("--seconds", type=float, default=30.0)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--models", nargs="+", default=list(FAULT_MODELS), choices=FAULT_MODELS)
    parser.add_argument("--classes", nargs="+", default=list(MODES), choices=MODES)
    parser.add_argument("--json", help="also write the rows to this JSON file")
    args = parser.parse_args(argv)
    rows = []
    print(
        f"effect size = RMS(faulted - healthy) / the sensor's healthy std, mean over "
        f"vib + acc x/y/z; "
        f"fault at {args.joint}, severity {args.severity}, {args.seconds:.0f} s"
    )
    print(f"{'fault':<14}{'model':<10}{'target':>8}{'1 hop':>8}{'2 hops':>8}{'effort+':>9}")
    for fault_class in args.classes:
        for model in args.models:
            row = measure(fault_class, args.joint, args.severity, model, args.seconds, args.seed)
            rows.append(row)
            h = row["effect_by_hops"]
            print(
                f"{fault_class:<14}{model:<10}{h[0]:>8.3f}{h.get(1, float('nan')):>8.3f}"
                f"{h.get(2, float('nan')):>8.3f}{row['target_effort_shift_nm']:>9.2f}",
                flush=True,
            )
    if args.json:
        from robohealth_mj.atomic import atomic_write_json

        atomic_write_json(args.json, rows)


if __name__ == "__main__":
    main()
