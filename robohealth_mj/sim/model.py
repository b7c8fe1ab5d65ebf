"""Building the MuJoCo model of the UR5e scene and naming its parts.

The MJCF in ``assets/ur5e`` holds the nominal physics. Config edits (time step, drive parameters)
are applied with dm-control's ``mjcf`` object model rather than by editing XML text, then the model
is compiled with ``mujoco`` itself.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

with warnings.catch_warnings():
    # dm-control probes for an OpenGL backend on import; model editing needs none.
    warnings.simplefilter("ignore")
    from dm_control import mjcf

from robohealth_mj.common.resources import asset_dir
from robohealth_mj.schema import JOINT_NAMES

ASSET_DIR = asset_dir()
SCENE_XML = ASSET_DIR / "ur5e" / "scene.xml"
HOME_POSE = np.array([-np.pi / 2, -np.pi / 2, np.pi / 2, -np.pi / 2, -np.pi / 2, 0.0])


def build_model(
    timestep: float = 0.001, drive_overrides: dict | None = None, scene: Path | str = SCENE_XML
) -> mujoco.MjModel:
    """Compile the scene, applying a physics time step and optional per-joint drive overrides.

    ``drive_overrides`` maps a joint name to any of ``armature``, ``damping``, ``frictionloss``
    (motor side) and ``stiffness``, ``tendon_damping``, ``backlash`` (the drive tendon).
    """
    scene = Path(scene)
    if not scene.is_file():
        raise FileNotFoundError(f"scene file not found: {scene} (set ROBOHEALTH_ASSETS?)")
    root = mjcf.from_path(str(scene))
    root.option.timestep = float(timestep)
    for joint, params in (drive_overrides or {}).items():
        _apply_drive_override(root, joint, dict(params))
    return mujoco.MjModel.from_xml_string(root.to_xml_string(), assets=root.get_assets())


def _apply_drive_override(root: mjcf.RootElement, joint: str, params: dict) -> None:
    if joint not in JOINT_NAMES:
        raise KeyError(f"drive override for unknown joint {joint!r}; known: {list(JOINT_NAMES)}")
    motor = root.find("joint", f"{joint}_joint")
    tendon = root.find("tendon", f"{joint}_drive")
    for key in ("armature", "damping", "frictionloss"):
        if key in params:
            setattr(motor, key, float(params.pop(key)))
    if "stiffness" in params:
        tendon.stiffness = float(params.pop("stiffness"))
    if "tendon_damping" in params:
        tendon.damping = float(params.pop("tendon_damping"))
    if "backlash" in params:
        half = float(params.pop("backlash"))
        tendon.springlength = [-half, half]
    if params:
        raise KeyError(f"unknown drive parameters for {joint}: {sorted(params)}")


@dataclass(frozen=True)
class ArmIndex:
    """Addresses of the arm's named parts in a compiled model, in schema joint order."""

    motor_qpos: np.ndarray
    deflection_qpos: np.ndarray
    motor_dof: np.ndarray
    deflection_dof: np.ndarray
    actuator: np.ndarray
    tendon: np.ndarray
    acc_sensor: np.ndarray  # [6, 3] sensordata addresses
    effort_sensor: np.ndarray  # [6]
    payload_body: int
    torque_limit: np.ndarray

    @classmethod
    def of(cls, model: mujoco.MjModel) -> ArmIndex:
        def joint(name: str) -> mujoco._structs._MjModelJointViews:
            return model.joint(name)

        motor = [joint(f"{j}_joint") for j in JOINT_NAMES]
        defl = [joint(f"{j}_deflection") for j in JOINT_NAMES]
        acc = [model.sensor(f"{j}_acc") for j in JOINT_NAMES]
        eff = [model.sensor(f"{j}_effort") for j in JOINT_NAMES]
        actuators = np.array([model.actuator(j).id for j in JOINT_NAMES])
        return cls(
            motor_qpos=np.array([int(m.qposadr[0]) for m in motor]),
            deflection_qpos=np.array([int(d.qposadr[0]) for d in defl]),
            motor_dof=np.array([int(m.dofadr[0]) for m in motor]),
            deflection_dof=np.array([int(d.dofadr[0]) for d in defl]),
            actuator=actuators,
            tendon=np.array([model.tendon(f"{j}_drive").id for j in JOINT_NAMES]),
            acc_sensor=np.array([[int(s.adr[0]) + k for k in range(3)] for s in acc]),
            effort_sensor=np.array([int(s.adr[0]) for s in eff]),
            payload_body=model.body("payload").id,
            torque_limit=model.actuator_forcerange[actuators, 1].copy(),
        )

    def set_link_pose(self, data: mujoco.MjData, q: np.ndarray) -> None:
        """Put the links at UR angles ``q`` with the drives untwisted."""
        data.qpos[self.motor_qpos] = q
        data.qpos[self.deflection_qpos] = 0.0
