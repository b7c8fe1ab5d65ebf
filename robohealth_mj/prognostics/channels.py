"""Wear read straight from the recorded channels each mechanical mode acts on, per joint.

The window model's severity head levels off for friction and backlash (the index stops rising
at half the wear on long lives, so the trend warns weeks early), yet the physics carries both
in one recorded channel each, nearly linearly in the severity (linear correlation 0.99 over the
held-out and fresh lives, ``studies/wear/severity_channels.py``):

- friction adds a torque against the motion: the mean of ``effort_residual`` x sign(``vel``) over
  the ticks the joint turns;
- a backlash gap lets the link lag its target: the RMS ``pos_error`` over the same ticks.

A reading divided by its (mode, joint)'s *scale*, the reading per unit severity fitted as a line
through the origin on labelled fault episodes (the standard corpus holds every pair at 0.3, 0.6
and 0.9), is in severity units. Seven more channels carry the other two modes and tell the four
apart (:mod:`robohealth_mj.prognostics.signature`): the residual's spread and its peak (a jam's
torque impulses: a few a minute at low severity, which the spread dilutes over the day's ticks
and an eighth-power mean does not), the lag signed against the motion, a dead zone and a
compliance fitted together to the lag against the drive torque (a gap against a softer drive),
and the joint's sensor package's vibration overall and in its highest band (the knocks of a gap
or a catching gear); the joint's speed rides along, as the duty the others depend on.
:class:`ChannelSums` accumulates a session tick by tick, as the monitor sees it. NumPy only.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from pathlib import Path

import numpy as np

from robohealth_mj.data.observability import MOVING_RAD_S
from robohealth_mj.schema import FAULT_CLASSES, FEATURE_NAMES

MODES = ("friction", "backlash")  # the modes with a scale: the first two channels
CHANNELS = (
    "friction",  # mean effort_residual x sign(vel) while turning
    "lag",  # RMS pos_error while turning
    "residual_rms",  # RMS effort_residual while turning
    "lag_against_motion",  # mean pos_error x sign(vel) while turning
    "gap",  # pos_error = gap x sign(effort) + compliance x effort, fitted while turning:
    "compliance",  # a dead zone (backlash) against a softer spring (stiffness loss)
    "vibration",  # mean of the joint's sensor's vib
    "vibration_high",  # mean of its vib_200_450 band
    "residual_peak",  # (mean effort_residual^8)^(1/8) while turning: a jam's rare impulses
    "speed",  # mean |vel| while turning: not a wear channel, the duty the others depend on
    "load",  # mean |effort| while turning: not a wear channel, the torque the drive carries
)
_F = {name: i for i, name in enumerate(FEATURE_NAMES)}
# The peak channel's power: an L8 norm of the residual weighs a catching gear's rare impulses,
# which an RMS dilutes over the day's ticks. On the validation lives (seed 42's signatures, the
# jam's wearing joint, mode known) the jam's severity read is 0.119 off without the channel and
# 0.095, 0.087, 0.082, 0.080, 0.078 at powers 4, 6, 8, 12, 16: past 8 the gain is small and the
# reading rests on ever fewer ticks (the limit is the day's largest residual).
PEAK_POWER = 8


class ChannelSums:
    """A session's running sums per joint, one per channel term (joints' nodes first; a
    joint's sensor package, where the sample has one, at node ``J + joint``)."""

    def __init__(self, n_joints: int) -> None:
        self.n = n_joints
        self.turned = np.zeros(n_joints)  # ticks the joint turned in
        self.ticks = np.zeros(n_joints)  # ticks its sensor package was read
        self.moving_sums = np.zeros((10, n_joints))  # over the turning ticks, see readings()
        self.sensor_sums = np.zeros((2, n_joints))  # vib, vib_200_450

    def add(self, x: np.ndarray) -> None:
        """Snapshots ``x [T, N, F]`` or one ``[N, F]``."""
        x = np.asarray(x, float)
        x = x[None] if x.ndim == 2 else x
        joints = x[:, : self.n, :]
        vel = joints[..., _F["vel"]]
        moving = np.abs(vel) > MOVING_RAD_S
        sign = np.sign(vel)
        residual = joints[..., _F["effort_residual"]]
        pos_error = joints[..., _F["pos_error"]]
        effort = joints[..., _F["effort"]]
        terms = (residual * sign, pos_error**2, residual**2, pos_error * sign,
                 pos_error * np.sign(effort), pos_error * effort, np.abs(effort), effort**2,
                 np.abs(vel), residual**PEAK_POWER)  # fmt: skip
        self.turned += moving.sum(axis=0)
        for k, term in enumerate(terms):
            self.moving_sums[k] += (term * moving).sum(axis=0)
        if x.shape[1] >= 2 * self.n:
            sensors = x[:, self.n : 2 * self.n, :]
            self.ticks += len(x)
            self.sensor_sums[0] += sensors[..., _F["vib"]].sum(axis=0)
            self.sensor_sums[1] += sensors[..., _F["vib_200_450"]].sum(axis=0)

    def readings(self) -> np.ndarray:
        """``[C, J]`` each channel's reading (:data:`CHANNELS`; NaN for a joint that never turned
        and for the vibration of samples without sensor packages)."""
        m, t = self.moving_sums, np.where(self.turned > 0, self.turned, np.nan)
        ticks = np.where(self.ticks > 0, self.ticks, np.nan)
        with np.errstate(invalid="ignore", divide="ignore"):
            # least squares of pos_error on [sign(effort), effort]: [[n, |e|], [|e|, e^2]] b = rhs
            det = self.turned * m[7] - m[6] ** 2
            gap = (m[7] * m[4] - m[6] * m[5]) / det
            compliance = (self.turned * m[5] - m[6] * m[4]) / det
            fitted = np.abs(det) > 1e-12 * np.maximum(self.turned * m[7], 1e-300)
            moving = [m[0] / t, np.sqrt(m[1] / t), np.sqrt(m[2] / t), m[3] / t]
            fit = [np.where(fitted, gap, np.nan), np.where(fitted, compliance, np.nan)]
            sensed = [self.sensor_sums[0] / ticks, self.sensor_sums[1] / ticks]
            peak = (m[9] / t) ** (1 / PEAK_POWER)
            return np.stack([*moving, *fit, *sensed, peak, m[8] / t, m[6] / t])


