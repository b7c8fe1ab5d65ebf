"""Arms of any joint count as data: the seven-joint FR3 read from this project's own description,
its gravity torques from the description's chain (URDF frames) against an independent
computation from the maker's other publication of the same arm (Franka's DH table, Craig's
convention). The chain code is checked on every UR arm against UR's DH table in
tests/sim/test_arms.py."""

from __future__ import annotations

import numpy as np
import pytest

from robohealth_mj.arms.chain import GRAVITY, gravity_torques
from robohealth_mj.arms.description import load_arm
from robohealth_mj.common.errors import InputError

# Franka's published DH table of the FR3 (frankaemika.github.io/docs, "Denavit-Hartenberg
# parameters", Craig's convention): a_{i-1}, d_i, alpha_{i-1} per joint, then the flange.
FR3_DH = {
    "a": [0.0, 0.0, 0.0, 0.0825, -0.0825, 0.0, 0.088, 0.0],
    "d": [0.333, 0.0, 0.316, 0.0, 0.384, 0.0, 0.0, 0.107],
    "alpha": [0.0, -np.pi / 2, np.pi / 2, np.pi / 2, -np.pi / 2, np.pi / 2, np.pi / 2, 0.0],
}
POSES = {
    "ready": [0.0, -np.pi / 4, 0.0, -3 * np.pi / 4, 0.0, np.pi / 2, np.pi / 4],
    "stretched": [0.0, 1.2, 0.0, -0.3, 0.0, 1.5, 0.0],
    "twisted": [0.8, -0.6, 1.1, -2.0, -1.4, 2.2, -0.7],
    "folded": [-1.5, 1.5, -2.0, -2.8, 2.0, 0.8, 2.5],
}


def craig_frames(dh: dict, q: np.ndarray) -> list[np.ndarray]:
    """Base -> frame i (i = 1..7, then the flange), modified DH: Rx(alpha) Tx(a) Rz(q) Tz(d)."""
    frames, current = [], np.eye(4)
    for i, (a, d, alpha) in enumerate(zip(dh["a"], dh["d"], dh["alpha"], strict=True)):
        angle = q[i] if i < len(q) else 0.0
        ca, sa, ct, st = np.cos(alpha), np.sin(alpha), np.cos(angle), np.sin(angle)
        step = np.array([
            [ct, -st, 0.0, a],
            [st * ca, ct * ca, -sa, -sa * d],
            [st * sa, ct * sa, ca, ca * d],
            [0.0, 0.0, 0.0, 1.0],
        ])  # fmt: skip
        current = current @ step
        frames.append(current)
    return frames


def craig_gravity_torques(arm, q: np.ndarray, payload_kg: float = 0.0) -> np.ndarray:
    """The holding torques from Franka's DH frames (the link frames the inertials are given in)."""
    frames = craig_frames(FR3_DH, q)
    points = [
        (f @ np.append(link.com, 1.0))[:3] for f, link in zip(frames[:7], arm.links, strict=True)
    ]
    points.append(frames[-1][:3, 3])
    masses = [link.mass for link in arm.links] + [payload_kg]
    tau = np.zeros(7)
    for j in range(7):
        axis, origin = frames[j][:3, 2], frames[j][:3, 3]
        for m, p in zip(masses[j:], points[j:], strict=True):
            tau[j] += m * GRAVITY * np.cross(axis, p - origin)[2]
    return tau


def test_the_fr3_is_seven_joints_with_its_drivers_names_and_ratings():
    fr3 = load_arm("fr3")
    assert fr3.n_joints == 7 and fr3.maker == "Franka Robotics" and fr3.torque_sensors
    assert fr3.joint_names == tuple(f"fr3_joint{k}" for k in range(1, 8))
    np.testing.assert_array_equal(fr3.rated_torque, [87, 87, 87, 87, 12, 12, 12])
    np.testing.assert_array_equal(fr3.speed_limit, [2.62, 2.62, 2.62, 2.62, 5.26, 4.18, 5.26])
    assert fr3.payload_kg == 3.0 and sum(link.mass for link in fr3.links) == pytest.approx(
        15.49, abs=0.01
    )


@pytest.mark.parametrize("pose", POSES)
@pytest.mark.parametrize("payload", [0.0, 3.0])
def test_fr3_gravity_torques_agree_with_frankas_dh_table(pose, payload):
    fr3 = load_arm("fr3")
    q = np.array(POSES[pose])
    ours, theirs = gravity_torques(fr3, q, payload), craig_gravity_torques(fr3, q, payload)
    assert np.max(np.abs(ours - theirs)) <= 0.005 * np.max(np.abs(theirs))
    assert np.max(np.abs(theirs)) > 5.0  # a pose that loads the arm, not a trivial zero


def test_a_description_with_a_bad_field_is_one_line_naming_it(tmp_path, monkeypatch):
    arm = tmp_path / "myarm"
    arm.mkdir()
    text = (load_arm("fr3").source / "arm.yaml").read_text().replace("name: fr3", "name: myarm")
    (arm / "arm.yaml").write_text(text.replace("mass: 2.9274653454", "mass: heavy", 1))
    monkeypatch.setenv("ROBOHEALTH_ASSETS", str(tmp_path))
    with pytest.raises(InputError, match=r"arm.yaml: field joints.0.mass is not a number"):
        load_arm("myarm")


