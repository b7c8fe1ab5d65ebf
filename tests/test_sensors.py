"""The piezo channel: a band-passed level that is continuous across chunks."""

from __future__ import annotations

import numpy as np

from robohealth_mj.sim.sensors import SensorPackage


def _tone(freq_hz: float, seconds: float = 1.0, rate: float = 1000.0) -> np.ndarray:
    t = np.arange(int(seconds * rate)) / rate
    acc = np.zeros((t.size, 6, 3))
    acc[:, 2, 0] = np.sin(2 * np.pi * freq_hz * t)
    return acc


def test_vibration_passes_the_band_and_rejects_slow_motion_and_gravity():
    in_band = SensorPackage(1000.0).process(_tone(120.0), 50)[1]
    slow = _tone(1.0)
    slow[:, :, 2] += 9.81
    below = SensorPackage(1000.0).process(slow, 50)[1]
    assert in_band[5:, 2].mean() > 0.6  # sine RMS is 0.707
    assert below[5:].max() < 0.01
    assert np.all(in_band[:, [0, 1, 3, 4, 5]] == 0.0)


def test_filter_state_carries_across_chunks():
    acc = _tone(80.0) + _tone(300.0)
    whole = SensorPackage(1000.0).process(acc, 50)
    pkg = SensorPackage(1000.0)
    parts = [pkg.process(acc[:400], 50), pkg.process(acc[400:], 50)]
    np.testing.assert_allclose(np.concatenate([p[1] for p in parts]), whole[1], atol=1e-12)
    np.testing.assert_allclose(np.concatenate([p[0] for p in parts]), whole[0], atol=1e-12)
