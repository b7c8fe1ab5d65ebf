"""An arm's rated joint torques, read from its description without building a model.

Light on purpose (no MuJoCo import): the on-line evaluation uses them to tell whether a faulted
joint carried load during an episode.
"""

from __future__ import annotations

import numpy as np

from robohealth_mj.arms.description import DEFAULT_ARM, load_arm


def rated_torque_nm(arm: str = DEFAULT_ARM) -> np.ndarray:
    """Rated peak torque (N m) per joint, base to tool."""
    return load_arm(arm).rated_torque.copy()


def joint_keys(arm: str = DEFAULT_ARM) -> tuple[str, ...]:
    """The arm's joints as its graph names them, base to tool."""
    return load_arm(arm).joint_keys
