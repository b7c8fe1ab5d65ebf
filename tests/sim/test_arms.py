"""Every arm built from its description: UR's numbers in the model, gravity torques as UR's DH
table gives them, drives scaled by one rule, stable and tracking like the UR5e."""

from __future__ import annotations

import shutil
from pathlib import Path

import mujoco
import numpy as np
import pytest
from hydra import compose, initialize_config_dir

from robohealth_mj.arms.description import LINK_BODIES, known_arms, load_arm
from robohealth_mj.common.errors import InputError
from robohealth_mj.common.resources import conf_dir
from robohealth_mj.recording.recorder import build_simulator, record_session
from robohealth_mj.schema import JOINT_NAMES
from robohealth_mj.sim.dynamics import gravity_torques
from robohealth_mj.sim.model import HOME_POSE, ArmIndex, build_model, default_drives

# An independent computation of the gravity torques: UR's DH table, with the link masses and centres
# of mass in the DH frames, and plain numpy forward kinematics. It shares no code and no frame
# convention with the MuJoCo builder (which reads UR's URDF-frame files).
G = 9.81


def dh_frames(dh: dict, q: np.ndarray) -> list[np.ndarray]:
    """Homogeneous transforms base -> frame i, i = 0..6 (standard DH)."""
    frames = [np.eye(4)]
    for i in range(6):
        ct, st = np.cos(q[i]), np.sin(q[i])
        ca, sa = np.cos(dh["alpha"][i]), np.sin(dh["alpha"][i])
        step = np.array([
            [ct, -st * ca, st * sa, dh["a"][i] * ct],
            [st, ct * ca, -ct * sa, dh["a"][i] * st],
            [0.0, sa, ca, dh["d"][i]],
            [0.0, 0.0, 0.0, 1.0],
        ])  # fmt: skip
        frames.append(frames[-1] @ step)
    return frames


def dh_gravity_torques(dh: dict, q: np.ndarray, payload_kg: float = 0.0) -> np.ndarray:
    """Torques (N m) that hold the arm still at ``q``, a point payload at the flange."""
    frames = dh_frames(dh, np.asarray(q, dtype=float))
    points = [(frames[i + 1] @ np.append(dh["com"][i], 1.0))[:3] for i in range(6)]
    masses = list(dh["mass"])
    points.append(frames[6][:3, 3])
    masses.append(payload_kg)
    tau = np.zeros(6)
    for i in range(6):
        axis, origin = frames[i][:3, 2], frames[i][:3, 3]
        for m, p in zip(masses[i:], points[i:], strict=True):  # the links joint i carries
            tau[i] += m * G * np.cross(axis, p - origin)[2]
    return tau


ARMS = ("ur3e", "ur5e", "ur10e", "ur16e", "ur20", "ur30")
POSES = {
    "home": HOME_POSE,
    "zero": np.zeros(6),
    "reaching": np.array([0.0, -1.0, 0.5, -1.0, 1.0, 0.3]),
    "folded": np.array([0.5, -2.0, 1.2, 0.4, -0.8, 1.0]),
}


@pytest.mark.parametrize("arm", ARMS)
def test_the_description_chain_gives_urs_dh_table_gravity(arm):
    """arms/chain.py (URDF frames, any joint count) against UR's DH table on every UR arm."""
    from robohealth_mj.arms.chain import gravity_torques as chain_gravity_torques

    ur = load_arm(arm)
    for q in POSES.values():
        for payload in (0.0, ur.payload_kg):
            ours = chain_gravity_torques(ur, np.array(q), payload)
            theirs = dh_gravity_torques(ur.dh, np.array(q), payload)
            assert np.max(np.abs(ours - theirs)) <= 1e-6 * np.max(np.abs(theirs))


def test_the_e_series_arms_ship():
    assert set(ARMS) <= set(known_arms())


