"""Bring your own arm: ``arm=path/to/arm.urdf``. A five-joint arm the test writes (a world
mount, axes about z and y, an endless joint, a flange) is read with its ratings, built into the
simulator's model, and its gravity torques agree with MuJoCo reading the user's file itself;
each thing a serial arm cannot be is one line naming the element."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from robohealth_mj.arms.chain import gravity_torques
from robohealth_mj.arms.description import load_arm
from robohealth_mj.common.errors import InputError
from robohealth_mj.sim.model import build_model

JOINTS = [  # name, origin xyz, axis, limit (None: continuous), effort, velocity, link mass
    ("j1", "0 0 0.2", "0 0 1", (-3.0, 3.0), 60, 2.0, 3.0),
    ("j2", "0 0.05 0.1", "0 1 0", (-2.0, 2.0), 60, 2.0, 2.5),
    ("j3", "0.3 0 0", "0 1 0", (-2.5, 2.5), 30, 2.5, 1.5),
    ("j4", "0.25 0 0", "0 1 0", (-2.0, 2.0), 10, 3.0, 0.8),
    ("j5", "0.05 0 0", "0 0 1", None, 10, 3.0, 0.4),
]


def _inertial(mass: float, com: str) -> str:
    m = mass * 1e-2
    moments = f'ixx="{m}" iyy="{m}" izz="{m / 2}" ixy="0" ixz="0" iyz="0"'
    return (f'<inertial><origin xyz="{com}" rpy="0 0 0"/><mass value="{mass}"/>'
            f"<inertia {moments}/></inertial>")  # fmt: skip


def write_arm(folder, payload: float | None = 2.0, edit=lambda text: text, ratings: str = ""):
    parts = ['<robot name="toy"><link name="world"/><link name="base">',
             _inertial(4.0, "0 0 0.05"), '</link><joint name="mount" type="fixed">',
             '<parent link="world"/><child link="base"/><origin xyz="0 0 0.1" rpy="0 0 0"/>',
             "</joint>"]  # fmt: skip
    parent = "base"
    for name, xyz, axis, bounds, effort, velocity, mass in JOINTS:
        link = f"l{name[1]}"
        kind = "continuous" if bounds is None else "revolute"
        span = "" if bounds is None else f'lower="{bounds[0]}" upper="{bounds[1]}" '
        parts += [f'<link name="{link}">{_inertial(mass, "0.1 0.01 0.02")}</link>',
                  f'<joint name="{name}" type="{kind}"><parent link="{parent}"/>',
                  f'<child link="{link}"/><origin xyz="{xyz}" rpy="0 0 0"/>',
                  f'<axis xyz="{axis}"/><limit {span}effort="{effort}" velocity="{velocity}"/>',
                  "</joint>"]  # fmt: skip
        parent = link
    parts += ['<link name="tool"/><joint name="flange" type="fixed"><parent link="l5"/>',
              '<child link="tool"/><origin xyz="0 0 0.04" rpy="0 0 0"/></joint>',
              "</robot>"]  # fmt: skip
    path = folder / "toy.urdf"
    path.write_text(edit("".join(parts)))
    if payload is not None or ratings:
        text = (f"payload_kg: {payload}\n" if payload is not None else "") + ratings
        (folder / "toy.ratings.yaml").write_text(text)
    return path


def test_a_users_urdf_is_an_arm_with_its_ratings(tmp_path):
    arm = load_arm(str(write_arm(tmp_path)))
    assert arm.n_joints == 5 and arm.joint_keys == ("j1", "j2", "j3", "j4", "j5")
    np.testing.assert_array_equal(arm.rated_torque, [60, 60, 30, 10, 10])
    np.testing.assert_array_equal(arm.speed_limit, [2.0, 2.0, 2.5, 3.0, 3.0])
    assert np.isinf(arm.position_limit[4]).all() and arm.position_limit[2, 1] == 2.5
    assert arm.payload_kg == 2.0 and arm.reach_m == pytest.approx(np.hypot(0.6, 0.05), rel=0.2)
    np.testing.assert_array_equal(arm.flange_xyz, [0, 0, 0.04])


def test_the_built_model_holds_the_torques_mujoco_reads_from_the_users_file(tmp_path):
    path = write_arm(tmp_path)
    arm, model = load_arm(str(path)), build_model(str(path))
    model.body_mass[model.body("payload").id] = 0.0  # the user's file carries no payload
    theirs_model = mujoco.MjModel.from_xml_path(str(path))  # MuJoCo's own URDF importer
    ours, theirs = mujoco.MjData(model), mujoco.MjData(theirs_model)
    motor = [model.joint(f"{k}_joint").dofadr[0] for k in arm.joint_keys]
    for q in ([0.0, 0.5, -0.8, 0.4, 1.0], [1.2, -0.7, 1.5, -1.0, -2.0], [0.0] * 5):
        ours.qpos[:] = 0.0
        ours.qpos[[model.joint(f"{k}_joint").qposadr[0] for k in arm.joint_keys]] = q
        theirs.qpos[:] = q
        mujoco.mj_forward(model, ours), mujoco.mj_forward(theirs_model, theirs)
        model_tau, chain_tau = ours.qfrc_bias[motor], gravity_torques(arm, np.array(q))
        scale = np.max(np.abs(theirs.qfrc_bias))
        assert np.max(np.abs(model_tau - theirs.qfrc_bias)) <= 0.005 * scale
        assert np.max(np.abs(chain_tau - theirs.qfrc_bias)) <= 0.005 * scale


@pytest.mark.parametrize(
    ("edit", "payload", "ratings", "said"),
    [
        (
            lambda t: t.replace(
                '<joint name="j5"',
                '<joint name="j4b" type="revolute">'
                '<parent link="l3"/><child link="x"/><axis xyz="0 0 1"/><limit '
                'effort="1" velocity="1"/></joint><link name="x">'
                + _inertial(0.1, "0 0 0")
                + '</link><joint name="j5"',
            ),
            2.0,
            "",
            "link 'l3' has 2 moving child joints (j4, j4b): a serial arm has one",
        ),
        (
            lambda t: t.replace(
                f'<link name="l3">{_inertial(1.5, "0.1 0.01 0.02")}</link>', '<link name="l3"/>'
            ),
            2.0,
            "",
            "link 'l3': no <inertial> with mass and inertia",
        ),
        (
            lambda t: t.replace('effort="30" velocity="2.5"', 'velocity="2.5"'),
            2.0,
            "",
            "joint 'j3': no effort rating",
        ),
        (
            lambda t: t.replace(
                '<joint name="j2" type="revolute"', '<joint name="j2" type="prismatic"'
            ),
            2.0,
            "",
            "joint 'j2' is prismatic: an arm of revolute joints only",
        ),
        (lambda t: t, None, "", "no rated payload: write payload_kg"),
        (lambda t: t[:40], 2.0, "", "not a readable URDF"),
    ],
    ids=["tree", "no_inertial", "no_effort", "prismatic", "no_payload", "not_xml"],
)
def test_what_a_serial_arm_cannot_be_is_one_line_naming_it(tmp_path, edit, payload, ratings, said):
    path = write_arm(tmp_path, payload=payload, edit=edit, ratings=ratings)
    with pytest.raises(InputError, match=said.replace("(", r"\(").replace(")", r"\)")) as info:
        load_arm(str(path))
    assert "\n" not in str(info.value) and str(path) in str(info.value)


def test_a_missing_rating_may_come_from_the_ratings_file(tmp_path):
    path = write_arm(tmp_path, edit=lambda t: t.replace('effort="30" velocity="2.5"',
                                                        'velocity="2.5"'),
                     ratings="joints: {j3: {effort: 25}}\n")  # fmt: skip
    assert load_arm(str(path)).rated_torque[2] == 25.0
