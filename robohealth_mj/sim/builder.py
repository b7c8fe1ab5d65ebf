"""Building an arm's MuJoCo scene from its description, through dm-control's ``mjcf``.

The body tree follows the maker's URDF frames (each link's frame on its joint, the joint's axis
as the description gives it, ``z`` on a UR), so joint zero and direction are the controller's;
an arm of any joint count. Every joint is two hinges on one axis in one body: ``<joint>_joint``,
the motor side (rotor inertia, friction, the position servo), and ``<joint>_deflection``, the
drive's output twisting against it; a fixed tendon on the deflection hinge is the drive's
compliance with a dead band of free play (backlash). The link angle a controller reports is the
sum of the two. Geometry is primitive (for rendering and the floor only: links do
not collide with each other).
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

with warnings.catch_warnings():
    # dm-control probes for an OpenGL backend on import; model editing needs none.
    warnings.simplefilter("ignore")
    from dm_control import mjcf

from robohealth_mj.arms.description import UR_HOME_POSE, ArmDescription
from robohealth_mj.common.errors import InputError
from robohealth_mj.schema import JOINT_NAMES

REFERENCE_REACH_M = 0.85  # the UR5e, whose size the scene's cameras and housings are drawn for
DRIVE_KEYS = ("armature", "damping", "frictionloss", "stiffness", "tendon_damping", "backlash",
              "kp", "kv")  # fmt: skip
ANGLES = ("backlash",)  # drive parameters that are angles: the same on every arm
HOME_POSE = UR_HOME_POSE  # the schema's arms' start pose (the UR family)
# The arm stands rotated about world z so that a UR5e's tool sits where the scene's cameras look.
BASE_YAW = np.pi / 2


def quat_rpy(rpy: np.ndarray) -> np.ndarray:
    """The quaternion (w x y z) of a URDF roll-pitch-yaw: ``Rz(yaw) Ry(pitch) Rx(roll)``."""
    out = np.array([1.0, 0.0, 0.0, 0.0])
    for axis, angle in zip(np.eye(3)[::-1], np.asarray(rpy, float)[::-1], strict=True):
        step = np.empty(4)
        mujoco.mju_axisAngle2Quat(step, axis, float(angle))
        mujoco.mju_mulQuat(out, out.copy(), step)
    return out


def _qmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    out = np.empty(4)
    mujoco.mju_mulQuat(out, np.asarray(a, float), np.asarray(b, float))
    return out


def _rotation(q: np.ndarray) -> np.ndarray:
    out = np.empty(9)
    mujoco.mju_quat2Mat(out, np.asarray(q, float))
    return out.reshape(3, 3)


def mount_quat(axis: np.ndarray) -> np.ndarray | None:
    """The quaternion (w x y z) of the frame a joint's sensor package is mounted in: its z the
    joint's axis, turned from the link frame by the shortest arc (``None``: the link frame's z
    already is the axis, as in every maker's description but KUKA's, whose pitch joints turn
    about y). So every arm's accelerometer reads along its joint axis on z, and a model trained
    on some makers reads another's sensors in the same frame (``studies/arms``)."""
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    if np.allclose(a, [0.0, 0.0, 1.0]):
        return None
    if np.allclose(a, [0.0, 0.0, -1.0]):
        return np.array([0.0, 1.0, 0.0, 0.0])  # half a turn about x
    q = np.array([1.0 + a[2], -a[1], a[0], 0.0])  # 1 + z.a, z x a
    return q / np.linalg.norm(q)


