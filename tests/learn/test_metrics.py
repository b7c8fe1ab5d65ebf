"""Every metric formula on hand-made predictions whose answers are worked out by hand: overall,
per class, per severity, per motion stratum; and the coupling correlation."""

from __future__ import annotations

import numpy as np
import pytest

from robohealth_mj.data.graphs import DEFAULT_C0, coupling_correlation
from robohealth_mj.learn.metrics import compute_metrics, detection_rates, flat_rows

# eleven windows; classes: 0 none, 1 backlash, 3 jam, 5 sensor_drift, 6 sensor_noise (one
# window); 2 and 4 absent. The first healthy window still carries its label's severity (a fault
# scheduled but not active): strata must not count it.
TRUE_CLASS = np.array([0, 0, 0, 1, 1, 3, 3, 3, 5, 5, 6])
PRED_CLASS = np.array([0, 1, 0, 1, 0, 3, 3, 5, 5, 0, 6])
TRUE_JOINT = np.array([-1, -1, -1, 2, 2, 4, 4, 4, 1, 1, 0])
PRED_JOINT = np.array([0, 0, 0, 2, 3, 4, 4, 0, 1, 5, 0])
ACTIVE = TRUE_CLASS != 0
SEVERITY = np.array([0.3, 0.0, 0.0, 0.3, 0.6, 0.3, 0.6, 0.9, 0.3, 0.9, 0.6])
SEVERITY_PRED = SEVERITY + np.array([0.0, 0.2, 0.0, 0.1, 0.0, -0.3, 0.0, 0.0, 0.0, 0.0, 0.0])
MOVING = np.array([False, False, False, True, False, True, False, True, True, False, False])


@pytest.fixture
def metrics() -> dict:
    return compute_metrics(
        PRED_CLASS, PRED_JOINT, TRUE_CLASS, TRUE_JOINT, ACTIVE, SEVERITY, SEVERITY_PRED, MOVING
    )


def test_accuracy_and_fault_present_accuracy(metrics):
    assert metrics["windows"] == 11
    assert metrics["accuracy"] == pytest.approx(7 / 11)
    # faulty-or-not agrees on 8: the jam called drift still counts as "a fault"
    assert metrics["fault_present_accuracy"] == pytest.approx(8 / 11)
    one = compute_metrics(*(np.array([v]) for v in (1, 2, 1, 2)), np.array([True]),
                          np.array([0.3]))  # fmt: skip
    assert one["accuracy"] == one["fault_present_accuracy"] == 1.0


def test_per_class_precision_recall_f1_and_support(metrics):
    pc = metrics["per_class"]
    expected = {  # (precision, recall, support)
        "none": (2 / 4, 2 / 3, 3),
        "backlash": (1 / 2, 1 / 2, 2),
        "jam": (2 / 2, 2 / 3, 3),
        "sensor_drift": (1 / 2, 1 / 2, 2),
        "sensor_noise": (1.0, 1.0, 1),
        "friction": (0.0, 0.0, 0),  # never predicted: precision 0, not undefined
    }
    for name, (p, r, n) in expected.items():
        assert pc[name]["precision"] == pytest.approx(p), name
        assert pc[name]["recall"] == pytest.approx(r), name
        assert pc[name]["support"] == n, name
        f1 = 2 * p * r / (p + r) if p + r else 0.0
        assert pc[name]["f1"] == pytest.approx(f1), name
    assert set(pc) == {
        "none", "backlash", "friction", "jam", "struct_weaken", "sensor_drift", "sensor_noise",
    }  # fmt: skip


def test_macro_f1_averages_the_classes_present_only(metrics):
    f1 = [4 / 7, 1 / 2, 4 / 5, 1 / 2, 1.0]  # none, backlash, jam, sensor_drift, sensor_noise
    assert metrics["macro_f1"] == pytest.approx(np.mean(f1))


def test_localisation_counts_faulted_windows_only(metrics):
    assert metrics["faulted_windows"] == 8
    assert metrics["localisation_accuracy"] == pytest.approx(5 / 8)


def test_confusion_matrix_rows_are_the_truth(metrics):
    cm = np.array(metrics["confusion_matrix"])
    assert cm.shape == (7, 7) and cm.sum() == 11 and cm[6, 6] == 1
    assert cm[0, 0] == 2 and cm[0, 1] == 1  # a healthy window called backlash
    assert cm[1, 0] == 1 and cm[3, 5] == 1 and cm[5, 0] == 1
    np.testing.assert_array_equal(cm.sum(axis=1), np.bincount(TRUE_CLASS, minlength=7))


def test_severity_mae(metrics):
    assert metrics["severity_mae"] == pytest.approx((0.2 + 0.1 + 0.3) / 11)


