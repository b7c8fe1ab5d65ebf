"""Topic names and message types of a robohealth bag (``conf/bag.yaml``)."""

from __future__ import annotations

from dataclasses import dataclass

from omegaconf import OmegaConf

from robohealth_mj.common.resources import conf_dir
from robohealth_mj.schema import JOINT_NAMES

JOINT_STATE = "sensor_msgs/msg/JointState"
IMU = "sensor_msgs/msg/Imu"
ARRAY = "std_msgs/msg/Float64MultiArray"
DIAGNOSTICS = "diagnostic_msgs/msg/DiagnosticArray"
VIBRATION_FIELDS = ("vib", "vib_20_80", "vib_80_200", "vib_200_450", "vib_kurtosis")


@dataclass(frozen=True)
class BagTopics:
    joint_states: str = "/joint_states"
    joint_errors: str = "/joint_tracking_error"
    imu: str = "/sensors/{joint}/imu"
    vibration: str = "/sensors/{joint}/vibration"
    fault_state: str = "/fault_state"
    health_diagnosis: str = "/health_diagnosis"
    aggregated: str = "/graph_sample"

    @classmethod
    def load(cls, **overrides: str) -> BagTopics:
        """``conf/bag.yaml`` with ``overrides``."""
        names = dict(OmegaConf.to_container(OmegaConf.load(conf_dir() / "bag.yaml")))
        names.update({k: v for k, v in overrides.items() if v})
        return cls(**names)

    def sample_topics(self) -> dict[str, str]:
        """Every topic one GraphSample is assembled from -> its message type."""
        out = {self.joint_states: JOINT_STATE, self.joint_errors: JOINT_STATE}
        for joint in JOINT_NAMES:
            out[self.imu.format(joint=joint)] = IMU
            out[self.vibration.format(joint=joint)] = ARRAY
        out[self.fault_state] = DIAGNOSTICS
        return out

    def aggregated_topics(self) -> dict[str, str]:
        """The aggregated live layout: the whole snapshot in one array, and the ground truth."""
        return {self.aggregated: ARRAY, self.fault_state: DIAGNOSTICS}
