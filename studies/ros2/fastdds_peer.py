"""A real ROS 2 node on Fast DDS (rclpy from the ``ros-rclpy`` wheels, run in their own venv):
publishes or subscribes ``/arm1/joint_states`` and prints how many messages went through.

    python fastdds_peer.py publish 60     # 60 JointStates at 20 Hz, the UR driver's names
    python fastdds_peer.py subscribe 8    # listen 8 s (sensor-data QoS), print the count
"""

from __future__ import annotations

import sys
import time

import rclpy
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import JointState

TOPIC = "/arm1/joint_states"
UR_NAMES = ["elbow_joint", "shoulder_lift_joint", "shoulder_pan_joint", "wrist_1_joint",
            "wrist_2_joint", "wrist_3_joint"]  # fmt: skip


def publish(node: Node, count: int) -> None:
    pub = node.create_publisher(JointState, TOPIC, 10)
    time.sleep(2.0)  # discovery
    for k in range(count):
        msg = JointState()
        msg.header.stamp.sec, msg.header.stamp.nanosec = 1, k * 50_000_000
        msg.name = UR_NAMES
        msg.position, msg.velocity, msg.effort = [float(k)] * 6, [0.0] * 6, [0.0] * 6
        pub.publish(msg)
        time.sleep(0.05)
    time.sleep(1.0)
    print(f"fastdds publisher: {count} published", flush=True)


def subscribe(node: Node, seconds: float) -> None:
    got: list[JointState] = []
    node.create_subscription(JointState, TOPIC, got.append, qos_profile_sensor_data)
    started = time.monotonic()
    while time.monotonic() - started < seconds:
        rclpy.spin_once(node, timeout_sec=0.05)
    print(f"fastdds subscriber: {len(got)} received", flush=True)


def main() -> None:
    rclpy.init()
    node = Node("robohealth_interop")
    if sys.argv[1] == "publish":
        publish(node, int(sys.argv[2]))
    else:
        subscribe(node, float(sys.argv[2]))
    node.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
