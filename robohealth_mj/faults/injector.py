"""One object the simulator asks about faults: which interval is active, what to change in the
physics, which torques to apply, and how to alter the readings, per the ``fault_model`` switch:

- ``physics``: mechanical faults change the dynamics only;
- ``analytic``: the physics stays healthy and the thesis's Table 2 signatures are painted on;
- ``hybrid`` (default): both. Sensor faults act on the readings in every model.
"""

from __future__ import annotations

import mujoco
import numpy as np

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
    ) -> None:
        if fault_model not in FAULT_MODELS:
            raise ValueError(f"fault_model must be one of {FAULT_MODELS}, got {fault_model!r}")
        self.schedule, self.parameters, self.fault_model = schedule, parameters, fault_model
        self.physics_on = fault_model != "analytic"
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
        self.rng_physics = np.random.default_rng([int(seed), 5])
        self.rng_readings = np.random.default_rng([int(seed), 6])

    def interval_at(self, tick: int) -> Interval:
        return self.schedule.interval_at(tick)

    def _mechanical(self, interval: Interval) -> bool:
        sc = interval.scenario
        return self.physics_on and sc is not None and sc.fault_class in MECHANICAL

    def enter(self, model: mujoco.MjModel, interval: Interval) -> None:
        """Set the simulated drives for an interval (restoring the nominal ones first)."""
        self.drives.apply(model, interval.scenario if self._mechanical(interval) else None)

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


def healthy_injector(model: mujoco.MjModel, tick_s: float) -> FaultInjector:
    """An injector that never injects (for healthy sessions built without a fault config)."""
    return FaultInjector(NoFaults(), FaultParameters({}, {}), "hybrid", model, tick_s, 0)
