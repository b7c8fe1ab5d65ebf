"""Alarms from per-tick decisions: debouncing and hysteresis, vectorised over streams.

A tick *votes* for a fault class when the model's top class is a fault with probability at least
``min_confidence``; it votes *healthy* when the top class is ``none`` with probability at least
``clear_confidence``; any other tick abstains (and breaks both runs). An alarm is raised after
``raise_after`` consecutive votes for one class, and cleared after ``clear_after`` consecutive
healthy votes: the gap between the two is the hysteresis that keeps a flickering decision from
toggling the alarm. ``raise_after`` votes for another class while an alarm is up re-raise it with
that class. The alarm's joint is the argmax of an exponential moving average of the joint scores
over the ticks that voted for its class, so one noisy localisation does not move it.

Each decided tick reports its stream's alarm state: ``NONE``, ``RAISED`` (this tick), ``HELD`` or
``CLEARED`` (this tick).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

NONE, RAISED, HELD, CLEARED = 0, 1, 2, 3
STATE_NAMES = ("none", "raised", "held", "cleared")


@dataclass(frozen=True)
class AlarmPolicy:
    """Debouncing (``raise_after``, ``clear_after``, in ticks) and hysteresis thresholds."""

    raise_after: int = 10
    clear_after: int = 10
    min_confidence: float = 0.9
    clear_confidence: float = 0.5
    joint_smoothing: float = 0.3  # EMA weight of the newest tick's joint scores

    def __post_init__(self) -> None:
        if self.raise_after < 1 or self.clear_after < 1:
            raise ValueError("alarm raise_after and clear_after must be at least 1 tick")
        for name in ("min_confidence", "clear_confidence", "joint_smoothing"):
            if not 0.0 <= getattr(self, name) <= 1.0:
                raise ValueError(f"alarm {name} must lie in [0, 1], got {getattr(self, name)}")


class AlarmBank:
    """Alarm state of every stream slot, updated in bulk once per tick."""

    _fields = ("vote", "run", "healthy", "alarm", "scores")

    def __init__(self, policy: AlarmPolicy, joints: int, capacity: int) -> None:
        self.policy, self.joints = policy, joints
        self.vote = np.full(capacity, -1, np.int64)  # class of the current run of fault votes
        self.run = np.zeros(capacity, np.int64)  # its length
        self.healthy = np.zeros(capacity, np.int64)  # current run of healthy votes
        self.alarm = np.zeros(capacity, np.int64)  # alarmed class (0: no alarm)
        self.scores = np.zeros((capacity, joints), np.float32)  # EMA of joint scores

    def ensure(self, capacity: int) -> None:
        for name in self._fields:
            old = getattr(self, name)
            if capacity > len(old):
                new = np.full((capacity, *old.shape[1:]), -1 if name == "vote" else 0, old.dtype)
                new[: len(old)] = old
                setattr(self, name, new)

    def reset(self, slots: np.ndarray) -> None:
        """Forget these slots (a stream released)."""
        self.vote[slots], self.run[slots], self.healthy[slots] = -1, 0, 0
        self.alarm[slots], self.scores[slots] = 0, 0.0

    def update(
        self, slots: np.ndarray, probs: np.ndarray, joint_scores: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """One decided tick per slot (distinct). ``probs [B, C]`` (class 0 = none), ``joint_scores
        [B, J]`` -> ``(state, alarmed class or 0, alarmed joint or -1)``, each ``[B]``."""
        p = self.policy
        top = probs.argmax(axis=1)
        conf = probs[np.arange(len(slots)), top]
        fault_vote = (top > 0) & (conf >= p.min_confidence)
        healthy_vote = (top == 0) & (conf >= p.clear_confidence)
        run = np.where(
            fault_vote & (self.vote[slots] == top), self.run[slots] + 1, fault_vote.astype(np.int64)
        )
        healthy = np.where(healthy_vote, self.healthy[slots] + 1, 0)

        was = self.alarm[slots]
        raise_now = (run >= p.raise_after) & (top != was)
        clear_now = (was > 0) & (healthy >= p.clear_after)
        alarm = np.where(raise_now, top, np.where(clear_now, 0, was))
        state = np.where(
            raise_now, RAISED, np.where(clear_now, CLEARED, np.where(alarm > 0, HELD, NONE))
        )
        # joint scores: averaged over the votes for the alarm's class (or the current run's)
        fresh = fault_vote & (((run == 1) & (was == 0)) | (raise_now & (was > 0)))
        agree = fault_vote & (top == np.where(was > 0, was, top)) & ~fresh
        scores = self.scores[slots]
        smoothed = (1 - p.joint_smoothing) * scores + p.joint_smoothing * joint_scores
        scores = np.where(fresh[:, None], joint_scores, np.where(agree[:, None], smoothed, scores))

        self.vote[slots] = np.where(fault_vote, top, -1)
        self.run[slots], self.healthy[slots] = run, healthy
        self.alarm[slots], self.scores[slots] = alarm, scores
        joint = np.where(alarm > 0, scores.argmax(axis=1), -1)
        return state, alarm, joint
