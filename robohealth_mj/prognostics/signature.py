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
is an onset transient that days do not repeat), and measures how far each (mode, channel)'s days
stray from it, as a share of the response: a channel's misfit counts in units of one healthy
spread plus that share of its predicted excess, so a channel whose fit swings from day to day
(the dead zone on a gravity-loaded joint) does not outvote one that tracks the wear (the lag).
:meth:`Signatures.read` gives the severity of a
named mode; :meth:`Signatures.call` names the mode whose signature explains most of the excess,
and says whether the call is sure (the runner-up explains far less).
No window model is needed. NumPy only.
"""

from __future__ import annotations

import math
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
SPEED, LOAD = CHANNELS.index("speed"), CHANNELS.index("load")  # covariates, not wear channels
WEAR = np.array([c not in (SPEED, LOAD) for c in range(len(CHANNELS))])
LAG = CHANNELS.index("lag")
BACKLASH, SPRING = MECHANICAL_CLASSES.index("backlash"), MECHANICAL_CLASSES.index("struct_weaken")
TRUSTED = (0.5, 2.0)  # the days' response over the episodes' for a channel to be read
# The excess a mode must explain (squared healthy spreads) to be read as wear: on the training
# lives' healthy joint-days the 99th-percentile reading is 0.76 with none, 0.24 at 9, 0.03 at 16.
DETECT = 16.0
# How much worse the runner-up must fit the day than the called mode (twice the log-likelihood
# ratio) for the call to be taken over the window model's: chosen on the validation lives (seed
# 42, val_lives and val_wide_lives; the wearing joint's raw MAE 0.066, 0.060, 0.059, 0.057, 0.060
# and 0.069 at 0, 5, 10, 20, 50 and 200). Backlash and a softer drive at a joint that carries the
# arm's weight fit a day alike (both sag by one offset under a one-sided torque): the last days'
# loads settle those calls (LOAD_DAYS below).
MARGIN = 20.0
# How far one channel may pull a severity read: a channel's squared misfit (in expected scatters)
# counts at most this much, so a channel whose days at one joint stray from the episodes' shape
# (a softer drive's gap at the first wrist: -12 spreads where the response says +1) adds a fixed
# penalty instead of dragging the read to the grid's end (1.5 at a truth of 0.41). Chosen on the
# validation lives (studies/wear/README.md, the fifth pass); the call's likelihood keeps every
# channel's whole misfit (limited there too, validation read worse).
OUTLIER = 25.0
# A gap and a softer spring make a joint that carries the arm's weight sag by one offset within a
# day: its torque keeps its sign and varies mostly by the motor's friction, which the spring never
# feels (studies/wear/results/load_dependence.md). From day to day the payload changes the load: a
# gap's lag holds, a spring's follows it. Over the last LOAD_DAYS days, the smoother of the two
# severity paths (the lag as it is, or per unit load) settles a call between the two, where the
# loads spanned LOAD_CHANGE of their mean and one path strays at most LOAD_CLEAR as far as the
# other (on the training and validation lives' loaded joints every such vote named the mode).
LOAD_DAYS = 5
LOAD_CHANGE = 0.15
LOAD_CLEAR = 0.5


@dataclass(frozen=True)
class Signatures:
    """``baseline [C, J, 3]``: a healthy reading is ``b0 + b1 v + b2 v^2`` at the joint's speed
    ``v``; ``spread [C, J]``: the healthy readings' spread about it; ``response [M, C, J, 4]``:
    the excess is ``s (r1 + r2 v) + s^2 (r3 + r4 v)`` at severity ``s`` of mode ``m``; ``use
    [M, C]``: the channels a mode is read from (modes in :data:`MECHANICAL_CLASSES` order; C over
    :data:`CHANNELS`, the speed's and load's rows unused); ``detect``, ``margin``: see
    :func:`adapt`; ``error [M, C]``: how far a day's excess strays from the response, as a share
    of it (None: not at all; see :func:`adapt`); ``outlier``: the most one channel's squared
    misfit counts in a severity read (:data:`OUTLIER`; infinite: no limit)."""

    baseline: np.ndarray
    spread: np.ndarray
    response: np.ndarray
    use: np.ndarray
    detect: float = 0.0
    margin: float = 0.0
    error: np.ndarray | None = None
    outlier: float = math.inf

    def excess(self, readings: np.ndarray) -> np.ndarray:
        """``[C, J]`` each reading above its healthy level at the day's speed, in spreads (NaN
        where a channel was not read)."""
        r = np.asarray(readings, float)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(WEAR[:, None], (r - _level(self.baseline, r)) / self.spread, np.nan)

    def _grid(self, readings: np.ndarray) -> tuple[np.ndarray, ...]:
        """``(excess [C, J], predicted [M, S, C, J], scatter [M, S, C, J])``: the day's excess
        and, per mode and grid severity, the excess the mode predicts on the channels it is read
        from (in spreads) and its expected squared scatter (one healthy spread, and
        :attr:`error` of the predicted excess)."""
        z = self.excess(readings)
        v = np.asarray(readings, float)[SPEED]
        predicted = _response(self.response[:, None], SEVERITY_GRID[:, None, None], v)
        predicted = np.nan_to_num(predicted / self.spread) * self.use[:, None, :, None]
        error = np.zeros(self.use.shape) if self.error is None else self.error
        return z, predicted, 1.0 + (error[:, None, :, None] * predicted) ** 2

    def _costs(self, grid: tuple[np.ndarray, ...]) -> tuple[np.ndarray, ...]:
        """``(cost [M, S, J], at_zero [M, J], seen [J], size [M, S, J])`` of a day's
        :meth:`_grid`: per mode and grid severity the squared misfit over the mode's channels,
        each in units of its expected scatter, the misfit of no wear, whether any channel was
        read, and the predicted excess's size over the channels read, in healthy spreads (how far
        a healthy day's noise can move the read). Each channel's term counts at most
        :attr:`outlier`."""
        z, predicted, scatter = grid
        read = np.isfinite(z)[None] & self.use[:, :, None]  # [M, C, J]
        miss = np.where(read[:, None], np.nan_to_num(z) - predicted, 0.0) ** 2 / scatter
        cost = np.minimum(miss, self.outlier).sum(axis=2)
        known = np.isfinite(self.response).all(axis=(1, 3))  # [M, J]: the pairs fitted
        size = np.sqrt((np.where(read[:, None], predicted, 0.0) ** 2).sum(axis=2))  # [M, S, J]
        cost = np.where(known[:, None], cost, np.inf)
        return cost, cost[:, 0], read.any(axis=(0, 1)), size

    def read(self, readings: np.ndarray, mode: np.ndarray) -> np.ndarray:
        """``[J]`` the severity of ``mode [J]`` on each joint: 0 where it explains less than
        :attr:`detect` of the excess (in squared spreads), NaN where nothing was read."""
        cost, at_zero, seen, _ = self._costs(self._grid(readings))
        return self._severity(cost, at_zero, seen, np.asarray(mode, int))

    def call(
        self, readings: np.ndarray, recent: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(mode [J], severity [J], sure [J])``: the mode whose signature fits the day best,
        its severity, and whether the call is sure. Each mode is read at its own severity and
        judged over every channel any mode reads (a channel it leaves unmoved counts its excess
        against it), as a Gaussian likelihood: each misfit in units of its expected scatter, plus
        that scatter's log, so that a mode cannot buy a loose fit by predicting a large, uncertain
        excess. The call is sure where the runner-up fits worse by at least ``margin`` (twice the
        log-likelihood ratio), wear was detected, the mode reads its severity to within
        :data:`SURE_SE` per spread of noise, and no other joint's sure call of that mode explains
        more (a catching gear's impulses and a gap's knocks travel through the arm: the joint
        that shows them most is their source). ``recent [K, C, J]``: the last days' readings,
        this one last: where backlash and a softer drive fit best, their loads settle the call
        between them (:meth:`settle`) and the lead is taken over the other two modes."""
        grid = self._grid(readings)
        cost, at_zero, seen, size = self._costs(grid)
        step = cost.argmin(axis=1)  # [M, J]: each mode's severity read, on the grid
        fit = np.where(np.isfinite(cost.min(axis=1)), self._misfit(grid, step), np.inf)
        mode = fit.argmin(axis=0)
        j = np.arange(len(mode))
        runner_up = np.sort(fit, axis=0)[1]
        if recent is not None:
            settled = self.settle(recent)
            pair = np.sort(np.argsort(fit, axis=0)[:2], axis=0)
            tied = (settled >= 0) & (pair == np.sort([[BACKLASH], [SPRING]], axis=0)).all(axis=0)
            mode = np.where(tied, settled, mode)
            others = np.delete(fit, [BACKLASH, SPRING], axis=0).min(axis=0)
            runner_up = np.where(tied, others, runner_up)
        lead = runner_up - fit[mode, j]
        best = (at_zero - cost.min(axis=1))[mode, j]  # the excess the call explains
        step = step[mode, j]
        # a spread of noise moves the severity read by about severity / size
        precise = size[mode, step, j] * SURE_SE >= SEVERITY_GRID[step]
        sure = precise & (best >= max(self.detect, 1e-12)) & (lead >= self.margin)
        for m in np.unique(mode[sure]):
            same = sure & (mode == m)
            sure &= ~same | (best >= best[same].max())
        return mode, self._severity(cost, at_zero, seen, mode), sure

    def _misfit(self, grid: tuple[np.ndarray, ...], step: np.ndarray) -> np.ndarray:
        """``[M, J]`` each mode's misfit at its severity ``SEVERITY_GRID[step [M, J]]`` (of a
        day's :meth:`_grid`) over every channel any mode reads: squared misfit per expected
        scatter plus the scatter's log."""
        z, predicted, scatter = grid
        at = step[:, None, None, :]  # [M, 1, 1, J]: each mode's own severity
        predicted = np.take_along_axis(predicted, at, axis=1)[:, 0]  # [M, C, J]
        scatter = np.take_along_axis(scatter, at, axis=1)[:, 0]
        miss = (np.nan_to_num(z)[None] - predicted) ** 2 / scatter + np.log(scatter)
        read = np.isfinite(z)[None] & self.use.any(axis=0)[None, :, None]
        return np.where(read, miss, 0.0).sum(axis=1)

    def settle(self, recent: np.ndarray) -> np.ndarray:
        """``[J]`` backlash or a softer drive (their :data:`MECHANICAL_CLASSES` index) where the
        last :data:`LOAD_DAYS` days (``recent [K, C, J]``, the latest last) tell them apart by
        their loads, else -1: a gap's lag holds as the load changes, a spring's follows it."""
        days = np.asarray(recent, float)[-LOAD_DAYS:]
        out = np.full(days.shape[-1], -1)
        if len(days) < LOAD_DAYS:
            return out
        lag = np.stack([self.excess(day)[LAG] for day in days])  # [K, J], in spreads
        load = days[:, LOAD]
        ok = (np.isfinite(lag) & np.isfinite(load) & (load > 0)).all(axis=0)
        ok &= (np.nan_to_num(lag) >= np.sqrt(self.detect)).all(axis=0)  # well above the noise
        if not ok.any():
            return out
        lag, load = lag[:, ok], load[:, ok]
        gap, spring = roughness(lag), roughness(lag / load)
        clear = (np.ptp(load, axis=0) >= LOAD_CHANGE * load.mean(axis=0)) & (
            np.minimum(gap, spring) <= LOAD_CLEAR * np.maximum(gap, spring)
        )
        out[np.flatnonzero(ok)[clear]] = np.where(gap < spring, BACKLASH, SPRING)[clear]
        return out

    def _severity(
        self, cost: np.ndarray, at_zero: np.ndarray, seen: np.ndarray, mode: np.ndarray
    ) -> np.ndarray:
        j = np.arange(cost.shape[-1])
        best = cost[mode, :, j]  # [J, S]
        severity = SEVERITY_GRID[best.argmin(axis=1)]
        with np.errstate(invalid="ignore"):  # a (mode, joint) never fitted: inf - inf, NaN below
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
            "error": None if self.error is None else np.round(self.error, 12).tolist(),
            "outlier": None if math.isinf(self.outlier) else self.outlier,
        }

    @classmethod
    def from_json(cls, data: Any, where: str) -> Signatures:
        try:
            parts = [np.asarray(data[k], float) for k in ("baseline", "spread", "response")]
            use = np.asarray(data["use"], int).astype(bool)
            channels = list(data["channels"])
            detect, margin = float(data["detect"]), float(data["margin"])
            error = None if data["error"] is None else np.asarray(data["error"], float)
            outlier = data.get("outlier")  # absent (written before the limit): none
            outlier = math.inf if outlier is None else float(outlier)
        except (TypeError, ValueError, KeyError) as exc:
            raise InputError(f"{where}: not a channel signature ({exc})") from None
        if not outlier > 0:
            raise InputError(f"{where}: outlier must be a positive misfit or null, got {outlier}")
        c, m = len(CHANNELS), len(MECHANICAL_CLASSES)
        j = parts[1].shape[-1] if parts[1].ndim == 2 else 0
        shapes = ((c, j, 3), (c, j), (m, c, j, 4), (m, c))
        if (
            channels != list(CHANNELS)
            or j == 0
            or any(p.shape != want for p, want in zip([*parts, use], shapes, strict=True))
            or (error is not None and error.shape != use.shape)
        ):
            raise InputError(
                f"{where}: a signature of channels {channels} over {parts[1].shape} joints; "
                f"this version reads {list(CHANNELS)}"
            )
        return cls(*parts, use, detect, margin, error, outlier)


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


