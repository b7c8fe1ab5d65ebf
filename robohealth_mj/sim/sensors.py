"""The co-located sensor package: what each joint's accelerometer and piezo element report.

The accelerometer is sampled at the physics rate. At each 20 Hz tick the package emits:

- the tick-mean acceleration (a decimated, anti-aliased MEMS reading, x/y/z);
- the piezo vibration level ``vib``: RMS over the tick of the 20-400 Hz band-passed acceleration
  magnitude (what a vibration transmitter such as an IFM VTV or a 4-20 mA velocity sensor reports);
- the piezo energy in three sub-bands (``vib_20_80``, ``vib_80_200``, ``vib_200_450``): where the
  energy sits, so a lowered drive resonance or a train of impacts is visible, not only its total
  (an octave-band vibration monitor such as the SKF CMSS or a band-power edge node reports these);
- the kurtosis of the 20-400 Hz signal over the tick (3 for Gaussian vibration; impacts raise it),
  the impact indicator of condition-monitoring practice.

The piezo's own transducer noise is added at the sample rate, before filtering, as a white noise of
``noise.piezo_density`` (m/s^2 per sqrt(Hz)), so every piezo channel sees it through its own band
as a real one would. The other channels get a Gaussian floor per tick (:meth:`add_noise`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import signal

from robohealth_mj.common.errors import InputError

BROADBAND_HZ = (20.0, 400.0)
SUB_BANDS_HZ: tuple[tuple[float, float], ...] = ((20.0, 80.0), (80.0, 200.0), (200.0, 450.0))


@dataclass(frozen=True)
class NoiseFloor:
    """Noise on each emitted channel: standard deviation per tick, except the piezo's density."""

    pos: float = 1e-4  # rad
    vel: float = 1e-3  # rad/s
    effort: float = 0.05  # N m
    acc: float = 0.02  # m/s^2 (MEMS accelerometer, tick mean)
    piezo_density: float = 2e-5  # m/s^2 / sqrt(Hz), white, at the sample rate (ICP-grade piezo)


@dataclass
class PiezoTick:
    """Per-tick piezo readings of a chunk: vib ``[n, 6]``, bands ``[n, 6, 3]``, kurt. ``[n, 6]``."""

    vib: np.ndarray
    bands: np.ndarray
    kurtosis: np.ndarray


class _StatefulBandPass:
    """A Butterworth band-pass whose state carries over chunk boundaries."""

    def __init__(self, band_hz: tuple[float, float], order: int, rate_hz: float) -> None:
        low, high = band_hz
        nyquist = rate_hz / 2.0
        if not 0.0 < low < high < nyquist:
            raise InputError(
                f"piezo band {tuple(band_hz)} Hz must satisfy 0 < low < high < {nyquist}"
            )
        self.sos = signal.butter(order, [low, high], btype="bandpass", fs=rate_hz, output="sos")
        self.zi: np.ndarray | None = None

    def __call__(self, flat: np.ndarray) -> np.ndarray:
        if self.zi is None:  # start in steady state on the first reading: no start-up ring
            self.zi = signal.sosfilt_zi(self.sos)[:, :, None] * flat[0][None, None, :]
        out, self.zi = signal.sosfilt(self.sos, flat, axis=0, zi=self.zi)
        return out


