"""Mechanical faults acting on the physics: drive parameters and applied torques.

The nominal drive parameters are snapshotted once; entering any interval first restores them
exactly, so a fault is undone bit for bit when it ends.
"""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np

from robohealth_mj.faults.catalogue import Scenario
from robohealth_mj.sim.model import ArmIndex


class DriveFaults:
    """Edits the simulated model's drives for BACKLASH, FRICTION, STRUCT_WEAKEN; torques for JAM."""

    _FIELDS = (
        "dof_frictionloss",
        "dof_damping",
        "tendon_stiffness",
        "tendon_damping",
        "tendon_lengthspring",
    )

    def __init__(self, model: mujoco.MjModel, params: dict[str, dict[str, Any]]) -> None:
        self.index = ArmIndex.of(model)
        self.params = params
        self.nominal = {name: getattr(model, name).copy() for name in self._FIELDS}

    def restore(self, model: mujoco.MjModel) -> None:
        for name, value in self.nominal.items():
            getattr(model, name)[:] = value

    def apply(self, model: mujoco.MjModel, scenario: Scenario | None, level: float = 1.0) -> None:
        """Restore the nominal drives, then degrade the target drive for ``scenario``.

        ``level`` in [0, 1] scales the severity while a fault develops or clears.
        """
        self.restore(model)
        if scenario is None or level <= 0.0:
            return
        s, j = scenario.severity * min(level, 1.0), scenario.joint
        dof, tendon = self.index.motor_dof[j], self.index.tendon[j]
        p = self.params.get(scenario.fault_class, {})
        if scenario.fault_class == "backlash":
            half = self.nominal["tendon_lengthspring"][tendon, 1] + p["gap_rad"] * s
            model.tendon_lengthspring[tendon] = [-half, half]
        elif scenario.fault_class == "friction":
            model.dof_frictionloss[dof] *= 1.0 + p["coulomb_gain"] * s
            model.dof_damping[dof] *= 1.0 + p["viscous_gain"] * s
        elif scenario.fault_class == "struct_weaken":
            model.tendon_stiffness[tendon] *= 1.0 - p["stiffness_drop"] * s
            model.tendon_damping[tendon] *= 1.0 - p["damping_drop"] * s

    def torques(
        self,
        scenario: Scenario | None,
        step_times: np.ndarray,
        ref_velocity: np.ndarray,
        rng: np.random.Generator,
        nv: int,
    ) -> np.ndarray:
        """Generalised forces ``[steps, nv]`` applied per physics step (jam events; else zero)."""
        out = np.zeros((step_times.size, nv))
        if scenario is None or scenario.fault_class != "jam":
            return out
        p, s, j = self.params["jam"], scenario.severity, scenario.joint
        dt = step_times[1] - step_times[0] if step_times.size > 1 else 1e-3
        starts = np.flatnonzero(rng.random(step_times.size) < p["rate_hz"] * s * dt)
        width = max(1, round(p["duration_s"] / dt))
        amplitude = p["torque_frac"] * s * self.index.torque_limit[j]
        column = out[:, self.index.motor_dof[j]]
        for k in starts:
            direction = np.sign(ref_velocity[k, j]) or 1.0
            column[k : k + width] = -amplitude * direction  # the gear catches against the motion
        return out
