"""The co-located sensor package: what each joint's accelerometer and piezo element report.

The accelerometer is sampled at the physics rate; at each 20 Hz tick the package emits the
tick-mean acceleration (a decimated, anti-aliased reading) and a piezo vibration level, the RMS over
the tick of the band-passed high-rate acceleration magnitude. Every channel carries a Gaussian
noise floor drawn from the session's random generator.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import signal

from robohealth_mj.schema import N_JOINTS


@dataclass(frozen=True)
class NoiseFloor:
    """Standard deviation of the Gaussian noise on each emitted channel."""

    pos: float = 1e-4
    vel: float = 1e-3
    effort: float = 0.05
    vib: float = 2e-3
    acc: float = 0.02


class SensorPackage:
    """Per-joint accelerometer + piezo synthesis with a stateful band-pass filter."""

    def __init__(
        self,
        physics_rate_hz: float,
        band_hz: tuple[float, float] = (20.0, 400.0),
        filter_order: int = 4,
        noise: dict | NoiseFloor | None = None,
    ) -> None:
        low, high = band_hz
        nyquist = physics_rate_hz / 2.0
        if not 0.0 < low < high < nyquist:
            raise ValueError(f"piezo band {band_hz} Hz must satisfy 0 < low < high < {nyquist}")
        self.sos = signal.butter(
            filter_order, [low, high], btype="bandpass", fs=physics_rate_hz, output="sos"
        )
        self.noise = noise if isinstance(noise, NoiseFloor) else NoiseFloor(**(noise or {}))
        self._zi: np.ndarray | None = None

    def reset(self) -> None:
        self._zi = None

    def process(self, acc: np.ndarray, tick_steps: int) -> tuple[np.ndarray, np.ndarray]:
        """High-rate accelerations ``[steps, 6, 3]`` -> tick means ``[ticks, 6, 3]`` and vibration
        ``[ticks, 6]`` (noise-free; :meth:`add_noise` adds the floor)."""
        steps = acc.shape[0]
        if steps % tick_steps:
            raise ValueError(f"{steps} steps is not a whole number of {tick_steps}-step ticks")
        flat = acc.reshape(steps, N_JOINTS * 3)
        if self._zi is None:  # start in steady state on the first reading: no start-up ring
            self._zi = signal.sosfilt_zi(self.sos)[:, :, None] * flat[0][None, None, :]
        band, self._zi = signal.sosfilt(self.sos, flat, axis=0, zi=self._zi)
        ticks = steps // tick_steps
        magnitude_sq = (band.reshape(ticks, tick_steps, N_JOINTS, 3) ** 2).sum(axis=-1)
        vib = np.sqrt(magnitude_sq.mean(axis=1))
        acc_mean = acc.reshape(ticks, tick_steps, N_JOINTS, 3).mean(axis=1)
        return acc_mean, vib

    def add_noise(
        self,
        rng: np.random.Generator,
        pos: np.ndarray,
        vel: np.ndarray,
        effort: np.ndarray,
        vib: np.ndarray,
        acc: np.ndarray,
    ) -> tuple[np.ndarray, ...]:
        """Add the noise floor to a chunk of tick readings (one draw order, so bytes reproduce)."""
        n = self.noise
        return (
            pos + rng.normal(0.0, n.pos, pos.shape),
            vel + rng.normal(0.0, n.vel, vel.shape),
            effort + rng.normal(0.0, n.effort, effort.shape),
            np.abs(vib + rng.normal(0.0, n.vib, vib.shape)),
            acc + rng.normal(0.0, n.acc, acc.shape),
        )
