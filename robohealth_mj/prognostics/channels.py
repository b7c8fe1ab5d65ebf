"""Wear read straight from the channel each of two mechanical modes acts on, per joint.

The window model's severity head levels off for friction and backlash (the index stops rising
at half the wear on long lives, so the trend warns weeks early), yet the physics carries both
in one recorded channel each, nearly linearly in the severity (linear correlation 0.99 over the
held-out and fresh lives, ``studies/wear/severity_channels.py``):

- friction adds a torque against the motion: the mean of ``effort_residual`` x sign(``vel``) over
  the ticks the joint turns;
- a backlash gap lets the link lag its target: the RMS ``pos_error`` over the same ticks.

A reading divided by its (mode, joint)'s *scale*, the reading per unit severity fitted as a line
through the origin on labelled fault episodes (the standard corpus holds every pair at 0.3, 0.6
and 0.9), is in severity units. :class:`ChannelSums` accumulates a session tick by tick, as the
monitor sees it. NumPy only.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

import numpy as np

from robohealth_mj.data.observability import MOVING_RAD_S
from robohealth_mj.schema import FAULT_CLASSES, FEATURE_NAMES

MODES = ("friction", "backlash")


class ChannelSums:
    """A session's running sums per joint: ticks turned, friction's and backlash's terms."""

    def __init__(self, n_joints: int) -> None:
        self.turned = np.zeros(n_joints)
        self.friction = np.zeros(n_joints)
        self.lag = np.zeros(n_joints)

    def add(self, x: np.ndarray) -> None:
        """Snapshots ``x [T, N, F]`` or one ``[N, F]`` (the joints' nodes first)."""
        x = np.asarray(x, float)
        x = x[None] if x.ndim == 2 else x
        joints = x[:, : len(self.turned), :]
        vel = joints[..., FEATURE_NAMES.index("vel")]
        moving = np.abs(vel) > MOVING_RAD_S
        residual = joints[..., FEATURE_NAMES.index("effort_residual")] * np.sign(vel)
        self.turned += moving.sum(axis=0)
        self.friction += (residual * moving).sum(axis=0)
        self.lag += (joints[..., FEATURE_NAMES.index("pos_error")] ** 2 * moving).sum(axis=0)

    def readings(self) -> np.ndarray:
        """``[2, J]`` friction's and backlash's readings (NaN for a joint that never turned)."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.stack([self.friction / self.turned, np.sqrt(self.lag / self.turned)])


def channel_readings(x: np.ndarray, n_joints: int) -> np.ndarray:
    """``[2, J]`` each mode's reading on each joint from snapshots ``x [T, N, F]``."""
    sums = ChannelSums(n_joints)
    sums.add(x)
    return sums.readings()


def fit_scales(sessions: Iterable[Path], n_joints: int) -> np.ndarray:
    """``[2, J]`` each (mode, joint)'s reading per unit severity: a line through the origin over
    the fault episodes of ``sessions`` (binary caches of labelled recordings)."""
    num = np.zeros((len(MODES), n_joints))
    den = np.zeros((len(MODES), n_joints))
    for session in sessions:
        z = np.load(session)
        x, cls, joint, sev = z["x"], z["fault_class"], z["fault_joint"], z["severity"]
        for m, mode in enumerate(MODES):
            for j in range(n_joints):
                mine = (cls == FAULT_CLASSES.index(mode)) & (joint == j) & (sev > 0)
                if not mine.any():
                    continue
                edges = np.flatnonzero(np.diff(np.concatenate([[0], mine.astype(int), [0]])))
                for start, end in zip(edges[::2], edges[1::2], strict=True):
                    reading = channel_readings(x[start:end], n_joints)[m, j]
                    if np.isfinite(reading):
                        s = float(sev[start])
                        num[m, j] += reading * s
                        den[m, j] += s * s
    with np.errstate(invalid="ignore", divide="ignore"):
        return num / den