class SensorPackage:
    """Per-joint accelerometer + piezo synthesis with stateful band-pass filters."""

    def __init__(
        self,
        physics_rate_hz: float,
        band_hz: tuple[float, float] = BROADBAND_HZ,
        sub_bands_hz: tuple[tuple[float, float], ...] = SUB_BANDS_HZ,
        filter_order: int = 4,
        noise: dict | NoiseFloor | None = None,
        joint_torque: bool | None = None,
    ) -> None:
        """``joint_torque``: what the controller reports as a joint's torque: True, a torque
        sensor in the joint (the link side of the drive); False, the motor's current; None, what
        the arm has (its description: the FR3, iiwa and Gen3 carry torque sensors)."""
        self.joint_torque = joint_torque
        if len(sub_bands_hz) != len(SUB_BANDS_HZ):
            raise InputError(
                f"sensors.sub_bands_hz needs {len(SUB_BANDS_HZ)} bands (the schema's), "
                f"got {len(sub_bands_hz)}"
            )
        self.rate_hz = float(physics_rate_hz)
        self.filters = [
            _StatefulBandPass(tuple(b), filter_order, self.rate_hz)
            for b in (band_hz, *sub_bands_hz)
        ]
        self.noise = noise if isinstance(noise, NoiseFloor) else NoiseFloor(**(noise or {}))
        # this arm's own transducers (sim/variation.py): sensitivity and noise factor per joint
        # (one value: every joint's alike, on an arm of any joint count)
        self.gain = np.ones(1)
        self.noise_scale = np.ones(1)
        # the torque sensing's floor per joint relative to the UR5e's (its rating over the UR5e's)
        self.effort_scale = np.ones(1)

    def reset(self) -> None:
        for f in self.filters:
            f.zi = None

    def piezo_sigma(self) -> float:
        """Per-sample standard deviation of the piezo's white noise (density x sqrt(Nyquist))."""
        return self.noise.piezo_density * np.sqrt(self.rate_hz / 2.0)

    def process(
        self, acc: np.ndarray, tick_steps: int, rng: np.random.Generator | None = None
    ) -> tuple[np.ndarray, PiezoTick]:
        """High-rate accelerations ``[steps, J, 3]`` -> tick-mean acceleration ``[ticks, J, 3]``
        (noise-free; :meth:`add_noise` adds its floor) and the piezo channels of each tick (with
        the transducer noise drawn from ``rng``; noise-free when ``rng`` is None)."""
        steps = acc.shape[0]
        if steps % tick_steps:
            raise ValueError(f"{steps} steps is not a whole number of {tick_steps}-step ticks")
        ticks, joints = steps // tick_steps, acc.shape[1]
        acc = acc * self.gain[None, :, None]  # each package's sensitivity
        flat = acc.reshape(steps, joints * 3)
        scale = np.repeat(np.broadcast_to(self.noise_scale, (joints,)), 3)[None, :]
        piezo = (
            flat if rng is None else flat + rng.normal(0.0, self.piezo_sigma(), flat.shape) * scale
        )

        def per_tick(filtered: np.ndarray) -> np.ndarray:  # [ticks, tick_steps, J, 3]
            return filtered.reshape(ticks, tick_steps, joints, 3)

        square = np.square(per_tick(self.filters[0](piezo)))
        second = square.mean(axis=1)  # per axis [ticks, 6, 3]
        fourth = np.square(square).mean(axis=1)
        power = second.sum(axis=-1)  # [ticks, 6]
        kurtosis = (fourth / np.maximum(np.square(second), 1e-30)).mean(axis=-1)
        band_power = [
            np.square(per_tick(f(piezo))).mean(axis=1).sum(axis=-1) for f in self.filters[1:]
        ]
        bands = np.sqrt(np.stack(band_power, axis=-1))
        acc_mean = acc.reshape(ticks, tick_steps, joints, 3).mean(axis=1)
        return acc_mean, PiezoTick(np.sqrt(power), bands, kurtosis)

    def add_noise(
        self,
        rng: np.random.Generator,
        pos: np.ndarray,
        vel: np.ndarray,
        effort: np.ndarray,
        acc: np.ndarray,
    ) -> tuple[np.ndarray, ...]:
        """Add the per-tick noise floor to a chunk of readings (one draw order, so bytes
        reproduce)."""
        n = self.noise
        return (
            pos + rng.normal(0.0, n.pos, pos.shape),
            vel + rng.normal(0.0, n.vel, vel.shape),
            effort + rng.normal(0.0, n.effort, effort.shape) * self.effort_scale,
            acc + rng.normal(0.0, n.acc, acc.shape) * self.noise_scale[None, :, None],
        )
