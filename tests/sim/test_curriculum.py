"""The trajectory curriculum (thesis §2.3.2)."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from hydra.utils import instantiate

from robohealth_mj.arms.description import known_arms, load_arm
from robohealth_mj.common.errors import user_error
from robohealth_mj.recording.recorder import build_curriculum
from robohealth_mj.sim.curriculum import CRUISE_SPEED, FAMILIES
from robohealth_mj.sim.model import ArmIndex

SPEED_LIMIT = 3.14  # rad/s, the UR5e joint speed limit (parameter file)


def _curriculum(record_cfg, *overrides, seed=0):
    cfg = record_cfg(*overrides)
    return instantiate(cfg.curriculum, seed=seed, _convert_="all")


def test_standard_curriculum_has_126_segments_in_three_families(record_cfg):
    c = _curriculum(record_cfg)
    families = [s.family for s in c.segments]
    assert len(c) == 126
    assert (
        families.count("single_joint"),
        families.count("joint_pair"),
        families.count("whole_arm"),
    ) == (54, 45, 27)
    assert {s.waveform for s in c.segments if s.family == "whole_arm"} == {
        "sine",
        "triangle",
        "compound",
    }
    pairs = {s.joints for s in c.segments if s.family == "joint_pair"}
    assert len(pairs) == 15


def test_speed_and_payload_lists_are_config(record_cfg):
    c = _curriculum(record_cfg, "curriculum.payload_scales=[2.2]", "curriculum.speed_scales=[1.0]")
    assert len(c) == 6 + 15 + 3
    assert {s.payload_scale for s in c.segments} == {2.2}
    assert c.payload_kg(0) == 2.2 * c.nominal_payload_kg


def test_order_is_shuffled_per_seed_and_reshuffled_per_pass(record_cfg):
    def order(seed, first_visit=0):
        c = _curriculum(record_cfg, seed=seed)
        return [c.scheduled(v).segment.index for v in range(first_visit, first_visit + 126)]

    assert order(1) == order(1)
    assert order(1) != order(2)
    assert sorted(order(1)) == list(range(126))
    assert order(1, 126) != order(1) and sorted(order(1, 126)) == list(range(126))


def test_reference_is_smooth_across_segments_and_within_speed_limits(record_cfg):
    c = _curriculum(record_cfg, seed=5)
    t_all, q_all, qd_all = [], [], []
    for visit in range(len(c)):
        t = c.scheduled(visit).t_start + np.arange(0.0, c.segment_s, 0.002)
        q, qd, _ = c.reference(visit, t)
        t_all.append(t), q_all.append(q), qd_all.append(qd)
    q, qd = np.concatenate(q_all), np.concatenate(qd_all)
    assert np.abs(qd).max() <= SPEED_LIMIT
    jumps = np.abs(np.diff(q, axis=0)).max()
    assert jumps < SPEED_LIMIT * 0.002 * 1.01  # no step anywhere, boundaries included


def test_reference_poses_stay_clear_of_the_floor_and_of_the_arm_itself(record_cfg, model):
    """Every reference pose of a full pass, for several seeds, has no contact at all."""
    data = mujoco.MjData(model)
    index = ArmIndex.of(model)
    for seed in (0, 1, 2):
        c = _curriculum(record_cfg, seed=seed)
        for visit in range(len(c)):
            t = c.scheduled(visit).t_start + np.arange(0.0, c.segment_s, 0.1)
            for q in c.position(visit, t):
                index.set_link_pose(data, q)
                mujoco.mj_kinematics(model, data)
                mujoco.mj_collision(model, data)
                assert data.ncon == 0, (seed, visit, q)


def test_pick_and_place_programs_move_point_to_point_and_dwell(record_cfg, model):
    """The programs unlike the curriculum (family pick_place): every move starts and stops at
    rest at a waypoint, within the speed limit, clear of contacts, smooth into the next segment;
    the default families leave them out (the 126 above)."""
    c = _curriculum(record_cfg, "curriculum.families=[pick_place]", seed=4)
    assert len(c) == 18 and {s.waveform for s in c.segments} == {"pick_place", "palletise"}
    data, index = mujoco.MjData(model), ArmIndex.of(model)
    q_all = []
    for visit in range(2 * len(c)):
        sched = c.scheduled(visit)
        t = sched.t_start + np.arange(0.0, c.segment_s, 0.002)
        q, qd, _ = c.reference(visit, t)
        q_all.append(q)
        assert np.abs(qd).max() <= SPEED_LIMIT
        np.testing.assert_allclose(q[0], sched.start_pose, atol=1e-9)
        resting = np.abs(qd).max(axis=1) < 1e-3
        assert 0.1 < resting.mean() < 0.9  # dwells between moves, and moves
        for pose in c.waypoints(visit):  # the program passes through every taught pose
            assert np.abs(q - pose).max(axis=1).min() < 1e-6
        for pose in q[::50]:
            index.set_link_pose(data, pose)
            mujoco.mj_kinematics(model, data)
            mujoco.mj_collision(model, data)
            assert data.ncon == 0, (visit, pose)
    assert np.abs(np.diff(np.concatenate(q_all), axis=0)).max() < SPEED_LIMIT * 0.002 * 1.01


def test_holds_move_once_from_rest_to_a_new_pose_and_hold_it(record_cfg):
    """Family hold: one move per segment, starting at the previous pose, ending at rest at the
    segment's centre within blend_s / speed scale, then no motion at all for the rest of the
    segment; a faster scale moves sooner; the default families leave holds out."""
    c = _curriculum(record_cfg, "curriculum.families=[hold]", seed=5)
    assert len(c) == 9 and {s.family for s in c.segments} == {"hold"}
    for visit in range(len(c)):
        sched = c.scheduled(visit)
        t = sched.t_start + np.arange(0.0, c.segment_s, 0.002)
        q, qd, _ = c.reference(visit, t)
        np.testing.assert_allclose(q[0], sched.start_pose, atol=1e-9)
        move_s = c.blend_s / sched.segment.speed_scale
        moving = np.abs(qd).max(axis=1) > 1e-6
        assert moving[t - sched.t_start < 0.5 * move_s].any()  # it moves at the start ...
        assert not moving[t - sched.t_start > move_s + 0.01].any()  # ... and then holds
        np.testing.assert_allclose(q[-1], sched.center, atol=1e-9)
        assert np.abs(qd).max() <= SPEED_LIMIT
    default = _curriculum(record_cfg, seed=5)
    assert "hold" not in {s.family for s in default.segments}


def test_cruise_moves_hold_a_constant_speed_together_and_stop_at_rest(record_cfg, model):
    """Family cruise (the way a UR controller runs point-to-point moves): two moves a segment,
    start to via to centre, every joint starting and stopping together; the leading joint holds
    the segment's cruise speed for more than a 1.6 s window at speed scale 1 somewhere in the
    family; within the speed limit, clear of contacts, smooth into the next segment; the default
    families leave it out."""
    c = _curriculum(record_cfg, "curriculum.families=[cruise]", seed=6)
    assert len(c) == 27 and {s.family for s in c.segments} == {"cruise"}
    data, index = mujoco.MjData(model), ArmIndex.of(model)
    q_all, longest_cruise = [], 0.0
    for visit in range(2 * len(c)):
        sched = c.scheduled(visit)
        t = sched.t_start + np.arange(0.0, c.segment_s, 0.002)
        q, qd, _ = c.reference(visit, t)
        q_all.append(q)
        speed = CRUISE_SPEED * sched.segment.speed_scale
        assert np.abs(qd).max() <= speed * 1.001
        np.testing.assert_allclose(q[0], sched.start_pose, atol=1e-9)
        np.testing.assert_allclose(q[-1], sched.center, atol=1e-9)
        via = c.via_pose(visit)
        turn = int(np.argmin(np.abs(q - via).max(axis=1)))
        assert np.abs(q[turn] - via).max() < 1e-6  # it turns at the via
        for a, b, part in ((sched.start_pose, via, q[:turn]), (via, sched.center, q[turn:])):
            moved = np.abs(b - a) > 1e-3  # every joint that moves is as far along as the others
            progress = (part[:, moved] - a[moved]) / (b - a)[moved]
            np.testing.assert_allclose(progress, progress[:, :1].repeat(moved.sum(), 1), atol=1e-9)
        if sched.segment.speed_scale == 1.0:
            at_speed = np.abs(qd).max(axis=1) > 0.99 * speed
            runs = np.diff(np.flatnonzero(np.diff(np.r_[0, at_speed, 0])))[::2]
            longest_cruise = max(longest_cruise, runs.max(initial=0) * 0.002)
        for pose in q[::50]:
            index.set_link_pose(data, pose)
            mujoco.mj_kinematics(model, data)
            mujoco.mj_collision(model, data)
            assert data.ncon == 0, (visit, pose)
    assert longest_cruise > 1.6
    assert np.abs(np.diff(np.concatenate(q_all), axis=0)).max() < SPEED_LIMIT * 0.002 * 1.01
    assert "cruise" not in {s.family for s in _curriculum(record_cfg, seed=6).segments}


def test_cruise_repeats_sets_the_familys_weight_and_refuses_none(record_cfg):
    """``+curriculum.cruise_repeats=N``: N cruise segments per speed and payload (default 3), so
    a corpus can weigh cruising motion; fewer than one is a one-line error."""
    six = _curriculum(record_cfg, "curriculum.families=[cruise]", "+curriculum.cruise_repeats=6")
    assert len(six) == 54 and {s.family for s in six.segments} == {"cruise"}
    with pytest.raises(Exception) as caught:
        _curriculum(record_cfg, "curriculum.families=[cruise]", "+curriculum.cruise_repeats=0")
    line = str(user_error(caught.value))  # what every command prints, exit status 2
    assert "cruise_repeats must be at least 1, got 0" in line and "\n" not in line


@pytest.mark.parametrize("name", known_arms())
def test_the_reference_keeps_every_joint_inside_its_range(record_cfg, name):
    """Every family (a pair's second joint, a quarter-period behind, swings twice its amplitude
    one way) commands each limited joint inside its range: the FR3's tool joint was sent 0.09 rad
    past its stop, where it sat, far off its reference."""
    cfg = record_cfg(f"arm={name}", "seed=940", f"curriculum.families={list(FAMILIES)}")
    arm = load_arm(name)
    c = build_curriculum(cfg, arm)
    low, high = arm.position_limit[:, 0], arm.position_limit[:, 1]
    for visit in range(len(c)):
        q = c.position(visit, c.scheduled(visit).t_start + np.linspace(0.0, c.segment_s, 200))
        assert np.all(q >= low) and np.all(q <= high), (visit, c.scheduled(visit).segment)