def test_each_fault_class_reports_its_own_localisation_and_severity_error(metrics):
    """What a sensing profile hides shows per class: localisation and severity error on that
    class's faulted windows only; the healthy window's false backlash call does not count."""
    pc = metrics["per_class"]
    expected = {"backlash": (1 / 2, 0.1 / 2), "jam": (2 / 3, 0.3 / 3), "sensor_drift": (1 / 2, 0.0),
                "sensor_noise": (1.0, 0.0)}  # fmt: skip
    for name, (loc, mae) in expected.items():
        assert pc[name]["localisation"] == pytest.approx(loc), name
        assert pc[name]["severity_mae"] == pytest.approx(mae), name
    assert "localisation" not in pc["none"] and "localisation" not in pc["friction"]
    # on faulted windows only: the healthy window's 0.2 error is not the head's to answer for
    assert metrics["severity_mae_faulted"] == pytest.approx((0.1 + 0.3) / 8)


def test_severity_strata_hold_the_faulted_windows_of_each_level(metrics):
    strata = metrics["by_severity"]
    assert set(strata) == {"0.3", "0.6", "0.9"}
    expected = {"0.3": (3, 1.0, 1.0), "0.6": (3, 2 / 3, 2 / 3), "0.9": (2, 0.0, 0.0)}
    for level, (n, acc, loc) in expected.items():
        assert strata[level]["windows"] == n
        assert strata[level]["accuracy"] == pytest.approx(acc), level
        assert strata[level]["localisation_accuracy"] == pytest.approx(loc), level
    assert strata["0.3"]["severity_mae"] == pytest.approx((0.1 + 0.3 + 0.0) / 3)


def test_motion_strata_split_the_faulted_windows(metrics):
    moving, still = metrics["by_motion"]["moving"], metrics["by_motion"]["still"]
    assert (moving["windows"], still["windows"]) == (4, 4)  # healthy windows in neither
    assert moving["accuracy"] == pytest.approx(3 / 4)
    assert still["accuracy"] == pytest.approx(2 / 4)
    assert moving["localisation_accuracy"] == pytest.approx(3 / 4)
    assert still["localisation_accuracy"] == pytest.approx(2 / 4)


def test_no_motion_strata_without_motion_flags_and_nothing_on_no_windows():
    m = compute_metrics(PRED_CLASS, PRED_JOINT, TRUE_CLASS, TRUE_JOINT, ACTIVE, SEVERITY)
    assert "by_motion" not in m and "severity_mae" not in m
    empty = np.zeros(0, int)
    m = compute_metrics(empty, empty, empty, empty, empty.astype(bool), empty.astype(float))
    assert m["windows"] == 0 and "accuracy" not in m and m["by_severity"] == {}
    healthy = compute_metrics(
        PRED_CLASS[:3], PRED_JOINT[:3], TRUE_CLASS[:3], TRUE_JOINT[:3], ACTIVE[:3], SEVERITY[:3]
    )
    assert np.isnan(healthy["localisation_accuracy"]) and healthy["faulted_windows"] == 0


def test_flat_rows_name_every_scalar_with_its_path(metrics):
    rows = dict(flat_rows(metrics, "heldout."))
    assert rows["heldout.accuracy"] == pytest.approx(7 / 11)
    assert rows["heldout.per_class.jam.recall"] == pytest.approx(2 / 3)
    assert rows["heldout.by_severity.0.6.accuracy"] == pytest.approx(2 / 3)
    assert rows["heldout.by_motion.still.windows"] == 4
    assert not any(name.endswith("confusion_matrix") for name in rows)  # not a scalar
    assert dict(flat_rows(metrics))["per_class.jam.support"] == 3  # no prefix by default


def test_coupling_correlation_is_the_mean_of_row_correlations():
    assert coupling_correlation(DEFAULT_C0, DEFAULT_C0) == pytest.approx(1.0)
    assert coupling_correlation(2.0 * DEFAULT_C0 + 1.0, DEFAULT_C0) == pytest.approx(1.0)
    assert coupling_correlation(-DEFAULT_C0, DEFAULT_C0) == pytest.approx(-1.0)
    mixed = DEFAULT_C0.copy()
    mixed[:3] *= -1.0  # three rows flipped, three kept
    assert coupling_correlation(mixed, DEFAULT_C0) == pytest.approx(0.0, abs=1e-6)
    flat = DEFAULT_C0.copy()
    flat[0] = 0.5  # a constant row has no correlation: it counts as 0, not NaN
    assert coupling_correlation(flat, DEFAULT_C0) == pytest.approx(5 / 6)
    one_row = np.array([[1.0, 2.0, 3.0, 4.0]])
    assert coupling_correlation(one_row, np.array([[1.0, 2.0, 3.0, 5.0]])) == pytest.approx(
        np.corrcoef([1, 2, 3, 4], [1, 2, 3, 5])[0, 1]
    )


def test_detection_rates_count_any_fault_class_as_a_detection(metrics):
    """Of three healthy windows one is called backlash; of eight faulted windows six are called
    some fault (the jam called drift counts), two are called none."""
    assert detection_rates(metrics) == pytest.approx((1 / 3, 6 / 8))
