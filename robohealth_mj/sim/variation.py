"""Arms that are not the nominal one: per-session draws of the arm's own physical parameters.

Every real UR5e differs from the datasheet (and from the controller's model of it) within some
spread: its drives' friction, damping, stiffness and rotor inertia, its links' masses, and the
sensitivity and noise of each sensor package bolted on. With a
spread set, each session draws its arm from its seed; the physics runs on the drawn arm while the
controller keeps its nominal model, so the tracking error and torque residual carry the mismatch
a real controller's model has. The drawn factors go into the manifest.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import mujoco
import numpy as np

from robohealth_mj.arms.description import DEFAULT_ARM, known_arms
from robohealth_mj.common.errors import InputError
from robohealth_mj.common.resources import is_arm_file
from robohealth_mj.common.seeds import stream
from robohealth_mj.sim.model import ArmIndex


@dataclass(frozen=True)
class ArmVariation:
    """Relative spreads: each factor is drawn uniformly from ``[1 - spread, 1 + spread]``, per
    joint (drive parameters) or per link (mass and inertia alike)."""

    friction: float = 0.0  # the motor's Coulomb friction
    damping: float = 0.0  # the motor's viscous damping
    stiffness: float = 0.0  # the drive's stiffness
    armature: float = 0.0  # the rotor's reflected inertia
    mass: float = 0.0  # each link's mass and inertia
    sensor_gain: float = 0.0  # each sensor package's sensitivity (accelerometer and piezo)
    sensor_noise: float = 0.0  # each sensor package's noise floor
    seed: int | None = None  # the arm's own seed (None: the session's), to run one arm twice
    name: str = DEFAULT_ARM  # which arm (a folder of assets/, or a user's URDF) this copy is of

    def __post_init__(self) -> None:
        if not is_arm_file(self.name) and self.name not in known_arms():
            raise InputError(
                f"arm.name: unknown arm {self.name!r}; known: {', '.join(known_arms())}"
            )
        for name, spread in self.spreads().items():
            if not 0.0 <= spread < 1.0:
                raise InputError(f"arm.{name}: a spread in [0, 1), got {spread}")

    def spreads(self) -> dict[str, float]:
        return {k: v for k, v in vars(self).items() if k not in ("seed", "name")}

    @property
    def nominal(self) -> bool:
        return not any(self.spreads().values())

    def draw(self, model: mujoco.MjModel, seed: int) -> tuple[mujoco.MjModel, dict]:
        """A copy of ``model`` with this session's arm (drawn from ``self.seed``, else the
        session's ``seed``), and the drawn factors (``{}`` when nominal: the model itself)."""
        if self.nominal:
            return model, {}
        rng = stream("sim.variation", seed if self.seed is None else self.seed)
        arm = copy.copy(model)
        idx = ArmIndex.of(arm)
        joints = idx.joints
        # each joint moves its own link: the body its motor joint sits in
        links = tuple(
            arm.body(arm.jnt_bodyid[arm.joint(f"{j}_deflection").id]).name for j in joints
        )

        def factors(spread: float, n: int) -> np.ndarray:
            return rng.uniform(1.0 - spread, 1.0 + spread, n)  # drawn even at 0: stable stream

        drawn: dict[str, dict[str, float]] = {}
        for name, values, where in (
            ("friction", arm.dof_frictionloss, idx.motor_dof),
            ("damping", arm.dof_damping, idx.motor_dof),
            ("stiffness", arm.tendon_stiffness, idx.tendon),
            ("armature", arm.dof_armature, idx.motor_dof),
        ):
            f = factors(getattr(self, name), len(joints))
            values[where] *= f
            drawn[name] = {j: round(float(v), 5) for j, v in zip(joints, f, strict=True)}
        f = factors(self.mass, len(links))
        for link, k in zip(links, f, strict=True):
            body = arm.body(link).id
            arm.body_mass[body] *= k
            arm.body_inertia[body] *= k
        drawn["mass"] = {link: round(float(v), 5) for link, v in zip(links, f, strict=True)}
        for name in ("sensor_gain", "sensor_noise"):  # applied by the sensor package
            f = factors(getattr(self, name), len(joints))
            drawn[name] = {j: round(float(v), 5) for j, v in zip(joints, f, strict=True)}
        return arm, drawn

    @staticmethod
    def apply_to_sensors(sensors, drawn: dict) -> None:
        """Give ``sensors`` (a SensorPackage) this arm's transducers (nothing for the nominal)."""
        if "sensor_gain" in drawn:
            sensors.gain = np.array(list(drawn["sensor_gain"].values()))
            sensors.noise_scale = np.array(list(drawn["sensor_noise"].values()))
