"""Bring your own arm: ``arm=path/to/arm.urdf``. A five-joint arm the test writes (a world
mount, axes about z and y, an endless joint, a flange) is read with its ratings, built into the
simulator's model, and its gravity torques agree with MuJoCo reading the user's file itself;
each thing a serial arm cannot be is one line naming the element."""

from __future__ import annotations

import json
from pathlib import Path

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


@pytest.fixture(scope="module")
def toy_deployed(tmp_path_factory) -> dict[str, Path]:
    """The five-joint arm through the entry points: four short sessions recorded with
    ``arm=<file>``, a small model trained on three and exported."""
    from robohealth_mj.export import main as export_main
    from robohealth_mj.record import main as record_main
    from robohealth_mj.train import main as train_main

    root = tmp_path_factory.mktemp("toy")
    urdf, corpus, run = write_arm(root), root / "corpus", root / "run"
    fast = ["session.progress=false", "faults.schedule.fault_s=1.0",
            "faults.schedule.healthy_s=1.0", "faults.schedule.severities=[0.9]",
            "faults.schedule.joints=[j2,j4]", "session.passes=1"]  # fmt: skip
    for name, seed in {"train_a": 1, "train_b": 2, "train_c": 3, "heldout": 4}.items():
        record_main([f"arm={urdf}", *fast, f"seed={seed}", f"session.out_dir={corpus / name}"])
    train_main([f"data.train=[{corpus}/train_*]", f"data.evaluate.heldout={corpus}/heldout",
                "data.evaluate.probe=null", "trainer.progress=false", "window=8",
                "variant=stgnn_fixed", "model.hidden=8", "trainer.epochs=1",
                f"out_dir={run}"])  # fmt: skip
    export_main([f"ckpt={run / 'best.ckpt'}", f"out={run / 'model.onnx'}"])
    return {"urdf": urdf, "heldout": corpus / "heldout", "onnx": run / "model.onnx"}


@pytest.mark.slow
def test_a_five_joint_users_arm_goes_through_record_train_export_and_monitor(
    toy_deployed, tmp_path
):
    """``arm=<your.urdf>`` downstream: recordings on the arm's own five-joint graph, a model
    trained and exported on it, the monitor diagnosing it joint by joint (by the file's names)."""
    from robohealth_mj.monitor import main as monitor_main
    from robohealth_mj.runtime.metadata import read_metadata

    urdf = toy_deployed["urdf"]
    manifest = json.loads((toy_deployed["heldout"] / "manifest.json").read_text())
    assert manifest["schema_version"] == "3.0" and manifest["arm"] == str(urdf.resolve())
    assert manifest["graph"]["joints"] == ["j1", "j2", "j3", "j4", "j5"]
    assert manifest["recording_run_id"].startswith("toy-s4-")
    assert set(manifest["stats"]["faulted_samples_per_joint"]) == {"j2", "j4"}
    meta = read_metadata(toy_deployed["onnx"])
    assert meta["joints"] == ["j1", "j2", "j3", "j4", "j5"] and meta["arm_graph"].n_nodes == 10
    assert meta["arm"] == str(urdf.resolve())

    out = tmp_path / "online.json"
    monitor_main([f"model={toy_deployed['onnx']}", f"file={toy_deployed['heldout']}",
                  "evaluate=true", f"out={out}", "quiet=true"])  # fmt: skip
    online = json.loads(out.read_text())
    assert online["decided_ticks"] > 0 and online["episodes"] > 0
    assert {k.split("@")[1] for k in online["alarms_by_class_and_joint"]} == {"j2", "j4"}


@pytest.mark.slow
def test_bench_counts_the_flops_of_a_five_joint_arms_model(toy_deployed):
    """bench's FLOP counter feeds the model the arm's own graph (10 nodes), not the UR's 12."""
    from robohealth_mj.benchmarks.fleet import model_flops

    assert model_flops(str(toy_deployed["onnx"]), incremental=False) > 0
    assert model_flops(str(toy_deployed["onnx"])) > 0


@pytest.mark.slow
def test_a_mixed_fleet_decides_each_arm_as_its_own_fleet_would(toy_deployed, deployed):
    """A six-joint UR5e model and the five-joint arm's in one process: every row of each arm
    gets the decision its arm's fleet alone gives it, and a row of one arm's graph sent to the
    other's model is flagged, not read."""
    from robohealth_mj.data.arrays import load_recordings
    from robohealth_mj.runtime.fleet import DECIDED, FleetRuntime
    from robohealth_mj.runtime.mixed import MixedFleet, Rows

    models = {"ur5e": deployed["structural_onnx"], "toy": toy_deployed["onnx"]}
    data = {"ur5e": load_recordings([deployed["heldout"]]).x[:60],
            "toy": load_recordings([toy_deployed["heldout"] / "graphs.jsonl"]).x[:60]}  # fmt: skip
    data["toy"] = data["toy"] / _toy_scale(toy_deployed["urdf"])  # the raw readings again
    mixed = MixedFleet(models, capacity=4, max_streams=4)
    alone = {k: FleetRuntime(str(m), strict=True, capacity=4, max_streams=4)
             for k, m in models.items()}  # fmt: skip
    slots = {k: mixed.register(k, [f"{k}_a", f"{k}_b"]) for k in models}
    own = {k: alone[k].register([f"{k}_a", f"{k}_b"]) for k in models}
    decided = 0
    for tick in range(len(data["toy"])):
        x = {k: np.stack([data[k][tick], data[k][(tick + 7) % 60]]) for k in models}
        index, t = np.full(2, tick), np.full(2, 0.05 * (tick + 1))
        both = mixed.step({k: Rows(slots[k], index, t, x[k]) for k in models})
        for k in models:
            single = alone[k].step(own[k], index, t, x[k])
            np.testing.assert_array_equal(both[k].status, single.status)
            np.testing.assert_allclose(both[k].probs, single.probs, atol=1e-6)
            np.testing.assert_allclose(both[k].joint_scores, single.joint_scores, atol=1e-6)
            decided += int((both[k].status == DECIDED).sum())
    assert decided > 100 and mixed.member("toy").joints == ["j1", "j2", "j3", "j4", "j5"]
    wrong = mixed.step({"toy": Rows(slots["toy"][:1], np.array([99]), np.array([9.0]),
                                    data["ur5e"][:1])})["toy"]  # fmt: skip
    assert "not (10, 15)" in wrong.reasons[0]


def _toy_scale(urdf: Path) -> np.ndarray:
    from robohealth_mj.data.relative import channel_scale

    return channel_scale(str(urdf.resolve()))
