"""Health across sessions: the state survives a restart, and reads back on /diagnostics."""

from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest
from omegaconf import OmegaConf

from robohealth_mj.common.errors import InputError
from robohealth_mj.prognostics.channels import CHANNELS
from robohealth_mj.prognostics.health import SessionHealth
from robohealth_mj.prognostics.index_model import IndexModel
from robohealth_mj.prognostics.rul import TrendRul
from robohealth_mj.prognostics.signature import LOAD_DAYS
from robohealth_mj.runtime.health import HealthTracker, health_fields
from robohealth_mj.runtime.monitor import SessionWear
from robohealth_mj.schema import FEATURE_NAMES, JOINT_NAMES


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


def test_the_history_keeps_each_sessions_channel_readings_for_the_next_sessions(tmp_path):
    """A joint that never turned reads NaN: kept as null, read back as NaN. A session that kept
    no readings breaks the run of recent days."""
    tracker = HealthTracker(tmp_path)
    readings = [np.full((3, 6), float(day)) for day in range(4)]
    readings[3][1, 4] = np.nan
    for day, channel in enumerate(readings):
        tracker.update("a", day, _session(0.1), channel=None if day == 1 else channel)
    recent = tracker.recent_channels("a", 3)
    assert len(recent) == 2  # day 1 kept none: days 2 and 3
    assert recent[0] == pytest.approx(readings[2]) and np.isnan(recent[1][1, 4])
    assert recent[1] == pytest.approx(readings[3], nan_ok=True)
    assert tracker.recent_channels("a", 0) == [] and tracker.recent_channels("b", 3) == []


def test_the_monitor_hands_the_index_the_last_days_channel_readings(tmp_path):
    """Each session's index reads that day's channels with the days before it (as many as the
    load test weighs, oldest first): here the elbow's load rises by 1 N m a day."""
    seen = []

    class Recorder:  # an index that keeps what the monitor handed it
        model = IndexModel("signature", "none")

        def calibrate(self, day: dict) -> np.ndarray:
            seen.append(day)
            return np.zeros(len(JOINT_NAMES))

        def band(self, low, high, index):
            return low, high

    cfg = OmegaConf.create({"state_dir": str(tmp_path), "day": 0, "calibration": None,
                            "threshold": 0.8, "lead_days": 10.0, "floor": 0.15})  # fmt: skip
    elbow, load = JOINT_NAMES.index("elbow"), CHANNELS.index("load")
    healthy = SimpleNamespace(
        valid=True, fault_class="none", class_probabilities={"none": 1.0},
        joint_scores=dict.fromkeys(JOINT_NAMES, 0.0),
    )  # fmt: skip
    for day in range(LOAD_DAYS + 1):
        cfg.day = day
        wear = SessionWear("arm1", cfg)
        wear.index = Recorder()
        x = np.zeros((2 * len(JOINT_NAMES), len(FEATURE_NAMES)))
        x[elbow, FEATURE_NAMES.index("vel")] = 0.5
        x[elbow, FEATURE_NAMES.index("effort")] = 10.0 + day
        for _ in range(40):
            wear.add(healthy, list(JOINT_NAMES), np.abs(x[: len(JOINT_NAMES), 0]), x)
        wear.finish()
    assert len(seen[0]["recent_channel"]) == 1
    recent = seen[-1]["recent_channel"]
    assert len(recent) == LOAD_DAYS and recent[-1] is seen[-1]["channel"]
    assert [r[load, elbow] for r in recent] == pytest.approx([11.0, 12.0, 13.0, 14.0, 15.0])


def test_health_fit_since_floor_reads_the_trend_from_the_day_wear_was_detected(tmp_path):
    """A joint read at 0 for ten days, then stepping onto its wear (0.02 a day, failing on day
    40): by day 14 the last ten sessions' line through the step warns, 26 days ahead; with
    ``health.fit_since_floor`` the line through the days since the floor does not yet."""
    from robohealth_mj.common.config import compose_config

    warned = {}
    for since in (False, True):
        overrides = [f"health.state_dir={tmp_path / str(since)}", "health.day=0",
                     "health.lead_days=15", "health.floor=0.2", "health.min_sessions=3",
                     f"health.fit_since_floor={str(since).lower()}"]  # fmt: skip
        tracker = SessionWear("arm1", compose_config("monitor", overrides).health).tracker
        for day in range(15):
            joints = tracker.update("arm1", day, _session(0.02 * day if day >= 10 else 0.0))
        warned[since] = joints[2].warning
    assert warned == {False: True, True: False}


def test_health_min_sessions_draws_no_trend_through_fewer_sessions(tmp_path):
    """``health.min_sessions=5`` with the fit since the floor: four sessions past detection give
    no RUL yet, the fifth gives one."""
    from robohealth_mj.common.config import compose_config

    overrides = [f"health.state_dir={tmp_path}", "health.day=0", "health.fit_since_floor=true",
                 "health.floor=0.2", "health.min_sessions=5"]  # fmt: skip
    tracker = SessionWear("arm1", compose_config("monitor", overrides).health).tracker
    ruls = [tracker.update("arm1", day, _session(0.3 + 0.02 * day))[2].rul.rul for day in range(5)]
    assert np.isinf(ruls[3]) and ruls[4] == pytest.approx((0.8 - 0.38) / 0.02)
