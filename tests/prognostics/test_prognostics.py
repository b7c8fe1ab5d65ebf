"""Health index, its calibration, RUL from its trend, the warning and the prognostics metrics."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robohealth_mj.common.errors import InputError
from robohealth_mj.prognostics import metrics
from robohealth_mj.prognostics.health import Calibration, session_health, window_attribution
from robohealth_mj.prognostics.rul import TrendRul, first_warning
from robohealth_mj.schema import FAULT_CLASSES


def test_rul_on_a_synthetic_linear_index_is_exact_and_its_interval_closes():
    days = np.arange(12.0)
    index = 0.05 + 0.03 * days
    est = TrendRul(threshold=0.8, window=6).estimate(days, index)
    truth = (0.8 - index[-1]) / 0.03
    assert est.rul == pytest.approx(truth, rel=1e-9)
    assert est.low == pytest.approx(truth, rel=1e-6) and est.high == pytest.approx(truth, rel=1e-6)
    assert est.rising and est.slope == pytest.approx(0.03)


def test_a_flat_or_noisy_healthy_index_gives_no_rul_and_no_warning():
    rng = np.random.default_rng(3)
    days = np.arange(30.0)
    flat = TrendRul().estimate(days, np.full(30, 0.02))
    assert math.isinf(flat.rul) and not flat.rising
    noisy = 0.03 + rng.normal(0, 0.02, 30)
    assert first_warning(TrendRul(), days, noisy, lead_days=10, floor=0.15) is None
    # high but not rising (a joint read with an offset): its early bound is near, yet no warning
    offset = 0.77 + 0.02 * (-1.0) ** days
    assert any(TrendRul().estimate(days[:k], offset[:k]).low <= 10 for k in range(3, 31))
    assert first_warning(TrendRul(), days, offset, lead_days=10, floor=0.15) is None


def test_the_warning_comes_when_the_early_bound_falls_under_the_lead_time():
    days = np.arange(40.0)
    index = 0.02 * days  # threshold 0.8 at day 40
    k = first_warning(TrendRul(threshold=0.8), days, index, lead_days=10, floor=0.15)
    assert days[k] == 30.0  # RUL 10 days after the session of day 30


def test_a_nonsense_threshold_is_refused():
    with pytest.raises(InputError, match="threshold"):
        TrendRul(threshold=0.0)


def test_session_index_attributes_severity_to_the_likely_joint_with_a_band():
    k = 400
    class_logits = np.full((k, len(FAULT_CLASSES)), -5.0)
    class_logits[:, FAULT_CLASSES.index("friction")] = 5.0
    joint_logits = np.full((k, 6), -5.0)
    joint_logits[:, 2] = 5.0
    severity = np.random.default_rng(0).uniform(0.3, 0.5, k)
    h = session_health(window_attribution(class_logits, joint_logits, severity))
    assert h.index[2] == pytest.approx(0.4, abs=0.01) and h.index[[0, 1, 3, 4, 5]].max() < 0.01
    assert h.low[2] < h.index[2] < h.high[2] and h.high[2] - h.low[2] < 0.03
    sensor = class_logits.copy()  # a sensor fault is no wear
    sensor[:, FAULT_CLASSES.index("friction")] = -5.0
    sensor[:, FAULT_CLASSES.index("sensor_drift")] = 5.0
    assert session_health(window_attribution(sensor, joint_logits, severity)).index.max() < 0.01


def test_the_calibration_is_monotone_and_maps_a_biased_index_back():
    rng = np.random.default_rng(1)
    truth = rng.uniform(0, 0.8, 500)
    raw = 0.5 * truth + rng.normal(0, 0.01, 500)  # an index reading half the severity
    cal = Calibration.fit(raw, truth)
    assert np.all(np.diff(cal.x) > 0) and np.all(np.diff(cal.y) >= 0)
    assert np.abs(cal(raw) - truth).mean() < 0.03


def test_the_metrics_score_a_perfect_and_a_biased_predictor():
    days = np.arange(20.0)
    eol = 20.0
    perfect = eol - days
    assert metrics.prognostic_horizon(days, perfect, eol, 0.0, 0.2) == 20.0
    assert metrics.alpha_lambda(days, perfect, eol, 0.0, 0.2, 0.5) is True
    assert metrics.relative_accuracy(days, perfect, eol, 0.0) == 1.0
    late = 1.5 * (eol - days)  # 50 % optimistic throughout
    assert metrics.alpha_lambda(days, late, eol, 0.0, 0.2, 0.5) is False
    assert metrics.relative_accuracy(days, late, eol, 0.0) == pytest.approx(0.5)
    # within 0.2 * 20 = 4 days only once the true RUL is under 8 days
    assert metrics.prognostic_horizon(days, late, eol, 0.0, 0.2) == 8.0


def test_the_progpy_filter_follows_a_noisy_linear_index_to_its_crossing():
    pytest.importorskip("progpy")
    from robohealth_mj.prognostics.progpy_rul import ProgpyRul

    rng = np.random.default_rng(0)
    days = np.arange(20.0)
    index = 0.03 * days + rng.normal(0, 0.02, 20)
    est = ProgpyRul(threshold=0.8, particles=100, samples=50).estimate(days, index)
    truth = (0.8 - 0.03 * 19) / 0.03  # 7.7 days
    assert est.rising and est.low <= truth <= est.high and abs(est.rul - truth) <= 3
    flat = ProgpyRul(threshold=0.8, particles=100, samples=50).estimate(days, np.full(20, 0.02))
    assert not flat.rising and flat.low > 30
