"""Sensing profiles: which channels each kind of node carries on the arm being monitored.

The recorder writes every channel. A profile says which of them the deployed arm really has, and
zeroes the rest before anything is learnt. ``full`` is everything. ``retrofit`` keeps only
position and velocity on the joints: condition-monitoring sensors bolted onto an arm whose
controller reports neither motor currents nor a torque model, so localisation must come from the
external sensors. ``stock`` is an arm as it leaves the factory: the controller's joint channels
and no sensor package, so its graph has no sensor nodes (a node kind with no channels is not in
the graph) and its label set has no sensor faults: a fault of a sensor that is not there leaves
the arm healthy, so those sessions are labelled ``none``. The mask, the nodes and the label set
ride with the graph (``GraphSpec``), into the checkpoint and into the exported model's input
stage, so training, evaluation, export and the runtime read the same channels.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import yaml

from robohealth_mj import schema
from robohealth_mj.common.errors import InputError
from robohealth_mj.common.resources import conf_dir


@dataclass(frozen=True)
class SensingProfile:
    """The channels joint nodes and sensor nodes carry (the node-type flags always stay). A
    sensor node repeats its joint's state channels (the schema), so ``joint_channels`` governs
    those copies too: a channel the controller does not report is nowhere in the graph."""

    name: str
    joint_channels: Sequence[str] = schema.STATE_FEATURES
    sensor_channels: Sequence[str] = schema.SENSOR_FEATURES
    classes: Sequence[str] = schema.FAULT_CLASSES  # the label set: what these channels can see

    def __post_init__(self) -> None:
        unknown = [c for c in self.classes if c not in schema.FAULT_CLASSES]
        if unknown or "none" not in self.classes:
            raise InputError(
                f"sensing {self.name}: classes must include 'none' and come from "
                f"{list(schema.FAULT_CLASSES)}, got {list(self.classes)}"
            )
        for kind, names, allowed in (
            ("joint_channels", self.joint_channels, schema.STATE_FEATURES),
            ("sensor_channels", self.sensor_channels, schema.SENSOR_FEATURES),
        ):
            unknown = [n for n in names if n not in allowed]
            if unknown:
                raise InputError(
                    f"sensing {self.name}: {kind} {unknown} unknown (one of {list(allowed)})"
                )

    @property
    def sensor_nodes(self) -> bool:
        """Whether the arm has sensor nodes at all (a profile with no sensor channels has none)."""
        return bool(len(self.sensor_channels))

    @property
    def label_set(self) -> tuple[str, ...]:
        """The classes in schema order (the index space every model and table shares)."""
        return tuple(c for c in schema.FAULT_CLASSES if c in self.classes)

    def mask(self, joints: int = schema.N_JOINTS) -> np.ndarray | None:
        """``[2J, F]`` of 1 (kept) and 0 (zeroed) on an arm of ``joints`` joints, or None when
        every channel is kept."""
        keep = np.zeros((2 * joints, schema.N_FEATURES), np.float32)
        keep[:, :2] = 1.0  # is_joint, is_sensor
        for name in self.joint_channels:  # on the joints and on their copies at the sensor nodes
            keep[:, schema.feature_index(name)] = 1.0
        for name in self.sensor_channels:
            keep[joints:, schema.feature_index(name)] = 1.0
        keep[:joints, schema.SENSOR_CHANNELS] = 1.0  # zero there already
        return None if keep.all() else keep


def load_profile(name: str) -> SensingProfile:
    """The profile ``conf/sensing/<name>.yaml`` (what a model's or a recording's name means)."""
    path = conf_dir() / "sensing" / f"{name}.yaml"
    if not path.is_file():
        raise InputError(f"no sensing profile {name!r} ({path} missing)")
    raw = yaml.safe_load(path.read_text())
    raw.pop("_target_", None)
    return SensingProfile(**raw)


def stock_profile_for(channels: Sequence[str], source: str) -> str:
    """The shipped profile with no sensor package whose joint channels are exactly ``channels``
    (how a controller log that lacks some channels is read); one line when none is."""
    want = set(channels)
    for path in sorted((conf_dir() / "sensing").glob("*.yaml")):
        profile = load_profile(path.stem)
        if not profile.sensor_nodes and set(profile.joint_channels) == want:
            return profile.name
    raise InputError(
        f"{source}: no sensing profile reads exactly the joint channels {sorted(want)}: add one "
        "to conf/sensing/ (joint_channels, no sensor_channels)"
    )


def refuse_missing_channels(model: str, data: str, source: str) -> None:
    """One line when data of profile ``data`` lacks channels a model of profile ``model`` reads
    (a stock model reads full recordings, a subset of them; a full model cannot read a log)."""
    if model == data:
        return
    have, need = load_profile(data), load_profile(model)
    lacking = [c for c in need.joint_channels if c not in have.joint_channels]
    lacking += [c for c in need.sensor_channels if c not in have.sensor_channels]
    if lacking:
        raise InputError(
            f"{source}: the data has the {data} profile's channels and the model reads the "
            f"{model} profile's: {lacking} missing; use a model trained with sensing={data}"
        )
