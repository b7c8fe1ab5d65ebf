"""The session recorder and its command line."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from robohealth_mj import schema
from robohealth_mj.data.jsonl import read_samples
from robohealth_mj.recorder import GRAPHS_FILE, MANIFEST_FILE, record_session

REPO = Path(__file__).resolve().parents[1]


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
    assert on_disk["schema_version"] == schema.SCHEMA_VERSION == "2.0"
    assert on_disk["config"]["seed"] == 11
    assert on_disk["code_version"]
    assert max(on_disk["stats"]["tracking_rms_rad"].values()) < 0.01
    # the default fault schedule: 12 s faulted, 8 s healthy, labels on every sample
    active = [s.fault.active for s in samples]
    assert active[:240] == [True] * 240 and active[240:400] == [False] * 160
    assert len({(s.fault.fault_class, s.fault.joint, s.fault.severity) for s in samples}) == 7
    assert {s.segment["family"] for s in samples} <= {"single_joint", "joint_pair", "whole_arm"}


def test_payload_outside_the_training_range_is_recorded(record_cfg, tmp_path):
    _record(record_cfg, tmp_path, "session.duration_s=2", "curriculum.payload_scales=[2.2]")
    assert {s.segment["payload_scale"] for s in read_samples(tmp_path / GRAPHS_FILE)} == {2.2}


def _cli(*args: str, **kwargs) -> subprocess.Popen:
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    return subprocess.Popen(
        [sys.executable, "-m", "robohealth_mj.record", *args],
        cwd=REPO,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        **kwargs,
    )


def test_an_interrupted_recording_is_readable_and_marked_incomplete(tmp_path):
    proc = _cli(
        "session.duration_s=3600",
        f"session.out_dir={tmp_path}",
        "session.progress=false",
        f"hydra.run.dir={tmp_path / 'hydra'}",
    )
    graphs = tmp_path / GRAPHS_FILE
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        if graphs.exists() and graphs.stat().st_size > 100_000:
            break
        time.sleep(0.1)
    proc.send_signal(signal.SIGINT)
    proc.communicate(timeout=60)
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
    )
    out, _ = proc.communicate(timeout=240)
    assert proc.returncode == 0, out
    manifests = sorted(tmp_path.glob(f"*/{MANIFEST_FILE}"))
    assert len(manifests) == 2
    run_ids = {json.loads(m.read_text())["recording_run_id"] for m in manifests}
    assert len(run_ids) == 2
    for m in manifests:
        assert len(list(read_samples(m.parent / GRAPHS_FILE))) == 40
