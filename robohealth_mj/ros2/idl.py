"""The ROS 2 message types this project speaks, as DDS IDL structs (ROS 2 Humble definitions).

Type names follow ``rmw_cyclonedds`` (``pkg::msg::dds_::Name_``); every struct is final (XCDR1,
no member headers), as ROS 2 declares them. Field names equal the ROS ones, so the bag code's
message factory and sample assembly work on these objects unchanged; :data:`TYPES` maps the
``rosbags`` type names to them. ``tests/ros2/test_ros2.py`` checks the bytes against ``rosbags``.
"""

# No `from __future__ import annotations`: the binding resolves these annotations at class creation.
from dataclasses import dataclass, field
from typing import Any

import cyclonedds.idl.annotations as annotate
import numpy as np
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import array, float64, int32, sequence, uint8, uint32


@dataclass
@annotate.final
class Time(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: int32 = 0
    nanosec: uint32 = 0


@dataclass
@annotate.final
class Header(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    stamp: Time = field(default_factory=Time)
    frame_id: str = ""


@dataclass
@annotate.final
class JointState(IdlStruct, typename="sensor_msgs::msg::dds_::JointState_"):
    header: Header = field(default_factory=Header)
    name: sequence[str] = field(default_factory=list)
    position: sequence[float64] = field(default_factory=list)
    velocity: sequence[float64] = field(default_factory=list)
    effort: sequence[float64] = field(default_factory=list)


@dataclass
@annotate.final
class Quaternion(IdlStruct, typename="geometry_msgs::msg::dds_::Quaternion_"):
    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0
    w: float64 = 1.0


@dataclass
@annotate.final
class Vector3(IdlStruct, typename="geometry_msgs::msg::dds_::Vector3_"):
    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0


def _zeros9() -> list[float]:
    return [0.0] * 9


@dataclass
@annotate.final
class Imu(IdlStruct, typename="sensor_msgs::msg::dds_::Imu_"):
    header: Header = field(default_factory=Header)
    orientation: Quaternion = field(default_factory=Quaternion)
    orientation_covariance: array[float64, 9] = field(default_factory=_zeros9)
    angular_velocity: Vector3 = field(default_factory=Vector3)
    angular_velocity_covariance: array[float64, 9] = field(default_factory=_zeros9)
    linear_acceleration: Vector3 = field(default_factory=Vector3)
    linear_acceleration_covariance: array[float64, 9] = field(default_factory=_zeros9)


@dataclass
@annotate.final
class MultiArrayDimension(IdlStruct, typename="std_msgs::msg::dds_::MultiArrayDimension_"):
    label: str = ""
    size: uint32 = 0
    stride: uint32 = 0


@dataclass
@annotate.final
class MultiArrayLayout(IdlStruct, typename="std_msgs::msg::dds_::MultiArrayLayout_"):
    dim: sequence[MultiArrayDimension] = field(default_factory=list)
    data_offset: uint32 = 0


@dataclass
@annotate.final
class Float64MultiArray(IdlStruct, typename="std_msgs::msg::dds_::Float64MultiArray_"):
    layout: MultiArrayLayout = field(default_factory=MultiArrayLayout)
    data: sequence[float64] = field(default_factory=list)


@dataclass
@annotate.final
class KeyValue(IdlStruct, typename="diagnostic_msgs::msg::dds_::KeyValue_"):
    key: str = ""
    value: str = ""


@dataclass
@annotate.final
class DiagnosticStatus(IdlStruct, typename="diagnostic_msgs::msg::dds_::DiagnosticStatus_"):
    level: uint8 = 0
    name: str = ""
    message: str = ""
    hardware_id: str = ""
    values: sequence[KeyValue] = field(default_factory=list)


# The levels (diagnostic_msgs constants), set outside the class body: the binding encodes every
# annotated class attribute.
DiagnosticStatus.OK, DiagnosticStatus.WARN, DiagnosticStatus.ERROR, DiagnosticStatus.STALE = range(
    4
)


@dataclass
@annotate.final
class DiagnosticArray(IdlStruct, typename="diagnostic_msgs::msg::dds_::DiagnosticArray_"):
    header: Header = field(default_factory=Header)
    status: sequence[DiagnosticStatus] = field(default_factory=list)


@dataclass
@annotate.final
class Duration(IdlStruct, typename="builtin_interfaces::msg::dds_::Duration_"):
    sec: int32 = 0
    nanosec: uint32 = 0


@dataclass
@annotate.final
class JointTrajectoryPoint(IdlStruct, typename="trajectory_msgs::msg::dds_::JointTrajectoryPoint_"):
    positions: sequence[float64] = field(default_factory=list)
    velocities: sequence[float64] = field(default_factory=list)
    accelerations: sequence[float64] = field(default_factory=list)
    effort: sequence[float64] = field(default_factory=list)
    time_from_start: Duration = field(default_factory=Duration)


@dataclass
@annotate.final
class Transform(IdlStruct, typename="geometry_msgs::msg::dds_::Transform_"):
    translation: Vector3 = field(default_factory=Vector3)
    rotation: Quaternion = field(default_factory=Quaternion)


@dataclass
@annotate.final
class Twist(IdlStruct, typename="geometry_msgs::msg::dds_::Twist_"):
    linear: Vector3 = field(default_factory=Vector3)
    angular: Vector3 = field(default_factory=Vector3)


@dataclass
@annotate.final
class MultiDOFJointTrajectoryPoint(
    IdlStruct, typename="trajectory_msgs::msg::dds_::MultiDOFJointTrajectoryPoint_"
):
    transforms: sequence[Transform] = field(default_factory=list)
    velocities: sequence[Twist] = field(default_factory=list)
    accelerations: sequence[Twist] = field(default_factory=list)
    time_from_start: Duration = field(default_factory=Duration)


MultiDOFPoint = MultiDOFJointTrajectoryPoint

# control_msgs/msg/JointTrajectoryControllerState, what a joint trajectory controller (the UR
# driver's scaled_joint_trajectory_controller) publishes on ~/controller_state. One DDS type name,
# two layouts: Humble's control_msgs 4.x keeps the deprecated desired/actual after the new fields;
# Jazzy's (5.3 on), Kilted's and Rolling's drop them and end with the speed scaling factor.
_STATE = "control_msgs::msg::dds_::JointTrajectoryControllerState_"


@dataclass
@annotate.final
class HumbleControllerState(IdlStruct, typename=_STATE):
    header: Header = field(default_factory=Header)
    joint_names: sequence[str] = field(default_factory=list)
    reference: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    feedback: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    error: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    output: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    desired: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    actual: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    multi_dof_joint_names: sequence[str] = field(default_factory=list)
    multi_dof_reference: MultiDOFPoint = field(default_factory=MultiDOFPoint)
    multi_dof_feedback: MultiDOFPoint = field(default_factory=MultiDOFPoint)
    multi_dof_error: MultiDOFPoint = field(default_factory=MultiDOFPoint)
    multi_dof_output: MultiDOFPoint = field(default_factory=MultiDOFPoint)
    multi_dof_desired: MultiDOFPoint = field(default_factory=MultiDOFPoint)
    multi_dof_actual: MultiDOFPoint = field(default_factory=MultiDOFPoint)


@dataclass
@annotate.final
class JazzyControllerState(IdlStruct, typename=_STATE):
    header: Header = field(default_factory=Header)
    joint_names: sequence[str] = field(default_factory=list)
    reference: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    feedback: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    error: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    output: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    multi_dof_joint_names: sequence[str] = field(default_factory=list)
    multi_dof_reference: MultiDOFPoint = field(default_factory=MultiDOFPoint)
    multi_dof_feedback: MultiDOFPoint = field(default_factory=MultiDOFPoint)
    multi_dof_error: MultiDOFPoint = field(default_factory=MultiDOFPoint)
    multi_dof_output: MultiDOFPoint = field(default_factory=MultiDOFPoint)
    speed_scaling_factor: float64 = 1.0


CONTROLLER_STATES: dict[str, type] = {
    "humble": HumbleControllerState,
    "jazzy": JazzyControllerState,
}


TYPES: dict[str, type] = {
    "builtin_interfaces/msg/Time": Time,
    "std_msgs/msg/Header": Header,
    "sensor_msgs/msg/JointState": JointState,
    "geometry_msgs/msg/Quaternion": Quaternion,
    "geometry_msgs/msg/Vector3": Vector3,
    "sensor_msgs/msg/Imu": Imu,
    "std_msgs/msg/MultiArrayDimension": MultiArrayDimension,
    "std_msgs/msg/MultiArrayLayout": MultiArrayLayout,
    "std_msgs/msg/Float64MultiArray": Float64MultiArray,
    "diagnostic_msgs/msg/KeyValue": KeyValue,
    "diagnostic_msgs/msg/DiagnosticStatus": DiagnosticStatus,
    "diagnostic_msgs/msg/DiagnosticArray": DiagnosticArray,
    "builtin_interfaces/msg/Duration": Duration,
    "trajectory_msgs/msg/JointTrajectoryPoint": JointTrajectoryPoint,
}


def _plain(value: Any) -> Any:
    """NumPy arrays and scalars (what the message factory builds with) as Python values."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    return value


class _Constructor:
    """An IDL class that takes NumPy values as ``rosbags`` classes do; other attributes (the
    status levels) are the class's."""

    def __init__(self, cls: type) -> None:
        self.cls = cls

    def __call__(self, **fields: Any) -> Any:
        return self.cls(**{k: _plain(v) for k, v in fields.items()})

    def __getattr__(self, name: str) -> Any:
        return getattr(self.cls, name)


class IdlStore:
    """Quacks like a ``rosbags`` typestore's ``.types`` for :class:`MessageFactory`."""

    def __init__(self) -> None:
        self.types = {name: _Constructor(cls) for name, cls in TYPES.items()}
