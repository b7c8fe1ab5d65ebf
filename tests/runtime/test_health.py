"""Health across sessions: the state survives a restart, and reads back on /diagnostics."""

from __future__ import annotations

import json

import numpy as np
import pytest

from robohealth_mj.common.errors import InputError
from robohealth_mj.prognostics.health import SessionHealth
from robohealth_mj.prognostics.rul import TrendRul
from robohealth_mj.runtime.health import HealthTracker, health_fields


def _session(elbow: float) -> SessionHealth:
    index = np.array([0.01, 0.02, elbow, 0.0, 0.01, 0.0])
    return SessionHealth(index, index - 0.01, index + 0.01, index, 300)


def test_the_health_state_survives_a_restart_of_the_runtime(tmp_path):
    first = HealthTracker(tmp_path, TrendRul(threshold=0.8), lead_days=10, floor=0.15)
    for day in range(10):
        first.update("arm_07", day, _session(0.04 * day))
    restarted = HealthTracker(tmp_path, TrendRul(threshold=0.8), lead_days=10, floor=0.15)
    joints = restarted.update("arm_07", 10, _session(0.40))
    elbow = joints[2]
    assert len(restarted.history("arm_07")["sessions"]) == 11
    assert elbow.rul.rul == pytest.approx(10.0, rel=1e-6)  # the trend spans the restart
    assert elbow.warning and not any(j.warning for k, j in enumerate(joints) if k != 2)
    assert restarted.history("other_arm")["sessions"] == []  # arms are kept apart


def test_a_session_out_of_order_or_a_broken_state_file_is_refused_and_nothing_is_lost(tmp_path):
    tracker = HealthTracker(tmp_path)
    tracker.update("a", 3, _session(0.1))
    with pytest.raises(InputError, match="not after"):
        tracker.update("a", 2, _session(0.1))
    assert len(tracker.history("a")["sessions"]) == 1
    (tmp_path / "b.health.json").write_text("{broken")
    with pytest.raises(InputError, match=r"b\.health\.json"):
        tracker.update("b", 1, _session(0.1))
    assert (tmp_path / "b.health.json").read_text() == "{broken"
    with pytest.raises(InputError, match="cannot name"):
        tracker.history("../x")


def test_the_diagnostics_carry_each_joint_index_band_rul_and_warning(tmp_path):
    tracker = HealthTracker(tmp_path, TrendRul(threshold=0.8), lead_days=10, floor=0.15)
    for day in range(6):
        joints = tracker.update("a", day, _session(0.1 * day))
    fields = dict(health_fields(joints))
    assert fields["health.elbow"] == "0.500" and fields["health.elbow.band"] == "0.490..0.510"
    assert fields["rul_days.elbow"] == "3.0" and fields["wear_warning.elbow"] == "true"
    assert fields["rul_days.wrist_1"] == "inf" and fields["wear_warning.wrist_1"] == "false"
    state = json.loads((tmp_path / "a.health.json").read_text())
    assert [s["day"] for s in state["sessions"]] == [0, 1, 2, 3, 4, 5]


def test_a_monotone_reading_keeps_a_worn_joint_worn_through_a_light_day(tmp_path):
    """Wear never heals: a day of light duty that reads the elbow low leaves its reported index
    and its trend where the wear had got to; the stored history keeps the day as read."""
    plain = HealthTracker(tmp_path / "plain", TrendRul(threshold=0.8), lead_days=10, floor=0.15)
    worn = HealthTracker(tmp_path / "worn", TrendRul(threshold=0.8), 10, 0.15, monotone=True)
    readings = [0.1, 0.2, 0.3, 0.4, 0.1]  # the last day the elbow barely turned
    for day, elbow in enumerate(readings):
        low, kept = (
            plain.update("arm", day, _session(elbow)),
            worn.update("arm", day, _session(elbow)),
        )
    assert low[2].index == pytest.approx(0.1) and kept[2].index == pytest.approx(0.8 / 3)
    assert kept[2].rul.slope > 0 and kept[2].rul.slope > low[2].rul.slope
    assert [s["index"][2] for s in worn.history("arm")["sessions"]] == readings
