"""Identifying a twin: on a log recorded from our own simulator with known drive parameters,
identification recovers them and reproduces the log's torque; the twin file changes the
simulated physics as it states; bad twin files are one-line errors."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
import yaml

from robohealth_mj.common.errors import InputError
from robohealth_mj.identify import main as identify_main
from robohealth_mj.schema import JOINT_NAMES
from robohealth_mj.sim.control import TrackingController
from robohealth_mj.sim.model import ArmIndex, build_model

K_T = np.array([12.0, 11.8, 9.7, 10.3, 11.4, 15.6])  # N*m per A of the test's "controller"
TRUE = {  # what the synthetic arm's drives really have (not the simulator's defaults)
    "armature": [4.0, 4.5, 1.5, 0.5, 0.45, 0.4],
    "damping": [20.0, 15.0, 9.0, 3.0, 2.5, 2.0],
    "frictionloss": [15.0, 17.0, 7.0, 2.5, 3.5, 2.0],
}
MAP = """name: test_rtde
time: timestamp
joint_index: [0, 1, 2, 3, 4, 5]
channels:
  pos: 'actual_q_{j}'
  vel: 'actual_qd_{j}'
  effort: 'actual_current_{j}'
  pos_error: ['actual_q_{j}', 'target_q_{j}']
  effort_residual: ['actual_current_{j}', 'target_current_{j}']