@pytest.mark.parametrize("arm", ARMS)
def test_builder_carries_urs_numbers(arm):
    desc, model = load_arm(arm), build_model(arm)
    index = ArmIndex.of(model)
    assert model.nv == 12 and model.nu == 6
    for body, link in zip(LINK_BODIES, desc.links, strict=True):
        assert model.body(body).mass[0] == pytest.approx(link.mass)
    np.testing.assert_allclose(index.torque_limit, desc.rated_torque)
    for j, joint in enumerate(JOINT_NAMES):
        limited = np.all(np.isfinite(desc.position_limit[j]))
        assert bool(model.jnt_limited[model.joint(f"{joint}_joint").id]) == limited
        if limited:
            np.testing.assert_allclose(model.joint(f"{joint}_joint").range, desc.position_limit[j])
    assert {"front", "side", "top"} <= {model.camera(i).name for i in range(model.ncam)}


@pytest.mark.parametrize("arm", ARMS)
def test_gravity_torques_match_urs_dh_table_within_half_a_percent(arm):
    desc = load_arm(arm)
    for payload in (0.0, desc.payload_kg):
        for pose, q in POSES.items():
            ours = gravity_torques(q, payload, arm=arm)
            theirs = dh_gravity_torques(desc.dh, q, payload)
            loaded = np.abs(theirs) > 0.01 * desc.rated_torque  # joints that carry load
            assert loaded.sum() >= 2, pose
            # within 0.5 % (of 1 % of the rating, on a joint that carries next to nothing)
            scale = np.maximum(np.abs(theirs), 0.01 * desc.rated_torque)
            assert np.all(np.abs(ours - theirs) <= 0.005 * scale), (pose, payload, ours, theirs)


def test_the_independent_check_can_fail():
    """A UR10e computed with the UR5e's table is far off: the comparison has teeth."""
    q = POSES["zero"]
    wrong = dh_gravity_torques(load_arm("ur5e").dh, q)
    assert abs(gravity_torques(q, arm="ur10e")[1] - wrong[1]) > 0.5 * abs(wrong[1])


def test_ur5e_keeps_its_drives_pose_and_sensors():
    """The UR5e built from UR's files is the old UR5e but for the inertials: same drive model, the
    same tool position at home (to 2 mm: UR's calibrated kinematics), the same named parts."""
    model = build_model("ur5e")
    index = ArmIndex.of(model)
    reference = default_drives().reference
    for j, joint in enumerate(JOINT_NAMES):
        assert model.actuator_gainprm[index.actuator[j], 0] == reference[joint]["kp"]
        assert model.tendon_stiffness[index.tendon[j]] == reference[joint]["stiffness"]
        assert model.dof_frictionloss[index.motor_dof[j]] == reference[joint]["frictionloss"]
    data = mujoco.MjData(model)
    index.set_link_pose(data, HOME_POSE)
    mujoco.mj_forward(model, data)
    np.testing.assert_allclose(data.site("tool_flange").xpos, [0.492, 0.134, 0.488], atol=0.002)
    # gravity at home, UR's parameters: the shoulder lift and elbow hold 20.3 N m (was 15.9)
    np.testing.assert_allclose(gravity_torques(HOME_POSE)[1:3], [-20.26, -20.26], atol=0.05)


def test_drives_scale_with_the_rated_torque():
    ur5e, ur10e = build_model("ur5e"), build_model("ur10e")
    i5, i10 = ArmIndex.of(ur5e), ArmIndex.of(ur10e)
    ratio = load_arm("ur10e").rated_torque / load_arm("ur5e").rated_torque
    np.testing.assert_allclose(
        ur10e.tendon_stiffness[i10.tendon], ur5e.tendon_stiffness[i5.tendon] * ratio
    )
    np.testing.assert_allclose(
        ur10e.dof_frictionloss[i10.motor_dof], ur5e.dof_frictionloss[i5.motor_dof] * ratio
    )
    # backlash is an angle: the same on every arm
    np.testing.assert_allclose(
        ur10e.tendon_lengthspring[i10.tendon], ur5e.tendon_lengthspring[i5.tendon]
    )


def _record_cfg(arm: str, seconds: float, out: Path):
    with initialize_config_dir(str(conf_dir()), version_base=None):
        return compose(
            "record",
            [f"arm={arm}", f"session.duration_s={seconds}", "seed=5", "faults=none",
             "session.progress=false", f"session.out_dir={out}"],
        )  # fmt: skip


