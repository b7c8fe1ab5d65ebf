"""Remaining useful life from a joint's health-index trend, with an interval, and the warning.

The baseline every other estimator is measured against: a straight line through the last
``window`` sessions' index (days on the x-axis), extrapolated to the failure threshold. Its
interval follows the slope's standard error: the early bound assumes the slope ``z`` standard
errors steeper, the late bound ``z`` flatter (infinite when that is not rising). On an exactly
linear index the interval closes onto the exact crossing.

A warning is raised when the early bound falls under ``lead_days``, but only on evidence of wear:
the slope significantly positive and the index above ``floor`` (a healthy joint's index wanders,
and a line through noise crosses any threshold eventually).

With ``since`` the line is fitted only on the sessions from the first whose index reached it: the
trend of the wear since it was detected. A mode the model sees only past some severity reads 0
and then jumps to 0.2-0.3 on the day it is detected; a line through that step is several times
steeper than the wear and warns weeks early (studies/wear/README.md, the fourth pass).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from robohealth_mj.common.errors import InputError


@dataclass(frozen=True)
class RulEstimate:
    rul: float  # days from the last session to the threshold (inf: no crossing in sight)
    low: float
    high: float
    level: float  # the fitted index at the last session
    slope: float  # index per day
    rising: bool  # the slope is significantly positive

    def warns(self, lead_days: float, floor: float) -> bool:
        return self.rising and self.level >= floor and self.low <= lead_days


@dataclass(frozen=True)
class TrendRul:
    """Least-squares line through the last ``window`` sessions (at least ``min_sessions``)."""

    threshold: float = 0.8
    window: int = 10
    min_sessions: int = 3
    z: float = 1.645  # one-sided 95 %
    since: float | None = None  # fit only from the first session whose index reached this

    def __post_init__(self) -> None:
        if not 0 < self.threshold <= 1:
            raise InputError(f"prognostics.threshold must be in (0, 1], got {self.threshold}")
        if self.window < 2 or not 2 <= self.min_sessions <= self.window:
            raise InputError(f"health.min_sessions must be >= 2 (and at most the trend's window, "
                             f"{self.window}), got {self.min_sessions}")  # fmt: skip
        if self.since is not None and not 0 <= self.since < self.threshold:
            raise InputError(f"health.floor must be in [0, health.threshold) to fit the trend "
                             f"since it, got {self.since}")  # fmt: skip

    def estimate(self, days: np.ndarray, index: np.ndarray) -> RulEstimate:
        """From a joint's sessions so far (``days [S]``, ``index [S]``, oldest first)."""
        d, h = np.asarray(days, float), np.asarray(index, float)
        last = float(h[np.isfinite(h)][-1]) if np.isfinite(h).any() else math.nan
        if self.since is not None:  # from the first session that reached it (none: no fit)
            reached = np.flatnonzero(h >= self.since)
            start = int(reached[0]) if len(reached) else len(h)
            d, h = d[start:], h[start:]
        d, h = d[-self.window :], h[-self.window :]
        keep = np.isfinite(h)
        d, h = d[keep], h[keep]
        if len(d) < self.min_sessions or np.ptp(d) == 0:
            return RulEstimate(math.inf, math.inf, math.inf, last, 0.0, False)
        dc = d - d.mean()
        slope = float((dc * (h - h.mean())).sum() / (dc**2).sum())
        level = float(h.mean() + slope * (d[-1] - d.mean()))
        resid = h - (h.mean() + slope * dc)
        dof = max(len(d) - 2, 1)
        se = math.sqrt(float((resid**2).sum()) / dof / float((dc**2).sum()))
        gap = self.threshold - level
        if gap <= 0:
            return RulEstimate(0.0, 0.0, 0.0, level, slope, slope - self.z * se > 0)

        def days_at(rate: float) -> float:
            return gap / rate if rate > 0 else math.inf

        return RulEstimate(
            days_at(slope),
            days_at(slope + self.z * se),
            days_at(slope - self.z * se),
            level,
            slope,
            slope - self.z * se > 0,
        )


def first_warning(
    estimator: TrendRul, days: np.ndarray, index: np.ndarray, lead_days: float, floor: float
) -> int | None:
    """The first session (position) at which ``estimator`` warns, replaying the sessions in
    order; ``None`` if it never does."""
    for k in range(1, len(days) + 1):
        if estimator.estimate(days[:k], index[:k]).warns(lead_days, floor):
            return k - 1
    return None
