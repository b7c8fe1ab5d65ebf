"""Placing a push on a link from the joint torques it leaves: the arm's chain against MuJoCo's
own kinematics, the batched cone fit against scipy's, and known pushes on the UR10e placed back."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from scipy.optimize import nnls

from robohealth_mj.arms.contact_place import (
    FRICTION,
    ArmSurface,
    cone,
    nonnegative_least_squares,
    place,
)
from robohealth_mj.schema import JOINT_NAMES
from robohealth_mj.sim.contact_surface import arm_surface
from robohealth_mj.sim.dynamics import nominal_model

POSE = np.array([-0.28, -1.95, -1.67, -1.53, 0.99, 0.39])  # a pose the real pushed arm held
NOISE = np.array([5.8, 10.2, 1.7, 0.56, 0.71, 2.0])  # N·m, the real arm's quiet deviations


@pytest.fixture(scope="module")
def surface() -> ArmSurface:
    return arm_surface("ur10e")


def test_the_chain_puts_links_and_axes_where_mujoco_does(surface):
    model, index = nominal_model("ur10e")
    data = mujoco.MjData(model)
    base = model.body("base").id
    for q in np.random.default_rng(0).uniform(-3.0, 3.0, (3, 6)):
        index.set_link_pose(data, q)
        mujoco.mj_kinematics(model, data)
        to_base = data.xmat[base].reshape(3, 3).T
        positions, rotations, axes, _ = surface.pose(q)
        for j, name in enumerate(JOINT_NAMES):
            joint = model.joint(f"{name}_joint")
            body = int(joint.bodyid[0])
            assert np.allclose(to_base @ (data.xpos[body] - data.xpos[base]), positions[j])
            assert np.allclose(to_base @ data.xmat[body].reshape(3, 3), rotations[j])
            assert np.allclose(to_base @ data.xaxis[joint.id], axes[j])


def test_the_batched_cone_fit_solves_as_scipy_does():
    rng = np.random.default_rng(1)
    a, b = rng.normal(size=(50, 14, 8)), rng.normal(size=14)
    x, squared = nonnegative_least_squares(a, b)
    assert (x >= 0).all()
    assert np.allclose(squared, [nnls(m, b)[1] ** 2 for m in a], atol=1e-6)


def test_a_push_stays_within_its_friction_angle_of_the_inward_normal():
    normal = np.random.default_rng(2).normal(size=(20, 3))
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    edges = cone(normal)  # [P, 3, E]
    inward = np.einsum("pke,pk->pe", edges, -normal)
    assert np.allclose(inward, 1.0 / np.hypot(1.0, FRICTION))  # every edge at the cone's rim
    assert np.allclose(edges.mean(axis=2) / inward.mean(axis=1, keepdims=True), -normal)


def torque_of(surface: ArmSurface, joint: int, k: int, newtons: float) -> np.ndarray:
    """The joint torques of a push square on (along the inward normal) the ``k``-th surface
    point of the link ``joint`` moves."""
    lever, normal = surface.lever(POSE)
    point = np.flatnonzero(surface.link == joint)[k]
    return lever[point] @ (-newtons * normal[point])


def test_a_push_across_the_forearm_is_placed_there_and_its_torques_reproduced(surface):
    torque = torque_of(surface, 2, 176 + 33, 80.0)  # on the capsule, across the elbow's axis
    assert abs(torque[2]) > 10 * NOISE[2] and np.allclose(torque[3:], 0.0)
    placed = place(surface, POSE, torque, NOISE)
    assert placed.joint == 2 and placed.chi2[2] < 0.1
    assert (placed.chi2[:2] > 1.0).all()  # no push on the base or the upper arm gives these
    lever, _ = surface.lever(POSE)
    best = np.flatnonzero(surface.link == 2)
    refits = np.einsum("pjk,k->pj", lever[best], placed.force_n[2])
    assert np.abs(refits - torque).max(axis=1).min() < 0.3 * NOISE.min()


def test_a_push_square_on_a_wrist_housing_loads_not_its_joint_but_is_placed_on_its_link(surface):
    """The most distal joint loaded would name wrist 2; the fit sees wrist 3's link."""
    torque = torque_of(surface, 5, 3, 40.0)  # the flange's side, through its axis
    assert abs(torque[5]) < 1e-9 and abs(torque[4]) > 5 * NOISE[4]
    placed = place(surface, POSE, torque, NOISE)
    assert placed.joint == 5 and placed.chi2[4] > 1.0


def test_torques_no_single_push_gives_are_placed_nowhere(surface):
    torque = np.array([0.0, 0.0, 0.0, 0.0, 30.0, 0.0])  # wrist 2 alone, nothing upstream
    assert place(surface, POSE, torque, NOISE).joint == -1


def test_the_surface_travels_as_plain_data(surface):
    again = ArmSurface.from_dict(surface.to_dict())
    assert again.link.dtype == np.int64 and np.allclose(again.point, surface.point, atol=1e-6)
    assert np.allclose(again.pose(POSE)[0], surface.pose(POSE)[0], atol=1e-5)
