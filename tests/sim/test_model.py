"""The built UR5e: compiles, steps cleanly, takes drive overrides (every arm: test_arms.py)."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from robohealth_mj.common.errors import InputError
from robohealth_mj.schema import JOINT_NAMES
from robohealth_mj.sim.dynamics import gravity_torques
from robohealth_mj.sim.model import HOME_POSE, ArmIndex, build_model


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


def _creep(model: mujoco.MjModel, seconds: float = 2.0) -> float:
    """How far the base's motor turns in ``seconds`` pushed at half its dry friction, with the
    servo off and no gravity: a sticking joint stays put, a creeping one does not."""
    model.opt.gravity[:] = 0.0
    model.actuator_gainprm[:] = 0.0
    model.actuator_biasprm[:] = 0.0
    data = mujoco.MjData(model)
    dof = ArmIndex.of(model).motor_dof[0]
    data.qfrc_applied[dof] = 0.5 * model.dof_frictionloss[dof]
    for _ in range(round(seconds / model.opt.timestep)):
        mujoco.mj_step(model, data)
    return abs(float(data.qpos[model.jnt_qposadr[model.dof_jntid[dof]]]))


def test_a_stiff_friction_constraint_makes_a_joint_stick_where_the_default_creeps():
    soft = _creep(build_model())
    stiff = build_model(
        friction_solref=[0.002, 1.0], friction_solimp=[0.999, 0.9999, 0.001, 0.5, 2]
    )
    assert soft > 1e-3  # MuJoCo's default dry friction gives way below its limit
    assert _creep(stiff) < soft / 50
    index = ArmIndex.of(stiff)
    np.testing.assert_allclose(stiff.dof_solref[index.motor_dof], [[0.002, 1.0]] * 6)
    np.testing.assert_allclose(
        stiff.dof_solref[index.deflection_dof], build_model().dof_solref[index.deflection_dof]
    )
    for bad in ({"friction_solref": [0.0005, 1.0]}, {"friction_solref": [0.01]},
                {"friction_solimp": [0.9, 1.0, 0.001, 0.5, 2]}):  # fmt: skip
        with pytest.raises(InputError, match=r"sim\.friction_sol"):
            build_model(**bad)
