"""An arm's kinematic chain in plain numpy, from its description alone (URDF convention: each
joint's frame placed in its parent link's by ``origin_xyz`` and roll-pitch-yaw, then turned by
the joint angle about its axis, z unless the description says otherwise).

Why here and not in MuJoCo: it is the computation the simulator is checked against (gravity
torques from the maker's numbers, sharing no code with the builder), and it serves any joint
count without building a model.
"""

from __future__ import annotations

import numpy as np

from robohealth_mj.arms.description import ArmDescription

GRAVITY = 9.81  # m/s^2, as the simulator's


def rotation_rpy(rpy: np.ndarray) -> np.ndarray:
    """URDF's fixed-axis roll, pitch, yaw: ``Rz(yaw) @ Ry(pitch) @ Rx(roll)``."""
    (cr, cp, cy), (sr, sp, sy) = np.cos(rpy), np.sin(rpy)
    return np.array([
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ])  # fmt: skip


def rotation_about(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues: the rotation by ``angle`` about the unit ``axis``."""
    x, y, z = axis
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k)


def link_frames(arm: ArmDescription, q: np.ndarray) -> list[np.ndarray]:
    """``[J]`` homogeneous transforms base -> link j at the joint angles ``q`` ``[J]``."""
    frames, current = [], np.eye(4)
    for link, angle in zip(arm.links, np.asarray(q, dtype=float), strict=True):
        place = np.eye(4)
        place[:3, :3], place[:3, 3] = rotation_rpy(link.origin_rpy), link.origin_xyz
        turn = np.eye(4)
        turn[:3, :3] = rotation_about(link.axis, angle)
        current = current @ place @ turn
        frames.append(current)
    return frames


def gravity_torques(arm: ArmDescription, q: np.ndarray, payload_kg: float = 0.0) -> np.ndarray:
    """``[J]`` joint torques (N m) that hold the arm still at ``q``, a point payload at the
    flange: for each joint, the moment about its axis of the weight of everything it carries."""
    frames = link_frames(arm, q)
    masses = [link.mass for link in arm.links] + [payload_kg]
    points = [(f @ np.append(link.com, 1.0))[:3] for f, link in zip(frames, arm.links, strict=True)]
    points.append((frames[-1] @ np.append(arm.flange_xyz, 1.0))[:3])
    tau = np.zeros(arm.n_joints)
    for j, (frame, link) in enumerate(zip(frames, arm.links, strict=True)):
        axis, origin = frame[:3, :3] @ link.axis, frame[:3, 3]
        for m, p in zip(masses[j:], points[j:], strict=True):  # what joint j carries
            tau[j] += m * GRAVITY * np.cross(axis, p - origin)[2]
    return tau
