"""The session recorder and its command line."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from robohealth_mj import schema
from robohealth_mj.data.read import read_samples
from robohealth_mj.recording.recorder import GRAPHS_FILE, MANIFEST_FILE, record_session


def _record(record_cfg, out: Path, *overrides: str) -> dict:
    return record_session(record_cfg(*overrides), out).manifest


def test_same_seed_same_bytes_different_seed_different(record_cfg, tmp_path):
    for name, seed in (("a", 1), ("b", 1), ("c", 2)):
        _record(record_cfg, tmp_path / name, f"seed={seed}", "session.duration_s=4")
    a, b, c = ((tmp_path / n / GRAPHS_FILE).read_bytes() for n in "abc")
    assert a == b
    assert a != c


def test_a_120_s_session_has_2400_valid_samples_and_a_complete_manifest(record_cfg, tmp_path):
    manifest = _record(record_cfg, tmp_path, "session.duration_s=120", "seed=11")
    samples = list(read_samples(tmp_path / GRAPHS_FILE))
    assert len(samples) == 2400
    assert [s.sample_index for s in samples] == list(range(2400))
    assert {s.recording_run_id for s in samples} == {manifest["recording_run_id"]}
    assert samples[-1].t == pytest.approx(120.0)
    on_disk = json.loads((tmp_path / MANIFEST_FILE).read_text())
    assert on_disk["status"] == "complete"
    assert on_disk["sample_count"] == on_disk["expected_samples"] == 2400
    assert on_disk["schema_version"] == schema.SCHEMA_VERSION == "3.0"
    assert on_disk["graph"]["nodes"] == list(schema.UR_GRAPH.nodes)  # the UR5e's own graph
    assert on_disk["config"]["seed"] == 11
    assert on_disk["code_version"]
    assert on_disk["arm"] == on_disk["arm_ratings"]["arm"] == "ur5e"  # the arm's name, by its key
    assert on_disk["arm_variation"] == {}  # the nominal arm: no factor drawn
    assert max(on_disk["stats"]["tracking_rms_rad"].values()) < 0.01
    # the default fault schedule: 12 s faulted, 8 s healthy, labels on every sample
    active = [s.fault.active for s in samples]
    assert active[:240] == [True] * 240 and active[240:400] == [False] * 160
    assert len({(s.fault.fault_class, s.fault.joint, s.fault.severity) for s in samples}) == 7
    assert {s.segment["family"] for s in samples} <= {"single_joint", "joint_pair", "whole_arm"}


def test_payload_outside_the_training_range_is_recorded(record_cfg, tmp_path):
    _record(record_cfg, tmp_path, "session.duration_s=2", "curriculum.payload_scales=[2.2]")
    assert {s.segment["payload_scale"] for s in read_samples(tmp_path / GRAPHS_FILE)} == {2.2}


def _cli(*args: str, cwd: Path, **kwargs) -> subprocess.Popen:
    """The command line from ``cwd`` (a directory of the test's own: configs come from the
    installed package, not the working directory)."""
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    return subprocess.Popen(
        [sys.executable, "-m", "robohealth_mj.record", *args],
        cwd=cwd,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        **kwargs,
    )


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_an_interrupted_recording_is_readable_and_marked_incomplete(tmp_path, signum):
    """Ctrl-C, or a job scheduler's SIGTERM: the lines written so far stay readable and the
    manifest says the session is incomplete."""
    proc = _cli(
        "session.duration_s=3600",
        f"session.out_dir={tmp_path}",
        "session.progress=false",
        f"hydra.run.dir={tmp_path / 'hydra'}",
        cwd=tmp_path,
    )
    graphs = tmp_path / GRAPHS_FILE
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        if graphs.exists() and graphs.stat().st_size > 100_000:
            break
        time.sleep(0.1)
    proc.send_signal(signum)
    proc.communicate(timeout=60)
    assert proc.returncode != 0
    manifest = json.loads((tmp_path / MANIFEST_FILE).read_text())
    assert manifest["status"] == "incomplete"
    assert manifest["incomplete_reason"] == "interrupted"
    samples = list(read_samples(graphs))
    assert 0 < len(samples) == manifest["sample_count"] < manifest["expected_samples"]


def test_multirun_records_sessions_in_parallel_with_joblib(tmp_path):
    proc = _cli(
        "-m",
        "seed=1,2",
        "hydra/launcher=joblib",
        "hydra.launcher.n_jobs=2",
        "session.duration_s=2",
        "session.progress=false",
        f"hydra.sweep.dir={tmp_path}",
        cwd=tmp_path,
    )
    out, _ = proc.communicate(timeout=240)
    assert proc.returncode == 0, out
    manifests = sorted(tmp_path.glob(f"*/{MANIFEST_FILE}"))
    assert len(manifests) == 2
    run_ids = {json.loads(m.read_text())["recording_run_id"] for m in manifests}
    assert len(run_ids) == 2
    for m in manifests:
        assert len(list(read_samples(m.parent / GRAPHS_FILE))) == 40


def _band_rms(raw: np.ndarray, band: tuple[float, float], ticks: int) -> tuple[np.ndarray, ...]:
    """Per tick, from raw accelerations ``[steps, 6, 3]`` at 1 kHz: the RMS of the band-passed
    magnitude (a 4th-order Butterworth started at rest on the first reading, as a sensor powered
    up on a still arm) and the axis-mean kurtosis. Written here from the definitions in the
    README, independently of the sensor package."""
    from scipy.signal import butter, sosfilt, sosfilt_zi

    sos = butter(4, band, btype="bandpass", fs=1000.0, output="sos")
    flat = raw.reshape(len(raw), -1)
    zi = sosfilt_zi(sos)[:, :, None] * flat[0][None, None, :]
    filtered = sosfilt(sos, flat, axis=0, zi=zi)[0].reshape(ticks, -1, 6, 3)
    second = (filtered**2).mean(axis=1)  # [ticks, 6, 3]
    kurtosis = ((filtered**4).mean(axis=1) / second**2).mean(axis=-1)
    return np.sqrt(second.sum(axis=-1)), kurtosis, np.sqrt(second.min(axis=-1))


def test_a_recorded_line_carries_what_each_channel_name_says(monkeypatch):
    """Each channel of a JSONL line against the same physics computed from the raw rollout: the
    link angle, its error to the reference, drive torque minus the controller's model torque,
    and the piezo levels and kurtosis from the raw 1 kHz accelerations (noise floors off, so the
    numbers are exact)."""
    from mujoco import rollout as rollout_module

    from robohealth_mj.common.config import compose_config
    from robohealth_mj.recording.recorder import build_simulator, chunk_lines

    cfg = compose_config("record", [
        "session.progress=false", "faults=fixed", "faults.schedule.fault_class=jam",
        "faults.schedule.joint=elbow", "faults.schedule.severity=0.9", "sensors.noise.pos=0",
        "sensors.noise.vel=0", "sensors.noise.effort=0", "sensors.noise.acc=0",
        "sensors.noise.piezo_density=0",
    ])  # fmt: skip
    sim = build_simulator(cfg)
    captured: dict[str, list] = {"state": [], "sensordata": [], "torque": []}
    real_rollout, real_controls = rollout_module.rollout, sim._controls

    def rollout(*args, **kwargs):
        state, sensordata = real_rollout(*args, **kwargs)
        captured["state"].append(state[0].copy())
        captured["sensordata"].append(sensordata[0].copy())
        return state, sensordata

    def controls(visit, step_times):
        ctrl, ref_velocity, torque, link = real_controls(visit, step_times)
        captured["torque"].append(torque)
        return ctrl, ref_velocity, torque, link

    monkeypatch.setattr(rollout_module, "rollout", rollout)
    monkeypatch.setattr(sim, "_controls", controls)
    lines, references = [], []
    for chunk in sim.run(70):  # the payload ramp (one-tick chunks), then whole chunks
        lines += [json.loads(line) for line in chunk_lines(sim, chunk, "probe")]
        references.append(sim.curriculum.position(chunk.visit, chunk.t))
    x = np.array([line["x"] for line in lines])  # [T, 12, F]
    state = np.concatenate(captured["state"])  # [steps, ...]
    sensordata = np.concatenate(captured["sensordata"])
    torque = np.concatenate(captured["torque"])
    idx = sim.index
    end = slice(sim.tick_steps - 1, None, sim.tick_steps)  # the last physics step of each tick
    link = state[end, 1 + idx.motor_qpos] + state[end, 1 + idx.deflection_qpos]
    drive = sensordata[end][:, idx.effort_sensor]
    f = {name: k for k, name in enumerate(schema.FEATURE_NAMES)}
    joints, sensors = x[:, :6], x[:, 6:]

    def close(got: np.ndarray, expected: np.ndarray) -> None:  # 6 significant digits a line
        np.testing.assert_allclose(got, expected, rtol=2e-5, atol=1e-9)

    assert len(lines) == 70 and not np.allclose(sensordata[:, idx.acc_sensor], 0)
    close(joints[..., f["pos"]], link)
    close(joints[..., f["effort"]], drive)
    close(joints[..., f["pos_error"]], link - np.concatenate(references))
    close(joints[..., f["effort_residual"]], drive - torque[end])
    close(sensors[..., f["pos_error"]], joints[..., f["pos_error"]])  # sensors carry the state
    acc = sensordata[:, idx.acc_sensor]  # [steps, 6, 3]
    vib, kurtosis, quietest_axis = _band_rms(acc, (20.0, 400.0), 70)
    close(sensors[..., f["vib"]], vib)
    # an axis that does not vibrate carries rounding noise, whose kurtosis no physics defines
    ringing = quietest_axis > 1e-4
    assert ringing.mean() > 0.4
    close(sensors[..., f["vib_kurtosis"]][ringing], kurtosis[ringing])
    for name, band in (("vib_20_80", (20.0, 80.0)), ("vib_80_200", (80.0, 200.0)),
                       ("vib_200_450", (200.0, 450.0))):  # fmt: skip
        close(sensors[..., f[name]], _band_rms(acc, band, 70)[0])
    mean_acc = acc.reshape(70, -1, 6, 3).mean(axis=1)
    for k, axis in enumerate("xyz"):
        close(sensors[..., f[f"acc_{axis}"]], mean_acc[..., k])
    assert not joints[..., schema.SENSOR_CHANNELS].any()  # joint nodes carry no sensor channel


@pytest.mark.parametrize(
    "command, needles",
    [
        ("record session.duration_s=-5", ["record: error: session.duration_s must be > 0"]),
        ("record arm=varied arm.mass=1.5", ["config 'arm'", "arm.mass: a spread in [0, 1)"]),
        ("record faults.schedule.severities=[]", ["config 'faults.schedule'", "schedule is empty"]),
        ("train sensing.joint_channels=[torque]", ["train: error: config 'sensing'", "'torque'"]),
    ],
)
def test_a_bad_config_value_is_one_line_and_exit_status_2(command, needles, tmp_path):
    """A value no constructor accepts, given on the command line: one line naming the key, exit
    status 2, no traceback (Hydra wraps a refusing ``_target_``; the entry point unwraps it)."""
    import subprocess
    import sys

    prog, *overrides = command.split()
    if prog == "record":
        overrides += [f"session.out_dir={tmp_path}", "session.progress=false"]
    else:
        overrides += [f"out_dir={tmp_path}"]
    args = [sys.executable, "-m", f"robohealth_mj.{prog}", *overrides]
    proc = subprocess.run(args, capture_output=True, text=True, timeout=300)
    lines = [line for line in proc.stderr.splitlines() if line.strip()]
    assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr
    assert len(lines) == 1, proc.stderr
    for needle in needles:
        assert needle in lines[0], lines[0]
