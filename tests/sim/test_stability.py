"""Physics stability at the edge of the envelope: every fault at severity 0.9 at the highest
speed and payload of the curriculum, for a full pass of the schedule."""

from __future__ import annotations

import json

import numpy as np

from robohealth_mj.data.read import read_samples
from robohealth_mj.recording.recorder import GRAPHS_FILE, MANIFEST_FILE, record_session
from robohealth_mj.schema import JOINT_NAMES


def test_every_fault_at_full_severity_runs_clean_at_top_speed_and_payload(record_cfg, tmp_path):
    cfg = record_cfg(
        "curriculum.speed_scales=[1.5]",
        "curriculum.payload_scales=[1.6]",
        "faults.schedule.severities=[0.9]",
        "session.passes=1",
        "seed=5",
    )
    record_session(cfg, tmp_path)
    manifest = json.loads((tmp_path / MANIFEST_FILE).read_text())
    assert manifest["status"] == "complete"
    assert manifest["mujoco_warnings"] == {}
    stats = manifest["stats"]
    assert stats["scenarios_covered"] == 36
    assert set(stats["torque_saturated_steps"]) == set(JOINT_NAMES)
    assert stats["max_contacts"] == 0
    samples = list(read_samples(tmp_path / GRAPHS_FILE))  # raises on any NaN or Inf
    assert len(samples) == manifest["sample_count"] == 36 * 400
    x = np.stack([s.x for s in samples])
    assert np.all(np.abs(x[:, :, 2]) < 7.0)  # no joint flew off
