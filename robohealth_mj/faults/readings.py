"""Faults that act on what the sensors report: the two sensor faults and the thesis's analytic
signature layer (Table 2) for the four mechanical faults, with ``exp(-decay * hops)`` propagation.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from robohealth_mj.faults.catalogue import Scenario


@dataclass
class TickReadings:
    """Per-tick readings of one chunk, edited in place: pos/vel/effort ``[n, J]``, vib ``[n, J]``,
    acc ``[n, J, 3]``, piezo sub-bands ``[n, J, 3]``, kurtosis ``[n, J]``."""

    pos: np.ndarray
    vel: np.ndarray
    effort: np.ndarray
    vib: np.ndarray
    acc: np.ndarray
    bands: np.ndarray
    kurtosis: np.ndarray


class ReadingFaults:
    """Stateful across chunks (drift integrators, reversal timers, jam phase, acc baseline)."""

    def __init__(
        self,
        physics: dict[str, dict[str, Any]],
        analytic: dict[str, dict[str, Any]],
        tick_s: float,
        torque_limit: np.ndarray,
        analytic_layer: bool,
    ) -> None:
        self.physics, self.analytic = physics, analytic
        self.tick_s = float(tick_s)
        self.torque_limit = np.asarray(torque_limit, dtype=float)
        self.analytic_layer = bool(analytic_layer)
        joints = len(self.torque_limit)
        chain = np.arange(joints)  # hops along the chain
        self.hops = np.abs(chain[:, None] - chain[None, :])
        self._interval: int | None = None
        self._drift = np.zeros((joints, 4))
        self._drift_sign = np.ones(4)
        self._since_reversal = 1e9
        self._last_vel = 0.0
        self._jam_phase = 0.0
        self._baseline: np.ndarray | None = None

    def influence(self, scenario: Scenario, decay: float) -> np.ndarray:
        """Severity attenuated by hop distance from the target joint, per sensor ``[J]``."""
        return scenario.severity * np.exp(-decay * self.hops[scenario.joint])

    def apply(
        self,
        scenario: Scenario | None,
        interval_start: int,
        r: TickReadings,
        rng: np.random.Generator,
    ) -> None:
        self._track_baseline(r.acc)
        if scenario is None:
            self._interval = None
            return
        if interval_start != self._interval:
            self._start(interval_start, rng)
        mode = scenario.fault_class
        if mode == "sensor_drift":
            self._sensor_drift(scenario, r, rng)
        elif mode == "sensor_noise":
            self._sensor_noise(scenario, r, rng)
        elif self.analytic_layer:
            getattr(self, f"_signature_{mode}")(scenario, r, rng)

    def _start(self, interval_start: int, rng: np.random.Generator) -> None:
        self._interval = interval_start
        self._drift[:] = 0.0
        self._drift_sign = rng.choice([-1.0, 1.0], size=4)
        self._since_reversal = 1e9
        self._jam_phase = 0.0

    def _track_baseline(self, acc: np.ndarray) -> None:
        """Slow per-sensor acceleration baseline (gravity + pose), so gains act on motion only."""
        alpha = min(1.0, self.tick_s / 1.0)
        for k in range(acc.shape[0]):
            if self._baseline is None:
                self._baseline = acc[k].copy()
            self._baseline += alpha * (acc[k] - self._baseline)

    # sensor faults (real transducer behaviour: applied in every fault model)

    def _sensor_drift(self, sc: Scenario, r: TickReadings, rng: np.random.Generator) -> None:
        p = self.physics["sensor_drift"]
        rate = np.asarray(p["rate"], dtype=float) * sc.severity * self._drift_sign
        j = sc.joint
        for k in range(r.vib.shape[0]):
            step = rate * self.tick_s + rng.normal(0.0, p["walk"], 4) * sc.severity * np.sqrt(
                self.tick_s
            )
            self._drift[j] += step
            # The drift offsets the transmitter's level output (and the MEMS axes); the sub-band
            # levels are filtered digitally from the raw signal, where an offset is DC and the
            # band-pass removes it.
            r.vib[k, j] = abs(r.vib[k, j] + self._drift[j, 0])
            r.acc[k, j] += self._drift[j, 1:]

    def _sensor_noise(self, sc: Scenario, r: TickReadings, rng: np.random.Generator) -> None:
        p = self.physics["sensor_noise"]
        w = self.influence(sc, p["decay"])
        r.vib[:] = np.abs(r.vib + rng.normal(0.0, 1.0, r.vib.shape) * w * p["sigma_vib"])
        r.acc += rng.normal(0.0, 1.0, r.acc.shape) * (w * p["sigma_acc"])[None, :, None]
        # Broadband transducer noise spreads over the sub-bands (a third of its power in each).
        sigma_band = (w * p["sigma_vib"] / np.sqrt(r.bands.shape[-1]))[None, :, None]
        r.bands[:] = np.abs(r.bands + rng.normal(0.0, 1.0, r.bands.shape) * sigma_band)

    # the thesis's analytic signatures (Table 2), layered on the physics readings

    def _jitter(self, rng: np.random.Generator, shape: Any) -> np.ndarray:
        return np.clip(1.0 + 0.2 * rng.normal(size=shape), 0.5, 1.5)

    def _signature_backlash(self, sc: Scenario, r: TickReadings, rng: np.random.Generator) -> None:
        p = self.analytic["backlash"]
        w = self.influence(sc, p["decay"])
        for k in range(r.vib.shape[0]):
            v = r.vel[k, sc.joint]
            if np.sign(v) != np.sign(self._last_vel) and abs(v - self._last_vel) > 1e-3:
                self._since_reversal = 0.0
            self._last_vel = v
            chatter = np.exp(-self._since_reversal / p["ring_s"])
            self._since_reversal += self.tick_s
            if chatter < 1e-3:
                continue
            r.vib[k] += p["chatter_gain"] * w * chatter * self._jitter(rng, len(self.hops))
            kick = -np.sign(v) * p["kick_gain"] * w * chatter * self._jitter(rng, len(self.hops))
            r.acc[k, :, 0] += kick  # opposite-axis kick against the reversal

    def _signature_friction(self, sc: Scenario, r: TickReadings, rng: np.random.Generator) -> None:
        p = self.analytic["friction"]
        w = self.influence(sc, p["decay"])
        load = np.abs(r.effort[:, sc.joint]) / self.torque_limit[sc.joint]
        r.vib += p["vib_gain"] * load[:, None] * w[None, :] * self._jitter(rng, r.vib.shape)
        r.acc[:, :, 2] += p["z_bias"] * w[None, :]

    def _signature_jam(self, sc: Scenario, r: TickReadings, rng: np.random.Generator) -> None:
        p = self.analytic["jam"]
        w = self.influence(sc, p["decay"])
        for k in range(r.vib.shape[0]):
            self._jam_phase += self.tick_s
            if self._jam_phase < p["period_s"]:
                continue
            self._jam_phase = 0.0
            r.vib[k] += p["impulse_gain"] * w * self._jitter(rng, len(self.hops))
            direction = rng.normal(size=3)
            direction /= np.linalg.norm(direction)
            r.acc[k] += p["impulse_gain"] * w[:, None] * direction[None, :]

    def _signature_struct_weaken(
        self, sc: Scenario, r: TickReadings, rng: np.random.Generator
    ) -> None:
        p = self.analytic["struct_weaken"]
        gain = 1.0 + p["gain"] * self.influence(sc, p["decay"])
        r.vib *= gain[None, :]
        if self._baseline is not None:
            r.acc[:] = self._baseline + (r.acc - self._baseline) * gain[None, :, None]
