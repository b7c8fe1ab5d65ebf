"""On-line evaluation: the alarm as it rises, detection per class and joint, and the episodes
physics hides from every channel."""

from __future__ import annotations

import numpy as np
import pytest

from robohealth_mj.arms.ratings import rated_torque_nm
from robohealth_mj.runtime.online_eval import LOADED_SHARE, MOVED_SPEED, OnlineEvaluator
from robohealth_mj.runtime.online_report import online_markdown
from robohealth_mj.runtime.runtime import HealthDiagnosis
from robohealth_mj.schema import JOINT_NAMES, FaultLabel

J = len(JOINT_NAMES)


def _diag(alarm: str = "none", cls: str | None = None, joint: str | None = None):
    return HealthDiagnosis(
        stamp=0.0, stream_id="s", sample_index=0, valid=True, fault_class="none",
        alarm=alarm, alarm_class=cls, alarm_joint=joint,
    )  # fmt: skip


def _activity(joint: str, speed: float, torque: float) -> tuple[np.ndarray, np.ndarray]:
    s, t = np.zeros(J), np.zeros(J)
    s[JOINT_NAMES.index(joint)], t[JOINT_NAMES.index(joint)] = speed, torque
    return s, t


def _episode(label: FaultLabel, alarms: list, activity, gap: int = 5) -> list:
    still = (np.zeros(J), np.zeros(J))
    return [(label, d, activity) for d in alarms] + [(FaultLabel(), _diag(), still)] * gap


def test_right_at_rise_counts_the_alarm_s_first_tick_not_a_later_correction():
    jam = FaultLabel("jam", "elbow", 0.6, True)
    drift = FaultLabel("sensor_drift", "wrist_1", 0.3, True)
    noise = FaultLabel("sensor_noise", "wrist_2", 0.9, True)
    moving = _activity("elbow", 0.5, 20.0)
    script = (
        # rises with the right class at the wrong joint, corrected two ticks later
        _episode(jam, [_diag("raised", "jam", "wrist_1")] + [_diag("held", "jam", "elbow")] * 3,
                 moving)
        # rises wrong-class, then re-raises right
        + _episode(drift, [_diag("raised", "jam", "wrist_1"), _diag("raised", "sensor_drift",
                   "wrist_1")], _activity("wrist_1", 0.5, 3.0))
        # right class and joint at once
        + _episode(noise, [_diag()] * 2 + [_diag("raised", "sensor_noise", "wrist_2")],
                   _activity("wrist_2", 0.5, 1.0))
    )  # fmt: skip
    ev = OnlineEvaluator(settle_ticks=2)
    for truth, d, (speed, torque) in script:
        ev.update(truth, d, speed, torque)
    r = ev.result()
    a = r["alarms"]
    assert a["detected"] == 3
    assert a["class_right_at_rise"] == 2  # jam and noise rose with their class; drift did not
    assert a["right_at_rise"] == 1 and a["right_at_rise_rate"] == pytest.approx(1 / 3)
    assert a["joint_detected"] == 3  # eventually every joint was right
    grid = r["alarms_by_class_and_joint"]
    assert set(grid) == {"jam@elbow", "sensor_drift@wrist_1", "sensor_noise@wrist_2"}
    assert grid["sensor_noise@wrist_2"]["right_at_rise"] == 1
    md = online_markdown({**r, "alarm_policy": {}})
    assert "class and joint right when the alarm rose: 1 of 3 detected episodes (0.333)" in md
    assert "| jam | – | – | 1/1 | – | – | – |" in md  # the class x joint grid


def test_friction_on_a_still_joint_and_weakening_without_load_are_counted_apart():
    rated = rated_torque_nm()
    elbow, pan = JOINT_NAMES.index("elbow"), JOINT_NAMES.index("shoulder_pan")
    cases = [
        # (label, speed, torque, hidden?)
        (FaultLabel("friction", "elbow", 0.3, True), 0.5 * MOVED_SPEED, 30.0, True),
        (FaultLabel("friction", "elbow", 0.6, True), 2.0 * MOVED_SPEED, 30.0, False),
        (FaultLabel("struct_weaken", "shoulder_pan", 0.3, True), 1.0,
         0.5 * LOADED_SHARE * rated[pan], True),
        (FaultLabel("struct_weaken", "elbow", 0.3, True), 0.0, 2.0 * LOADED_SHARE * rated[elbow],
         False),
        (FaultLabel("jam", "elbow", 0.3, True), 0.0, 0.0, False),  # needs neither
    ]  # fmt: skip
    script = []
    for label, speed, torque, _ in cases:
        act = _activity(label.joint, speed, torque)
        script += _episode(label, [_diag("raised", label.fault_class, label.joint)] * 3, act)
    ev = OnlineEvaluator(settle_ticks=2)
    for truth, d, (speed, torque) in script:
        ev.update(truth, d, speed, torque)
    r = ev.result()
    assert r["physically_hidden_episodes"] == [
        "friction@elbow@0.3",
        "struct_weaken@shoulder_pan@0.3",
    ]
    vis = r["alarms_by_visibility"]
    assert vis["physically_hidden"]["episodes"] == 2 and vis["observable"]["episodes"] == 3
    # without the joints' activity nothing is claimed either way
    blind = OnlineEvaluator(settle_ticks=2)
    for truth, d, _ in script:
        blind.update(truth, d)
    assert blind.result()["alarms_by_visibility"] == {}
    assert blind.result()["physically_hidden_episodes"] == []


def test_rated_torques_come_from_the_arm_s_parameter_file():
    assert rated_torque_nm().tolist() == [150.0, 150.0, 150.0, 28.0, 28.0, 28.0]


def test_contact_calls_are_counted_apart_from_the_alarms():
    evaluator = OnlineEvaluator(settle_ticks=0)
    pattern = [False, True, True, False, True, False, False]  # two calls, three ticks
    for on in pattern * 10:
        d = _diag()
        d.contact, d.contact_joint = on, "elbow" if on else None
        evaluator.update(FaultLabel(), d)
    result = evaluator.result()
    assert (result["contact_calls"], result["contact_ticks"]) == (20, 30)
    assert result["contact_calls_per_hour"] == pytest.approx(20 / (70 * 0.05 / 3600))
    assert result["false_alarms"] == 0  # a contact is no fault alarm
    assert "- contact watch: 20 calls (30 ticks" in online_markdown(result)
