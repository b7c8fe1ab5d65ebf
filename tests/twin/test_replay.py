"""The arm's own program as a curriculum (curriculum=replay): a recorded session follows the
logged trajectory, speed scales dilate its time, the program is the seed's, and bad logs or
speeds are one-line errors naming the file or the joint."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from robohealth_mj.arms.description import load_arm
from robohealth_mj.common.config import compose_config
from robohealth_mj.common.errors import InputError
from robohealth_mj.recording.recorder import record_session
from robohealth_mj.twin.replay import ReplayCurriculum

HOME = np.array([0.0, -1.6, 1.4, -1.4, -1.5, 0.0])
W = 2 * np.pi * np.array([0.21, 0.17, 0.29, 0.27, 0.23, 0.31])
AMP = np.array([0.5, 0.3, 0.4, 0.4, 0.4, 0.4])


def _log(path: Path, seconds: float, phase: float, scale: float = 1.0) -> Path:
    """A 100 Hz log in the public UR10e logs' layout (31 numbers a row, no header): a
    multi-sine from rest to rest, positions and velocities (currents zero)."""
    t = np.arange(0.0, seconds, 0.01)
    envelope = np.sin(np.pi * t / seconds)[:, None] ** 2
    q = HOME + scale * AMP * envelope * np.sin(W * t[:, None] + phase)
    qd = np.gradient(q, t, axis=0)
    rows = np.hstack([t[:, None] + 100.0, q, qd, np.zeros((len(t), 18))])
    np.savetxt(path, rows, delimiter=",", fmt="%.6f")
    return path


def _curriculum(files: list[Path], **kw) -> ReplayCurriculum:
    arm = load_arm("ur10e")
    return ReplayCurriculum([str(f) for f in files], rated_payload_kg=arm.payload_kg,
                            speed_limit_rad_s=arm.speed_limit.tolist(), **kw)  # fmt: skip


def test_a_recorded_session_follows_the_logged_trajectory(tmp_path):
    log = _log(tmp_path / "a.csv", 12.0, 0.3)
    out = tmp_path / "rec"
    cfg = compose_config("record", [
        "session.progress=false", "arm=ur10e", "curriculum=replay", f"curriculum.files=[{log}]",
        "curriculum.hold_s=0", "faults=none", "session.duration_s=14",
        "seed=2",
    ])  # fmt: skip
    result = record_session(cfg, out)
    assert result.manifest["status"] == "complete"
    lines = (out / "graphs.jsonl").read_text().splitlines()
    samples = [json.loads(line) for line in lines]
    assert {s["segment"]["family"] for s in samples} == {"replay"}
    assert {s["segment"]["waveform"] for s in samples} == {"a"}
    pos = np.array([[n[2] for n in s["x"][:6]] for s in samples])
    t = np.array([s["t"] for s in samples])
    start = _curriculum([log], hold_s=0.0)._plays[0][0]
    logged = np.loadtxt(log, delimiter=",")
    expected = np.stack(
        [np.interp(t - start, logged[:, 0] - 100.0, logged[:, 1 + j]) for j in range(6)], 1
    )
    moving = (t > start + 1.0) & (t < start + 11.0)
    assert np.sqrt(np.mean((pos[moving] - expected[moving]) ** 2)) < 0.01
    assert np.ptp(pos[moving], axis=0).min() > 0.2  # it moved as the log moved
    pos_error = np.array([[n[5] for n in s["x"][:6]] for s in samples])
    assert np.sqrt(np.mean(pos_error**2)) < 2e-3  # measured against the replayed reference


def test_speed_scales_dilate_time_and_the_program_is_the_seeds(tmp_path):
    a, b = _log(tmp_path / "a.csv", 10.0, 0.0), _log(tmp_path / "b.csv", 6.0, 1.0)
    c1 = _curriculum([a, b], speed_scales=[1.0], passes=1, hold_s=0.0)
    c2 = _curriculum([a, b], speed_scales=[2.0], passes=1, hold_s=0.0)
    assert c1.period_s - c2.period_s == pytest.approx(8.0, abs=0.1)  # 16 s of logs at 2x: 8 s
    (start1, log1, _), (start2, log2, _) = c1._plays[0], c2._plays[0]
    assert log1 == log2
    tau = np.linspace(0.0, 2.9, 30)  # at 2x the log's second 2 tau plays at tau
    np.testing.assert_allclose(c2.position(0, start2 + tau), c1.position(0, start1 + 2 * tau),
                               atol=2e-3)  # fmt: skip
    s1, s2 = _curriculum([a, b], seed=1), _curriculum([a, b], seed=1)
    t = np.linspace(0.0, 100.0, 1001)
    assert np.array_equal(s1.position(0, t), s2.position(0, t))
    orders = {tuple(p[1] for p in _curriculum([a, b], seed=s)._plays) for s in range(6)}
    assert len(orders) > 1
    q, qd, qdd = s1.reference(0, np.array([s1.period_s - 1e-6, 0.0]))
    np.testing.assert_allclose(q[0], q[1], atol=1e-6)  # the loop closes smoothly
    np.testing.assert_allclose(qd[0], qd[1], atol=1e-4)
    np.testing.assert_allclose(qdd[0], qdd[1], atol=1e-2)


def test_bad_logs_and_speeds_are_one_line_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match=r"missing\.csv"):
        _curriculum([tmp_path / "missing.csv"])
    done = subprocess.run(
        [sys.executable, "-m", "robohealth_mj.record", f"hydra.run.dir={tmp_path}/run",
         "curriculum=replay", f"curriculum.files=[{tmp_path}/missing.csv]"],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    err = done.stderr.strip().splitlines()
    assert done.returncode == 2 and len(err) == 1, done.stderr
    assert "config 'curriculum': no log at" in err[0] and "missing.csv" in err[0]
    fast = _log(tmp_path / "fast.csv", 4.0, 0.0, scale=3.0)
    with pytest.raises(InputError, match=r"joint \d would replay at .* over the arm's limit"):
        _curriculum([fast], speed_scales=[2.0])
    with pytest.raises(InputError, match=r"curriculum.files"):
        _curriculum([])
    with pytest.raises(InputError, match=r"payload_kg"):
        _curriculum([_log(tmp_path / "a.csv", 4.0, 0.0)], payload_kg=100.0)


def test_the_mount_lifts_the_base_and_changes_no_torque():
    """A real arm's program can reach below its base plane: on a pedestal (sim.mount_height_m)
    the arm clears our floor, with the same dynamics; a mount below the floor is refused."""
    import mujoco

    from robohealth_mj.sim.model import ArmIndex, build_model

    low = np.array([0.0, -2.9, -0.6, -1.0, 0.7, -1.1])  # a pose from a public UR10e log
    gravity = []
    for height in (0.0, 0.8):
        m = build_model("ur10e", mount_height_m=height)
        d = mujoco.MjData(m)
        ArmIndex.of(m).set_link_pose(d, low)
        mujoco.mj_forward(m, d)
        assert d.xpos[m.body("base").id][2] == pytest.approx(height)
        lowest = (d.geom_xpos[:, 2] - m.geom_rbound)[1:].min()
        assert (lowest < 0.0) == (height == 0.0)  # on the floor this pose is inside it
        gravity.append(d.qfrc_bias.copy())
    np.testing.assert_allclose(gravity[0], gravity[1], atol=1e-9)
    with pytest.raises(InputError, match=r"sim.mount_height_m: in \[0, 10\] m, got -1"):
        build_model("ur10e", mount_height_m=-1.0)


def test_a_twins_effort_reads_as_noisily_as_its_arm(tmp_path):
    """The twin's effort_noise_nm is what one tick of the simulated effort reads at rest; a twin
    stating none keeps the sensor package's; a bad value is one line naming the key."""
    import yaml

    from robohealth_mj.twin.identify import nominal_drives

    still = _log(tmp_path / "still.csv", 10.0, 0.0, scale=0.0)
    stated = np.array([1.0, 0.8, 0.5, 0.3, 0.3, 0.3])
    noise = {}
    for name, value in (("noisy", stated.tolist()), ("none", None), ("bad", [1.0, -1.0])):
        twin = {"arm": "ur10e", "drive_overrides": nominal_drives("ur10e").overrides(),
                "effort_noise_nm": value}  # fmt: skip
        (tmp_path / f"{name}.yaml").write_text(yaml.safe_dump(twin))
        cfg = compose_config("record", [
            "session.progress=false", "arm=ur10e", "curriculum=replay",
            f"curriculum.files=[{still}]", "curriculum.hold_s=0", "faults=none",
            "session.duration_s=10", f"sim.twin={tmp_path / name}.yaml",
        ])  # fmt: skip
        if name == "bad":
            with pytest.raises(InputError, match=r"bad.yaml: key 'effort_noise_nm': 6 numbers"):
                record_session(cfg, tmp_path / name)
            continue
        record_session(cfg, tmp_path / name)
        lines = (tmp_path / name / "graphs.jsonl").read_text().splitlines()[20:]
        effort = np.array([[n[4] for n in json.loads(line)["x"][:6]] for line in lines])
        noise[name] = np.diff(effort, axis=0).std(axis=0) / np.sqrt(2.0)
    # the noise adds in quadrature to what the drives themselves move at rest
    added = np.sqrt(np.maximum(noise["noisy"] ** 2 - noise["none"] ** 2, 0.0))
    np.testing.assert_allclose(added, stated, rtol=0.2)
    assert (noise["none"] < 0.5 * stated).all()
