"""``python -m robohealth_mj.bench``: throughput benchmarks (not tests).

    python -m robohealth_mj.bench sim [--duration 60]

``sim`` measures, in one run, the raw ``mj_step`` rate of the scene and the recorder's throughput
(physics + control + sensor synthesis + JSONL writing), and reports their ratio.
"""

from __future__ import annotations

import argparse
import tempfile
import time

import mujoco
import numpy as np

from robohealth_mj.config import compose_config
from robohealth_mj.recorder import build_simulator, record_session


def raw_step_rate(model: mujoco.MjModel, data: mujoco.MjData, seconds: float = 3.0) -> float:
    """Physics steps per wall second with steps batched in C (``mj_step`` with ``nstep``)."""
    batch = 1000
    mujoco.mj_step(model, data, nstep=batch)  # warm-up
    steps, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        mujoco.mj_step(model, data, nstep=batch)
        steps += batch
    return steps / (time.perf_counter() - start)


def bench_sim(duration_s: float, overrides: list[str]) -> dict[str, float]:
    cfg = compose_config(
        "record", [f"session.duration_s={duration_s}", "session.progress=false", *overrides]
    )
    sim = build_simulator(cfg)
    data = mujoco.MjData(sim.model)
    data.qpos[:] = sim.data.qpos
    data.ctrl[:] = sim.data.qpos[sim.index.motor_qpos]
    steps_per_s = raw_step_rate(sim.model, data)
    with tempfile.TemporaryDirectory() as tmp:
        result = record_session(cfg, tmp)
    sim_s = result.manifest["sample_count"] / result.manifest["rates"]["tick_hz"]
    recorder_rate = sim_s / result.wall_s
    raw_sim_s = steps_per_s * sim.dt
    return {
        "raw_steps_per_s": steps_per_s,
        "raw_sim_s_per_s": raw_sim_s,
        "recorder_sim_s_per_s": recorder_rate,
        "ratio": recorder_rate / raw_sim_s,
    }


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(
        prog="python -m robohealth_mj.bench",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = parser.add_subparsers(dest="what", required=True)
    sim = sub.add_parser("sim", help="raw mj_step rate vs recorder throughput")
    sim.add_argument("--duration", type=float, default=60.0, help="simulated seconds to record")
    sim.add_argument("overrides", nargs="*", help="Hydra overrides for conf/record.yaml")
    args = parser.parse_args(argv)
    if args.what == "sim":
        r = bench_sim(args.duration, args.overrides)
        print(
            f"raw mj_step rate      {r['raw_steps_per_s']:>10.0f} steps/s "
            f"({r['raw_sim_s_per_s']:.1f} sim s per wall s)"
        )
        print(
            f"recorder throughput   {r['recorder_sim_s_per_s']:>10.1f} sim s per wall s "
            f"({r['recorder_sim_s_per_s']:.0f}x real time)"
        )
        print(f"recorder / raw        {r['ratio']:>10.1%}   (target >= 50%)")
        np.testing.assert_(r["ratio"] > 0)


if __name__ == "__main__":
    main()
