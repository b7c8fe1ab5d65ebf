"""What a planner is told: the first warning on any joint, judged against a band of notice, and
an index read as wear that never heals."""

from __future__ import annotations

import numpy as np

from robohealth_mj.prognostics.health import isotonic, monotone_index
from robohealth_mj.prognostics.planner import (
    WarningRule,
    first_warning,
    outcome_shares,
    replay_warnings,
)
from robohealth_mj.prognostics.rul import TrendRul


def _life(wearing: int, rate: float, days: int = 30, joints: int = 6, seed: int = 0):
    """A wearing joint's index rising at ``rate`` per day from 0; the others noise around 0.02."""
    rng = np.random.default_rng(seed)
    d = np.arange(float(days))
    index = 0.02 + rng.normal(0, 0.005, (days, joints))
    index[:, wearing] = rate * d
    return d, index


def test_the_first_warning_is_judged_on_every_joint_as_a_monitor_replays_it():
    days, index = _life(wearing=2, rate=0.02)  # reaches 0.8 on day 40
    rule = WarningRule(TrendRul(threshold=0.8), lead_days=15, floor=0.1)
    warned = replay_warnings(days, index, rule)
    first = first_warning(days, warned, wearing_joint=2, failure_day=40.0)
    assert first.outcome == "in_band" and first.warned_joint == 2 and 5 <= first.lead_days <= 20
    # the same history with another joint rising faster: that one is named, and it is wrong
    index[:, 4] = 0.03 * days
    wrong = first_warning(days, replay_warnings(days, index, rule), 2, 40.0)
    assert wrong.outcome == "wrong_joint" and wrong.warned_joint == 4


def test_early_late_and_missed_warnings_count_against_the_band():
    days, index = _life(wearing=0, rate=0.02)
    warned = np.zeros(index.shape, bool)
    assert first_warning(days, warned, 0, 40.0).outcome == "missed"
    warned[5, 0] = True  # 35 days ahead
    assert first_warning(days, warned, 0, 40.0).outcome == "early"
    warned[:, :] = False
    warned[37 - 10, 0] = True  # day 27: 13 days ahead, inside 5..20
    assert first_warning(days, warned, 0, 40.0).outcome == "in_band"
    assert first_warning(days, warned, 0, 30.0).outcome == "late"  # 3 days ahead
    shares = outcome_shares([first_warning(days, warned, 0, f) for f in (40.0, 30.0)])
    assert shares["in_band"] == 0.5 and shares["late"] == 0.5 and shares["early"] == 0.0


def test_the_wear_index_never_falls_and_uses_only_the_days_so_far():
    noisy = np.array([0.1, 0.3, 0.2, 0.25, 0.5, 0.45])
    fit = isotonic(noisy)
    assert np.all(np.diff(fit) >= 0) and np.isclose(fit.sum(), noisy.sum())
    # least squares: the violators pooled to their mean
    assert np.allclose(fit, [0.1, 0.25, 0.25, 0.25, 0.475, 0.475])
    seen = [monotone_index(noisy[: k + 1])[-1] for k in range(len(noisy))]
    assert np.isclose(seen[2], 0.25) and seen[1] == 0.3  # day 1 read before day 2 was known
    with_gap = monotone_index(np.array([0.2, np.nan, 0.1]))
    assert np.isnan(with_gap[1]) and np.allclose(with_gap[[0, 2]], 0.15)


def test_a_trend_fitted_since_detection_does_not_warn_weeks_early_on_the_detection_step():
    """A mode the model reads only past some severity: 0 for ten days while the joint wears,
    then a step to the truth. A line through the step warns far ahead of failure; the line
    through the days since the index reached the floor warns inside the band."""
    days, index = _life(wearing=1, rate=0.02, days=40)  # failure (0.8) on day 40
    index[:10, 1] = 0.0
    late = WarningRule(TrendRul(threshold=0.8), lead_days=15, floor=0.15)
    since = WarningRule(TrendRul(threshold=0.8, since=0.15), lead_days=15, floor=0.15)
    step = first_warning(days, replay_warnings(days, index, late), 1, 40.0)
    detected = first_warning(days, replay_warnings(days, index, since), 1, 40.0)
    assert step.outcome == "early" and step.lead_days > 25
    assert detected.outcome == "in_band" and detected.warned_joint == 1
    # a joint that never reached the level has no trend (and keeps its last reading)
    healthy = TrendRul(since=0.15).estimate(days, index[:, 3])
    assert not healthy.rising and healthy.level == index[-1, 3]
