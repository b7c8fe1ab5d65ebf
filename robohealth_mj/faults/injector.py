"""One object the simulator asks about faults: which interval is active, what to change in the
physics, which torques to apply, and how to alter the readings, per the ``fault_model`` switch:

- ``physics``: mechanical faults change the dynamics only;
- ``analytic``: the physics stays healthy and the thesis's Table 2 signatures are painted on;
- ``hybrid``: both (the thesis's setting; ``physics`` is the default).

Sensor faults act on the readings in every model.
"""

from __future__ import annotations

import mujoco
import numpy as np

from robohealth_mj.common.errors import InputError
from robohealth_mj.common.seeds import stream
from robohealth_mj.faults.catalogue import FAULT_MODELS, MECHANICAL, FaultParameters
from robohealth_mj.faults.mechanical import DriveFaults
from robohealth_mj.faults.readings import ReadingFaults, TickReadings
from robohealth_mj.faults.scheduler import FaultScheduler, FixedFault, Interval, NoFaults
from robohealth_mj.sim.model import ArmIndex

Schedule = FaultScheduler | FixedFault | NoFaults


class FaultInjector:
    def __init__(
        self,
        schedule: Schedule,
        parameters: FaultParameters,
        fault_model: str,
        model: mujoco.MjModel,
        tick_s: float,
        seed: int,
        ramp_s: float = 0.5,
    ) -> None:
        if fault_model not in FAULT_MODELS:
            raise InputError(f"fault_model must be one of {FAULT_MODELS}, got {fault_model!r}")
        self.schedule, self.parameters, self.fault_model = schedule, parameters, fault_model
        self.physics_on = fault_model != "analytic"
        self.ramp_ticks = round(ramp_s / tick_s)
        self.drives = DriveFaults(model, parameters.physics)
        self.readings = ReadingFaults(
            parameters.physics,
            parameters.analytic,
            tick_s,
            ArmIndex.of(model).torque_limit,
            analytic_layer=fault_model != "physics",
        )
        # Separate streams: the physics of a fault is the same whether or not the analytic layer
        # draws random numbers too.
        self.rng_physics = stream("faults.physics", seed)
        self.rng_readings = stream("faults.readings", seed)

    def _mechanical(self, interval: Interval) -> bool:
        sc = interval.scenario
        return self.physics_on and sc is not None and sc.fault_class in MECHANICAL

    def prepare(self, model: mujoco.MjModel, tick: int) -> tuple[Interval, int]:
        """Set the simulated drives for ``tick``; return its interval and for how many ticks the
        drives stay as set.

        A mechanical fault develops over its first ``ramp_ticks`` and clears over its last, so
        the drives are exactly nominal when the fault interval ends and no parameter step rings
        the arm (a real drive degrades, it does not switch).
        """
        interval = self.schedule.interval_at(tick)
        if not self._mechanical(interval):
            self.drives.apply(model, None)
            return interval, interval.end_tick - tick
        into, left = tick - interval.start_tick, interval.end_tick - tick - 1
        ramp = self.ramp_ticks
        if ramp and (into < ramp or left < ramp):
            level = _smoothstep(min((into + 1) / ramp, left / ramp, 1.0))
            self.drives.apply(model, interval.scenario, level)
            return interval, 1
        self.drives.apply(model, interval.scenario)
        return interval, interval.end_tick - ramp - tick

    def torques(
        self, interval: Interval, step_times: np.ndarray, ref_velocity: np.ndarray, nv: int
    ) -> np.ndarray:
        scenario = interval.scenario if self._mechanical(interval) else None
        return self.drives.torques(scenario, step_times, ref_velocity, self.rng_physics, nv)

    def alter_readings(self, interval: Interval, readings: TickReadings) -> None:
        self.readings.apply(interval.scenario, interval.start_tick, readings, self.rng_readings)

    def describe(self) -> dict:
        return {
            "fault_model": self.fault_model,
            "schedule": self.schedule.describe(),
            "parameters": self.parameters.as_dict(),
        }


def _smoothstep(u: float) -> float:
    u = min(max(u, 0.0), 1.0)
    return u * u * (3.0 - 2.0 * u)


def healthy_injector(model: mujoco.MjModel, tick_s: float) -> FaultInjector:
    """An injector that never injects (for healthy sessions built without a fault config)."""
    return FaultInjector(NoFaults(), FaultParameters({}, {}), "physics", model, tick_s, 0)
