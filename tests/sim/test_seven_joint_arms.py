"""The builder on arms of another joint count (the four seven-joint arms of assets/): the body
tree, drives and sensors per joint, the compiled model's gravity torques against the
description's chain (itself checked against the makers' other publications and MuJoCo's URDF
importer in tests/arms), and a held pose that stays put at the simulation's time step."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from robohealth_mj.arms.chain import gravity_torques
from robohealth_mj.arms.description import load_arm
from robohealth_mj.sim.model import build_model

SEVEN = ("fr3", "iiwa14", "gen3", "xarm7")


def _pose(model: mujoco.MjModel, keys: tuple[str, ...], q: np.ndarray) -> np.ndarray:
    qpos = np.zeros(model.nq)  # the deflection hinges at rest
    for key, angle in zip(keys, q, strict=True):
        qpos[model.joint(f"{key}_joint").qposadr[0]] = angle
    return qpos


@pytest.mark.parametrize("name", SEVEN)
def test_the_builder_gives_every_joint_its_drive_sensor_and_servo(name):
    arm, model = load_arm(name), build_model(name)
    assert model.njnt == 2 * arm.n_joints and model.nu == arm.n_joints  # motor + deflection
    for key, body in zip(arm.joint_keys, arm.link_bodies, strict=True):
        assert model.joint(f"{key}_deflection").bodyid[0] == model.body(body).id
        model.sensor(f"{key}_acc"), model.sensor(f"{key}_effort"), model.tendon(f"{key}_drive")
    np.testing.assert_allclose(model.actuator_forcerange[:, 1], arm.rated_torque)
    home = model.key("home").qpos[::2]
    assert np.all(home >= arm.position_limit[:, 0]) and np.all(home <= arm.position_limit[:, 1])


@pytest.mark.parametrize("name", ("ur5e", *SEVEN))
def test_every_sensor_package_reads_along_its_joint_axis_on_z(name):
    """Whatever the maker's link frames (KUKA's pitch joints turn about y, the others' about z),
    each accelerometer's z is its joint's axis and it sits off the axis on its link: so at the
    home pose a pitch joint's package reads gravity across the axis, never along it, on every
    arm, and a model trained on some makers reads another's packages in the same frame."""
    arm, model = load_arm(name), build_model(name)
    data = mujoco.MjData(model)
    data.qpos[:] = model.key("home").qpos
    mujoco.mj_forward(model, data)
    for key in arm.joint_keys:
        site, joint = model.site(f"{key}_sensor").id, model.joint(f"{key}_joint").id
        z = data.site_xmat[site].reshape(3, 3)[:, 2]
        np.testing.assert_allclose(z, data.xaxis[joint], atol=1e-9)
        offset = data.site_xpos[site] - data.xanchor[joint]
        assert np.linalg.norm(offset - (offset @ z) * z) > 0.02  # off the axis, on the link
    data.qacc[:] = 0.0  # held still: the accelerometer reads gravity (up) in its mount frame
    mujoco.mj_inverse(model, data)
    pitch = [k for k in arm.joint_keys if abs(data.xaxis[model.joint(f"{k}_joint").id][2]) < 0.1]
    assert len(pitch) >= 2
    for key in pitch:
        reading = data.sensor(f"{key}_acc").data
        assert abs(reading[2]) < 0.5 and np.hypot(reading[0], reading[1]) > 9.5


@pytest.mark.parametrize("name", SEVEN)
def test_the_models_gravity_torques_are_the_descriptions(name):
    """Four poses within the limits (an endless joint across one turn), without and with the
    rated payload: the compiled model's holding torques within 0.5 % of the chain's."""
    arm, model = load_arm(name), build_model(name)
    data = mujoco.MjData(model)
    motor = [model.joint(f"{k}_joint").dofadr[0] for k in arm.joint_keys]
    limits = np.where(np.isfinite(arm.position_limit), arm.position_limit, [-np.pi, np.pi])
    for payload in (0.0, arm.payload_kg):
        model.body_mass[model.body("payload").id] = payload
        for f in (0.5, 0.3, 0.7, 0.9):
            q = limits[:, 0] + f * (limits[:, 1] - limits[:, 0])
            data.qpos[:], data.qvel[:] = _pose(model, arm.joint_keys, q), 0.0
            mujoco.mj_forward(model, data)
            ours, chain = data.qfrc_bias[motor], gravity_torques(arm, q, payload)
            assert np.max(np.abs(ours - chain)) <= 0.005 * np.max(np.abs(chain)), (q, payload)


@pytest.mark.parametrize("name", SEVEN)
def test_a_held_pose_with_the_rated_payload_stays_put_at_the_time_step(name):
    """Home (each joint mid-range: the forearm out, loaded) with the rated payload, under the
    servo and the controller's feed-forward as the recorder drives it."""
    from robohealth_mj.sim.control import TrackingController

    arm, model = load_arm(name), build_model(name)
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    model.body_mass[model.body("payload").id] = arm.payload_kg
    controller = TrackingController(build_model(name))
    controller.set_payload(arm.payload_kg)
    home, rest = arm.home_pose()[None], np.zeros((1, arm.n_joints))
    data.ctrl[:] = controller.commands(home, rest, rest)[0][0]
    for _ in range(3000):  # 3 s at 1 kHz under the servo
        mujoco.mj_step(model, data)
    assert not any(w.number for w in data.warning) and np.all(np.isfinite(data.qpos))
    assert np.max(np.abs(data.qvel)) < 1e-2
    moved = data.qpos[::2] + data.qpos[1::2] - model.key("home").qpos[::2]
    assert np.max(np.abs(moved)) < 2e-3  # rad: the servo holds the weight


