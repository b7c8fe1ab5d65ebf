"""Joint trajectory tracking the way a UR controller does it.

PD on the motor angle (the drive's position actuator) plus a feed-forward torque from inverse
dynamics of the controller's own nominal model, friction compensation, and compensation of the
drive's static twist so the *link* follows the reference. The controller's model is a private copy
that faults never touch: when a drive degrades, the controller's assumptions go stale, as on a
real robot.
"""

from __future__ import annotations

import copy

import mujoco
import numpy as np

from robohealth_mj.sim.model import ArmIndex


class TrackingController:
    """Turns reference link trajectories into position-actuator commands."""

    def __init__(
        self,
        model: mujoco.MjModel,
        knot_dt: float = 0.01,
        coulomb_velocity_scale: float = 0.05,
        backlash_torque_scale: float = 0.5,
    ) -> None:
        self.model = copy.copy(model)
        self.model.opt.disableflags |= (
            mujoco.mjtDisableBit.mjDSBL_FRICTIONLOSS
            | mujoco.mjtDisableBit.mjDSBL_CONTACT
            | mujoco.mjtDisableBit.mjDSBL_LIMIT
        )
        self.data = mujoco.MjData(self.model)
        self.index = ArmIndex.of(self.model)
        act = self.index.actuator
        self.kp = self.model.actuator_gainprm[act, 0].copy()
        self.kv = -self.model.actuator_biasprm[act, 2].copy()
        self.coulomb = model.dof_frictionloss[self.index.motor_dof].copy()
        self.stiffness = model.tendon_stiffness[self.index.tendon].copy()
        self.backlash = model.tendon_lengthspring[self.index.tendon, 1].copy()
        self.knot_dt = float(knot_dt)
        self.coulomb_velocity_scale = float(coulomb_velocity_scale)
        self.backlash_torque_scale = float(backlash_torque_scale)

    def set_payload(self, payload_kg: float) -> None:
        """The payload the user declared to the controller (as on a UR teach pendant)."""
        self.model.body_mass[self.index.payload_body] = payload_kg

    def inverse_dynamics(
        self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Motor torque and drive (spring) torque ``[n, J]`` along a rigid reference motion."""
        idx, d = self.index, self.data
        motor = np.empty_like(q)
        spring = np.empty_like(q)
        for k in range(q.shape[0]):
            d.qpos[idx.motor_qpos] = q[k]
            d.qpos[idx.deflection_qpos] = 0.0
            d.qvel[idx.motor_dof] = qd[k]
            d.qvel[idx.deflection_dof] = 0.0
            d.qacc[idx.motor_dof] = qdd[k]
            d.qacc[idx.deflection_dof] = 0.0
            mujoco.mj_inverse(self.model, d)
            motor[k] = d.qfrc_inverse[idx.motor_dof]
            spring[k] = d.qfrc_inverse[idx.deflection_dof]
        return motor, spring

    def commands(
        self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Actuator commands, feed-forward (motor) torques and the drives' output (link-side)
        torques for reference samples ``[n, J]``."""
        motor, spring = self.inverse_dynamics(q, qd, qdd)
        tau_ff = motor + self.coulomb * np.tanh(qd / self.coulomb_velocity_scale)
        ctrl = (q - self.twist(spring)) + (self.kv * qd + tau_ff) / self.kp
        return ctrl, tau_ff, spring

    def twist(self, spring: np.ndarray) -> np.ndarray:
        """Drive deflection (link minus motor angle) that produces the required drive torque.

        The drive's passive force on the deflection hinge is ``-k (delta -/+ b)`` outside the
        dead band, so carrying a required generalised force ``tau`` takes
        ``delta = -(tau/k + b sgn tau)``.
        """
        return -(
            spring / self.stiffness + self.backlash * np.tanh(spring / self.backlash_torque_scale)
        )

    def static_twist(self, q: np.ndarray) -> np.ndarray:
        """Drive deflection ``[J]`` that carries gravity at rest pose ``q`` (for a quiet start)."""
        zeros = np.zeros((1, q.size))
        _, spring = self.inverse_dynamics(q[None], zeros, zeros)
        return self.twist(spring)[0]
