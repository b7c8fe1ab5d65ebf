"""The instrumented arm running the curriculum: controller + sensor package + faults composed on
the physics. It sits above ``sim/`` and ``faults/`` (faults use sim's model index; sim knows
nothing of faults), so layers point one way. Physics in C, bookkeeping in NumPy.

Each chunk of ticks is one ``mujoco.rollout`` call: the controller's commands for every physics
step are computed up front (inverse dynamics at knots, interpolated), so no Python runs between
physics steps. Chunks never straddle a curriculum segment, because the payload changes there.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import mujoco
import numpy as np
from mujoco import rollout

from robohealth_mj.common.seeds import stream
from robohealth_mj.faults.injector import FaultInjector, healthy_injector
from robohealth_mj.faults.readings import TickReadings
from robohealth_mj.schema import ArmGraph, FaultLabel
from robohealth_mj.sim.control import TrackingController
from robohealth_mj.sim.curriculum import Curriculum
from robohealth_mj.sim.model import ArmIndex
from robohealth_mj.sim.pushes import Push, applied_forces
from robohealth_mj.sim.sensors import SensorPackage


@dataclass
class TickChunk:
    """Readings of consecutive 20 Hz ticks, all within one curriculum visit."""

    t: np.ndarray  # [n] sim time of each tick
    visit: int
    pos: np.ndarray  # [n, 6] measured link angle
    vel: np.ndarray  # [n, 6]
    effort: np.ndarray  # [n, 6] torque the drive applies
    pos_error: np.ndarray  # [n, 6] measured link angle minus the controller's target
    effort_residual: np.ndarray  # [n, 6] drive torque minus the controller's model torque
    vib: np.ndarray  # [n, 6]
    acc: np.ndarray  # [n, 6, 3]
    bands: np.ndarray  # [n, 6, 3] piezo sub-band RMS
    kurtosis: np.ndarray  # [n, 6] piezo kurtosis over the tick
    true_pos: np.ndarray  # [n, 6] noise-free link angle
    reference: np.ndarray  # [n, 6]
    saturated_steps: np.ndarray  # [J] physics steps at the torque limit, per joint
    contacts: int  # contacts present at the end of the chunk
    fault: FaultLabel  # the ground truth, constant over the chunk


class ArmSimulator:
    """Runs the session: curriculum reference -> controller -> physics -> sensor package."""

    def __init__(
        self,
        model: mujoco.MjModel,
        curriculum: Curriculum,
        controller: TrackingController,
        sensors: SensorPackage,
        seed: int,
        tick_hz: float = 20.0,
        chunk_s: float = 1.0,
        faults: FaultInjector | None = None,
        pushes: list[Push] | None = None,
        torque_sensors: bool = False,
    ) -> None:
        """``torque_sensors``: the arm's joints carry torque sensors (an FR3's, an iiwa's, a
        Gen3's), so its controller reports the torque on the link side of each drive and its
        model of that torque, not the motor's (see :meth:`link_torque`)."""
        self.model, self.curriculum = model, curriculum
        self.torque_sensors = bool(torque_sensors)
        self.controller, self.sensors = controller, sensors
        self.index = ArmIndex.of(model)
        self.graph = ArmGraph(self.index.joints)  # the samples' graph: the arm's own
        self.dt = float(model.opt.timestep)
        self.tick_steps = _whole(1.0 / (tick_hz * self.dt), "physics steps per tick")
        self.tick_s = self.tick_steps * self.dt
        self.ticks_per_segment = _whole(curriculum.segment_s / self.tick_s, "ticks per segment")
        self.chunk_ticks = max(1, round(chunk_s / self.tick_s))
        self.payload_ramp_ticks = round(curriculum.payload_ramp_s / self.tick_s)
        self.rng = stream("recording.sensors", seed)
        self.data = mujoco.MjData(model)
        self.tick = 0  # ticks completed
        self.nstate = mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_FULLPHYSICS)
        self.faults = faults or healthy_injector(model, self.tick_s)
        self.pushes = list(pushes or [])  # external forces on the links (sim/pushes.py)
        self._interval = None
        self._start_at_rest()

    def _start_at_rest(self) -> None:
        """Start at the first reference pose with the drives already carrying gravity."""
        q0 = self.curriculum.scheduled(0).start_pose
        self._apply_payload(0)
        twist = self.controller.static_twist(q0)
        d, idx = self.data, self.index
        d.qpos[idx.motor_qpos] = q0 - twist
        d.qpos[idx.deflection_qpos] = twist
        mujoco.mj_forward(self.model, d)

    def _apply_payload(self, visit: int, fraction: float = 1.0) -> None:
        """Set the payload part-way (``fraction``) from the previous visit's to this visit's."""
        new = self.curriculum.payload_kg(visit)
        old = self.curriculum.payload_kg(visit - 1) if visit > 0 else new
        u = min(max(fraction, 0.0), 1.0)
        payload = old + (new - old) * u * u * (3.0 - 2.0 * u)
        self.model.body_mass[self.index.payload_body] = payload
        self.controller.set_payload(payload)

    def link_torque(self, qpos: np.ndarray, qvel: np.ndarray) -> np.ndarray:
        """``[n, J]`` what a joint torque sensor reads: the torque the drive's output carries
        to the link, the passive force of its compliance (stiffness outside the backlash band,
        damping) on the deflection hinge, from the states ``qpos [n, nq]``, ``qvel [n, nv]``;
        with the model's present values, so a weakened or loose drive reads as it is."""
        idx, m = self.index, self.model
        twist = qpos[:, idx.deflection_qpos]
        low, high = m.tendon_lengthspring[idx.tendon, 0], m.tendon_lengthspring[idx.tendon, 1]
        stretch = twist - np.clip(twist, low, high)
        rate = qvel[:, idx.deflection_dof]
        return -m.tendon_stiffness[idx.tendon] * stretch - m.tendon_damping[idx.tendon] * rate

    @property
    def time(self) -> float:
        return self.tick * self.tick_s

    def run(self, n_ticks: int) -> Iterator[TickChunk]:
        """Advance ``n_ticks`` ticks, yielding chunks as they are simulated."""
        end = self.tick + n_ticks
        while self.tick < end:
            visit, tick_in_visit = divmod(self.tick, self.ticks_per_segment)
            self._interval, steady = self.faults.prepare(self.model, self.tick)
            n = min(
                self.chunk_ticks,
                end - self.tick,
                self.ticks_per_segment - tick_in_visit,
                steady,
            )
            if tick_in_visit < self.payload_ramp_ticks:
                # The payload is taken on gradually while the arm is at rest between segments;
                # a step in load would ring the drives at every segment boundary.
                n = 1
                self._apply_payload(visit, (tick_in_visit + 1) / self.payload_ramp_ticks)
            elif tick_in_visit == 0:
                self._apply_payload(visit)
            yield self._simulate(visit, n)

    def _simulate(self, visit: int, n_ticks: int) -> TickChunk:
        steps = n_ticks * self.tick_steps
        first = self.tick * self.tick_steps
        step_times = (first + np.arange(steps)) * self.dt
        ctrl, ref_velocity, model_torque, model_link = self._controls(visit, step_times)
        forces = self.faults.torques(self._interval, step_times, ref_velocity, self.model.nv)
        controls, spec = [ctrl, forces], _CONTROL_SPEC
        if self.pushes:  # only then: the rollout's inputs grow by six per body
            controls.append(applied_forces(self.model, self.data, self.pushes, step_times))
            spec |= int(mujoco.mjtState.mjSTATE_XFRC_APPLIED)
        state0 = np.empty(self.nstate)
        mujoco.mj_getState(self.model, self.data, state0, mujoco.mjtState.mjSTATE_FULLPHYSICS)
        state, sensordata = rollout.rollout(
            self.model,
            self.data,
            state0[None],
            np.hstack(controls)[None],
            control_spec=spec,
            initial_warmstart=self.data.qacc_warmstart[None],
        )
        state, sensordata = state[0], sensordata[0]
        self.tick += n_ticks
        at_tick = slice(self.tick_steps - 1, None, self.tick_steps)
        expected = model_link if self.torque_sensors else model_torque
        return self._readings(visit, state, sensordata, expected[at_tick])

    def _controls(
        self, visit: int, step_times: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Commands, reference velocities and the controller's model torques, motor side and
        link side, for every physics step (inverse dynamics at knots on a global grid,
        interpolated)."""
        knot_dt = self.controller.knot_dt
        k0 = int(np.floor(step_times[0] / knot_dt + 1e-9))
        k1 = int(np.ceil(step_times[-1] / knot_dt - 1e-9))
        knots = np.arange(k0, max(k1, k0 + 1) + 1) * knot_dt
        q, qd, qdd = self.curriculum.reference(visit, knots)
        ctrl_knots, torque_knots, link_knots = self.controller.commands(q, qd, qdd)

        def per_step(values: np.ndarray) -> np.ndarray:
            return np.stack(
                [np.interp(step_times, knots, values[:, j]) for j in range(values.shape[1])], axis=1
            )

        return per_step(ctrl_knots), per_step(qd), per_step(torque_knots), per_step(link_knots)

    def _readings(
        self, visit: int, state: np.ndarray, sensordata: np.ndarray, model_torque: np.ndarray
    ) -> TickChunk:
        idx = self.index
        at_tick = slice(self.tick_steps - 1, None, self.tick_steps)
        qpos = state[at_tick, 1 : 1 + self.model.nq]
        qvel = state[at_tick, 1 + self.model.nq : 1 + self.model.nq + self.model.nv]
        t = state[at_tick, 0]
        true_pos = qpos[:, idx.motor_qpos] + qpos[:, idx.deflection_qpos]
        vel = qvel[:, idx.motor_dof] + qvel[:, idx.deflection_dof]
        effort_all = sensordata[:, idx.effort_sensor]  # the motor's torque (from its current)
        reported = self.link_torque(qpos, qvel) if self.torque_sensors else effort_all[at_tick]
        acc_mean, piezo = self.sensors.process(
            sensordata[:, idx.acc_sensor], self.tick_steps, self.rng
        )
        pos, vel, effort, acc = self.sensors.add_noise(self.rng, true_pos, vel, reported, acc_mean)
        readings = TickReadings(pos, vel, effort, piezo.vib, acc, piezo.bands, piezo.kurtosis)
        self.faults.alter_readings(self._interval, readings)
        scenario = self._interval.scenario
        reference = self.curriculum.position(visit, t)
        return TickChunk(
            t=t,
            visit=visit,
            pos=readings.pos,
            vel=readings.vel,
            effort=readings.effort,
            pos_error=readings.pos - reference,
            effort_residual=readings.effort - model_torque,
            vib=readings.vib,
            acc=readings.acc,
            bands=readings.bands,
            kurtosis=readings.kurtosis,
            true_pos=true_pos,
            reference=reference,
            saturated_steps=(np.abs(effort_all) >= 0.999 * idx.torque_limit).sum(axis=0),
            contacts=int(self.data.ncon),
            fault=scenario.label if scenario is not None else FaultLabel(),
        )


_CONTROL_SPEC = int(mujoco.mjtState.mjSTATE_CTRL | mujoco.mjtState.mjSTATE_QFRC_APPLIED)


def _whole(value: float, what: str) -> int:
    n = round(value)
    if n < 1 or abs(value - n) > 1e-6:
        raise ValueError(f"{what} must be a whole number, got {value:.6g}; adjust the rates")
    return n
