"""Severity as the median of a distribution over levels, given the fault (the trees' ``levels``
severity objective).

A regression on faulted windows predicts the conditional mean (squared error) or median
(absolute error) of the severity over every fault at once, and where the windows leave the level
uncertain it settles between levels. Measured on the standard corpus's validation split (3
levels, W = 32, ``studies/wear/results/severity_objective.md``): squared error 0.143 MAE,
absolute error
0.136, one level classifier over every fault 0.129 read as its expectation and 0.115 as its
median, one per fault class mixed by the class posterior 0.100, and one per (fault class, joint)
mixed by the class and joint posteriors 0.094 (held-out: 0.099 over three seeds, against 0.137
for squared error). That last is this module:

* the levels are the training severities' distinct values when there are few (the standard
  corpus's 0.3/0.6/0.9), else the medians of ``max_levels`` equal-count bins (lives' continuous
  wear);
* per (fault class, joint) of the training windows, a LightGBM multiclass booster over the
  levels, stopping early on the validation windows of that fault (a fixed distribution where the
  training windows hold one level or the validation split none of the fault's windows);
* at inference ``P(level) = Σ_(c,j) P(c | faulted) P(j) P(level | c, j)`` with the class and joint
  boosters' probabilities, and the severity is the level where that distribution's cumulative sum
  first reaches one half: its median, which minimises the expected absolute error the severity
  is scored by.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np

from robohealth_mj.models.boosting import booster_text, train_early_stopped


def severity_levels(severity: np.ndarray, max_levels: int) -> np.ndarray:
    """``[L]`` ascending levels: the distinct values of ``severity`` if at most ``max_levels``,
    else the medians of ``max_levels`` equal-count bins."""
    distinct = np.unique(np.round(severity.astype(np.float64), 6))
    if len(distinct) <= max_levels:
        return distinct
    order = np.sort(severity.astype(np.float64))
    return np.unique(np.round([np.median(b) for b in np.array_split(order, max_levels)], 6))


def nearest_level(severity: np.ndarray, levels: np.ndarray) -> np.ndarray:
    """``[K]`` index of the level nearest each severity."""
    return np.abs(severity[:, None] - levels[None, :]).argmin(1)


def median_level(distribution: np.ndarray, levels: np.ndarray) -> np.ndarray:
    """``[B]`` the level where each row of ``distribution [B, L]`` first sums to one half."""
    return levels[(np.cumsum(distribution, axis=1) >= 0.5 - 1e-9).argmax(1)]


def level_classifier(params: dict[str, Any], n_levels: int) -> dict[str, Any]:
    """``params`` for a LightGBM multiclass booster over ``n_levels`` severity levels."""
    return {**params, "objective": "multiclass", "num_class": n_levels, "metric": "multi_logloss"}


class SeverityLevels:
    """Level classifiers per (fault class, joint) and the levels they classify into."""

    def __init__(self, levels: np.ndarray, groups: dict[tuple[int, int], Any]) -> None:
        # groups[(c, j)]: a LightGBM booster, or a fixed distribution [L] where the training
        # windows of that fault hold a single level or the validation split holds none of them
        self.levels, self.groups = np.asarray(levels, np.float64), groups

    @classmethod
    def fit(
        cls,
        train: tuple[np.ndarray, ...],
        val: tuple[np.ndarray, ...],
        params: dict[str, Any],
        rounds: int,
        early_stopping_rounds: int,
        max_levels: int = 10,
    ) -> tuple[SeverityLevels, dict[str, Any]]:
        """``train``/``val``: (features ``[K, D]``, fault class ``[K]``, joint ``[K]``, severity
        ``[K]``) of faulted windows. Returns the fitted levels and a record (the levels, each
        group's rounds: 0 for a fixed distribution)."""
        feats, fault, joint, severity = train
        levels = severity_levels(severity, max_levels)
        groups: dict[tuple[int, int], Any] = {}
        record: dict[str, Any] = {"levels": levels.tolist(), "rounds": {}}
        for c, j in sorted({(int(c), int(j)) for c, j in zip(fault, joint, strict=True)}):
            tr = (fault == c) & (joint == j)
            va = (val[1] == c) & (val[2] == j)
            y = nearest_level(severity[tr], levels)
            if len(np.unique(y)) < 2 or not va.any():
                groups[(c, j)] = np.bincount(y, minlength=len(levels)) / len(y)
                record["rounds"][f"{c},{j}"] = 0
                continue
            booster = train_early_stopped(
                level_classifier(params, len(levels)),
                (feats[tr], y),
                (val[0][va], nearest_level(val[3][va], levels)),
                rounds,
                early_stopping_rounds,
            )
            groups[(c, j)] = booster
            record["rounds"][f"{c},{j}"] = int(booster.best_iteration)
        record["best_iteration"] = max(record["rounds"].values(), default=0)
        return cls(levels, groups), record

    def distribution(
        self, feats: np.ndarray, class_probs: np.ndarray, joint_probs: np.ndarray
    ) -> np.ndarray:
        """``[B, L]``: ``Σ_(c,j) P(c | faulted) P(j) P(level | c, j)`` over the groups held,
        the weights renormalised over them."""
        keys = sorted(self.groups)
        weights = np.stack([class_probs[:, c] * joint_probs[:, j] for c, j in keys], axis=1)
        total = weights.sum(1, keepdims=True)
        weights = np.where(total > 0, weights / np.maximum(total, 1e-300), 1.0 / len(keys))
        mix = np.zeros((len(feats), len(self.levels)))
        for k, key in enumerate(keys):
            model = self.groups[key]
            given = model if isinstance(model, np.ndarray) else model.predict(feats)
            mix += weights[:, [k]] * np.reshape(given, (-1, len(self.levels)))
        return mix

    def predict(
        self, feats: np.ndarray, class_probs: np.ndarray, joint_probs: np.ndarray
    ) -> np.ndarray:
        """``[B]`` the median level of :meth:`distribution`."""
        return median_level(self.distribution(feats, class_probs, joint_probs), self.levels)

    def to_bytes(self) -> bytes:
        groups = {
            f"{c},{j}": (m.tolist() if isinstance(m, np.ndarray) else booster_text(m).decode())
            for (c, j), m in self.groups.items()
        }
        return json.dumps({"levels": self.levels.tolist(), "groups": groups}).encode()

    @classmethod
    def from_bytes(cls, data: bytes) -> SeverityLevels:
        import lightgbm as lgb

        bundle = json.loads(data.decode())
        groups = {
            tuple(int(v) for v in key.split(",")): (
                np.asarray(m) if isinstance(m, list) else lgb.Booster(model_str=m)
            )
            for key, m in bundle["groups"].items()
        }
        return cls(np.asarray(bundle["levels"]), groups)
