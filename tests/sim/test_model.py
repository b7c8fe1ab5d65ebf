"""The UR5e MJCF: compiles, steps cleanly, and carries the parameter file's numbers."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
import yaml

from robohealth_mj.schema import JOINT_NAMES
from robohealth_mj.sim.dynamics import gravity_torques
from robohealth_mj.sim.model import ASSET_DIR, HOME_POSE, ArmIndex, build_model

PARAMS = yaml.safe_load((ASSET_DIR / "ur5e" / "ur5e_parameters.yaml").read_text())


def _quat(q) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    return q / np.linalg.norm(q)


def test_scene_steps_one_second_of_random_commands_without_warnings(model):
    data = mujoco.MjData(model)
    index = ArmIndex.of(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    rng = np.random.default_rng(0)
    for _ in range(20):  # a new random in-range command every 50 ms
        data.ctrl[:] = HOME_POSE + rng.uniform(-0.3, 0.3, 6)
        mujoco.mj_step(model, data, nstep=50)
    assert [w.number for w in data.warning] == [0] * len(data.warning)
    assert np.all(np.isfinite(data.qpos)) and np.all(np.isfinite(data.sensordata))
    assert np.all(np.abs(data.actuator_force) <= index.torque_limit + 1e-9)


def test_model_has_named_cameras_and_twelve_dofs(model):
    cameras = {model.camera(i).name for i in range(model.ncam)}
    assert {"front", "side"} <= cameras
    assert model.nv == 12 and model.nu == 6


def test_mjcf_matches_the_parameter_file(model):
    for link in PARAMS["links"]:
        body = model.body(link["body"])
        np.testing.assert_allclose(body.pos, link["pos"], atol=1e-9)
        np.testing.assert_allclose(np.abs(body.quat @ _quat(link["quat"])), 1.0, atol=1e-9)
        np.testing.assert_allclose(body.mass, link["mass"], rtol=1e-9)
        np.testing.assert_allclose(body.ipos, link["com"], atol=1e-9)
        np.testing.assert_allclose(np.sort(body.inertia), np.sort(link["diaginertia"]), rtol=1e-6)
        joint = model.joint(f"{link['joint']['name']}_joint")
        np.testing.assert_allclose(joint.axis, link["joint"]["axis"])
        np.testing.assert_allclose(joint.range, link["joint"]["range"])
        drive = PARAMS["drives"][link["joint"]["size"]]
        np.testing.assert_allclose(joint.armature, drive["armature"])
        actuator = model.actuator(link["joint"]["name"])
        np.testing.assert_allclose(
            actuator.forcerange, [-drive["torque_limit"], drive["torque_limit"]]
        )
    np.testing.assert_allclose(model.body("base").mass, PARAMS["base"]["mass"])
    np.testing.assert_allclose(model.site("tool_flange").pos, PARAMS["tool_flange"]["pos"])


def test_gravity_torques_agree_with_the_parameter_file_check_values():
    expected = np.array([0.0, -15.9, -15.9, -1.4, 0.0, 0.0])
    np.testing.assert_allclose(gravity_torques(HOME_POSE), expected, atol=0.1)


def test_payload_adds_the_torque_of_a_point_mass_at_the_flange(model):
    payload = 3.0
    data = mujoco.MjData(model)
    index = ArmIndex.of(model)
    index.set_link_pose(data, HOME_POSE)
    mujoco.mj_forward(model, data)
    jac = np.zeros((3, model.nv))
    mujoco.mj_jacSite(model, data, jac, None, model.site("tool_flange").id)
    expected = jac[:, index.motor_dof].T @ np.array([0.0, 0.0, payload * 9.81])
    added = gravity_torques(HOME_POSE, payload) - gravity_torques(HOME_POSE)
    np.testing.assert_allclose(added, expected, atol=1e-6)
    assert added[1] < -5.0  # the lift joint carries it


def test_gravity_torques_rejects_bad_input():
    with pytest.raises(ValueError, match="shape"):
        gravity_torques(np.zeros(5))
    with pytest.raises(ValueError, match="payload"):
        gravity_torques(HOME_POSE, -1.0)


def test_drive_overrides_edit_the_named_joint_only():
    edited = build_model(
        drive_overrides={"elbow": {"frictionloss": 7.0, "stiffness": 5000.0, "backlash": 0.001}}
    )
    index = ArmIndex.of(edited)
    j = JOINT_NAMES.index("elbow")
    assert edited.dof_frictionloss[index.motor_dof[j]] == 7.0
    assert edited.tendon_stiffness[index.tendon[j]] == 5000.0
    np.testing.assert_allclose(edited.tendon_lengthspring[index.tendon[j]], [-0.001, 0.001])
    assert edited.dof_frictionloss[index.motor_dof[0]] != 7.0
    with pytest.raises(KeyError, match="unknown joint"):
        build_model(drive_overrides={"knee": {"damping": 1.0}})
    with pytest.raises(KeyError, match="unknown drive parameters"):
        build_model(drive_overrides={"elbow": {"stifness": 1.0}})


def test_missing_scene_is_a_clear_error(tmp_path: Path):
    with pytest.raises(FileNotFoundError, match="scene file not found"):
        build_model(scene=tmp_path / "nope.xml")
