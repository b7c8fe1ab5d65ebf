"""Compiling an arm's MuJoCo model and naming its parts.

The arm is data (``assets/<arm>/``, :mod:`robohealth_mj.arms.description`);
:mod:`robohealth_mj.sim.builder` turns it into MJCF with our drive model through dm-control's
``mjcf``, and ``mujoco`` compiles it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import mujoco
import numpy as np
from omegaconf import OmegaConf

from robohealth_mj.arms.description import DEFAULT_ARM, load_arm
from robohealth_mj.common.errors import InputError
from robohealth_mj.common.resources import asset_dir, conf_dir
from robohealth_mj.sim.builder import DRIVE_KEYS, HOME_POSE, DriveModel, build_arm_scene

ASSET_DIR = asset_dir()
SCENE_XML = ASSET_DIR / "scene.xml"
__all__ = ["HOME_POSE", "ArmIndex", "build_model", "default_drives"]


@cache
def default_drives() -> DriveModel:
    """The drive model of the packaged ``conf/sim/default.yaml`` (one source of its numbers)."""
    cfg = OmegaConf.load(conf_dir() / "sim" / "default.yaml")
    return DriveModel(
        OmegaConf.to_container(cfg.drives), tuple(float(v) for v in cfg.reference_torque_nm)
    )


def build_model(
    arm: str = DEFAULT_ARM,
    timestep: float = 0.001,
    drives: Mapping[str, Mapping[str, float]] | None = None,
    reference_torque_nm: list[float] | None = None,
    drive_overrides: dict | None = None,
    scene: Path | str = SCENE_XML,
    twin: Path | str | None = None,
    mount_height_m: float = 0.0,
    friction_solref: Sequence[float] | None = None,
    friction_solimp: Sequence[float] | None = None,
) -> mujoco.MjModel:
    """Compile arm ``arm`` in the scene at physics time step ``timestep``.

    ``drives``/``reference_torque_nm``: the drive model stated for the UR5e (default: the packaged
    config's); ``drive_overrides`` maps a joint name to any of ``armature``, ``damping``,
    ``frictionloss`` (motor side) and ``stiffness``, ``tendon_damping``, ``backlash`` (the drive
    tendon), set after scaling to the arm. ``twin``: an identified twin file of this arm
    (``python -m robohealth_mj.identify``) whose drive parameters replace the scaled ones (before
    ``drive_overrides``). ``mount_height_m``: the base stands this high above the floor (a
    real arm on a table or pedestal, whose program reaches below its base plane).
    ``friction_solref`` ``[timeconst, dampratio]`` and ``friction_solimp`` ``[dmin, dmax, width,
    midpoint, power]``: the motor joints' dry friction constraint (MuJoCo's ``solreffriction`` and
    ``solimpfriction``; default MuJoCo's own). MuJoCo's dry friction is soft: a joint held below
    its friction limit creeps, so a servo at rest pulls it onto its target within a fraction of a
    second and the drive ends up carrying exactly the model torque. A shorter time constant and an
    impedance nearer 1 make it stick, as a real gear does: the drive then keeps whatever torque
    it stopped with.
    """
    scene = Path(scene)
    if not scene.is_file():
        raise FileNotFoundError(f"scene file not found: {scene} (set ROBOHEALTH_ASSETS?)")
    if not float(timestep) > 0:
        raise InputError(f"sim.timestep: must be > 0, got {timestep}")
    if not 0.0 <= float(mount_height_m) <= 10.0:
        raise InputError(f"sim.mount_height_m: in [0, 10] m, got {mount_height_m}")
    model = (
        default_drives()
        if drives is None
        else DriveModel(drives, tuple(reference_torque_nm or default_drives().reference_torque_nm))
    )
    description = load_arm(str(arm))
    per_joint = model.for_arm(description)
    if twin:
        from robohealth_mj.sim.twin_file import read_twin

        for joint, params in read_twin(twin, str(arm)).items():
            per_joint[joint].update(params)
    for joint, params in (drive_overrides or {}).items():
        if joint not in description.joint_keys:
            raise KeyError(
                f"drive override for unknown joint {joint!r}; known: {list(description.joint_keys)}"
            )
        unknown = sorted(set(params) - set(DRIVE_KEYS))
        if unknown:
            raise KeyError(f"unknown drive parameters for {joint}: {unknown}")
        per_joint[joint].update({k: float(v) for k, v in params.items()})
    root = build_arm_scene(description, per_joint, scene, float(mount_height_m))
    root.option.timestep = float(timestep)
    compiled = mujoco.MjModel.from_xml_string(root.to_xml_string(), assets=root.get_assets())
    if friction_solref is not None:
        solref = [float(v) for v in friction_solref]
        if len(solref) != 2 or not solref[0] >= 2 * float(timestep) or not solref[1] > 0:
            raise InputError(
                f"sim.friction_solref: [timeconst >= 2 x timestep, dampratio > 0], got {solref}"
            )
        compiled.dof_solref[ArmIndex.of(compiled).motor_dof] = solref
    if friction_solimp is not None:
        solimp = [float(v) for v in friction_solimp]
        if len(solimp) != 5 or not 0 < solimp[0] <= solimp[1] < 1:
            raise InputError(
                f"sim.friction_solimp: [dmin, dmax, width, midpoint, power] with "
                f"0 < dmin <= dmax < 1, got {solimp}"
            )
        compiled.dof_solimp[ArmIndex.of(compiled).motor_dof] = solimp
    return compiled


@dataclass(frozen=True)
class ArmIndex:
    """Addresses of the arm's named parts in a compiled model, in schema joint order."""

    motor_qpos: np.ndarray
    deflection_qpos: np.ndarray
    motor_dof: np.ndarray
    deflection_dof: np.ndarray
    actuator: np.ndarray
    tendon: np.ndarray
    acc_sensor: np.ndarray  # [J, 3] sensordata addresses
    effort_sensor: np.ndarray  # [J]
    payload_body: int
    torque_limit: np.ndarray
    joints: tuple[str, ...] = ()  # the joints' names (the servos'), base to tool

    @classmethod
    def of(cls, model: mujoco.MjModel) -> ArmIndex:
        def joint(name: str) -> mujoco._structs._MjModelJointViews:
            return model.joint(name)

        keys = [model.actuator(k).name for k in range(model.nu)]  # one servo per joint, in order
        motor = [joint(f"{j}_joint") for j in keys]
        defl = [joint(f"{j}_deflection") for j in keys]
        acc = [model.sensor(f"{j}_acc") for j in keys]
        eff = [model.sensor(f"{j}_effort") for j in keys]
        actuators = np.arange(model.nu)
        return cls(
            motor_qpos=np.array([int(m.qposadr[0]) for m in motor]),
            deflection_qpos=np.array([int(d.qposadr[0]) for d in defl]),
            motor_dof=np.array([int(m.dofadr[0]) for m in motor]),
            deflection_dof=np.array([int(d.dofadr[0]) for d in defl]),
            actuator=actuators,
            tendon=np.array([model.tendon(f"{j}_drive").id for j in keys]),
            acc_sensor=np.array([[int(s.adr[0]) + k for k in range(3)] for s in acc]),
            effort_sensor=np.array([int(s.adr[0]) for s in eff]),
            payload_body=model.body("payload").id,
            torque_limit=model.actuator_forcerange[actuators, 1].copy(),
            joints=tuple(keys),
        )

    def set_link_pose(self, data: mujoco.MjData, q: np.ndarray) -> None:
        """Put the links at UR angles ``q`` with the drives untwisted."""
        data.qpos[self.motor_qpos] = q
        data.qpos[self.deflection_qpos] = 0.0