def test_another_arms_joints_take_the_ur5e_drive_of_their_class():
    fr3 = load_arm("fr3")  # 87 N m x 4, 12 N m x 3
    assert list(fr3.ur_counterparts()) == [
        "shoulder_lift", "shoulder_lift", "shoulder_lift", "shoulder_lift", "wrist_2", "wrist_2",
        "wrist_3",
    ]  # fmt: skip
    assert load_arm("ur10e").ur_counterparts() == load_arm("ur5e").joint_keys  # each its own


@pytest.mark.parametrize("name", SEVEN)
def test_the_index_and_the_nominal_model_serve_any_joint_count(name):
    """ArmIndex reads the joints from the model's servos; the controller's nominal model gives
    the holding torques of the chain (sim/dynamics.gravity_torques on a seven-joint arm)."""
    from robohealth_mj.sim.dynamics import gravity_torques as model_gravity
    from robohealth_mj.sim.model import ArmIndex

    arm = load_arm(name)
    index = ArmIndex.of(build_model(name))
    assert index.motor_dof.shape == (7,) and index.acc_sensor.shape == (7, 3)
    q = arm.home_pose() + 0.3
    np.testing.assert_allclose(
        model_gravity(q, arm.payload_kg, arm=name), gravity_torques(arm, q, arm.payload_kg),
        rtol=1e-9, atol=1e-9,
    )  # fmt: skip
    with pytest.raises(ValueError, match=r"shape \(7,\)"):
        model_gravity(np.zeros(6), arm=name)


@pytest.mark.parametrize("name", SEVEN)
def test_record_arm_records_the_arms_seven_joint_graph(name, record_cfg, tmp_path):
    """``record arm=<arm>``: a session on the arm's own graph, its joints by the maker's names,
    every line valid, the fault schedule over its seven joints, tracking in the UR5e's range."""
    from robohealth_mj.data.read import read_samples
    from robohealth_mj.recording.recorder import record_session

    arm = load_arm(name)
    result = record_session(record_cfg(f"arm={name}", "session.duration_s=3"), tmp_path)
    graph = result.manifest["graph"]
    assert graph["joints"] == list(arm.joint_keys) and len(graph["nodes"]) == 14
    samples = list(read_samples(tmp_path / "graphs.jsonl"))
    assert len(samples) == 60 and all(s.graph.joints == arm.joint_keys for s in samples)
    assert result.manifest["faults"]["schedule"]["scenarios_per_pass"] == 7 * 6 * 3
    assert max(result.manifest["stats"]["tracking_rms_rad"].values()) < 2e-3


def test_an_arm_with_joint_torque_sensors_reports_the_link_side_torque(record_cfg):
    """The FR3's controller reports its joints' torque sensors (the drive's output on the link)
    and its model of that torque: the healthy residual is the sensor's noise, while the same arm
    read from its motors' currents (``sensors.joint_torque=false``) carries the friction its
    model only approximates."""
    from robohealth_mj.recording.recorder import build_simulator

    residual = {}
    for sensed, setting in ((True, "null"), (False, "false")):  # the arm's sensors; its motors
        sim = build_simulator(
            record_cfg("arm=fr3", "faults=none", f"sensors.joint_torque={setting}")
        )
        assert sim.torque_sensors is sensed
        chunks = list(sim.run(100))
        r = np.concatenate([c.effort_residual for c in chunks])
        residual[sensed] = float(np.sqrt(np.mean(r**2)))
        if sensed:  # what the sensor reads is what the drive's compliance carries
            last = chunks[-1]
            assert np.abs(last.effort - last.effort_residual).max() > 0.5  # a real torque
    assert residual[True] < 0.1 and residual[True] < 0.5 * residual[False], residual


def test_the_contact_watch_places_a_push_on_a_seven_joint_arms_links():
    """Commissioning's contact placing reads the arm's own chain: seven joints, every link's
    surface; a push at a point of the sixth link, pressing along its inward normal, is placed
    on a link at or beyond it (the joints before cannot tell it from one further out)."""
    from robohealth_mj.arms.contact_place import place
    from robohealth_mj.sim.contact_surface import arm_surface

    surface = arm_surface("fr3")
    assert surface.axis.shape == (7, 3) and set(np.unique(surface.link)) == set(range(7))
    q = load_arm("fr3").home_pose()
    lever, normal = surface.lever(q)
    k = int(np.flatnonzero(surface.link == 5)[0])
    torque = lever[k] @ (-20.0 * normal[k])  # 20 N pressing on the point
    where = place(surface, q, torque, np.full(7, 0.05))
    assert len(where.chi2) == 7 and where.joint >= 5