optional: [pos_error]
units: {pos: rad, vel: rad/s, effort: A, pos_error: rad, effort_residual: A}
torque_constant: [12.0, 11.8, 9.7, 10.3, 11.4, 15.6]
"""


def _true_overrides() -> dict:
    return {j: {k: TRUE[k][i] for k in TRUE} for i, j in enumerate(JOINT_NAMES)}


def _simulated_log(path: Path, seconds: float, phase: float) -> Path:
    """Our UR10e with the TRUE drives tracks a multi-sine; written as a 100 Hz RTDE CSV with
    the actuator force as current and the controller's model torque (rigid body and rotor
    inertia) as target moment; no target position."""
    model = build_model("ur10e", drive_overrides=_true_overrides())
    idx = ArmIndex.of(model)
    model.body_mass[idx.payload_body] = 0.0  # nothing at the flange, as in the real logs
    data = mujoco.MjData(model)
    dt = model.opt.timestep
    t = np.arange(0.0, seconds, dt)
    w = 2 * np.pi * np.array([0.21, 0.17, 0.29, 0.27, 0.23, 0.31])
    amp = np.array([0.8, 0.5, 0.6, 0.6, 0.6, 0.6])
    home = np.array([0.0, -1.6, 1.4, -1.4, -1.5, 0.0])
    arg = w * t[:, None] + phase * np.arange(1, 7)
    q = home + amp * (np.sin(arg) + 0.3 * np.sin(2.3 * arg))
    qd = amp * w * (np.cos(arg) + 0.69 * np.cos(2.3 * arg))
    qdd = -amp * w**2 * (np.sin(arg) + 1.587 * np.sin(2.3 * arg))
    controller = TrackingController(model)
    controller.set_payload(0.0)
    ctrl, *_ = controller.commands(q, qd, qdd)
    motor, _ = controller.inverse_dynamics(q, qd, qdd)
    moment = motor - np.asarray(TRUE["damping"]) * qd  # the controller's model: no friction
    idx.set_link_pose(data, q[0])
    data.qvel[idx.motor_dof] = qd[0]
    rows = []
    for k in range(len(t)):
        data.ctrl[idx.actuator] = ctrl[k]
        mujoco.mj_step(model, data)
        if k % 10 == 0:
            link_q = data.qpos[idx.motor_qpos] + data.qpos[idx.deflection_qpos]
            link_qd = data.qvel[idx.motor_dof] + data.qvel[idx.deflection_dof]
            current = data.sensordata[idx.effort_sensor] / K_T
            rows.append([t[k], *link_q, *link_qd, *current, *current, *moment[k]])
    names = ["timestamp"] + [f"{c}_{j}" for c in ("actual_q", "actual_qd", "actual_current",
                                                  "target_current", "target_moment")
                                for j in range(6)]  # fmt: skip
    lines = [",".join(names)] + [",".join(f"{v:.9g}" for v in r) for r in rows]
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.fixture(scope="module")
def twin(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("twin")
    (root / "map.yaml").write_text(MAP)
    fit = _simulated_log(root / "fit.csv", 40.0, 0.0)
    val = _simulated_log(root / "val.csv", 20.0, 1.3)
    identify_main(["arm=ur10e", f"fit={fit}", f"validate={val}", f"map={root / 'map.yaml'}",
                   f"out={root / 'out'}"])  # fmt: skip
    return root / "out"


def test_identification_recovers_the_simulated_drives(twin):
    content = yaml.safe_load((twin / "twin.yaml").read_text())
    assert content["arm"] == "ur10e" and content["fit"]["used_model_torque"]
    got = content["drive_overrides"]
    armature = np.array([got[j]["armature"] for j in JOINT_NAMES])
    np.testing.assert_allclose(armature, TRUE["armature"], rtol=0.05)  # from the model torque
    # friction and k_t from the current: within 10 % where the torque is large against the
    # drive's ringing (shoulders, elbow); studies/real_arms/README.md gives every joint's recovery
    friction = np.array([got[j]["frictionloss"] for j in JOINT_NAMES])
    np.testing.assert_allclose(friction[:3], TRUE["frictionloss"][:3], rtol=0.10)
    np.testing.assert_allclose(content["torque_constant_nm_per_a"][:3], K_T[:3], rtol=0.10)


def test_the_twin_reproduces_a_log_the_fit_never_saw(twin):
    (row,) = yaml.safe_load((twin / "fidelity.json").read_text())
    after, before = np.array(row["after_vs_current"]), np.array(row["before_vs_current"])
    assert after.max() < 0.05  # within 5 % of each joint's range (the rest: the drive ringing)
    assert (before > 1.2 * after).all()  # the simulator's nominal drives are not this arm's


def test_the_twin_file_changes_the_simulated_physics(twin):
    nominal = build_model("ur10e")
    model = build_model("ur10e", twin=twin / "twin.yaml")
    dof = ArmIndex.of(model).motor_dof
    content = yaml.safe_load((twin / "twin.yaml").read_text())["drive_overrides"]
    for k in ("armature", "damping", "frictionloss"):
        stated = [content[j][k] for j in JOINT_NAMES]
        np.testing.assert_allclose(getattr(model, f"dof_{k}")[dof], stated, rtol=1e-6)
        assert not np.allclose(getattr(nominal, f"dof_{k}")[dof], stated, rtol=0.05)


def test_a_twin_of_another_arm_or_a_bad_value_is_one_line(tmp_path, twin):
    with pytest.raises(InputError, match=r"the twin is of .ur10e.*pass arm=ur10e"):
        build_model("ur5e", twin=twin / "twin.yaml")
    bad = yaml.safe_load((twin / "twin.yaml").read_text())
    bad["drive_overrides"]["elbow"]["damping"] = -1.0
    (tmp_path / "bad.yaml").write_text(yaml.safe_dump(bad))
    with pytest.raises(InputError, match=r"drive_overrides\.elbow\.damping': a number >= 0"):
        build_model("ur10e", twin=tmp_path / "bad.yaml")


def test_the_effort_noise_is_read_from_the_holds_not_their_offsets():
    """A real drive's current is noisier than our torque sensor: identification reads the noise
    one 20 Hz tick sees from the logs' holds (a second or more), whatever offset each hold has."""
    from robohealth_mj.twin.identify import effort_noise
    from robohealth_mj.twin.joint_log import JointLog

    rng = np.random.default_rng(0)
    t = np.arange(0.0, 30.0, 0.01)
    qd = np.where(((t % 10.0) < 4.0)[:, None], 0.3, 0.0) * np.ones((1, 6))  # 4 s move, 6 s hold
    sigma = np.array([0.7, 0.55, 0.25, 0.13, 0.15, 0.2])
    offset = np.floor(t / 10.0)[:, None] * np.array([3.0, -2.0, 1.0, 0.5, -0.5, 0.2])
    torque = offset + rng.normal(0.0, 1.0, (len(t), 6)) * sigma
    log = JointLog("holds", t, np.zeros((len(t), 6)), qd, torque / K_T, None)
    np.testing.assert_allclose(effort_noise([log], K_T), sigma, rtol=0.15)
    moving = JointLog("moving", t, np.zeros((len(t), 6)), qd + 0.3, torque / K_T, None)
    assert effort_noise([moving], K_T) is None  # no hold: the simulator's noise is kept


def test_the_acceleration_is_right_on_unevenly_spaced_rows():
    """A logger's rows come 10 or 12 ms apart (as on the public UR10e logs): the acceleration of
    a known motion is estimated within 1 % of its peak (filtering the rows as if evenly spaced
    was 3.4 % off)."""
    from robohealth_mj.twin.identify import motion
    from robohealth_mj.twin.joint_log import JointLog

    steps = np.random.default_rng(0).choice([0.010, 0.012], size=3000, p=[2 / 3, 1 / 3])
    t = np.concatenate([[0.0], np.cumsum(steps)])
    w = 2 * np.pi * np.array([0.3, 0.5, 0.8, 1.0, 1.2, 0.4])
    qd = 0.5 * np.sin(w * t[:, None])
    qdd = 0.5 * w * np.cos(w * t[:, None])
    log = JointLog("uneven", t, np.zeros_like(qd), qd, np.zeros_like(qd), None)
    got = motion(log, 5.0)
    inner = slice(100, -100)  # the filter's edges
    error = np.sqrt(np.mean((got.qdd - qdd)[inner] ** 2, axis=0)) / np.abs(qdd).max(axis=0)
    assert error.max() < 0.01
    np.testing.assert_allclose(got.qd[inner], qd[inner], atol=0.005)


