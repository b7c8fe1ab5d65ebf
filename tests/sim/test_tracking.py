"""Healthy tracking: the controller follows the curriculum like a real UR."""

from __future__ import annotations

import numpy as np

from robohealth_mj.recording.recorder import build_simulator


def test_healthy_tracking_error_is_under_10_mrad_at_nominal_speed_and_payload(record_cfg):
    cfg = record_cfg("curriculum.speed_scales=[1.0]", "curriculum.payload_scales=[1.0]", "seed=3")
    sim = build_simulator(cfg)
    chunks = list(sim.run(20 * 60))  # six segments
    err = np.concatenate([c.true_pos - c.reference for c in chunks])
    rms = np.sqrt((err**2).mean(axis=0))
    assert np.all(rms < 0.01), rms
    assert sum(c.saturated_steps.sum() for c in chunks) == 0
    assert max(c.contacts for c in chunks) == 0
    effort = np.concatenate([c.effort for c in chunks])
    assert np.all(np.abs(effort) <= sim.index.torque_limit + 0.5)  # + noise floor
    assert all(w.number == 0 for w in sim.data.warning)


def test_the_arm_moves_and_the_sensors_see_it(record_cfg):
    sim = build_simulator(record_cfg("seed=4"))
    chunks = list(sim.run(20 * 10))
    pos = np.concatenate([c.pos for c in chunks])
    acc = np.concatenate([c.acc for c in chunks])
    vib = np.concatenate([c.vib for c in chunks])
    assert np.ptp(pos, axis=0).max() > 0.2
    gravity = np.linalg.norm(acc, axis=-1).mean()
    assert 8.0 < gravity < 12.0  # accelerometers read gravity plus motion
    assert np.all(np.isfinite(vib)) and np.all(vib >= 0)
