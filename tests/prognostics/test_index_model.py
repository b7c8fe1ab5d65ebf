"""Reading the daily index: per-joint and per-mode calibration maps, windows where the joint
turned, and the saved form the monitor loads."""

from __future__ import annotations

import json

import numpy as np
import pytest

from robohealth_mj.common.errors import InputError
from robohealth_mj.prognostics.health import Calibration
from robohealth_mj.prognostics.index_model import (
    FittedIndex,
    IndexModel,
    fit_index,
    session_reading,
)


def _day(truth: list[float], raw: list[float], moving: list[float | None], mode: int = 1) -> dict:
    modes = np.zeros((4, len(raw)))
    modes[mode] = raw
    return {"truth": truth, "raw": raw, "raw_moving": moving, "raw_modes": modes.tolist()}


def _days(n: int = 40) -> list[dict]:
    """Joint 0 reads its wear at half scale, joint 1 at full scale; joint 0 turns in a quarter
    of the windows, so over only those it reads its wear in full."""
    rng = np.random.default_rng(0)
    out = []
    for _ in range(n):
        s0, s1 = rng.uniform(0, 0.8, 2)
        out.append(_day([s0, s1], [0.5 * s0, s1], [s0, s1]))
    return out


def test_a_joint_that_reads_low_is_mapped_back_by_its_own_calibration():
    days = _days()
    probe = _day([0.6, 0.6], [0.3, 0.6], [0.6, 0.6])
    pooled = fit_index(IndexModel("all", "pooled"), days).calibrate(probe)
    per_joint = fit_index(IndexModel("all", "joint"), days).calibrate(probe)
    assert abs(pooled[0] - 0.6) > 0.1  # one map cannot serve both joints
    assert per_joint == pytest.approx([0.6, 0.6], abs=0.06)
    moving = fit_index(IndexModel("moving", "pooled"), days).calibrate(probe)
    assert moving == pytest.approx([0.6, 0.6], abs=0.06)  # the still windows no longer dilute


def test_a_session_reading_splits_by_mode_and_keeps_only_the_windows_a_joint_turned_in():
    by_mode = np.zeros((4, 3, 2))  # 4 windows, 3 modes, 2 joints
    by_mode[:, 2, 0] = [0.8, 0.0, 0.0, 0.0]  # joint 0: evidence in the one window it turned
    moved = np.array([[True, False], [False, False], [False, False], [False, False]])
    r = session_reading(by_mode, moved)
    assert r["raw_moving"] == [pytest.approx(0.8), None]
    assert np.argmax(np.array(r["raw_modes"])[:, 0]) == 2 and r["raw_modes"][2][0] == 0.2


def test_the_saved_index_reads_back_and_an_old_calibration_still_loads(tmp_path):
    fitted = fit_index(IndexModel("moving", "mode_joint", monotone=True), _days())
    path = tmp_path / "calibration.json"
    path.write_text(json.dumps(fitted.to_json()))
    back = FittedIndex.load(path)
    probe = _day([0.4, 0.2], [0.2, 0.2], [0.4, 0.2])
    assert back.model == fitted.model and back.calibrate(probe) == pytest.approx(
        fitted.calibrate(probe)
    )
    old = tmp_path / "old.json"
    old.write_text(json.dumps({"x": [0.0, 0.5], "y": [0.0, 1.0]}))
    assert FittedIndex.load(old).model == IndexModel() and not FittedIndex.load(old).cells
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"x": [0, 1], "y": [0, 1], "index_model": {"raw": "maybe"}}))
    with pytest.raises(InputError, match="raw 'maybe'"):
        FittedIndex.load(bad)


def test_a_mode_that_over_reads_and_one_that_under_reads_are_each_mapped_back():
    """Backlash (mode 0) reads its wear at twice the scale, friction (mode 1) at half: one map
    cannot serve both, a map per mode the model names can."""
    rng = np.random.default_rng(1)
    days = []
    for k in range(80):
        s = rng.uniform(0, 0.4)
        mode, scale = (0, 2.0) if k % 2 else (1, 0.5)
        days.append(_day([s, 0.0], [scale * s, 0.0], [scale * s, 0.0], mode=mode))
    over, under = _day([0.3, 0], [0.6, 0], [0.6, 0], mode=0), _day([0.3, 0], [0.15, 0], [0.15, 0])
    pooled = fit_index(IndexModel("all", "pooled"), days)
    by_mode = fit_index(IndexModel("all", "mode"), days)
    assert abs(pooled.calibrate(over)[0] - pooled.calibrate(under)[0]) > 0.05
    assert by_mode.calibrate(over)[0] == pytest.approx(0.3, abs=0.05)
    assert by_mode.calibrate(under)[0] == pytest.approx(0.3, abs=0.05)


def test_a_reading_that_is_zero_on_most_days_is_still_mapped_over_its_worn_range():
    """Most joint-days of a channel reading are healthy and read exactly 0; the map's knots must
    still spread over the worn readings (here the truth is the reading squared)."""
    raw = np.concatenate([np.zeros(900), np.linspace(0.01, 1.0, 100)])
    truth = np.concatenate([np.zeros(900), np.linspace(0.01, 1.0, 100) ** 2])
    cal = Calibration.fit(raw, truth)
    assert cal(0.5) == pytest.approx(0.25, abs=0.05) and cal(0.9) == pytest.approx(0.81, abs=0.05)
    assert cal(0.0) == pytest.approx(0.0, abs=1e-6)


def test_an_index_in_severity_units_can_be_read_without_a_map():
    days = _days()
    fitted = fit_index(IndexModel("all", "none"), days)
    assert fitted.calibrate(days[0]) == pytest.approx(np.clip(days[0]["raw"], 0, 1))


def test_the_map_does_not_depend_on_the_order_of_the_days():
    """Readings tie (a channel form reads many days as exactly 0 or on a 0.01 grid); a rerun
    that meets the same days in another order must fit the same map."""
    rng = np.random.default_rng(4)
    raw = rng.choice(np.linspace(0.0, 1.0, 11), 400)
    truth = np.clip(raw + rng.normal(0, 0.2, 400), 0, 1)
    order = rng.permutation(400)
    assert Calibration.fit(raw, truth) == Calibration.fit(raw[order], truth[order])
