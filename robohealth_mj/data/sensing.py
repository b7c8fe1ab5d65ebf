"""Sensing profiles: which channels each kind of node carries on the arm being monitored.

The recorder writes every channel. A profile says which of them the deployed arm really has, and
zeroes the rest before anything is learnt. ``full`` is everything. ``retrofit`` keeps only
position and velocity on the joints: condition-monitoring sensors bolted onto an arm whose
controller reports neither motor currents nor a torque model, so localisation must come from the
external sensors. The mask rides with the graph (``GraphSpec.channel_mask``), into the checkpoint
and into the exported model's input stage, so training, evaluation, export and the runtime read
the same channels.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from robohealth_mj import schema


@dataclass(frozen=True)
class SensingProfile:
    """The channels joint nodes and sensor nodes carry (the node-type flags always stay). A
    sensor node repeats its joint's state channels (the schema), so ``joint_channels`` governs
    those copies too: a channel the controller does not report is nowhere in the graph."""

    name: str
    joint_channels: Sequence[str] = schema.STATE_FEATURES
    sensor_channels: Sequence[str] = schema.SENSOR_FEATURES

    def __post_init__(self) -> None:
        for kind, names, allowed in (
            ("joint_channels", self.joint_channels, schema.STATE_FEATURES),
            ("sensor_channels", self.sensor_channels, schema.SENSOR_FEATURES),
        ):
            unknown = [n for n in names if n not in allowed]
            if unknown:
                raise ValueError(
                    f"sensing {self.name}: {kind} {unknown} unknown (one of {list(allowed)})"
                )

    def mask(self) -> np.ndarray | None:
        """``[12, F]`` of 1 (kept) and 0 (zeroed), or None when every channel is kept."""
        keep = np.zeros((schema.N_NODES, schema.N_FEATURES), np.float32)
        keep[:, :2] = 1.0  # is_joint, is_sensor
        for name in self.joint_channels:  # on the joints and on their copies at the sensor nodes
            keep[:, schema.feature_index(name)] = 1.0
        for name in self.sensor_channels:
            keep[schema.N_JOINTS :, schema.feature_index(name)] = 1.0
        keep[: schema.N_JOINTS, schema.SENSOR_CHANNELS] = 1.0  # zero there already
        return None if keep.all() else keep
