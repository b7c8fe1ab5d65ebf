"""Where on the arm a push was, from the joint torques it left: a force fit on the arm's kinematics.

Why a fit and not only the most distal joint loaded: a force on a link loads that link's joint
only through its lever about the joint's axis. A hand pressing square on a joint's round
housing pushes through that axis, so it loads the joints before it and not that one: the most
distal joint loaded is a lower bound on where the push was. The joints before it still say
where: one force at a point of a link gives the joint torques ``tau = J(p)^T F`` (``J`` the point's
positional Jacobian), and only points of some links give the measured pattern. Per link, at each
point of its collision surface, this fits a force inside the friction cone there (non-negative
weights on the cone's edges, as contact-particle filters do), so the force's line meets the link
near that point: a force whose line misses every link is what the cone keeps out (on a convex
link a pull reads as a push from the far side). The best point is scored by chi-square against
each joint's noise, with a mild cost on forces beyond a hand's; the link named is the most
proximal one whose best point explains the torques to within ``accept``.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
from scipy.optimize import nnls

from robohealth_mj.schema import JOINT_NAMES
from robohealth_mj.sim.dynamics import nominal_model

FRICTION = 0.5  # the friction cone's half-angle tangent
CONE_EDGES = 8
FORCE_SCALE_N = 150.0  # a hand's push: a force this size adds about 1 to chi-square
AROUND, ALONG = 16, 7  # surface points: around each geom, and along its axis


@dataclass(frozen=True)
class LinkFit:
    """The best single push on one link: chi-square of the torques left unexplained (with the
    force's cost), the force (N, world frame) and the point it acts at (m, world frame)."""

    joint: str  # the joint that moves the link
    chi2: float
    force_n: np.ndarray
    point_m: np.ndarray


def surface(model: mujoco.MjModel, geom: int) -> tuple[np.ndarray, np.ndarray]:
    """Points ``[P, 3]`` on a cylinder's or capsule's surface and the outward normals there, in
    the geom's frame (its axis is z)."""
    radius, half = model.geom_size[geom][:2]
    points, normals = [], []
    for angle in np.linspace(0.0, 2 * np.pi, AROUND, endpoint=False):
        out = np.array([np.cos(angle), np.sin(angle), 0.0])
        for z in np.linspace(-half, half, ALONG):
            points.append(radius * out + [0.0, 0.0, z])
            normals.append(out)
        for end in (1.0, -1.0):
            if model.geom_type[geom] == mujoco.mjtGeom.mjGEOM_CAPSULE:  # the hemispheres
                for lat in (np.pi / 6, np.pi / 3):
                    n = np.cos(lat) * out + [0.0, 0.0, end * np.sin(lat)]
                    points.append(radius * n + [0.0, 0.0, end * half])
                    normals.append(n)
            else:  # the flat ends
                for r in (0.45 * radius, 0.9 * radius):
                    points.append(r * out + [0.0, 0.0, end * half])
                    normals.append(np.array([0.0, 0.0, end]))
    return np.array(points), np.array(normals)


def tangents(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors across a surface's unit ``normal``, square to it and to each other."""
    t1 = np.cross(normal, [1.0, 0.0, 0.0])
    if np.linalg.norm(t1) < 0.1:
        t1 = np.cross(normal, [0.0, 1.0, 0.0])
    t1 /= np.linalg.norm(t1)
    return t1, np.cross(normal, t1)


def cone(normal: np.ndarray) -> np.ndarray:
    """``[3, CONE_EDGES]`` the unit edges of the friction cone of a push into a surface."""
    t1, t2 = tangents(normal)
    angles = np.linspace(0.0, 2 * np.pi, CONE_EDGES, endpoint=False)
    across = np.outer(t1, np.cos(angles)) + np.outer(t2, np.sin(angles))
    edges = -normal[:, None] + FRICTION * across
    return edges / np.linalg.norm(edges, axis=0)


def area(model: mujoco.MjModel, geom: int) -> float:
    """A cylinder's or capsule's surface area (m²)."""
    radius, half = model.geom_size[geom][:2]
    ends = 4 * np.pi * radius**2 if model.geom_type[geom] == mujoco.mjtGeom.mjGEOM_CAPSULE else (
        2 * np.pi * radius**2)  # fmt: skip
    return float(2 * np.pi * radius * 2 * half + ends)


def fit_links(
    arm: str, q: np.ndarray, torque_nm: np.ndarray, noise_nm: np.ndarray
) -> list[LinkFit]:
    """Per link of ``arm``, base to flange, the best single push explaining the external torque
    on the joints ``torque_nm [6]`` at pose ``q [6]`` (rad, UR convention). A holding drive
    answers a push with the opposite torque, so this is minus the torque residual's change.
    ``noise_nm [6]`` weighs each joint's misfit."""
    model, index = nominal_model(arm)
    data = mujoco.MjData(model)
    index.set_link_pose(data, np.asarray(q, dtype=float))
    mujoco.mj_kinematics(model, data)
    mujoco.mj_comPos(model, data)
    scale = 1.0 / np.asarray(noise_nm, dtype=float)
    target = np.asarray(torque_nm, dtype=float) * scale
    jac = np.zeros((3, model.nv))
    prior = np.eye(CONE_EDGES) / FORCE_SCALE_N
    padded = np.concatenate([target, np.zeros(CONE_EDGES)])
    fits = []
    for name in JOINT_NAMES:
        body = int(model.joint(f"{name}_joint").bodyid[0])
        best = LinkFit(name, np.inf, np.zeros(3), np.zeros(3))
        for geom in np.flatnonzero(model.geom_bodyid == body):
            turn = data.geom_xmat[geom].reshape(3, 3)
            for point, normal in zip(*surface(model, geom), strict=True):
                where = data.geom_xpos[geom] + turn @ point
                mujoco.mj_jac(model, data, jac, None, where, body)
                edges = cone(turn @ normal)
                system = np.vstack([(jac[:, index.motor_dof].T @ edges) * scale[:, None], prior])
                weights, misfit = nnls(system, padded)
                if misfit**2 < best.chi2:
                    best = LinkFit(name, float(misfit**2), edges @ weights, where)
        fits.append(best)
    return fits


def nearest_link(fits: list[LinkFit], accept: float) -> LinkFit | None:
    """The most proximal link whose best push explains the torques (chi-square within
    ``accept``); None if no single push does."""
    return next((fit for fit in fits if fit.chi2 <= accept), None)