@dataclass(frozen=True)
class DriveModel:
    """Our drive model, stated for the UR5e and scaled to any arm by one rule: each parameter
    times the joint's rated torque over the UR5e joint's (angles, i.e. backlash, unchanged)."""

    reference: Mapping[str, Mapping[str, float]]  # joint -> DRIVE_KEYS, for the UR5e
    reference_torque_nm: tuple[float, ...]  # the UR5e's rated torques, schema joint order

    def __post_init__(self) -> None:
        if sorted(self.reference) != sorted(JOINT_NAMES):
            raise InputError(f"sim.drives needs exactly the joints {list(JOINT_NAMES)}")
        for joint, params in self.reference.items():
            missing = sorted(set(DRIVE_KEYS) - set(params))
            unknown = sorted(set(params) - set(DRIVE_KEYS))
            if missing or unknown:
                problem = f"missing {missing[0]}" if missing else f"unknown key {unknown[0]}"
                raise InputError(f"sim.drives.{joint}: {problem} (keys: {', '.join(DRIVE_KEYS)})")
            for key, value in params.items():
                if not float(value) >= 0.0:
                    raise InputError(f"sim.drives.{joint}.{key}: must be >= 0, got {value}")
        if len(self.reference_torque_nm) != len(JOINT_NAMES):
            raise InputError(f"sim.reference_torque_nm needs {len(JOINT_NAMES)} values")

    def for_arm(self, arm: ArmDescription) -> dict[str, dict[str, float]]:
        """Each joint's drive parameters on ``arm``: on a UR arm each joint's own, on any other
        the UR5e joint of its class (``arm.ur_counterparts()``), scaled by rated torque."""
        out = {}
        for j, (joint, ref) in enumerate(zip(arm.joint_keys, arm.ur_counterparts(), strict=True)):
            scale = float(arm.rated_torque[j]) / float(
                self.reference_torque_nm[JOINT_NAMES.index(ref)]
            )
            out[joint] = {
                k: float(v) * (1.0 if k in ANGLES else scale)
                for k, v in self.reference[ref].items()
            }
        return out


