"""Wear that progresses: a joint's fault severity as a function of its accumulated use.

A real reducer does not fail on a clock: its friction and backlash grow with the revolutions it
turns under load. Here a life's severity is a function of the joint's *normalised usage*
``nu = U / U_design``, where ``U`` is the usage accumulated so far (:func:`joint_usage`) and
``U_design`` the usage at which the path reaches the failure threshold (the first day's usage times
the life's design days). Busier days wear the joint faster; a life's failure day follows from what
it actually ran, not from the calendar.

Paths (each monotone non-decreasing in ``nu``, 0 at ``nu = 0``, the threshold at ``nu = 1``):

- :class:`LinearWear`: ``s = threshold * nu``;
- :class:`AcceleratingWear`: exponential growth, ``s = threshold * (e^(k nu) - 1) / (e^k - 1)``;
- :class:`StepThenLinearWear`: healthy until ``nu0``, a step (a chipped tooth, a brinelled race),
  then linear to the threshold.

Their shape parameters are drawn from the life's seed (:func:`draw_path`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from robohealth_mj.common.errors import InputError


@dataclass(frozen=True)
class LinearWear:
    threshold: float
    kind: str = "linear"

    def severity(self, nu: float) -> float:
        return float(min(max(nu, 0.0), 1.5) * self.threshold)


@dataclass(frozen=True)
class AcceleratingWear:
    threshold: float
    growth: float  # k: how sharply wear accelerates (k -> 0 is linear)
    kind: str = "accelerating"

    def severity(self, nu: float) -> float:
        nu = min(max(nu, 0.0), 1.5)
        return float(self.threshold * math.expm1(self.growth * nu) / math.expm1(self.growth))


@dataclass(frozen=True)
class StepThenLinearWear:
    threshold: float
    onset: float  # nu0: normalised usage at which the step happens
    step: float  # severity right after the step
    kind: str = "step_then_linear"

    def severity(self, nu: float) -> float:
        nu = min(max(nu, 0.0), 1.5)
        if nu < self.onset:
            return 0.0
        return float(
            self.step + (self.threshold - self.step) * (nu - self.onset) / (1 - self.onset)
        )


WearPath = LinearWear | AcceleratingWear | StepThenLinearWear
PATH_KINDS = ("linear", "accelerating", "step_then_linear")


def draw_path(
    kind: str,
    threshold: float,
    rng: np.random.Generator,
    growth: Sequence[float] = (1.5, 3.0),
    onset: Sequence[float] = (0.2, 0.5),
    step: Sequence[float] = (0.1, 0.25),
) -> WearPath:
    """A path of ``kind`` with its shape drawn from ``rng`` (uniform in each range)."""
    if not 0.0 < threshold <= 1.0:
        raise InputError(f"wear threshold must be in (0, 1], got {threshold}")
    if kind == "linear":
        return LinearWear(threshold)
    if kind == "accelerating":
        return AcceleratingWear(threshold, float(rng.uniform(*growth)))
    if kind == "step_then_linear":
        return StepThenLinearWear(
            threshold, float(rng.uniform(*onset)), float(rng.uniform(*step)) * threshold
        )
    raise InputError(f"unknown wear path {kind!r}; known: {list(PATH_KINDS)}")


def path_record(path: WearPath) -> dict[str, Any]:
    """The path as the life's manifest records it."""
    return asdict(path)


LOAD_LIFE_EXPONENT = 3.0  # ISO 281's ball-bearing load-life exponent


def joint_usage(
    velocity: np.ndarray, effort: np.ndarray, rated_torque: np.ndarray, tick_s: float
) -> np.ndarray:
    """Usage per joint ``[J]`` of one session, in load-weighted output revolutions.

    ``velocity`` and ``effort`` are ``[T, J]`` (rad/s, N m). Each revolution counts
    ``1 + (|tau| / tau_rated)^3``: a bearing's life in revolutions falls with the cube of its load
    (ISO 281), and the 1 keeps a lightly loaded joint wearing by its travel.
    """
    load = np.abs(effort) / np.asarray(rated_torque)[None, :]
    weight = 1.0 + load**LOAD_LIFE_EXPONENT
    return (np.abs(velocity) * weight).sum(axis=0) * tick_s / (2 * math.pi)