def test_every_arm_is_stable_and_tracks_like_the_ur5e(tmp_path):
    """Ten seconds of curriculum on each arm at the same fraction of its limits: no warning, no
    saturation, tracking error within 2x the UR5e's."""
    rms = {}
    for arm in ARMS:
        result = record_session(_record_cfg(arm, 10.0, tmp_path / arm), tmp_path / arm)
        summary = result.manifest["stats"]
        assert result.manifest["arm_ratings"]["arm"] == arm
        assert sum(summary["torque_saturated_steps"].values()) == 0, arm
        rms[arm] = np.array(list(summary["tracking_rms_rad"].values()))
    for arm in ARMS:
        assert np.all(rms[arm] <= 2.0 * rms["ur5e"] + 1e-5), (arm, rms[arm], rms["ur5e"])


def test_curriculum_scales_to_the_arm(tmp_path):
    ur5e = build_simulator(_record_cfg("ur5e", 1.0, tmp_path)).curriculum
    ur10e = build_simulator(_record_cfg("ur10e", 1.0, tmp_path)).curriculum
    assert ur10e.nominal_payload_kg / ur5e.nominal_payload_kg == pytest.approx(12.5 / 5.0)
    # the UR10e's shoulders are limited to 120 deg/s: two thirds of the UR5e's sweep
    np.testing.assert_allclose(ur10e.amplitude[:2], ur5e.amplitude[:2] * 2 / 3)
    np.testing.assert_allclose(ur10e.amplitude[2:], ur5e.amplitude[2:])
    limits = load_arm("ur10e").speed_limit
    for visit in range(len(ur10e.segments)):
        seg = ur10e.scheduled(visit)
        t = seg.t_start + np.linspace(0, ur10e.segment_s, 400)
        _, qd, _ = ur10e.reference(visit, t)
        assert np.all(np.abs(qd) <= limits), visit


def test_varied_goes_on_top_of_any_arm(tmp_path):
    with initialize_config_dir(str(conf_dir()), version_base=None):
        cfg = compose("record", ["arm=[ur10e,varied]", "seed=4"])
        alone = compose("record", ["arm=varied"])
    sim = build_simulator(cfg)
    assert sim.ratings["arm"] == "ur10e" and sim.arm["friction"]
    assert build_simulator(alone).ratings["arm"] == "ur5e"


def test_bad_or_unknown_arm_is_one_line(tmp_path, monkeypatch):
    with pytest.raises(InputError, match=r"unknown arm 'ur7e'; known: .*ur10e"):
        load_arm("ur7e")
    assets = tmp_path / "assets"
    shutil.copytree(load_arm("ur5e").source.parent, assets)
    limits = assets / "ur5e" / "ur_description" / "joint_limits.yaml"
    limits.write_text(limits.read_text().replace("max_effort: 28.0", "max_efort: 28.0", 1))
    monkeypatch.setenv("ROBOHEALTH_ASSETS", str(assets))
    with pytest.raises(
        InputError, match=r"joint_limits.yaml: missing field joint_limits.wrist_1_joint.max_effort"
    ):
        load_arm("ur5e")


def test_a_model_refuses_another_arms_recordings_in_one_line(tmp_path):
    """The arm rides in each recording's manifest; a model trained on one arm refuses another's
    (evaluate, export and commission all check through check_recordings)."""
    from robohealth_mj import schema
    from robohealth_mj.data.graphs import structural_graph
    from robohealth_mj.learn.checkpoint import check_recordings, training_arms

    files = {}
    for arm in ("ur5e", "ur3e"):
        out = tmp_path / arm
        record_session(_record_cfg(arm, 1.0, out), out)
        files[arm] = out / "graphs.jsonl"
    assert training_arms([files["ur5e"], files["ur3e"]]) == ["ur3e", "ur5e"]
    ckpt = {
        "schema": {
            "version": schema.SCHEMA_VERSION,
            "node_names": list(schema.NODE_NAMES),
            "edges": [list(e) for e in schema.EDGES],
        },
        "graph": structural_graph().as_dict(),
        "arms": training_arms([files["ur5e"]]),
    }
    check_recordings(ckpt, [files["ur5e"]])
    with pytest.raises(
        InputError, match=r"ur3e/graphs.jsonl: a recording of a ur3e; the model was trained on ur5e"
    ):
        check_recordings(ckpt, [files["ur3e"]])
    check_recordings({**ckpt, "arms": ["ur3e", "ur5e"]}, [files["ur3e"]])  # trained on both
