"""The piezo channels: band-passed levels that are continuous across chunks, sub-bands that sit
where the energy is, and a kurtosis that sees impacts."""

from __future__ import annotations

import numpy as np

from robohealth_mj.sim.sensors import SensorPackage


def _tone(freq_hz: float, seconds: float = 1.0, rate: float = 1000.0) -> np.ndarray:
    t = np.arange(int(seconds * rate)) / rate
    acc = np.zeros((t.size, 6, 3))
    acc[:, 2, 0] = np.sin(2 * np.pi * freq_hz * t)
    return acc


def test_vibration_passes_the_band_and_rejects_slow_motion_and_gravity():
    in_band = SensorPackage(1000.0).process(_tone(120.0), 50)[1].vib
    slow = _tone(1.0)
    slow[:, :, 2] += 9.81
    below = SensorPackage(1000.0).process(slow, 50)[1]
    assert in_band[5:, 2].mean() > 0.6  # sine RMS is 0.707
    assert below.vib[5:].max() < 0.01 and below.bands[5:].max() < 0.01
    assert np.all(in_band[:, [0, 1, 3, 4, 5]] == 0.0)


def test_each_sub_band_holds_the_energy_of_its_own_frequencies():
    """A resonance that moves down (a softer drive) moves the energy to a lower band."""
    for freq, band in ((45.0, 0), (130.0, 1), (320.0, 2)):
        bands = SensorPackage(1000.0).process(_tone(freq), 50)[1].bands[5:, 2]  # [ticks, 3]
        assert bands[:, band].mean() > 0.55
        others = [b for b in range(3) if b != band]
        assert bands[:, others].max() < 0.25 * bands[:, band].mean()


def test_kurtosis_is_three_for_gaussian_vibration_and_rises_with_impacts():
    rng = np.random.default_rng(0)
    acc = rng.normal(size=(2000, 6, 3))
    quiet = SensorPackage(1000.0).process(acc, 50)[1].kurtosis[5:, 2]
    knocked = acc.copy()
    knocked[::50, 2, :] += 25.0  # one sharp impact per tick
    impacts = SensorPackage(1000.0).process(knocked, 50)[1].kurtosis[5:, 2]
    assert abs(np.median(quiet) - 3.0) < 0.5
    assert np.median(impacts) > 2.0 * np.median(quiet)


def test_piezo_noise_floor_follows_its_density():
    pkg = SensorPackage(1000.0, noise={"piezo_density": 1e-3})
    silent = np.zeros((4000, 6, 3))
    vib = pkg.process(silent, 50, np.random.default_rng(1))[1].vib[10:]
    # white noise of density d over 20-400 Hz on 3 axes: RMS ~ d * sqrt(3 * 380)
    assert 0.7 < np.median(vib) / (1e-3 * np.sqrt(3 * 380.0)) < 1.3


def test_filter_state_carries_across_chunks():
    acc = _tone(80.0) + _tone(300.0)
    whole = SensorPackage(1000.0).process(acc, 50)
    pkg = SensorPackage(1000.0)
    parts = [pkg.process(acc[:400], 50), pkg.process(acc[400:], 50)]
    for name in ("vib", "bands", "kurtosis"):
        joined = np.concatenate([getattr(p[1], name) for p in parts])
        np.testing.assert_allclose(joined, getattr(whole[1], name), atol=1e-9)
    np.testing.assert_allclose(np.concatenate([p[0] for p in parts]), whole[0], atol=1e-12)
