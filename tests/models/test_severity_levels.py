"""The trees' ``levels`` severity head: levels from the training severities, one classifier per
(fault class, joint), the median of their mixture under the fault's posterior."""

from __future__ import annotations

import numpy as np
import pytest

from robohealth_mj.models.severity_levels import SeverityLevels, nearest_level, severity_levels

PARAMS = {"num_leaves": 4, "min_child_samples": 20, "verbosity": -1, "deterministic": True,
          "force_col_wise": True, "seed": 0, "num_threads": 1}  # fmt: skip


def test_levels_are_the_distinct_severities_or_bin_medians():
    assert severity_levels(np.array([0.3, 0.9, 0.6, 0.3]), 10).tolist() == [0.3, 0.6, 0.9]
    wear = np.random.default_rng(0).uniform(0, 0.8, 5000)  # continuous, as in a life
    levels = severity_levels(wear, 10)
    assert len(levels) == 10 and np.all(np.diff(levels) > 0)
    assert np.abs(wear - levels[nearest_level(wear, levels)]).max() < 0.06  # half a bin


def _faults(n: int, seed: int):
    """Two faults on one joint: feature 0 shows fault 1's level, feature 1 fault 2's, inverted."""
    rng = np.random.default_rng(seed)
    fault = rng.integers(1, 3, n)
    level = rng.integers(0, 3, n)
    feats = rng.normal(0, 0.2, (n, 3))
    feats[fault == 1, 0] += level[fault == 1]
    feats[fault == 2, 1] += 2 - level[fault == 2]
    return feats, fault, np.zeros(n, int), np.array([0.3, 0.6, 0.9])[level]


def test_the_median_of_the_mixture_reads_each_fault_s_level_and_survives_a_round_trip():
    train, val = _faults(1500, 0), _faults(600, 1)
    head, record = SeverityLevels.fit(train, val, PARAMS, rounds=100, early_stopping_rounds=20)
    assert record["levels"] == [0.3, 0.6, 0.9] and set(record["rounds"]) == {"1,0", "2,0"}
    feats, fault, _, severity = val
    classes = np.zeros((len(feats), 3))
    classes[np.arange(len(feats)), fault] = 1.0  # the fault known
    joints = np.ones((len(feats), 1))
    predicted = head.predict(feats, classes, joints)
    assert np.abs(predicted - severity).mean() < 0.03
    # told the wrong fault, the head reads the wrong feature: the class posterior is used
    wrong = classes[:, [0, 2, 1]]
    assert np.abs(head.predict(feats, wrong, joints) - severity).mean() > 0.15
    # one window that fault 1 reads as level 0.3 and fault 2 as 0.9: the median follows the more
    # probable fault, where an expectation would say a level neither holds (0.54)
    window, ones = np.zeros((2, 3)), np.ones((2, 1))
    posterior = np.array([[0.0, 0.6, 0.4], [0.0, 0.4, 0.6]])
    assert head.predict(window, posterior, ones) == pytest.approx([0.3, 0.9])
    again = SeverityLevels.from_bytes(head.to_bytes())
    np.testing.assert_array_equal(again.predict(feats, classes, joints), predicted)


def test_a_fault_seen_at_one_level_gets_that_level():
    feats, fault, joint, severity = _faults(900, 2)
    severity = np.where(fault == 2, 0.6, severity)
    head, record = SeverityLevels.fit(
        (feats, fault, joint, severity), _faults(300, 3), PARAMS, 50, 10
    )
    assert record["rounds"]["2,0"] == 0  # a fixed distribution, no booster
    classes = np.tile([0.0, 0.0, 1.0], (5, 1))
    assert head.predict(feats[:5], classes, np.ones((5, 1))) == pytest.approx([0.6] * 5)
