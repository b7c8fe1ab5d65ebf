"""The force fit that places a push on a link from the joint torques it leaves: known pushes on
the UR10e's links, their torques from its kinematics, placed back."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from robohealth_mj.sim.dynamics import nominal_model
from robohealth_mj.twin import contact_fit

POSE = np.array([-0.28, -1.95, -1.67, -1.53, 0.99, 0.39])  # a pose the real pushed arm held
NOISE = np.array([5.8, 10.2, 1.7, 0.56, 0.71, 2.0])  # N·m, the real arm's quiet deviations


def push_torque(link: str, geom_index: int, point_index: int, newtons: float) -> np.ndarray:
    """The joint torques ``J^T F`` of a push square on (along the inward normal) a surface point
    of ``link``'s ``geom_index``-th geom."""
    model, index = nominal_model("ur10e")
    data = mujoco.MjData(model)
    index.set_link_pose(data, POSE)
    mujoco.mj_kinematics(model, data)
    mujoco.mj_comPos(model, data)
    body = model.body(link).id
    geom = int(np.flatnonzero(model.geom_bodyid == body)[geom_index])
    points, normals = contact_fit.surface(model, geom)
    turn = data.geom_xmat[geom].reshape(3, 3)
    where = data.geom_xpos[geom] + turn @ points[point_index]
    jac = np.zeros((3, model.nv))
    mujoco.mj_jac(model, data, jac, None, where, body)
    return jac[:, index.motor_dof].T @ (-newtons * (turn @ normals[point_index]))


@pytest.fixture(scope="module")
def forearm_push():
    torque = push_torque("forearm_link", 1, 33, 80.0)  # on the capsule, across the elbow
    return torque, contact_fit.fit_links("ur10e", POSE, torque, NOISE)


def test_a_push_on_the_forearm_is_placed_there_and_its_torques_reproduced(forearm_push):
    torque, fits = forearm_push
    assert abs(torque[2]) > 10 * NOISE[2] and np.allclose(torque[3:], 0.0)  # elbow loaded
    named = contact_fit.nearest_link(fits, accept=1.0)
    assert named is not None and named.joint == "elbow"
    assert named.chi2 < 0.1
    assert [f.chi2 > 1.0 for f in fits[:2]] == [True, True]  # base or upper arm cannot
    model, index = nominal_model("ur10e")
    data = mujoco.MjData(model)
    index.set_link_pose(data, POSE)
    mujoco.mj_kinematics(model, data)
    mujoco.mj_comPos(model, data)
    jac = np.zeros((3, model.nv))
    mujoco.mj_jac(model, data, jac, None, named.point_m, model.body("forearm_link").id)
    refit = jac[:, index.motor_dof].T @ named.force_n
    assert np.all(np.abs(refit - torque) < 0.3 * NOISE)


def test_a_push_square_on_a_wrist_housing_loads_not_its_joint_but_is_placed_on_its_link():
    """The most distal joint loaded would name wrist 2; only the fit sees wrist 3's link."""
    torque = push_torque("wrist_3_link", 0, 3, 40.0)  # the flange's side, through its axis
    assert abs(torque[5]) < 1e-9 and abs(torque[4]) > 5 * NOISE[4]
    fits = contact_fit.fit_links("ur10e", POSE, torque, NOISE)
    named = contact_fit.nearest_link(fits, accept=1.0)
    assert named is not None and named.joint == "wrist_3"
    assert fits[4].chi2 > 1.0  # no push on wrist 2's own link gives these torques


def test_torques_no_single_push_gives_are_placed_nowhere():
    torque = np.array([0.0, 0.0, 0.0, 0.0, 30.0, 0.0])  # wrist 2 alone, with no lever upstream
    fits = contact_fit.fit_links("ur10e", POSE, torque, NOISE)
    assert contact_fit.nearest_link(fits, accept=1.0) is None
