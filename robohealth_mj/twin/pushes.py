"""The pushes a real log holds, found in hindsight: the logs of an arm pushed while it holds a
pose carry no label of when or where, so a push is read off the log's own torque residual
(measured minus the controller's model torque). The monitor is judged against what this finds;
it decides tick by tick, this looks at the whole log."""

from __future__ import annotations

import numpy as np

LEVEL_TICKS, RECENT_TICKS = 60, 20  # the level: the median residual 3 s to 1 s before (20 Hz)
FIRST_TICK = 25  # the log's first second and a quarter gives the first level
MERGE_TICKS, MIN_TICKS = 10, 5  # pushes under 0.5 s apart are one; shorter than 5 ticks: none


def pushes(
    residual: np.ndarray, rated_nm: np.ndarray, share: float
) -> tuple[np.ndarray, list[tuple[int, int]]]:
    """Residuals ``[T, J]`` (N·m) -> per tick how far each joint's residual is off its level,
    relative to its rating ``[T, J]``, and the pushes as (first, last) ticks: where a joint is
    more than ``share`` of its rating off."""
    off = np.zeros_like(residual, dtype=np.float64)
    for t in range(FIRST_TICK, len(residual)):
        level = np.median(residual[max(0, t - LEVEL_TICKS) : t - RECENT_TICKS], axis=0)
        off[t] = np.abs(residual[t] - level)
    off /= rated_nm
    episodes: list[list[int]] = []
    for t in np.flatnonzero(off.max(axis=1) > share).tolist():
        if episodes and t - episodes[-1][1] <= MERGE_TICKS:
            episodes[-1][1] = t
        else:
            episodes.append([t, t])
    return off, [(a, b) for a, b in episodes if b - a >= MIN_TICKS - 1]


def most_distal_loaded(off: np.ndarray, share: float) -> int:
    """The most distal joint a push loads by more than ``share`` of the rating: the joint
    nearest it or short of it (a force on a link loads the joints before it, none after, and
    that link's own only through a lever about its axis).
    ``off [T, J]`` over the push's ticks."""
    return int(np.flatnonzero(off.max(axis=0) > share).max())