def roughness(paths: np.ndarray) -> np.ndarray:
    """``[J]`` how far each column of ``paths [K, J]`` (one value a day) strays from a straight
    line through the days, relative to its mean: the load test's measure of a severity path."""
    y = paths / paths.mean(axis=0)
    t = np.arange(len(y))
    slope, intercept = np.polyfit(t, y, 1)
    return (y - (slope * t[:, None] + intercept)).std(axis=0)


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
                    response[m, c, j] = _growing_fit(design[ok], excess[ok, c], speed[ok])
            response[m, ~WEAR, j] = 0.0
    use = np.tile(WEAR, (len(MECHANICAL_CLASSES), 1))
    return Signatures(baseline, spread, response, use)


def _growing_fit(design: np.ndarray, excess: np.ndarray, speed: np.ndarray) -> np.ndarray:
    """``[4]`` the response's least-squares terms, grown from no wear in the direction it ends:
    a softer drive's lag grows as 1 / (1 - 0.85 s), steeply at the end, and a quadratic fitted
    at 0.3, 0.6 and 0.9 bends below zero at low severity, so a day 0.1 worn could only be read
    as 0.3. Where the linear term points against the response at 0.9 (at the episodes' mean
    speed), the excess is fitted by the quadratic terms alone."""
    terms = np.linalg.lstsq(design, excess, rcond=None)[0]
    v = float(np.mean(speed))
    if (terms[0] + terms[1] * v) * _response(terms, 0.9, v) < 0:
        terms = np.r_[0.0, 0.0, np.linalg.lstsq(design[:, 2:], excess, rcond=None)[0]]
    return terms


