"""The figures a maintenance planner acts on, from a life's daily index replayed as a monitor runs.

A monitor does not know which joint wears: every day it re-estimates every joint's RUL from the
history so far and warns on whichever joint's estimate crosses first. So a life is judged by its
*first* warning on any joint, classified against a band of useful notice before failure:

- ``in_band``: first warned ``band[0]``..``band[1]`` days before failure, on the wearing joint;
- ``early``: on the wearing joint, more than ``band[1]`` days ahead (parts and a stop booked
  weeks before they are needed; the index usually over-reads);
- ``late``: on the wearing joint, less than ``band[0]`` days ahead, or after failure;
- ``wrong_joint``: the first warning names another joint (the planner services the wrong drive);
- ``missed``: no warning before the life ends.

Healthy arm-days (the healthy lives and the days before a wearing life's onset) count the days on
which any joint warns.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from robohealth_mj.prognostics.rul import TrendRul

OUTCOMES = ("in_band", "early", "late", "wrong_joint", "missed")
DEFAULT_BAND = (5.0, 20.0)  # days of notice a planner can use (studies/wear/README.md)


@dataclass(frozen=True)
class WarningRule:
    """Warn on a joint when its trend's early RUL bound is under ``lead_days``, its trend is
    significantly rising and its index is at least ``floor``."""

    estimator: TrendRul
    lead_days: float
    floor: float

    def warns(self, days: np.ndarray, index: np.ndarray) -> bool:
        return self.estimator.estimate(days, index).warns(self.lead_days, self.floor)


@dataclass(frozen=True)
class Replay:
    """Every joint's trend estimate on every day of a life, from the days so far (each ``[S, J]``):
    what any lead time and floor are judged on without estimating again."""

    low: np.ndarray
    level: np.ndarray
    rising: np.ndarray

    def warned(self, lead_days: float, floor: float) -> np.ndarray:
        """``[S, J]`` bool: the joints :class:`WarningRule` would warn on each day."""
        return self.rising & (self.level >= floor) & (self.low <= lead_days)


def replay_estimates(
    days: np.ndarray,
    index: np.ndarray,
    estimator: TrendRul,
    online: Callable[[np.ndarray], np.ndarray] | None = None,
) -> Replay:
    """Replay a life day by day (``days [S]``, ``index [S, J]``) as a monitor sees it: each joint's
    estimate from the days so far. ``online`` maps a joint's history ``[k]`` to the index the
    monitor reads on it (e.g. :func:`robohealth_mj.prognostics.health.monotone_index`)."""
    return replay_many(days, index, [estimator], online)[0]


def replay_many(
    days: np.ndarray,
    index: np.ndarray,
    estimators: Sequence[TrendRul],
    online: Callable[[np.ndarray], np.ndarray] | None = None,
) -> list[Replay]:
    """:func:`replay_estimates` for several estimators, reading each day's history once."""
    index = np.asarray(index, float)
    low = [np.full(index.shape, np.inf) for _ in estimators]
    level = [np.full(index.shape, np.nan) for _ in estimators]
    rising = [np.zeros(index.shape, bool) for _ in estimators]
    for k in range(len(days)):
        for j in range(index.shape[1]):
            history = index[: k + 1, j]
            seen = online(history) if online else history
            for e, estimator in enumerate(estimators):
                r = estimator.estimate(days[: k + 1], seen)
                low[e][k, j], level[e][k, j], rising[e][k, j] = r.low, r.level, r.rising
    return [Replay(*arrays) for arrays in zip(low, level, rising, strict=True)]


def replay_warnings(
    days: np.ndarray,
    index: np.ndarray,
    rule: WarningRule,
    online: Callable[[np.ndarray], np.ndarray] | None = None,
) -> np.ndarray:
    """``[S, J]`` bool: whether each joint warns on each day, given only the days so far."""
    return replay_estimates(days, index, rule.estimator, online).warned(rule.lead_days, rule.floor)


@dataclass(frozen=True)
class FirstWarning:
    outcome: str
    day: float | None
    warned_joint: int | None  # the joint the first warning named
    lead_days: float | None  # failure day less the warning day


def first_warning(
    days: Sequence[float],
    warned: np.ndarray,
    wearing_joint: int,
    failure_day: float,
    band: tuple[float, float] = DEFAULT_BAND,
) -> FirstWarning:
    """A wearing life's first warning on any joint (``warned [S, J]``), classified."""
    hits = np.flatnonzero(warned.any(axis=1))
    if not len(hits):
        return FirstWarning("missed", None, None, None)
    k = int(hits[0])
    joints = np.flatnonzero(warned[k])
    joint = wearing_joint if wearing_joint in joints else int(joints[0])
    lead = float(failure_day) - float(days[k])
    if joint != wearing_joint:
        outcome = "wrong_joint"
    elif lead > band[1]:
        outcome = "early"
    elif lead < band[0]:
        outcome = "late"
    else:
        outcome = "in_band"
    return FirstWarning(outcome, float(days[k]), joint, lead)


def outcome_shares(warnings: Sequence[FirstWarning]) -> dict[str, float]:
    """The share of lives with each outcome (:data:`OUTCOMES`)."""
    n = max(len(warnings), 1)
    return {o: sum(w.outcome == o for w in warnings) / n for o in OUTCOMES}
