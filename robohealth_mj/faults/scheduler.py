"""Which fault is active when: the thesis's ``fault_scheduler`` and a fixed single-fault schedule.

Time is counted in ticks. A schedule is a sequence of intervals, each either healthy (scenario
``None``) or faulted; the recorder splits its chunks at interval boundaries.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from robohealth_mj.common.errors import InputError
from robohealth_mj.common.seeds import stream
from robohealth_mj.faults.catalogue import MODES, Scenario
from robohealth_mj.schema import JOINT_NAMES


@dataclass(frozen=True)
class Interval:
    scenario: Scenario | None
    start_tick: int
    end_tick: int  # exclusive


class NoFaults:
    """A healthy session."""

    def __init__(
        self, tick_s: float = 0.05, seed: int = 0, arm_joints: Sequence[str] | None = None
    ) -> None:
        del tick_s, seed, arm_joints  # same construction signature as the other schedules

    def interval_at(self, tick: int) -> Interval:
        return Interval(None, 0, 2**62)

    def describe(self) -> dict:
        return {"kind": "none"}


class FaultScheduler:
    """Each pass enumerates joints x faults x severities (108 by default), reshuffled per pass;
    each scenario is ``fault_s`` faulted then ``healthy_s`` healthy."""

    def __init__(
        self,
        tick_s: float,
        fault_s: float = 12.0,
        healthy_s: float = 8.0,
        severities: Sequence[float] = (0.3, 0.6, 0.9),
        classes: Sequence[str] = MODES,
        joints: Sequence[str] = JOINT_NAMES,
        seed: int = 0,
        arm_joints: Sequence[str] | None = None,
    ) -> None:
        """``arm_joints``: the simulated arm's joints (default the UR's); ``joints`` those that
        fail, by the arm's names (the UR's six, the default, stand for every joint of an arm
        of other joints)."""
        arm = tuple(arm_joints or JOINT_NAMES)
        if tuple(joints) == JOINT_NAMES and arm != JOINT_NAMES:
            joints = arm
        unknown = [j for j in joints if j not in arm]
        if unknown:
            raise InputError(f"unknown joints in faults.joints: {unknown}; known: {list(arm)}")
        self.scenarios = [
            Scenario(c, arm.index(j), float(s), None if arm == JOINT_NAMES else j)
            for j, c, s in itertools.product(joints, classes, severities)
        ]
        if not self.scenarios:
            raise InputError("the fault schedule is empty: no joints, classes or severities")
        self.fault_ticks = _ticks(fault_s, tick_s, "faults.fault_s")
        self.healthy_ticks = _ticks(healthy_s, tick_s, "faults.healthy_s")
        self.seed = int(seed)
        self._orders: dict[int, np.ndarray] = {}

    @property
    def scenario_ticks(self) -> int:
        return self.fault_ticks + self.healthy_ticks

    @property
    def pass_ticks(self) -> int:
        return self.scenario_ticks * len(self.scenarios)

    def order(self, pass_index: int) -> np.ndarray:
        if pass_index not in self._orders:
            rng = stream("faults.schedule", self.seed, pass_index)
            self._orders[pass_index] = rng.permutation(len(self.scenarios))
        return self._orders[pass_index]

    def scenario(self, k: int) -> Scenario:
        n = len(self.scenarios)
        return self.scenarios[int(self.order(k // n)[k % n])]

    def interval_at(self, tick: int) -> Interval:
        k, offset = divmod(tick, self.scenario_ticks)
        start = k * self.scenario_ticks
        if offset < self.fault_ticks:
            return Interval(self.scenario(k), start, start + self.fault_ticks)
        return Interval(None, start + self.fault_ticks, start + self.scenario_ticks)

    def describe(self) -> dict:
        return {
            "kind": "scheduler",
            "scenarios_per_pass": len(self.scenarios),
            "fault_ticks": self.fault_ticks,
            "healthy_ticks": self.healthy_ticks,
        }


class FixedFault:
    """One fault from ``onset_s`` on (optionally until ``end_s``): for probes and tests."""

    def __init__(
        self,
        tick_s: float,
        fault_class: str,
        joint: str,
        severity: float,
        onset_s: float = 0.0,
        end_s: float | None = None,
        seed: int = 0,
        arm_joints: Sequence[str] | None = None,
    ) -> None:
        arm = tuple(arm_joints or JOINT_NAMES)
        if joint not in arm:
            raise InputError(f"unknown joint {joint!r}; known: {list(arm)}")
        name = None if arm == JOINT_NAMES else joint
        self.scenario_ = Scenario(fault_class, arm.index(joint), float(severity), name)
        self.onset = _ticks(onset_s, tick_s, "faults.onset_s", allow_zero=True)
        self.end = 2**62 if end_s is None else _ticks(end_s, tick_s, "faults.end_s")
        if self.end <= self.onset:
            raise InputError("faults.end_s must be after faults.onset_s")

    def interval_at(self, tick: int) -> Interval:
        if tick < self.onset:
            return Interval(None, 0, self.onset)
        if tick < self.end:
            return Interval(self.scenario_, self.onset, self.end)
        return Interval(None, self.end, 2**62)

    def describe(self) -> dict:
        return {
            "kind": "fixed",
            "scenario": vars(self.scenario_),
            "onset_tick": self.onset,
            "end_tick": self.end,
        }


def _ticks(seconds: float, tick_s: float, name: str, allow_zero: bool = False) -> int:
    n = round(seconds / tick_s)
    if abs(n * tick_s - seconds) > 1e-6 or n < (0 if allow_zero else 1):
        raise InputError(f"{name}={seconds} must be a positive whole number of {tick_s} s ticks")
    return n