def adapt(episodic: Signatures, days: Iterable[tuple[np.ndarray, np.ndarray, int]]) -> Signatures:
    """Bring episode-fitted signatures to whole days: ``days`` of ``(readings [C, J], truth
    [J], mode)`` (``mode``: the index of the life's wearing mode, -1 for a healthy life). The
    healthy level and spread are re-fitted on the joints at severity 0; each (mode, channel)'s
    response is scaled by the least-squares ratio of the days' excess to the episodes'
    prediction, pooled over joints, and read only where that ratio lies in :data:`TRUSTED`;
    then how far the days stray from that response is measured (:func:`_relative_error`). A
    severity read counts each channel's misfit up to :data:`OUTLIER`."""
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
    error = _relative_error(baseline, spread, response, days)  # 0 where a channel is unread
    return Signatures(baseline, spread, response, use, DETECT, MARGIN, error, OUTLIER)


def _relative_error(
    baseline: np.ndarray,
    spread: np.ndarray,
    response: np.ndarray,
    days: list[tuple[np.ndarray, np.ndarray, int]],
) -> np.ndarray:
    """``[M, C]`` how far the wearing joints' days stray from the response, as a share of it:
    the scatter beyond one healthy spread, pooled over days and joints. A channel that tracks the
    severity day after day (backlash's lag: 0.14) keeps its weight at any severity; one whose
    fit swings from day to day (the dead zone and compliance on a joint whose torque seldom
    changes sign: 0.2-0.8) stops outvoting it once its predicted excess is large."""
    num = np.zeros(response.shape[:2])
    den = np.zeros_like(num)
    for r, truth, mode in days:
        s = np.asarray(truth, float)
        for j in np.flatnonzero(s > 0) if mode >= 0 else ():
            z = (r[:, j] - _level(baseline, r)[:, j]) / spread[:, j]
            predicted = _response(response[mode, :, j], s[j], r[SPEED, j]) / spread[:, j]
            ok = np.isfinite(z) & np.isfinite(predicted)
            num[mode, ok] += np.maximum((z[ok] - predicted[ok]) ** 2 - 1.0, 0.0)
            den[mode, ok] += predicted[ok] ** 2
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(den > 0, np.sqrt(num / den), 0.0)
