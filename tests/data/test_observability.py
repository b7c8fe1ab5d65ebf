"""Calling only what a window can show: friction and backlash only on a joint that moved."""

from __future__ import annotations

import numpy as np
import pytest

from robohealth_mj.common.errors import InputError
from robohealth_mj.data.observability import check_observability, hide_unobservable
from robohealth_mj.schema import FAULT_CLASSES

CLASSES = list(FAULT_CLASSES)  # none, backlash, friction, jam, struct_weaken, sensor_drift, ...
NONE, BACKLASH, FRICTION, JAM = 0, 1, 2, 3


def _probs(rows: int = 3, seed: int = 0) -> np.ndarray:
    p = np.random.default_rng(seed).random((rows, len(CLASSES))).astype(np.float32)
    return p / p.sum(axis=1, keepdims=True)


def test_a_window_in_which_every_joint_moved_keeps_its_probabilities():
    probs = _probs()
    scores = np.random.default_rng(1).random((3, 6))
    out = hide_unobservable(probs, scores, np.ones((3, 6), bool), CLASSES)
    np.testing.assert_allclose(out, probs, atol=1e-7)


def test_on_a_still_arm_friction_and_backlash_go_to_none_and_nothing_else_moves():
    probs = _probs()
    out = hide_unobservable(probs, np.full((3, 6), 1 / 6), np.zeros((3, 6), bool), CLASSES)
    assert (out[:, [BACKLASH, FRICTION]] == 0).all()
    np.testing.assert_allclose(
        out[:, NONE], probs[:, NONE] + probs[:, BACKLASH] + probs[:, FRICTION], rtol=1e-6
    )
    np.testing.assert_array_equal(out[:, JAM:], probs[:, JAM:])  # seen at rest too
    np.testing.assert_allclose(out.sum(axis=1), 1.0, rtol=1e-6)


def test_a_fault_placed_mostly_on_a_still_joint_keeps_the_share_on_the_moving_ones():
    probs = np.array([[0.1, 0.0, 0.8, 0.1, 0, 0, 0]], np.float32)
    scores = np.array([[0.8, 0.2, 0, 0, 0, 0]])  # friction mostly on the pan, which stood still
    moved = np.array([[False, True, False, False, False, False]])
    out = hide_unobservable(probs, scores, moved, CLASSES)
    np.testing.assert_allclose(out[0, [NONE, FRICTION, JAM]], [0.1 + 0.64, 0.16, 0.1], rtol=1e-6)
    # independent sigmoid scores are read as where the fault would be, normalised
    sig = hide_unobservable(probs, 2 * scores, moved, CLASSES)
    np.testing.assert_allclose(sig, out, rtol=1e-6)


def test_a_label_set_without_motion_only_faults_is_left_alone():
    classes = ["none", "jam", "struct_weaken"]
    probs = np.array([[0.2, 0.5, 0.3]], np.float32)
    out = hide_unobservable(probs, np.ones((1, 6)), np.zeros((1, 6), bool), classes)
    np.testing.assert_array_equal(out, probs)


def test_bad_settings_are_one_line_errors():
    assert check_observability("motion", ["pos", "vel", "effort"]) == "motion"
    assert check_observability("all", ["pos"]) == "all"
    with pytest.raises(InputError, match="observability must be one of"):
        check_observability("moving")
    with pytest.raises(InputError, match="needs the joints' velocity"):
        check_observability("motion", ["pos", "effort"])