def build_arm_scene(
    arm: ArmDescription,
    drives: Mapping[str, Mapping[str, float]],
    scene: Path,
    mount_height_m: float = 0.0,
) -> mjcf.RootElement:
    """The scene (``scene``: floor, lights, cameras) with ``arm`` standing at the origin,
    ``mount_height_m`` above the floor (on a pedestal, so its links can reach below the base)."""
    root = mjcf.from_path(str(scene))
    root.model = arm.name
    root.compiler.angle = "radian"
    size = arm.reach_m / REFERENCE_REACH_M
    for camera in root.worldbody.find_all("camera"):
        camera.pos = np.asarray(camera.pos) * size
    root.statistic.center = np.asarray(root.statistic.center) * size
    root.statistic.extent = float(root.statistic.extent) * size

    base = root.worldbody.add(
        "body",
        name="base",
        pos=[0.0, 0.0, float(mount_height_m)],
        quat=_qmul(quat_rpy([0, 0, BASE_YAW]), quat_rpy([0, 0, np.pi])),
    )
    r, h, m = arm.base_radius, arm.base_length, arm.base_mass  # UR's cylinder inertial
    ixx = m * (3 * r * r + h * h) / 12.0
    moments = [ixx, ixx, m * r * r / 2.0] if r > 0 else [1e-3] * 3  # the base does not move
    base.add("inertial", mass=m, pos=[0, 0, 0], diaginertia=moments)
    base.add("geom", name="base_housing", type="cylinder", size=[0.075 * size, 0.045 * size],
             pos=[0, 0, 0.045 * size], material="linkgray", contype=0, conaffinity=1)  # fmt: skip

    parent = base
    big = arm.rated_torque >= 0.5 * float(np.max(arm.rated_torque))  # drawn as base joints
    for j, (joint, body_name, link) in enumerate(
        zip(arm.joint_keys, arm.link_bodies, arm.links, strict=True)
    ):
        body = parent.add(
            "body", name=body_name, pos=link.origin_xyz, quat=quat_rpy(link.origin_rpy)
        )
        rot = _rotation(quat_rpy(link.inertia_rpy))
        inertia = rot @ link.inertia @ rot.T  # into the link frame
        full = [inertia[i, j] for i, j in ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))]
        body.add("inertial", mass=link.mass, pos=link.com, fullinertia=full)
        d = drives[joint]
        limited = bool(np.all(np.isfinite(arm.position_limit[j])))
        body.add(
            "joint", name=f"{joint}_joint", type="hinge", axis=link.axis,
            range=arm.position_limit[j] if limited else None, limited=limited,
            armature=d["armature"], damping=d["damping"], frictionloss=d["frictionloss"],
        )  # fmt: skip
        body.add("joint", name=f"{joint}_deflection", type="hinge", axis=link.axis,
                 armature=0, damping=0, frictionloss=0)  # fmt: skip
        radius = (0.06 if big[j] else 0.045) * size
        mount = mount_quat(link.axis)  # the housing and the sensor package around the axis
        turn = np.eye(3) if mount is None else _rotation(mount)
        body.add("geom", name=f"{joint}_housing", type="cylinder", size=[radius, 1.1 * radius],
                 quat=mount, material="urblue", contype=0, conaffinity=1)  # fmt: skip
        if j + 1 < len(arm.links):  # the link's tube to the next joint
            nxt = arm.links[j + 1].origin_xyz
            if np.linalg.norm(nxt[:2]) > 2 * radius:
                z = float(link.com[2])
                body.add("geom", name=f"{body_name}_tube", type="capsule", size=[0.8 * radius],
                         fromto=[0, 0, z, nxt[0], nxt[1], z], material="linkgray",
                         contype=0, conaffinity=1)  # fmt: skip
        place = turn @ _sensor_position(turn.T @ link.com, radius, 0.1 * size)
        body.add("site", name=f"{joint}_sensor", pos=place, quat=mount, size=[0.008 * size],
                 rgba=[1, 0.5, 0, 1], group=4)  # fmt: skip
        root.tendon.add(
            "fixed", name=f"{joint}_drive", stiffness=d["stiffness"], damping=d["tendon_damping"],
            springlength=[-d["backlash"], d["backlash"]],
        ).add("joint", joint=f"{joint}_deflection", coef=1)  # fmt: skip
        root.actuator.add(
            "position", name=joint, joint=f"{joint}_joint", kp=d["kp"], kv=d["kv"],
            forcerange=[-arm.rated_torque[j], arm.rated_torque[j]], ctrllimited=False,
            forcelimited=True,
        )  # fmt: skip
        root.sensor.add("accelerometer", name=f"{joint}_acc", site=f"{joint}_sensor")
        parent = body
    parent.add("geom", name="flange", type="cylinder", size=[0.038 * size, 0.006 * size],
               pos=[0, 0, -0.006 * size], material="black", contype=0, conaffinity=0)  # fmt: skip
    parent.add("site", name="tool_flange", pos=arm.flange_xyz, size=[0.008 * size], group=4)
    payload = parent.add("body", name="payload", pos=arm.flange_xyz)
    # a point mass at the flange; the recorder sets its mass per curriculum segment
    payload.add("inertial", mass=arm.payload_kg * 0.4, pos=[0, 0, 0], diaginertia=[1e-9] * 3)
    for joint in arm.joint_keys:
        root.sensor.add("actuatorfrc", name=f"{joint}_effort", actuator=joint)
    home = arm.home_pose()
    qpos = np.stack([home, np.zeros(arm.n_joints)], axis=1).ravel()
    root.keyframe.add("key", name="home", qpos=qpos, ctrl=home)
    return root


def _sensor_position(com: np.ndarray, radius: float, along: float) -> np.ndarray:
    """The sensor package sits on its link next to the joint, on the side of the link's centre of
    mass (so on the link, not in the air), at the centre of mass's height: on the housing, or
    ``along`` out on a long link (the upper arm and forearm, as on the first UR5e). ``com`` in
    the mount frame (z the joint axis), and so the result."""
    radial = np.array([com[0], com[1]], dtype=float)
    norm = float(np.linalg.norm(radial))
    direction = radial / norm if norm > 1e-6 else np.array([1.0, 0.0])
    distance = max(radius, min(norm, along))
    return np.array([distance * direction[0], distance * direction[1], float(com[2])])
