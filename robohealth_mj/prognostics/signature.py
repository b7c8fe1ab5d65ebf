"""Which mechanical mode wears a joint, and how far, from the recorded channels alone.

Each mode moves the channels of :mod:`robohealth_mj.prognostics.channels` in its own pattern
(the standard corpus's labelled episodes at severity 0.9, in healthy spreads): friction raises the
torque against the motion (~120) and the lag (~50); a backlash gap the lag (~220) and the dead
zone; a catching gear the residual's spread (~33) and the vibration (~21-48), with no mean
torque; a softer drive the lag (~25) and the compliance. A healthy joint's readings follow its
speed (a quadratic in the joint's mean speed explains 75-97 % of a healthy day's friction, lag and
residual readings on the shoulder and elbow), so the healthy level is a quadratic in the speed
and a reading is taken as its excess over that level, in healthy spreads.

:class:`Signatures` holds per mode, channel and joint the excess's response to the severity (a
quadratic through zero whose terms grow with the speed: a jam's impulses grow in rate and size
together, viscous friction with the speed). The shapes come from the
standard corpus's short labelled episodes (every mode and joint at 0.3, 0.6 and 0.9,
:func:`fit_signatures`); :func:`adapt` re-fits the healthy level and spread on whole operating
days and scales each (mode, channel)'s response by what days of known wear show, keeping only
the channels the days bear out within a factor of two (a backlash episode's vibration, for one,
is an onset transient that days do not repeat). :meth:`Signatures.read` gives the severity of a
named mode; :meth:`Signatures.call` names the mode whose signature explains most of the excess,
and says whether the call is sure (the runner-up explains far less).
No window model is needed. NumPy only.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from robohealth_mj.common.errors import InputError
from robohealth_mj.prognostics.channels import CHANNELS, labelled_stretches
from robohealth_mj.prognostics.health import MECHANICAL_CLASSES
from robohealth_mj.schema import FAULT_CLASSES

SEVERITY_GRID = np.linspace(0.0, 1.5, 151)  # the severities a reading weighs (0.01 apart)
# A call is taken only where one healthy spread of noise moves the severity read by at most this
# much (the wear target's MAE): a softer drive at the shoulder pan or the last wrist moves the
# channels a few spreads at full severity, so a healthy day's noise there would read as wear.
SURE_SE = 0.05
MIN_EPISODE_TICKS = 50  # shorter labelled stretches (a fault's edges) are not fitted
SPEED = CHANNELS.index("speed")  # the covariate: every other channel is a wear channel
WEAR = np.array([c != SPEED for c in range(len(CHANNELS))])
TRUSTED = (0.5, 2.0)  # the days' response over the episodes' for a channel to be read
# The excess a mode must explain (squared healthy spreads) to be read as wear: on the training
# lives' healthy joint-days the 99th-percentile reading is 0.76 with none, 0.24 at 9, 0.03 at 16.
DETECT = 16.0
# How much more of the excess the called mode must explain than the runner-up, as a share of its
# own, for the call to be taken over the window model's: chosen on the validation lives (seed 42;
# the wearing joint's raw MAE 0.105, 0.093, 0.088, 0.081, 0.085 and 0.084 at 0, 0.3, 0.5, 0.7,
# 0.9 and never). Backlash and a softer drive at the elbow and shoulder explain each other's
# readings nearly as well (both lag under a one-sided gravity torque): those calls are not taken.
MARGIN = 0.7


@dataclass(frozen=True)
class Signatures:
    """``baseline [C, J, 3]``: a healthy reading is ``b0 + b1 v + b2 v^2`` at the joint's speed
    ``v``; ``spread [C, J]``: the healthy readings' spread about it; ``response [M, C, J, 4]``:
    the excess is ``s (r1 + r2 v) + s^2 (r3 + r4 v)`` at severity ``s`` of mode ``m``; ``use
    [M, C]``: the channels a mode is read from (modes in :data:`MECHANICAL_CLASSES` order; C over
    :data:`CHANNELS`, the speed's rows unused); ``detect``, ``margin``: see :func:`adapt`."""

    baseline: np.ndarray
    spread: np.ndarray
    response: np.ndarray
    use: np.ndarray
    detect: float = 0.0
    margin: float = 0.0

    def excess(self, readings: np.ndarray) -> np.ndarray:
        """``[C, J]`` each reading above its healthy level at the day's speed, in spreads (NaN
        where a channel was not read)."""
        r = np.asarray(readings, float)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(WEAR[:, None], (r - _level(self.baseline, r)) / self.spread, np.nan)

    def _costs(self, readings: np.ndarray) -> tuple[np.ndarray, ...]:
        """``(cost [M, S, J], at_zero [M, J], seen [J], size [M, S, J])``: per mode and grid
        severity the squared misfit over the mode's channels, the misfit of no wear, whether any
        channel was read, and the predicted excess's size over the channels read (in spreads)."""
        z = self.excess(readings)  # [C, J]
        v = np.asarray(readings, float)[SPEED]
        predicted = _response(self.response[:, None], SEVERITY_GRID[:, None, None], v)
        predicted = np.nan_to_num(predicted / self.spread)  # [M, S, C, J]
        read = np.isfinite(z)[None] & self.use[:, :, None]  # [M, C, J]
        miss = np.where(read[:, None], np.nan_to_num(z) - predicted, 0.0) ** 2
        cost = miss.sum(axis=2)
        known = np.isfinite(self.response).all(axis=(1, 3))  # [M, J]: the pairs fitted
        size = np.sqrt((np.where(read[:, None], predicted, 0.0) ** 2).sum(axis=2))  # [M, S, J]
        cost = np.where(known[:, None], cost, np.inf)
        return cost, cost[:, 0], read.any(axis=(0, 1)), size

    def read(self, readings: np.ndarray, mode: np.ndarray) -> np.ndarray:
        """``[J]`` the severity of ``mode [J]`` on each joint: 0 where it explains less than
        :attr:`detect` of the excess (in squared spreads), NaN where nothing was read."""
        cost, at_zero, seen, _ = self._costs(readings)
        return self._severity(cost, at_zero, seen, np.asarray(mode, int))

    def call(self, readings: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(mode [J], severity [J], sure [J])``: the mode whose signature explains most of the
        excess (the misfit of no wear less its best misfit), its severity, and whether the call
        is sure: the mode reads its severity to within :data:`SURE_SE` per spread of noise, wear
        was detected, the runner-up explains at most ``1 - margin`` as much, and no
        other joint's sure call of that mode explains more (a catching gear's impulses and a
        gap's knocks travel through the arm: the joint that shows them most is their source)."""
        cost, at_zero, seen, size = self._costs(readings)
        explained = at_zero - cost.min(axis=1)  # [M, J]
        explained = np.where(np.isfinite(explained), explained, -np.inf)
        mode = explained.argmax(axis=0)
        best, second = np.sort(explained, axis=0)[[-1, -2]]
        j = np.arange(len(mode))
        step = cost[mode, :, j].argmin(axis=1)  # the severity read, on the grid
        # a spread of noise moves the severity read by about severity / size
        precise = size[mode, step, j] * SURE_SE >= SEVERITY_GRID[step]
        sure = precise & (best >= max(self.detect, 1e-12)) & (best - second > self.margin * best)
        for m in np.unique(mode[sure]):
            same = sure & (mode == m)
            sure &= ~same | (best >= best[same].max())
        return mode, self._severity(cost, at_zero, seen, mode), sure

    def _severity(
        self, cost: np.ndarray, at_zero: np.ndarray, seen: np.ndarray, mode: np.ndarray
    ) -> np.ndarray:
        j = np.arange(cost.shape[-1])
        best = cost[mode, :, j]  # [J, S]
        severity = SEVERITY_GRID[best.argmin(axis=1)]
        severity[at_zero[mode, j] - best.min(axis=1) < self.detect] = 0.0
        return np.where(seen & np.isfinite(best).any(axis=1), severity, np.nan)

    def size(self, severity: float, speed: np.ndarray) -> np.ndarray:
        """``[M, J]`` how far each mode at ``severity`` moves its channels from a healthy day at
        the joints' ``speed [J]``, in healthy spreads: the physics' own limit on reading it (one
        spread of noise moves the severity read by about ``severity / size``)."""
        predicted = _response(self.response, severity, np.asarray(speed, float)[None, None])
        z = np.nan_to_num(predicted / self.spread) * self.use[:, :, None]  # [M, C, J]
        return np.sqrt((z**2).sum(axis=1))

    def to_json(self) -> dict[str, Any]:
        return {
            "channels": list(CHANNELS),
            "modes": list(MECHANICAL_CLASSES),
            **{k: np.round(getattr(self, k), 12).tolist() for k in ("baseline", "spread")},
            "response": np.round(self.response, 12).tolist(),
            "use": self.use.astype(int).tolist(),
            "detect": self.detect,
            "margin": self.margin,
        }

    @classmethod
    def from_json(cls, data: Any, where: str) -> Signatures:
        try:
            parts = [np.asarray(data[k], float) for k in ("baseline", "spread", "response")]
            use = np.asarray(data["use"], int).astype(bool)
            channels = list(data["channels"])
            detect, margin = float(data["detect"]), float(data["margin"])
        except (TypeError, ValueError, KeyError) as exc:
            raise InputError(f"{where}: not a channel signature ({exc})") from None
        c, m = len(CHANNELS), len(MECHANICAL_CLASSES)
        j = parts[1].shape[-1] if parts[1].ndim == 2 else 0
        shapes = ((c, j, 3), (c, j), (m, c, j, 4), (m, c))
        if (
            channels != list(CHANNELS)
            or j == 0
            or any(p.shape != want for p, want in zip([*parts, use], shapes, strict=True))
        ):
            raise InputError(
                f"{where}: a signature of channels {channels} over {parts[1].shape} joints; "
                f"this version reads {list(CHANNELS)}"
            )
        return cls(*parts, use, detect, margin)


def _speed_fit(readings: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``readings [E, C, J]`` of healthy stretches → ``(baseline [C, J, 3], spread [C, J])``."""
    _, c_n, j_n = readings.shape
    baseline, spread = np.zeros((c_n, j_n, 3)), np.full((c_n, j_n), np.nan)
    for j in range(j_n):
        v = readings[:, SPEED, j]
        for c in np.flatnonzero(WEAR):
            y = readings[:, c, j]
            ok = np.isfinite(y) & np.isfinite(v)
            if ok.sum() < 6:
                continue
            design = np.stack([np.ones(ok.sum()), v[ok], v[ok] ** 2], axis=1)
            baseline[c, j] = np.linalg.lstsq(design, y[ok], rcond=None)[0]
            sd = float(np.std(y[ok] - design @ baseline[c, j]))
            spread[c, j] = sd if sd > 0 else np.nan
    return baseline, spread


def _response(response: np.ndarray, severity, speed) -> np.ndarray:
    """The excess ``response [..., 4]`` predicts at ``severity`` and the joint's ``speed``."""
    r = [response[..., k] for k in range(4)]
    return severity * (r[0] + r[1] * speed) + severity**2 * (r[2] + r[3] * speed)


def _level(baseline: np.ndarray, readings: np.ndarray) -> np.ndarray:
    v = readings[SPEED]
    return baseline[..., 0] + baseline[..., 1] * v + baseline[..., 2] * v**2


def fit_signatures(sessions: Iterable[Path], n_joints: int) -> Signatures:
    """Fit on labelled recordings (the standard corpus holds every mode and joint at severity
    0.3, 0.6 and 0.9): the healthy stretches' level and spread, then per (mode, joint) each
    channel's quadratic response by least squares. Every channel is read."""
    healthy, faulty = [], []
    for session in sessions:
        for cls, joint, sev, readings in labelled_stretches(session, n_joints, MIN_EPISODE_TICKS):
            if cls == FAULT_CLASSES.index("none"):
                healthy.append(readings)
            elif FAULT_CLASSES[cls] in MECHANICAL_CLASSES and sev > 0:
                faulty.append((MECHANICAL_CLASSES.index(FAULT_CLASSES[cls]), joint, sev, readings))
    if len(healthy) < 6 or not faulty:
        raise InputError("channel signatures: the recordings hold no healthy and faulty stretches")
    baseline, spread = _speed_fit(np.stack(healthy))
    response = np.full((len(MECHANICAL_CLASSES), len(CHANNELS), n_joints, 4), np.nan)
    for m in range(len(MECHANICAL_CLASSES)):
        for j in range(n_joints):
            mine = [(s, r) for mm, jj, s, r in faulty if mm == m and jj == j]
            if len({s for s, _ in mine}) < 2:
                continue
            sev = np.array([s for s, _ in mine])
            speed = np.array([r[SPEED, j] for _, r in mine])
            design = np.stack([sev, sev * speed, sev**2, sev**2 * speed], axis=1)
            excess = np.stack([r[:, j] - _level(baseline, r)[:, j] for _, r in mine])  # [E, C]
            for c in np.flatnonzero(WEAR):
                ok = np.isfinite(excess[:, c]) & np.isfinite(speed)
                if ok.sum() >= 6:
                    response[m, c, j] = np.linalg.lstsq(design[ok], excess[ok, c], rcond=None)[0]
            response[m, SPEED, j] = 0.0
    use = np.tile(WEAR, (len(MECHANICAL_CLASSES), 1))
    return Signatures(baseline, spread, response, use)


def adapt(episodic: Signatures, days: Iterable[tuple[np.ndarray, np.ndarray, int]]) -> Signatures:
    """Bring episode-fitted signatures to whole days: ``days`` of ``(readings [C, J], truth
    [J], mode)`` (``mode``: the index of the life's wearing mode, -1 for a healthy life). The
    healthy level and spread are re-fitted on the joints at severity 0; each (mode, channel)'s
    response is scaled by the least-squares ratio of the days' excess to the episodes'
    prediction, pooled over joints, and read only where that ratio lies in :data:`TRUSTED`."""
    days = list(days)
    healthy = [r[:, j] for r, truth, _ in days for j in np.flatnonzero(np.asarray(truth) == 0)]
    if len(healthy) < 6:
        raise InputError("channel signatures: too few healthy joint-days to adapt to")
    baseline, spread = episodic.baseline.copy(), episodic.spread.copy()
    for j in range(spread.shape[1]):
        mine = [r[:, j] for r, truth, _ in days if truth[j] == 0]
        if len(mine) >= 6:
            b, sd = _speed_fit(np.stack(mine)[:, :, None])
            baseline[:, j], spread[:, j] = b[:, 0], sd[:, 0]
    num = np.zeros((len(MECHANICAL_CLASSES), len(CHANNELS)))
    den = np.zeros_like(num)
    for r, truth, mode in days:
        if mode < 0:
            continue
        excess = r - _level(baseline, r)
        s = np.asarray(truth, float)
        for j in np.flatnonzero(s > 0):
            predicted = _response(episodic.response[mode, :, j], s[j], r[SPEED, j])
            ok = np.isfinite(excess[:, j]) & np.isfinite(predicted)
            num[mode, ok] += excess[ok, j] * predicted[ok]
            den[mode, ok] += predicted[ok] ** 2
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.where(den > 0, num / den, np.nan)
    use = WEAR[None] & (ratio > TRUSTED[0]) & (ratio < TRUSTED[1])
    response = episodic.response * np.where(use, ratio, 0.0)[:, :, None, None]
    response[~np.isfinite(episodic.response)] = np.nan
    return Signatures(baseline, spread, response, use, DETECT, MARGIN)
