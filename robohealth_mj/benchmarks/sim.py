"""Simulator benchmark: raw ``mj_step`` rate against the recorder's throughput, in one run."""

from __future__ import annotations

import tempfile
import time

import mujoco

from robohealth_mj.common.config import compose_config
from robohealth_mj.recording.recorder import build_simulator, record_session


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
