"""An arm's chain and collision surface from its MuJoCo model, for placing a push on a link
(:mod:`robohealth_mj.arms.contact_place`, which the runtime runs without MuJoCo).

Why points on the collision geoms: a push lands on the arm's surface, and which link's surface
a force's line can meet is what tells a push on a housing from one on the link before it.
"""

from __future__ import annotations

import mujoco
import numpy as np

from robohealth_mj.arms.contact_place import ArmSurface
from robohealth_mj.sim.dynamics import nominal_model

AROUND, ALONG = 16, 7  # surface points: around each geom, and along its axis


def geom_surface(model: mujoco.MjModel, geom: int) -> tuple[np.ndarray, np.ndarray]:
    """Points ``[P, 3]`` on a cylinder's or capsule's surface and the outward normals there, in
    the geom's frame (its axis is z): rings along the side, and the flat ends or hemispheres."""
    radius, half = model.geom_size[geom][:2]
    capsule = model.geom_type[geom] == mujoco.mjtGeom.mjGEOM_CAPSULE
    points, normals = [], []
    for angle in np.linspace(0.0, 2 * np.pi, AROUND, endpoint=False):
        out = np.array([np.cos(angle), np.sin(angle), 0.0])
        for z in np.linspace(-half, half, ALONG):
            points.append(radius * out + [0.0, 0.0, z])
            normals.append(out)
        for end in (1.0, -1.0):
            for k in (1, 2):
                if capsule:  # at 30 and 60 degrees of latitude
                    n = np.cos(k * np.pi / 6) * out + [0.0, 0.0, end * np.sin(k * np.pi / 6)]
                    points.append(radius * n + [0.0, 0.0, end * half])
                    normals.append(n)
                else:  # rings on the flat end
                    points.append(0.45 * k * radius * out + [0.0, 0.0, end * half])
                    normals.append(np.array([0.0, 0.0, end]))
    return np.array(points), np.array(normals)


def geom_area(model: mujoco.MjModel, geom: int) -> float:
    """A cylinder's or capsule's surface area (m²)."""
    radius, half = model.geom_size[geom][:2]
    capsule = model.geom_type[geom] == mujoco.mjtGeom.mjGEOM_CAPSULE
    return float(4 * np.pi * radius * half + (4 if capsule else 2) * np.pi * radius**2)


def geom_in_body(model: mujoco.MjModel, geom: int) -> tuple[np.ndarray, np.ndarray]:
    """A geom's position ``[3]`` and rotation ``[3, 3]`` in its body's frame."""
    turn = np.empty(9)
    mujoco.mju_quat2Mat(turn, model.geom_quat[geom])
    return model.geom_pos[geom].copy(), turn.reshape(3, 3)


def arm_surface(arm: str) -> ArmSurface:
    """The chain of ``arm``'s joints and its links' collision surfaces."""
    model, _ = nominal_model(arm)
    offset_pos, offset_rot, anchor, axis = [], [], [], []
    link, point, normal = [], [], []
    joints = [model.actuator(k).name for k in range(model.nu)]  # one servo per joint, in order
    for j, name in enumerate(joints):
        joint = model.joint(f"{name}_joint")
        body = int(joint.bodyid[0])
        turn = np.empty(9)
        mujoco.mju_quat2Mat(turn, model.body_quat[body])
        offset_pos.append(model.body_pos[body].copy())
        offset_rot.append(turn.reshape(3, 3))
        anchor.append(model.jnt_pos[joint.id].copy())
        axis.append(model.jnt_axis[joint.id].copy())
        for geom in np.flatnonzero(model.geom_bodyid == body):
            pos, rot = geom_in_body(model, int(geom))
            p, n = geom_surface(model, int(geom))
            point.append(pos + p @ rot.T)
            normal.append(n @ rot.T)
            link.append(np.full(len(p), j))
    return ArmSurface(
        np.array(offset_pos), np.array(offset_rot), np.array(anchor), np.array(axis),
        np.concatenate(link), np.concatenate(point), np.concatenate(normal),
    )  # fmt: skip