def channel_readings(x: np.ndarray, n_joints: int) -> np.ndarray:
    """``[C, J]`` each channel's reading on each joint from snapshots ``x [T, N, F]``."""
    sums = ChannelSums(n_joints)
    sums.add(x)
    return sums.readings()


def labelled_stretches(
    session: Path, n_joints: int, min_ticks: int = 1
) -> Iterator[tuple[int, int, float, np.ndarray]]:
    """``(fault class, joint, severity, readings [C, J])`` per labelled stretch of a recording's
    binary cache (consecutive samples with one class, joint and severity; at least
    ``min_ticks`` of them)."""
    z = np.load(session)
    x, cls, joint, sev = z["x"], z["fault_class"], z["fault_joint"], z["severity"]
    key = np.stack([cls, joint, np.round(sev * 1000)], axis=1)
    change = np.flatnonzero((np.diff(key, axis=0) != 0).any(axis=1)) + 1
    for start, end in zip(np.r_[0, change], np.r_[change, len(cls)], strict=True):
        if end - start >= min_ticks:
            readings = channel_readings(x[start:end], n_joints)
            yield int(cls[start]), int(joint[start]), float(sev[start]), readings


def fit_scales(sessions: Iterable[Path], n_joints: int) -> np.ndarray:
    """``[2, J]`` each (mode, joint)'s reading per unit severity: a line through the origin over
    the fault episodes of ``sessions`` (binary caches of labelled recordings)."""
    num = np.zeros((len(MODES), n_joints))
    den = np.zeros((len(MODES), n_joints))
    for session in sessions:
        for cls, j, s, readings in labelled_stretches(session, n_joints):
            if FAULT_CLASSES[cls] not in MODES:  # a healthy stretch (severity 0) adds nothing
                continue
            m = MODES.index(FAULT_CLASSES[cls])
            if np.isfinite(readings[m, j]):
                num[m, j] += readings[m, j] * s
                den[m, j] += s * s
    with np.errstate(invalid="ignore", divide="ignore"):
        return num / den
