"""Wear paths: reproducible from their seed, monotone, at the threshold at the design usage."""

from __future__ import annotations

import numpy as np
import pytest

from robohealth_mj.common.errors import InputError
from robohealth_mj.faults.wear import PATH_KINDS, draw_path, joint_usage


@pytest.mark.parametrize("kind", PATH_KINDS)
def test_a_path_is_reproducible_from_its_seed_and_differs_by_seed(kind):
    a = draw_path(kind, 0.8, np.random.default_rng([5, 12]))
    b = draw_path(kind, 0.8, np.random.default_rng([5, 12]))
    c = draw_path(kind, 0.8, np.random.default_rng([6, 12]))
    assert a == b
    if kind != "linear":  # the linear path has no shape to draw
        assert a != c


@pytest.mark.parametrize("kind", PATH_KINDS)
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_path_is_monotone_from_healthy_to_the_threshold(kind, seed):
    path = draw_path(kind, 0.8, np.random.default_rng(seed))
    nu = np.linspace(0, 1.2, 241)
    s = np.array([path.severity(v) for v in nu])
    assert s[0] == 0.0
    assert np.all(np.diff(s) >= -1e-12)
    assert path.severity(1.0) == pytest.approx(0.8)
    assert path.severity(0.999) < 0.8


def test_accelerating_wear_grows_faster_late_and_a_step_is_a_step():
    acc = draw_path("accelerating", 0.8, np.random.default_rng(0))
    assert acc.severity(1.0) - acc.severity(0.9) > acc.severity(0.1) - acc.severity(0.0)
    step = draw_path("step_then_linear", 0.8, np.random.default_rng(0))
    before, after = step.severity(step.onset - 1e-6), step.severity(step.onset)
    assert before == 0.0 and after == pytest.approx(step.step) and after > 0.05


def test_an_unknown_path_or_threshold_is_refused_in_one_line():
    with pytest.raises(InputError, match="unknown wear path"):
        draw_path("sudden", 0.8, np.random.default_rng(0))
    with pytest.raises(InputError, match="threshold"):
        draw_path("linear", 1.5, np.random.default_rng(0))


def test_usage_counts_revolutions_and_weighs_load_by_its_cube():
    tick = 0.05
    vel = np.full((200, 2), 2 * np.pi)  # one revolution per second, 10 s
    unloaded = joint_usage(vel, np.zeros((200, 2)), np.array([10.0, 10.0]), tick)
    assert unloaded == pytest.approx([10.0, 10.0])
    half = joint_usage(vel, np.full((200, 2), 5.0), np.array([10.0, 10.0]), tick)
    assert half == pytest.approx([10.0 * (1 + 0.5**3)] * 2)
    still = joint_usage(np.zeros((200, 2)), np.full((200, 2), 9.0), np.array([10.0, 10.0]), tick)
    assert still == pytest.approx([0.0, 0.0])  # holding a load turns nothing
