"""Windows labelled by what they show: only the windows that straddle a change differ, or (rule
``visible``) those whose fault nothing shows."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from robohealth_mj.common.errors import InputError
from robohealth_mj.data.arrays import Recording
from robohealth_mj.data.windows import label_windows, make_windows
from robohealth_mj.schema import feature_index

W = 8


def _recording() -> Recording:
    """Two runs; run 0: healthy, friction@elbow 0.6, healthy, jam@wrist_1 0.3, a gap, healthy."""
    t = 90
    cls = np.zeros(t, np.int64)
    joint = -np.ones(t, np.int64)
    sev = np.zeros(t, np.float32)
    cls[10:25], joint[10:25], sev[10:25] = 2, 2, 0.6
    cls[33:40], joint[33:40], sev[33:40] = 3, 3, 0.3
    cls[60:70], joint[60:70], sev[60:70] = 1, 0, 0.9
    run = np.zeros(t, np.int32)
    run[50:] = 1
    index = np.arange(t, dtype=np.int64)
    index[42:] += 5  # a gap in run 0
    return Recording(
        x=np.zeros((t, 12, 15), np.float32), run=run, run_ids=["a", "b"], sample_index=index,
        fault_class=cls, fault_joint=joint, severity=sev, active=cls > 0,
        payload_scale=np.ones(t, np.float32), sources=["a", "b"],
    )  # fmt: skip


@pytest.mark.parametrize("rule", ["majority", "time_weighted"])
def test_the_rule_changes_exactly_the_straddling_windows(rule):
    rec = _recording()
    windows = make_windows(rec, W, stride=1)
    other = label_windows(rec, W, rule)
    rows = windows.start[:, None] + np.arange(W)[None, :]
    code = rec.fault_class * 7 + rec.fault_joint + 1
    uniform = (code[rows] == code[rows[:, :1]]).all(axis=1)
    end = windows.end
    same = (
        (other.fault_class[end] == rec.fault_class[end])
        & (other.fault_joint[end] == rec.fault_joint[end])
        & np.isclose(other.severity[end], rec.severity[end])
    )
    assert same[uniform].all()  # a window inside one interval keeps its label
    assert not same[~uniform].all() and (~uniform).sum() > 10  # straddling windows change
    for k in np.flatnonzero(~uniform):  # the label is the window's majority fault
        values, counts = np.unique(code[rows[k]], return_counts=True)
        top = values[counts == counts.max()]
        expected = code[rows[k][-1]] if code[rows[k][-1]] in top else top[0]
        assert other.fault_class[end[k]] * 7 + other.fault_joint[end[k]] + 1 == expected
        carrying = code[rows[k]] == expected
        mean = rec.severity[rows[k]][carrying].mean()
        want = mean if rule == "majority" else mean * carrying.sum() / W
        assert other.severity[end[k]] == pytest.approx(want, abs=1e-6)


def test_last_is_the_recording_itself_and_an_unknown_rule_is_refused():
    rec = _recording()
    assert label_windows(rec, W, "last") is rec
    with pytest.raises(InputError, match="labels must be one of"):
        label_windows(rec, W, "first")


def test_visible_calls_healthy_exactly_the_motion_only_faults_of_a_joint_that_stood_still():
    rec = _recording()
    vel = rec.x[:, :6, feature_index("vel")]  # a view: what the rule reads
    vel[12, 2] = 0.2  # the friction's elbow turns once, at snapshot 12
    vel[:, 4] = 0.5  # another joint turns all along: it shows nothing of the elbow
    vel[33:40, 3] = 0.0  # the jammed wrist_1 stands still
    cls, joint = rec.fault_class.copy(), rec.fault_joint.copy()
    cls[50:58], joint[50:58] = 1, 0  # backlash on the base at the head of run 1 ...
    vel[48, 0] = 0.3  # ... whose base stands still; only run 0 turned it, at its end
    rec = replace(rec, fault_class=cls, fault_joint=joint, active=cls > 0)
    out = label_windows(rec, W, "visible")
    changed = np.flatnonzero(out.fault_class != rec.fault_class)
    # friction windows ending 10, 11 and 20-24 do not hold snapshot 12; the base never turned in
    # run 1 (its first W - 1 snapshots end no whole window: they keep their label)
    assert changed.tolist() == [10, 11, *range(20, 25), *range(57, 58), *range(60, 70)]
    assert (out.fault_joint[changed] == -1).all() and (out.severity[changed] == 0).all()
    assert not out.active[changed].any()
    assert (out.fault_class[12:20] == 2).all()  # the turn is inside these windows: kept
    assert (out.fault_class[33:40] == 3).all()  # a jam acts on a still joint too: kept
    vel[65, 0] = -0.06  # a turn either way, just above MOVING_RAD_S, shows the backlash
    again = label_windows(rec, W, "visible")
    assert (again.fault_class[65:70] == 1).all() and (again.fault_class[60:65] == 0).all()
