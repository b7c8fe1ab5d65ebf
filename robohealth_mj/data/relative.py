"""Channels that mean the same on every arm: torques and speeds relative to the joint's ratings.

A UR16e shoulder carries 330 N m where a UR3e wrist carries 28; a model reading newton-metres
learns one arm's scale. Every torque channel (``effort``, ``effort_residual``) is read relative
to the joint's rated torque and ``vel`` relative to its speed limit, both expressed in the
reference arm's units (the UR5e's, so a UR5e reads exactly as it always did and every earlier
figure stands): ``effort' = effort * rated_ref / rated_arm``. Half the rated torque is 75 on any
arm's shoulder, as on the UR5e's. Angles (``pos``, ``pos_error``) and the sensor package's
channels are left as they are.

Applied once, where recordings are read (:func:`robohealth_mj.data.arrays.load_recordings`), so
every model, baseline and statistic sees relative channels; the exported model applies the
deployed arm's scale in its input stage, so a deployment still feeds raw readings.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from robohealth_mj import schema
from robohealth_mj.arms.description import DEFAULT_ARM, load_arm

REFERENCE_ARM = DEFAULT_ARM  # relative channels are expressed in this arm's units
TORQUE_CHANNELS = ("effort", "effort_residual")
SPEED_CHANNELS = ("vel",)


@cache
def _scale(arm: str) -> np.ndarray:
    own, ref = load_arm(arm), load_arm(REFERENCE_ARM)
    j = own.n_joints
    scale = np.ones((2 * j, schema.N_FEATURES), np.float32)
    # each joint against the reference arm's joint of its class (an arm of other joints)
    k = own.ur_counterpart_index()  # the reference arm is a UR: its joints are the UR's
    torque = (ref.rated_torque[k] / own.rated_torque).astype(np.float32)
    speed = (ref.speed_limit[k] / own.speed_limit).astype(np.float32)
    for names, per_joint in ((TORQUE_CHANNELS, torque), (SPEED_CHANNELS, speed)):
        for name in names:
            col = schema.feature_index(name)
            scale[:j, col] = per_joint  # the joint nodes
            scale[j:, col] = per_joint  # the copies on each joint's sensor node
    scale.setflags(write=False)
    return scale


def channel_scale(arm: str) -> np.ndarray:
    """``[2J, F]`` factors that turn arm ``arm``'s raw schema snapshot into relative channels
    (all ones for the reference arm)."""
    return _scale(str(arm))


def to_relative(x: np.ndarray, arm: str) -> np.ndarray:
    """Raw snapshots ``[..., 2J, F]`` of arm ``arm`` -> relative channels (a new array)."""
    return (x * channel_scale(arm)).astype(np.float32)


def to_raw(x: np.ndarray, arm: str) -> np.ndarray:
    """Relative snapshots ``[..., 2J, F]`` -> arm ``arm``'s raw readings (a new array)."""
    return (x / channel_scale(arm)).astype(np.float32)