def test_the_cutoff_is_chosen_on_the_fit_logs_or_given(twin, tmp_path, capsys):
    """``cutoff_hz=auto`` picks the low-pass whose fit best predicts held-out fit data (one fit
    log: its halves) and the twin file says which and why; a given cutoff is used as given; a bad
    one is one line, exit 2."""
    from robohealth_mj.twin.identify import CUTOFF_GRID_HZ

    fitted = yaml.safe_load((twin / "twin.yaml").read_text())["fit"]
    scores = fitted["held_out_nrmse_by_cutoff_hz"]
    assert sorted(scores) == sorted(CUTOFF_GRID_HZ)
    assert fitted["cutoff_hz"] == min(scores, key=scores.get)
    root = twin.parent
    identify_main(["arm=ur10e", f"fit={root / 'fit.csv'}", f"map={root / 'map.yaml'}",
                   "cutoff_hz=7", f"out={tmp_path / 'given'}"])  # fmt: skip
    given = yaml.safe_load((tmp_path / "given" / "twin.yaml").read_text())["fit"]
    assert given["cutoff_hz"] == 7.0 and "held_out_nrmse_by_cutoff_hz" not in given
    capsys.readouterr()
    for bad in ("cutoff_hz=-1", "cutoff_hz=fast"):
        with pytest.raises(SystemExit) as done:
            identify_main(["arm=ur10e", f"fit={root / 'fit.csv'}", f"map={root / 'map.yaml'}",
                           bad, f"out={tmp_path / 'bad'}"])  # fmt: skip
        err = capsys.readouterr().err.strip()
        assert done.value.code == 2 and "\n" not in err and "cutoff_hz: a frequency" in err
    assert not (tmp_path / "bad").exists()


def test_a_recording_kept_for_reuse_is_reused_only_on_its_own_twin(twin, tmp_path):
    """The research scripts record on the twin once and reuse it; after the twin is identified
    again, a recording on the old one is refused in one line, never silently reused."""
    from robohealth_mj.sim.twin_file import mark_recorded, recorded_on

    out = tmp_path / "recording"
    out.mkdir()
    done = out / "graphs.jsonl"
    assert not recorded_on(out, done, twin / "twin.yaml")  # nothing recorded yet
    done.write_text("{}\n")
    assert recorded_on(out, done, twin / "twin.yaml")  # unmarked: taken as it is
    mark_recorded(out, twin / "twin.yaml")
    assert recorded_on(out, done, twin / "twin.yaml")
    again = yaml.safe_load((twin / "twin.yaml").read_text())
    again["drive_overrides"]["elbow"]["armature"] *= 1.05
    (tmp_path / "again.yaml").write_text(yaml.safe_dump(again))
    with pytest.raises(InputError, match=r"recording: recorded on another twin than .*again"):
        recorded_on(out, done, tmp_path / "again.yaml")
    same = yaml.safe_load((twin / "twin.yaml").read_text())
    same["code_version"] = "elsewhere"  # what does not change the physics does not count
    (tmp_path / "same.yaml").write_text(yaml.safe_dump(same))
    assert recorded_on(out, done, tmp_path / "same.yaml")


def test_auto_cutoff_without_a_fold_to_score_it_on_is_one_line():
    """Each joint moving in one fit log only: no log can be left out, and the error says what
    to pass instead of a fit that would fail deep inside."""
    from robohealth_mj.twin.identify import choose_cutoff
    from robohealth_mj.twin.joint_log import JointLog

    t = np.arange(0.0, 20.0, 0.01)
    logs = []
    for moving in (0, 1):
        qd = np.zeros((len(t), 6))
        qd[:, moving] = 0.3 * np.sin(t)
        q = np.array([0.0, -1.6, 1.4, -1.4, -1.5, 0.0]) + np.cumsum(qd, axis=0) * 0.01
        logs.append(
            JointLog(f"only_{moving}", t, q, qd, np.ones((len(t), 6)), np.ones((len(t), 6)))
        )
    with pytest.raises(InputError, match=r"cutoff_hz=auto found nothing to score.*pass cutoff_hz="):
        choose_cutoff("ur10e", logs)