def _urdf(arm, payload_kg: float) -> str:
    """The description as a URDF (the maker's own format), for MuJoCo's URDF importer: a second
    computation of the same published numbers, through code that shares nothing with ours."""

    def inertial(mass, com, inertia) -> str:
        i = inertia
        moments = (f'ixx="{i[0, 0]}" iyy="{i[1, 1]}" izz="{i[2, 2]}" ixy="{i[0, 1]}" '
                   f'ixz="{i[0, 2]}" iyz="{i[1, 2]}"')  # fmt: skip
        return (f'<inertial><origin xyz="{" ".join(map(str, com))}" rpy="0 0 0"/>'
                f'<mass value="{mass}"/><inertia {moments}/></inertial>')  # fmt: skip

    base = inertial(1.0, [0, 0, 0], np.eye(3) * 1e-3)
    parts = ['<robot name="arm"><mujoco><compiler balanceinertia="true" discardvisual="true"/>'
             f'</mujoco><link name="l0">{base}</link>']  # fmt: skip
    for k, link in enumerate(arm.links, start=1):
        parts.append(f'<link name="l{k}">{inertial(link.mass, link.com, link.inertia)}</link>')
        parts.append(
            f'<joint name="j{k}" type="revolute"><parent link="l{k - 1}"/><child link="l{k}"/>'
            f'<origin xyz="{" ".join(map(str, link.origin_xyz))}" '
            f'rpy="{" ".join(map(str, link.origin_rpy))}"/>'
            f'<axis xyz="{" ".join(map(str, link.axis))}"/>'
            '<limit lower="-10" upper="10" effort="1000" velocity="10"/></joint>'
        )
    if payload_kg:
        parts.append(f'<link name="payload">{inertial(payload_kg, [0, 0, 0], np.eye(3) * 1e-6)}'
                     f'</link><joint name="flange" type="fixed"><parent link="l{arm.n_joints}"/>'
                     f'<child link="payload"/><origin xyz="{" ".join(map(str, arm.flange_xyz))}"'
                     ' rpy="0 0 0"/></joint>')  # fmt: skip
    return "".join(parts) + "</robot>"


@pytest.mark.parametrize("name", ["fr3", "iiwa14", "gen3", "xarm7"])
def test_gravity_torques_agree_with_mujoco_reading_the_makers_urdf(name):
    """Every seven-joint arm: the chain's holding torques at four poses within its limits, with
    and without the rated payload, against MuJoCo's own URDF import (qfrc_bias at rest)."""
    mujoco = pytest.importorskip("mujoco")
    arm = load_arm(name)
    limits = np.where(np.isfinite(arm.position_limit), arm.position_limit, [-np.pi, np.pi])
    low, high = limits[:, 0], limits[:, 1]  # a joint without limits: one turn
    poses = [low + f * (high - low) for f in (0.5, 0.3, 0.7)] + [low + 0.9 * (high - low)]
    for payload in (0.0, arm.payload_kg):
        model = mujoco.MjModel.from_xml_string(_urdf(arm, payload))
        data = mujoco.MjData(model)
        for q in poses:
            data.qpos[:] = q
            mujoco.mj_forward(model, data)
            ours, theirs = gravity_torques(arm, q, payload), data.qfrc_bias.copy()
            assert np.max(np.abs(ours - theirs)) <= 0.005 * np.max(np.abs(theirs)), (q, payload)


def test_the_iiwa14_carries_kukas_ratings_and_its_drivers_names():
    iiwa = load_arm("iiwa14")
    assert iiwa.n_joints == 7 and iiwa.maker == "KUKA" and iiwa.torque_sensors
    np.testing.assert_array_equal(iiwa.rated_torque, [320, 320, 176, 176, 110, 40, 40])
    assert iiwa.payload_kg == 14.0
    assert iiwa.base_mass + sum(link.mass for link in iiwa.links) == pytest.approx(29.9, abs=0.01)
    assert [tuple(link.axis) for link in iiwa.links][1] == (0.0, 1.0, 0.0)


def test_the_gen3_is_kinovas_with_the_vision_module_and_four_endless_joints():
    gen3 = load_arm("gen3")
    assert gen3.n_joints == 7 and gen3.maker == "Kinova" and gen3.payload_kg == 4.0
    np.testing.assert_array_equal(gen3.rated_torque, [39, 39, 39, 39, 9, 9, 9])
    assert np.isinf(gen3.position_limit[[0, 2, 4, 6]]).all()
    assert np.isfinite(gen3.position_limit[[1, 3, 5]]).all()
    assert gen3.links[-1].mass == 0.5  # the bracelet with the vision module (0.364 kg without)
    assert gen3.base_mass + sum(link.mass for link in gen3.links) == pytest.approx(8.19, abs=0.01)


def test_a_limit_with_one_bound_is_refused(tmp_path, monkeypatch):
    arm = tmp_path / "halfarm"
    arm.mkdir()
    text = (load_arm("gen3").source / "arm.yaml").read_text().replace("name: gen3", "name: halfarm")
    (arm / "arm.yaml").write_text(
        text.replace("limit: {velocity: 1.3963", "limit: {lower: -1, velocity: 1.3963", 1)
    )
    monkeypatch.setenv("ROBOHEALTH_ASSETS", str(tmp_path))
    with pytest.raises(InputError, match=r"joints.0.limit needs lower and upper, or neither"):
        load_arm("halfarm")


def test_the_xarm7_is_ufactorys_with_no_torque_sensors():
    xarm = load_arm("xarm7")
    assert xarm.n_joints == 7 and xarm.maker == "UFACTORY" and not xarm.torque_sensors
    np.testing.assert_array_equal(xarm.rated_torque, [50, 50, 30, 30, 30, 20, 20])
    assert xarm.joint_names == tuple(f"joint{k}" for k in range(1, 8)) and xarm.payload_kg == 3.5
