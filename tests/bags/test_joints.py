"""Which joint is which: the names a driver gives the joints, found in any order."""

from __future__ import annotations

import pytest

from robohealth_mj.bags.joints import joint_names, joint_order
from robohealth_mj.common.errors import InputError
from robohealth_mj.schema import JOINT_NAMES

UR = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
      "wrist_2_joint", "wrist_3_joint")  # fmt: skip


def test_presets_lists_and_the_driver_s_prefix():
    assert joint_names() == JOINT_NAMES
    assert joint_names("ur_driver") == UR
    assert joint_names("ur_driver", "arm1_")[0] == "arm1_shoulder_pan_joint"
    assert joint_names(list("abcdef"), "x/") == tuple(f"x/{c}" for c in "abcdef")
    with pytest.raises(InputError, match=r"ros2.joint_names: unknown preset 'ur10'"):
        joint_names("ur10")
    with pytest.raises(InputError, match="need distinct names, base to tool"):
        joint_names(["a", "b", "c", "d", "e", "e"])
    with pytest.raises(InputError, match="need distinct names, base to tool"):
        joint_names(["a"])  # an arm of one joint is no chain
    assert len(joint_names("xarm_ros2")) == 7  # a seven-joint driver's preset


def test_joints_are_found_by_name_in_any_order_and_a_missing_one_is_named():
    assert joint_order(JOINT_NAMES) is None  # the schema's own order: nothing to reorder
    alphabetical = sorted(UR)  # how the UR driver lists them: elbow_joint first
    order = joint_order(alphabetical, UR)
    assert [alphabetical[k] for k in order] == list(UR)
    with_gripper = [*alphabetical, "finger_joint"]
    assert [with_gripper[k] for k in joint_order(with_gripper, UR)] == list(UR)
    with pytest.raises(ValueError, match=r"field 'name': joint 'wrist_3_joint' missing \(1 of 6"):
        joint_order([n for n in alphabetical if n != "wrist_3_joint"], UR)
